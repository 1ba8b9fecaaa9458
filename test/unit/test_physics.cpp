// Physics correctness through the World (issue 4, item 4): collisions
// conserve what they must, a dropped ball rebounds to e^2 h and a sliding
// cube stops after v^2 / (2 mu g).
#include "dynamics.hpp"
#include "physics.hpp"
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

// Flat ground for a ball: a plate's voxels give it bumps (its leaf spheres)
// that would hold and shake a rolling ball, so the ground is the top of a
// static ball of radius 1 km centred 1 km below z = 0 (over 2 m it drops 2 mm).
void addRoundGround(World& w, const Material& m) {
  const ShapeId globe = preset(w, "sphere", 8, 250.0);
  EntitySpec ground;
  ground.shape = globe;
  ground.is_static = true;
  ground.material = m;
  ground.pose.position = Vec3(0.0, 0.0, -1000.0);
  w.addEntity(ground);
}

// A ball (0.2 m, the sphere preset) on the ground, rolling along +x at v0
// without slipping (w = v0 / r about +y), under gravity g (which may lean
// along x: a slope). Returns the world; the ball is entity 1.
World rollingBall(double rolling_resistance, const Vec3& gravity, double v0, double start) {
  WorldConfig config;
  config.gravity = gravity;
  World w(config);
  const double radius = 0.2;
  Material m{0.0, 0.8};
  m.rolling_resistance = rolling_resistance;
  addRoundGround(w, m);
  const ShapeId ball = preset(w, "sphere", 8, 0.05);
  EntitySpec s = body(ball, Vec3(start, 0.0, radius), Vec3(v0, 0.0, 0.0), m);
  s.angular_velocity = Vec3(0.0, v0 / radius, 0.0);
  w.addEntity(s);
  return w;
}

TEST(Physics, BallRollsOnWithoutRollingResistance) {
  const double v0 = 1.0, start = -1.2, dt = 1.0 / 120.0;
  World w = rollingBall(0.0, Vec3(0.0, 0.0, -kG), v0, start);
  const double e0 = kineticEnergy(w.bodies()[1]);
  double path = 0.0;  // what the stored velocity adds up to
  for (int i = 0; i < 240; ++i) {
    w.step(dt, Budget::unlimited());
    path += w.bodies()[1].linear_velocity.x() * dt;
  }
  const BodyState& b = w.bodies()[1];
  EXPECT_GT(b.linear_velocity.x(), 0.97 * v0);
  EXPECT_GT(kineticEnergy(b), 0.95 * e0);
  // Still rolling, not sliding (w r within 4 %: the contact point sits a
  // little inside the ball, so it rolls on a slightly smaller radius).
  EXPECT_NEAR(b.angular_velocity.y() * 0.2, b.linear_velocity.x(), 0.04 * v0);
  EXPECT_NEAR(b.pose.position.x() - start, path, 0.01);                      // stored velocity = motion
  EXPECT_GT(b.pose.position.x() - start, 1.9 * v0);
  EXPECT_NEAR(b.pose.position.z(), 0.2, 0.005);
}

// Rolling resistance c: a torque c r N against the roll. A solid ball then
// slows at a = c g / (1 + 2/5) = 5 c g / 7 and stops after v0^2 / (2 a).
TEST(Physics, RollingResistanceStopsABallAfterVSquaredOverTwoA) {
  const double c = 0.1, v0 = 1.0, start = -1.2, dt = 1.0 / 120.0;
  World w = rollingBall(c, Vec3(0.0, 0.0, -kG), v0, start);
  const double a = 5.0 * c * kG / 7.0;
  int steps = 0;
  while (w.bodies()[1].linear_velocity.x() > 1e-3 && steps < 600) {
    w.step(dt, Budget::unlimited());
    ++steps;
  }
  const double stop = w.bodies()[1].pose.position.x();
  EXPECT_NEAR(stop - start, v0 * v0 / (2.0 * a), 0.05 * v0 * v0 / (2.0 * a));
  EXPECT_NEAR(steps * dt, v0 / a, 0.05 * v0 / a);
  // It stays where it stopped: the resistance only opposes, never drives.
  for (int i = 0; i < 120; ++i) w.step(dt, Budget::unlimited());
  EXPECT_NEAR(w.bodies()[1].pose.position.x(), stop, 2e-3);
}

// On a slope of angle t the ball is held when c >= tan t (torque about the
// contact), else it rolls down at a = 5 g (sin t - c cos t) / 7.
TEST(Physics, RollingResistanceHoldsABallOnASlopeOnlyAboveTanTheta) {
  const double slope = 10.0 * 3.14159265358979 / 180.0, dt = 1.0 / 120.0, start = 0.0;
  const Vec3 g = kG * Vec3(std::sin(slope), 0.0, -std::cos(slope));  // downhill: +x
  for (const double c : {0.25, 0.1}) {  // tan 10 deg = 0.176
    World w = rollingBall(c, g, 0.0, start);
    for (int i = 0; i < 120; ++i) w.step(dt, Budget::unlimited());
    const double x = w.bodies()[1].pose.position.x() - start;
    if (c > std::tan(slope)) {
      EXPECT_LT(std::abs(x), 1e-3) << "c = " << c;
    } else {
      const double a = 5.0 * kG * (std::sin(slope) - c * std::cos(slope)) / 7.0;
      EXPECT_NEAR(x, 0.5 * a, 0.1 * 0.5 * a) << "c = " << c;
      EXPECT_NEAR(w.bodies()[1].linear_velocity.x(), a, 0.1 * a) << "c = " << c;
    }
  }
}

}  // namespace
}  // namespace stc
