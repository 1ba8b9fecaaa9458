#include "sphere_union.hpp"

#include <algorithm>
#include <cmath>

namespace stc::truth {

void forEachUnionBoundaryPoint(const std::vector<Ball>& balls, double spacing,
                               const std::function<void(std::size_t, const Vec3&)>& visit) {
  // Balls that can hide part of ball i: those that intersect it.
  std::vector<std::vector<std::size_t>> neighbours(balls.size());
  for (std::size_t i = 0; i < balls.size(); ++i)
    for (std::size_t j = 0; j < balls.size(); ++j)
      if (i != j && (balls[i].centre - balls[j].centre).norm() < balls[i].radius + balls[j].radius)
        neighbours[i].push_back(j);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Ball& b = balls[i];
    const int n = std::max(16, static_cast<int>(4.0 * M_PI * b.radius * b.radius / (spacing * spacing)));
    for (int s = 0; s < n; ++s) {
      const double z = 1.0 - 2.0 * (s + 0.5) / n, rho = std::sqrt(1.0 - z * z);
      const Vec3 p = b.centre + b.radius * Vec3(rho * std::cos(golden * s), rho * std::sin(golden * s), z);
      const bool hidden = std::any_of(neighbours[i].begin(), neighbours[i].end(), [&](std::size_t j) {
        return (p - balls[j].centre).squaredNorm() < balls[j].radius * balls[j].radius;
      });
      if (!hidden) visit(i, p);
    }
  }
}

}  // namespace stc::truth
