// Physics correctness through the World (issue 4, item 4): collisions
// conserve what they must, a dropped ball rebounds to e^2 h and a sliding
// cube stops after v^2 / (2 mu g).
#include "sphere_tree_collision/dynamics.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace stc {
namespace {

constexpr double kG = 9.81;

ShapeId preset(World& w, const std::string& name, int resolution, double voxel) {
  PresetParams p;
  p.resolution = resolution;
  p.voxel_size = voxel;
  return w.addShape(name + std::to_string(resolution) + "_" + std::to_string(voxel), makePreset(name, p));
}

EntitySpec body(ShapeId shape, const Vec3& position, const Vec3& velocity, const Material& material,
                double density = 1000.0) {
  EntitySpec s;
  s.shape = shape;
  s.pose.position = position;
  s.linear_velocity = velocity;
  s.material = material;
  s.density = density;
  return s;
}

double relativeError(double value, double reference) {
  return std::abs(value - reference) / std::abs(reference);
}
double relativeError(const Vec3& value, const Vec3& reference) {
  return (value - reference).norm() / reference.norm();
}

// Two balls (0.4 m) head-on along x, no gravity; returns the world once they separate.
World headOn(double restitution) {
  World w;
  const ShapeId ball = preset(w, "sphere", 8, 0.05);
  const Material m{restitution, 0.0};
  w.addEntity(body(ball, Vec3(-0.6, 0.0, 0.0), Vec3(2.0, 0.0, 0.0), m, 1000.0));
  w.addEntity(body(ball, Vec3(0.6, 0.0, 0.0), Vec3(-1.0, 0.0, 0.0), m, 3000.0));
  return w;
}

TEST(Physics, HeadOnElasticCollisionConservesMomentumAndKineticEnergy) {
  World w = headOn(1.0);
  const Vec3 p0 = linearMomentum(w.bodies());
  const double e0 = kineticEnergy(w.bodies()[0]) + kineticEnergy(w.bodies()[1]);
  int touching = 0;
  for (int i = 0; i < 240; ++i) {
    w.step(1.0 / 240.0, Budget::unlimited());
    if (!w.contacts().empty()) ++touching;
  }
  ASSERT_GT(touching, 0);
  const std::vector<BodyState>& b = w.bodies();
  EXPECT_LE(relativeError(linearMomentum(b), p0), 1e-6);
  EXPECT_LE(relativeError(kineticEnergy(b[0]) + kineticEnergy(b[1]), e0), 1e-6);
  // 1D elastic, m2 = 3 m1: v1' = -2.5, v2' = 0.5.
  EXPECT_NEAR(b[0].linear_velocity.x(), -2.5, 1e-6);
  EXPECT_NEAR(b[1].linear_velocity.x(), 0.5, 1e-6);
  EXPECT_NEAR(b[0].linear_velocity.y(), 0.0, 1e-9);
}

TEST(Physics, InelasticCollisionEndsWithEqualNormalVelocities) {
  World w = headOn(0.0);
  const Vec3 p0 = linearMomentum(w.bodies());
  for (int i = 0; i < 240; ++i) w.step(1.0 / 240.0, Budget::unlimited());
  const std::vector<BodyState>& b = w.bodies();
  EXPECT_LE(relativeError(linearMomentum(b), p0), 1e-6);
  EXPECT_NEAR(b[0].linear_velocity.x(), b[1].linear_velocity.x(), 1e-6);
  EXPECT_NEAR(b[0].linear_velocity.x(), (2.0 - 3.0) / 4.0, 1e-6);  // (m 2 + 3m (-1)) / 4m
}

TEST(Physics, OffCentreHitConservesLinearAndAngularMomentum) {
  World w;
  const ShapeId ball = preset(w, "sphere", 8, 0.05);
  const ShapeId cube = preset(w, "cube", 8, 0.05);
  w.addEntity(body(ball, Vec3(-0.7, 0.13, 0.05), Vec3(3.0, 0.0, 0.0), Material{0.5, 0.5}));
  w.addEntity(body(cube, Vec3(0.0, 0.0, 0.0), Vec3::Zero(), Material{0.5, 0.5}, 500.0));
  const Vec3 p0 = linearMomentum(w.bodies());
  const Vec3 l0 = angularMomentum(w.bodies());
  int touching = 0;
  for (int i = 0; i < 240; ++i) {
    w.step(1.0 / 240.0, Budget::unlimited());
    if (!w.contacts().empty()) ++touching;
  }
  ASSERT_GT(touching, 0);
  const std::vector<BodyState>& b = w.bodies();
  EXPECT_GT(b[1].angular_velocity.norm(), 0.1);  // the hit was off-centre: the cube spins
  EXPECT_LE(relativeError(linearMomentum(b), p0), 1e-6);
  EXPECT_LE(relativeError(angularMomentum(b), l0), 1e-6);
  EXPECT_LT(kineticEnergy(b[0]) + kineticEnergy(b[1]), 0.5 * 3.0 * 3.0 / b[0].inv_mass);
}

// A static plate (2 m wide, 25 cm thick) with its top face at z = 0.
void addFloor(World& w, int resolution, double voxel, const Material& m) {
  const ShapeId plate = preset(w, "plate", resolution, voxel);
  EntitySpec floor;
  floor.shape = plate;
  floor.is_static = true;
  floor.material = m;
  const double thickness = w.shape(plate).voxels.extent().z();
  floor.pose.position = Vec3(0.0, 0.0, -0.5 * thickness);
  w.addEntity(floor);
}

TEST(Physics, DroppedBallReboundsToESquaredH) {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -kG);
  World w(config);
  const double e = 0.5, h = 1.0, radius = 0.2;
  addFloor(w, 16, 0.125, Material{e, 0.5});
  const ShapeId ball = preset(w, "sphere", 8, 0.05);
  w.addEntity(body(ball, Vec3(0.03, -0.02, h + radius), Vec3::Zero(), Material{e, 0.5}));
  double apex = 0.0;
  bool rebounded = false;
  for (int i = 0; i < 240 * 2; ++i) {
    w.step(1.0 / 240.0, Budget::unlimited());
    const BodyState& b = w.bodies()[1];
    if (b.linear_velocity.z() > 0.0) rebounded = true;
    if (rebounded) apex = std::max(apex, b.pose.position.z() - radius);
    if (rebounded && b.linear_velocity.z() < 0.0) break;  // past the first apex
  }
  ASSERT_TRUE(rebounded);
  EXPECT_NEAR(apex, e * e * h, 0.05 * e * e * h);
}

