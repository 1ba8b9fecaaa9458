// How deep two cubes of half side h overlap, by the separating axes of two
// boxes (their true shapes, not their spheres).
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {

// The least overlap over the 15 axes; < 0 when apart.
inline double cubeOverlap(const Pose& a, const Pose& b, double h) {
  const Mat3 ra = a.orientation.toRotationMatrix(), rb = b.orientation.toRotationMatrix();
  const Vec3 d = b.position - a.position;
  double least = std::numeric_limits<double>::infinity();
  const auto along = [&](const Vec3& axis) {
    const double length = axis.norm();
    if (length < 1e-9) return;
    const Vec3 u = axis / length;
    const double reach = h * ((ra.transpose() * u).cwiseAbs().sum() + (rb.transpose() * u).cwiseAbs().sum());
    least = std::min(least, reach - std::abs(d.dot(u)));
  };
  for (int i = 0; i < 3; ++i) {
    along(ra.col(i));
    along(rb.col(i));
    for (int j = 0; j < 3; ++j) along(ra.col(i).cross(rb.col(j)));
  }
  return least;
}

}  // namespace stc
