// minimalEnclosingSphere: known answers, degenerate voxel-corner inputs, and
// optimality against a brute force over all support sets of up to 4 points.
#include "enclosing_sphere.hpp"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <random>

namespace stc {
namespace {

bool encloses(const Sphere& s, const std::vector<Vec3>& points) {
  for (const Vec3& p : points)
    if ((p - s.centre).norm() > s.radius * (1.0 + 1e-12) + 1e-12) return false;
  return true;
}

// Smallest sphere through the given points (circumsphere in their affine hull),
// or radius -1 if they are affinely dependent.
Sphere through(const std::vector<Vec3>& q) {
  const int n = static_cast<int>(q.size());
  if (n == 1) return {q[0], 0.0};
  Eigen::MatrixXd a(3, n - 1);
  Eigen::VectorXd b(n - 1);
  for (int i = 1; i < n; ++i) {
    a.col(i - 1) = q[i] - q[0];
    b(i - 1) = a.col(i - 1).squaredNorm();
  }
  const Eigen::MatrixXd gram = 2.0 * a.transpose() * a;
  if (std::abs(gram.determinant()) < 1e-9) return {Vec3::Zero(), -1.0};
  const Vec3 c = q[0] + a * gram.ldlt().solve(b);
  return {c, (q[0] - c).norm()};
}

// Exhaustive: the smallest sphere through some 1..4 of the points that encloses all.
double bruteForceRadius(const std::vector<Vec3>& p) {
  const int n = static_cast<int>(p.size());
  double best = std::numeric_limits<double>::infinity();
  const auto consider = [&](const std::vector<Vec3>& support) {
    const Sphere s = through(support);
    if (s.radius >= 0.0 && s.radius < best && encloses(s, p)) best = s.radius;
  };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j) {
      consider({p[i], p[j]});
      for (int k = j + 1; k < n; ++k) {
        consider({p[i], p[j], p[k]});
        for (int l = k + 1; l < n; ++l) consider({p[i], p[j], p[k], p[l]});
      }
    }
  return best;
}

TEST(EnclosingSphere, KnownAnswers) {
  std::vector<Vec3> empty;
  EXPECT_EQ(minimalEnclosingSphere(empty).radius, 0.0);
  std::vector<Vec3> one = {Vec3(1, 2, 3)};
  EXPECT_EQ(minimalEnclosingSphere(one).radius, 0.0);
  std::vector<Vec3> two = {Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0.5, 0)};
  Sphere s = minimalEnclosingSphere(two);
  EXPECT_NEAR(s.radius, 1.0, 1e-12);
  EXPECT_TRUE(s.centre.isApprox(Vec3(1, 0, 0), 1e-12));
  // Cube corners, each repeated (shared by neighbouring voxels): many
  // cospherical and coplanar points.
  std::vector<Vec3> cube;
  for (int rep = 0; rep < 3; ++rep)
    for (int o = 0; o < 8; ++o) cube.emplace_back(o & 1, (o >> 1) & 1, (o >> 2) & 1);
  s = minimalEnclosingSphere(cube);
  EXPECT_NEAR(s.radius, std::sqrt(3.0) / 2.0, 1e-12);
  EXPECT_LT((s.centre - Vec3::Constant(0.5)).norm(), 1e-12);
  // A flat square of voxel corners: the answer is the circle's sphere.
  std::vector<Vec3> square;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) square.emplace_back(i, j, 0);
  s = minimalEnclosingSphere(square);
  EXPECT_NEAR(s.radius, std::sqrt(8.0), 1e-12);
}

TEST(EnclosingSphere, OptimalAgainstBruteForce) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> grid(0, 3);
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<Vec3> points;
    const int n = 5 + trial % 8;
    for (int i = 0; i < n; ++i) {
      // Half the trials on a coarse integer grid: ties and degeneracies.
      points.push_back(trial % 2 ? Vec3(u(rng), u(rng), u(rng)) : Vec3(grid(rng), grid(rng), grid(rng)));
    }
    const std::vector<Vec3> original = points;
    const Sphere s = minimalEnclosingSphere(points);
    EXPECT_TRUE(encloses(s, original)) << trial;
    EXPECT_NEAR(s.radius, bruteForceRadius(original), 1e-9) << trial;
  }
}

}  // namespace
}  // namespace stc
