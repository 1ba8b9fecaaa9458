// Smallest enclosing sphere of a point set (Welzl, iterative form).
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <vector>

namespace stc {

struct Sphere {
  Vec3 centre = Vec3::Zero();
  double radius = 0.0;
};

// Always a valid enclosing sphere: the radius is the exact max distance from
// the returned centre to the points (so rounding can only make it larger, by
// ulps, never leave a point out). Reorders `points` (random shuffle, fixed seed
// so results are reproducible). Empty input gives radius 0 at the origin.
Sphere minimalEnclosingSphere(std::vector<Vec3>& points);

}  // namespace stc
