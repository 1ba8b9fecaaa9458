// InteriorField: how deep a point lies inside a shape's voxels, and which way
// is out. A sphere-tree covers the surface only (paper 3.2): a body pressed
// more than a voxel into another is inside that body's shell of leaf spheres,
// where no leaf pair measures how deep it is, and no contact pushed it out
// (docs/response.md, "Bodies inside each other"). Built once per shape
// (ShapeLibrary::addShape) by an exact Euclidean distance transform.
#pragma once

#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstdint>
#include <vector>

namespace stc {

// What InteriorField::probe says of a point (body frame).
struct InteriorProbe {
  bool inside = false;  // in an occupied voxel
  // Inside: the distance to the nearest empty voxel (metres, > 0 but on the
  // surface). Outside: minus the distance to the nearest occupied voxel, at
  // most that far (within a voxel's diagonal of it).
  double depth = 0.0;
  Vec3 out = Vec3::Zero();  // inside: unit direction to that empty voxel (body frame)
};

class InteriorField {
 public:
  InteriorField() = default;
  // body_origin: the grid-frame point the body frame is centred on (ShapeInfo::body_origin).
  // A grid whose padded box has more than kMaxCells cells gets no field
  // (built() false: its pairs keep their surface contacts only).
  InteriorField(const VoxelShape& voxels, const Vec3& body_origin);
  // 2^21: 10 MB kept and about 60 MB while it is built (a 128^3 grid fits; a
  // 2,000 x 2,000 plate, 4 million voxels and 12 million padded cells, does not).
  static constexpr std::int64_t kMaxCells = std::int64_t{1} << 21;

  InteriorProbe probe(const Vec3& point_body) const;
  double voxelSize() const { return voxel_; }
  bool built() const { return !nearest_.empty(); }

 private:
  // The grid padded by one empty cell on every side: every occupied cell has
  // an empty one to escape to. Padded cell (i, j, k) is grid cell (i-1, j-1, k-1).
  std::size_t cellIndex(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(px_) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(py_) * k);
  }
  int px_ = 0, py_ = 0, pz_ = 0;
  double voxel_ = 0.0;
  Vec3 corner_ = Vec3::Zero();               // the padded grid's min corner (body frame)
  std::vector<std::uint8_t> solid_;          // per padded cell
  std::vector<std::int32_t> nearest_;        // per padded cell: the nearest cell of the other kind
};

}  // namespace stc
