// A solid cube of voxels with its sphere-tree and node bounds, for tests of
// the contact steps: 4 x 4 x 4 voxels of 10 cm, body origin at its centre.
#pragma once

#include "shape_bounds.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstdint>
#include <vector>

namespace stc_test {

struct SolidCube {
  stc::VoxelShape shape = stc::VoxelShape::create(4, 4, 4, 0.1, std::vector<std::uint8_t>(64, 1));
  stc::Vec3 origin = stc::Vec3::Constant(0.2);
  stc::SphereTree tree = stc::SphereTree::build(shape, origin);
  stc::ShapeBounds bounds = stc::makeShapeBounds(tree, &shape, origin);
};

}  // namespace stc_test
