// Random poses for tests and benchmarks: uniform rotations and directions from
// a seeded engine, so every run draws the same cases.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <random>

namespace stc::truth {

using Rng = std::mt19937_64;

// Uniform over the unit sphere.
Vec3 randomDirection(Rng& rng);
// Uniform over SO(3) (Shoemake's method).
Quat randomRotation(Rng& rng);
// Uniform in [lo, hi).
double randomUniform(Rng& rng, double lo, double hi);

}  // namespace stc::truth
