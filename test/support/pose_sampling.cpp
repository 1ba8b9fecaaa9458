#include "pose_sampling.hpp"

#include <algorithm>
#include <cmath>

namespace stc::truth {

double randomUniform(Rng& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

Vec3 randomDirection(Rng& rng) {
  const double z = randomUniform(rng, -1.0, 1.0);
  const double phi = randomUniform(rng, 0.0, 2.0 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

Quat randomRotation(Rng& rng) {
  const double u1 = randomUniform(rng, 0.0, 1.0);
  const double u2 = randomUniform(rng, 0.0, 2.0 * M_PI);
  const double u3 = randomUniform(rng, 0.0, 2.0 * M_PI);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  return Quat(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3)).normalized();
}

}  // namespace stc::truth