TEST(Physics, SlidingCubeStopsAfterVSquaredOverTwoMuG) {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -kG);
  World w(config);
  const double mu = 0.5, v0 = 3.0;
  addFloor(w, 32, 0.1, Material{0.0, mu});
  const ShapeId cube = preset(w, "cube", 8, 0.05);
  const double start = -1.2;
  w.addEntity(body(cube, Vec3(start, 0.0, 0.2), Vec3(v0, 0.0, 0.0), Material{0.0, mu}));
  const double dt = 1.0 / 240.0;
  int steps = 0;
  while (w.bodies()[1].linear_velocity.norm() > 1e-6 && steps < 240 * 3) {
    w.step(dt, Budget::unlimited());
    ++steps;
  }
  const BodyState& b = w.bodies()[1];
  const double expected = v0 * v0 / (2.0 * mu * kG);
  EXPECT_NEAR(b.pose.position.x() - start, expected, 0.05 * expected);
  EXPECT_NEAR(b.pose.position.y(), 0.0, 1e-3);
  EXPECT_NEAR(b.pose.position.z(), 0.2, 0.01 * 0.05);  // on the floor, not in it
  EXPECT_NEAR(steps * dt, v0 / (mu * kG), 0.05 * v0 / (mu * kG));
}

}  // namespace
}  // namespace stc
