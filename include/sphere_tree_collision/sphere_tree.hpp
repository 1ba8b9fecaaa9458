// SphereTree: octree sphere-tree of a VoxelShape (paper 3.3.1), stored as one
// flat breadth-first array with contiguous children.
#pragma once

#include "sphere_tree_collision/voxel_shape.hpp"

#include <string>
#include <vector>

namespace stc {

enum class SphereFit : std::uint8_t {
  Paper,  // circumscribed sphere of the octree cell (r = sqrt(3) a / 2)
  // Of the smallest sphere around the cell's surface voxels, the smallest around
  // its occupied voxels, and the paper sphere: the one with the smallest h.
  // Never larger (radius) nor looser (h) than Paper on the same cell.
  Tight,
};
// "paper" | "tight"; throws InputError("sphere_fit") otherwise.
SphereFit parseSphereFit(const std::string& name);
const char* toString(SphereFit fit);

struct SphereTreeOptions {
  int max_levels = 4;  // 1..8; throws InputError("max_levels") otherwise
  SphereFit fit = SphereFit::Tight;
};

struct SphereNode {
  Vec3 centre = Vec3::Zero();  // body frame
  double radius = 0.0;
  // Max distance from a point of this sphere (the whole ball, centre included)
  // to the shape part it covers (the occupied voxels of its octree cell); a
  // rigorous upper bound, within 0.1 voxel + 3% of the radius of the true
  // value. If spheres a and b touch, overlap or nest, the true gap between the
  // shapes is <= h_a + h_b. Plus the shape's surfaceMargin(), so that for a
  // voxelised mesh the bound holds for the mesh, not only for its voxels.
  double h = 0.0;
  std::int32_t first_child = -1;  // index of the first child; children contiguous
  std::int32_t child_count = 0;
  std::int32_t parent = -1;
  std::int32_t level = 0;
};

class SphereTree {
 public:
  // Body frame = grid frame translated by -body_origin (usually the centre of
  // mass), so node centres are relative to body_origin.
  // Every level covers every surface voxel completely; cells that hold no
  // surface voxel (occluded on all six sides) are removed with their subtree.
  // A shape with isSphere() gets a one-level tree.
  static SphereTree build(const VoxelShape& shape, const Vec3& body_origin,
                          const SphereTreeOptions& options = SphereTreeOptions{});

  const std::vector<SphereNode>& nodes() const { return nodes_; }
  const SphereNode& node(std::int32_t i) const { return nodes_[static_cast<std::size_t>(i)]; }
  const SphereNode& root() const { return nodes_.front(); }
  bool isLeaf(std::int32_t i) const { return node(i).child_count == 0; }
  int levelCount() const { return static_cast<int>(level_begin_.size()) - 1; }
  // Nodes of level L are [levelBegin(L), levelBegin(L + 1)).
  std::int32_t levelBegin(int level) const { return level_begin_[static_cast<std::size_t>(level)]; }
  SphereFit fit() const { return fit_; }

 private:
  std::vector<SphereNode> nodes_;
  std::vector<std::int32_t> level_begin_;  // levelCount() + 1 entries
  SphereFit fit_ = SphereFit::Tight;
};

}  // namespace stc
