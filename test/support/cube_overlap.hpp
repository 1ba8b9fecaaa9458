// How deep two cubes of half side h overlap, by the separating axes of two
// boxes (their true shapes, not their spheres), and the deepest overlap of
// a world of cubes over its ticks.
#pragma once

#include "physics.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

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

// `ticks` unlimited ticks of a world of cubes of half side h: the deepest
// overlap of two movable cubes in contact at the end of any tick, and how
// many times the swept test held a body back.
struct CubeOverlapRun {
  double deepest = -1.0;
  int held_back = 0;
};
inline CubeOverlapRun deepestCubeOverlap(World& w, int ticks, double dt, double h) {
  CubeOverlapRun run;
  for (int s = 0; s < ticks; ++s) {
    w.step(dt, Budget::unlimited());
    run.held_back += static_cast<int>(physicsReport(w).sweep.clamped);
    const std::vector<BodyState>& b = w.bodies();
    for (const Contact& c : w.contacts()) {
      if (b[c.index_a].is_static || b[c.index_b].is_static) continue;
      run.deepest = std::max(run.deepest, cubeOverlap(b[c.index_a].pose, b[c.index_b].pose, h));
    }
  }
  return run;
}

}  // namespace stc
