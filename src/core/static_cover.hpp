// Faces of static bodies' voxel boxes that are not surfaces: inside the
// body's own voxels, against another static body lying flush (a floor of
// tiles, where each tile's rim meets its neighbour), or closed by the user
// (EntitySpec::closed_faces: the back of a one-sided wall). A contact normal
// through such a face points into solid ground: a body pressed into a seam
// was pushed sideways by both tiles and by nothing up, and sank (the
// internal-edge problem of tiled static geometry). PairGeometry::refine
// keeps every normal out of covered faces, so tiles hold a body as one floor.
#pragma once

#include "shape_bounds.hpp"
#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace stc {

// What the cover needs of a shape: its grid, the grid point the body frame is
// centred on (ShapeInfo::body_origin) and its node boxes.
struct CoverShape {
  const VoxelShape* voxels = nullptr;
  Vec3 body_origin = Vec3::Zero();
  const ShapeBounds* bounds = nullptr;
};

// Per static body (dense index, kept parallel to the World's arrays), per
// node: the covered faces of its voxel box. A face is covered when the points
// just outside it, one per voxel of the face (at most 16 x 16), all lie in
// occupied voxels of the body or of another static body. A body's closed
// faces (EntitySpec::closed_faces) are covered on every node. Movable bodies
// have no mask: their faces move apart. An update measures again only the
// static bodies added or moved since the last one and those near them or
// near where one was removed.
class StaticCover {
 public:
  void add(const BodyState& body, std::uint8_t closed_faces = 0);  // a body appended at the end
  void remove(std::size_t index, std::size_t last);  // swap-remove, as the World's arrays
  void clear();
  // Measures the masks again where a static body came, went or moved since
  // the last call (never per tick otherwise). shapes: by the bodies' shape ids. Returns whether it rebuilt.
  bool update(const std::vector<BodyState>& bodies, const std::vector<std::uint32_t>& body_shapes,
              const std::vector<CoverShape>& shapes);
  // The node masks of body `index` (faceBit per node), nullptr when none of
  // its faces is covered (every movable body).
  const std::uint8_t* of(std::size_t index) const {
    return index < masks_.size() && !masks_[index].empty() ? masks_[index].data() : nullptr;
  }
  // EntitySpec::closed_faces of body `index`, as added.
  std::uint8_t closedFaces(std::size_t index) const { return closed_[index]; }

 private:
  std::vector<std::vector<std::uint8_t>> masks_;  // by dense index; empty: nothing covered
  std::vector<Pose> poses_;                       // static poses the masks were built for
  std::vector<std::uint8_t> is_static_;
  std::vector<std::uint8_t> closed_;              // EntitySpec::closed_faces
  std::vector<std::uint8_t> dirty_;               // static, added or moved since the last update
  std::vector<Vec3> removed_;                     // where static bodies left from since then
  bool stale_ = false;
};

}  // namespace stc
