// Sample points on the boundary of a union of spheres (a sphere-tree level):
// the fit-error measure of docs/tightness.md and docs/meshes.md.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <cstddef>
#include <functional>
#include <vector>

namespace stc::truth {

struct Ball {
  Vec3 centre;
  double radius = 0.0;
};

// Area-uniform (Fibonacci) points about `spacing` apart on each ball's sphere
// (at least 16 per ball), keeping those outside every other ball: the
// boundary of the union. `visit(ball index, point)` sees each kept point.
void forEachUnionBoundaryPoint(const std::vector<Ball>& balls, double spacing,
                               const std::function<void(std::size_t, const Vec3&)>& visit);

}  // namespace stc::truth
