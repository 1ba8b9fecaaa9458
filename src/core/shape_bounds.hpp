// Per-shape bounds of every sphere-tree node, computed once per shape (the
// World builds them in addShape): the voxels' box inside each sphere (contact
// surfaces) and the leaves' reach below each node (sweeps).
#pragma once

#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace stc {

// Where the shape is inside each node's sphere. A sphere only says the shape
// lies within r of its centre (up to h inside for a leaf); the voxels whose
// centres lie in the sphere also bound it by their axis-aligned box (body
// frame). The surface of the node towards a direction u is then taken at
// support(u) = min(r, box support): an outer bound of the node's part of the
// shape, exact for a single-voxel leaf (a cube) and for a box-shaped part
// face-on, where r alone leaves a gap of up to h.
struct ShapeBounds {
  const SphereTree* tree = nullptr;
  std::vector<Vec3> box_offset;  // per node: box centre minus sphere centre (body frame)
  std::vector<Vec3> box_half;    // per node: box half extents
  std::vector<double> reach;     // per node: max over its leaves of |c_leaf - c_node| + r_leaf
  std::vector<double> thinnest;  // per node: least half extent of its leaves' boxes (sweeps)
  // Per node: the box of its leaves' boxes (body frame, centre and half
  // extents): a leaf box's extent along any body axis lies within it (sweeps).
  std::vector<Vec3> leaves_centre;
  std::vector<Vec3> leaves_half;
  double min_leaf_radius = 0.0;
  double bound_radius = 0.0;     // max over leaves of |c_leaf| + r_leaf (about the body origin)

  // Distance from node's centre to its surface towards `direction_body` (unit, body frame).
  double support(std::int32_t node, const Vec3& direction_body) const {
    const std::size_t i = static_cast<std::size_t>(node);
    const double box = box_offset[i].dot(direction_body) + box_half[i].dot(direction_body.cwiseAbs());
    return std::min(tree->node(node).radius, box);
  }
};
// voxels == nullptr: boxes are the spheres' cubes (support = r). body_origin:
// the grid-frame point the tree was built about (ShapeInfo::body_origin).
ShapeBounds makeShapeBounds(const SphereTree& tree, const VoxelShape* voxels = nullptr,
                            const Vec3& body_origin = Vec3::Zero());

}  // namespace stc
