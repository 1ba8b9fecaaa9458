// Welzl's smallest enclosing ball as nested incremental loops (expected linear
// time after a shuffle; no deep recursion). Degenerate support sets (coplanar
// or coincident points, common with voxel corners) are handled by solving for
// the smallest sphere through them in their affine hull with a rank-revealing
// least-squares solve, and the final radius is recomputed exactly.
#include "enclosing_sphere.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <random>

namespace stc {
namespace {

// Smallest sphere whose boundary passes through all of q[0..n) (n <= 4).
Sphere sphereThrough(const Vec3* q, int n) {
  if (n == 0) return {Vec3::Zero(), -1.0};
  if (n == 1) return {q[0], 0.0};
  // c = q0 + A lambda, with 2 (q_i - q0) . (c - q0) = |q_i - q0|^2.
  // Fixed maximum sizes: no heap allocation per support set.
  Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, 3> a(3, n - 1);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> b(n - 1);
  for (int i = 1; i < n; ++i) {
    a.col(i - 1) = q[i] - q[0];
    b(i - 1) = a.col(i - 1).squaredNorm();
  }
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3> gram = 2.0 * a.transpose() * a;
  const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1> lambda =
      gram.completeOrthogonalDecomposition().solve(b);
  const Vec3 c = q[0] + a * lambda;
  double r2 = 0.0;
  for (int i = 0; i < n; ++i) r2 = std::max(r2, (q[i] - c).squaredNorm());
  return {c, std::sqrt(r2)};
}

bool outside(const Sphere& s, const Vec3& p) {
  if (s.radius < 0.0) return true;
  const double r = s.radius * (1.0 + 1e-12) + 1e-12;
  return (p - s.centre).squaredNorm() > r * r;
}

}  // namespace

Sphere minimalEnclosingSphere(std::vector<Vec3>& points) {
  if (points.empty()) return {};
  std::mt19937 rng(0x5eed);
  std::shuffle(points.begin(), points.end(), rng);
  const std::size_t n = points.size();
  Vec3 support[4];
  Sphere s = sphereThrough(points.data(), 1);
  for (std::size_t i = 1; i < n; ++i) {
    if (!outside(s, points[i])) continue;
    support[0] = points[i];
    s = sphereThrough(support, 1);
    for (std::size_t j = 0; j < i; ++j) {
      if (!outside(s, points[j])) continue;
      support[1] = points[j];
      s = sphereThrough(support, 2);
      for (std::size_t k = 0; k < j; ++k) {
        if (!outside(s, points[k])) continue;
        support[2] = points[k];
        s = sphereThrough(support, 3);
        for (std::size_t l = 0; l < k; ++l) {
          if (!outside(s, points[l])) continue;
          support[3] = points[l];
          s = sphereThrough(support, 4);
        }
      }
    }
  }
  // Exact radius about the final centre: a valid enclosure whatever rounding did.
  double r2 = 0.0;
  for (const Vec3& p : points) r2 = std::max(r2, (p - s.centre).squaredNorm());
  s.radius = std::sqrt(r2);
  return s;
}

}  // namespace stc
