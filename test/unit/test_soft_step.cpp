// The soft step (ResponseOptions::solver = soft, ContactSolver::solveSoft):
// the stiff scenes of the default solver's suite (stability_scenes.hpp) with
// the soft step, stored velocity against real motion, momentum, the cradle's
// energy, the same bits at 1 and 2 threads.
#include "stability_scenes.hpp"
#include "same_state.hpp"

#include "sphere_tree_collision/dynamics.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace stc::stability {
namespace {

constexpr double kRestingPenetration = 0.1;  // voxels, in resting scenes (as test_stability)
constexpr double kDrift = 0.1;               // voxels per second once settled

ResponseOptions soft() {
  ResponseOptions o;
  o.solver = SolverKind::Soft;
  return o;
}

void expectSane(const Scene& scene, const Metrics& m, double max_penetration, double energy_tolerance) {
  SCOPED_TRACE(scene.name);
  EXPECT_EQ(m.nan_count, 0u);
  EXPECT_LE(m.energy_gain, energy_tolerance);
  EXPECT_LE(m.max_penetration, max_penetration);
  EXPECT_LE(m.max_speed, scene.speed_bound);
}

TEST(SoftStep, StackOfTenCubesRestsAndStands) {
  Scene scene = stack(10, 0.05, 1.0 / 60.0, 10.0, 2.0, soft());
  const Metrics m = run(scene);
  expectSane(scene, m, kRestingPenetration, 1e-3);
  EXPECT_LE(m.drift, kDrift);
  EXPECT_LE(m.final_max_speed, 0.01);
  const auto& b = scene.world->bodies();
  for (std::size_t k = 1; k < scene.movers.size(); ++k) {
    const Vec3 d = b[scene.movers[k]].pose.position - b[scene.movers[k - 1]].pose.position;
    EXPECT_NEAR(d.z(), 8 * scene.voxel, kRestingPenetration * scene.voxel);
    // Settling shifts a cube sideways by up to 2.6 mm (0.05 voxel) at first; then it rests.
    EXPECT_LE(std::hypot(d.x(), d.y()), kRestingPenetration * scene.voxel);
  }
}

void expectMassRatioHolds(double ratio) {
  SCOPED_TRACE(ratio);
  Scene scene = massRatio(ratio, 5.0, soft());
  const std::size_t heavy = scene.movers.back();
  const Vec3 rest = scene.world->bodies()[heavy].pose.position;
  const Metrics m = run(scene);
  expectSane(scene, m, kRestingPenetration, 1e-3);
  EXPECT_LE(m.drift, kDrift);
  EXPECT_LE((scene.world->bodies()[heavy].pose.position - rest).norm(), kRestingPenetration * scene.voxel);
}

TEST(SoftStep, HeavyCubeOnLightCubesHoldsAtMassRatio10) { expectMassRatioHolds(10.0); }
TEST(SoftStep, HeavyCubeOnLightCubesHoldsAtMassRatio100) { expectMassRatioHolds(100.0); }
TEST(SoftStep, HeavyCubeOnLightCubesHoldsAtMassRatio1000) { expectMassRatioHolds(1000.0); }

TEST(SoftStep, OneVoxelSphereAtHundredMetresPerSecondDoesNotTunnelThroughAOneVoxelPlate) {
  Scene scene = fastSphere(100.0, 0.5, soft());
  const std::size_t ball = scene.movers.front();
  double lowest = 1e9;
  const Metrics m = run(scene, [&](const World& w, int) {
    lowest = std::min(lowest, w.bodies()[ball].pose.position.z());
  });
  expectSane(scene, m, 0.25, 1e-3);
  EXPECT_GT(lowest, 0.5 * scene.voxel);  // the plate's top face: the centre never passes it
  const BodyState& b = scene.world->bodies()[ball];
  EXPECT_NEAR(b.linear_velocity.z(), 50.0, 0.5);  // bounced back with e = 0.5
  EXPECT_GT(b.pose.position.z(), 1.0);
}

// A ball dropped onto a static plate, through the fall, the bounce and the
// rest: each tick it moves with a velocity between the ones stored at the
// tick's start and end (the tick moves by the mean of its substeps'
// velocities and stores the last one's; a landing stops it inside the tick),
// within 10 % + 0.05 m/s.
TEST(SoftStep, DroppedBallStoresTheVelocityItMovesWithAndComesToRest) {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  config.response = soft();
  World w(config);
  PresetParams p;
  p.resolution = 16;
  p.voxel_size = 0.125;
  const ShapeId plate = w.addShape("plate", makePreset("plate", p));
  EntitySpec floor;
  floor.shape = plate;
  floor.is_static = true;
  floor.pose.position = Vec3(0.0, 0.0, -0.5 * w.shape(plate).voxels.extent().z());
  w.addEntity(floor);
  p.resolution = 8;
  p.voxel_size = 0.05;
  const ShapeId sphere = w.addShape("sphere", makePreset("sphere", p));
  EntitySpec ball;
  ball.shape = sphere;
  ball.pose.position = Vec3(0.03, -0.02, 1.2);
  ball.material = Material{0.3, 0.5};
  w.addEntity(ball);
  const double dt = 1.0 / 60.0;
  int bounced = 0;
  for (int t = 0; t < 180; ++t) {
    const Vec3 before = w.bodies()[1].pose.position;
    const Vec3 v_start = w.bodies()[1].linear_velocity;
    w.step(dt, Budget::unlimited());
    const BodyState& b = w.bodies()[1];
    const Vec3 real = (b.pose.position - before) / dt;
    const double tolerance = 0.1 * real.norm() + 0.05;
    for (int axis = 0; axis < 3; ++axis) {
      const double lo = std::min(v_start[axis], b.linear_velocity[axis]) - tolerance;
      const double hi = std::max(v_start[axis], b.linear_velocity[axis]) + tolerance;
      EXPECT_TRUE(real[axis] >= lo && real[axis] <= hi)
          << "tick " << t << " axis " << axis << " stored " << v_start[axis] << " -> " << b.linear_velocity[axis]
          << " real " << real[axis];
    }
    if (v_start.z() < -1.0 && b.linear_velocity.z() > 0.5) ++bounced;
  }
  EXPECT_EQ(bounced, 1);  // e = 0.3: one bounce that shows at 60 Hz
  const BodyState& b = w.bodies()[1];
  EXPECT_LE(b.linear_velocity.norm(), 0.01);
  EXPECT_NEAR(b.pose.position.z(), 0.2, 0.1 * 0.05);  // on the plate, within a tenth of a voxel
}

// Two balls head-on in free space (as test_physics): momentum is kept.
TEST(SoftStep, HeadOnCollisionConservesMomentum) {
  WorldConfig config;
  config.response = soft();
  World w(config);
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 0.05;
  const ShapeId ball = w.addShape("sphere", makePreset("sphere", p));
  for (const auto& [x, v, density] : {std::tuple{-0.6, 2.0, 1000.0}, std::tuple{0.6, -1.0, 3000.0}}) {
    EntitySpec s;
    s.shape = ball;
    s.pose.position = Vec3(x, 0.0, 0.0);
    s.linear_velocity = Vec3(v, 0.0, 0.0);
    s.material = Material{0.5, 0.3};
    s.density = density;
    w.addEntity(s);
  }
  const Vec3 p0 = linearMomentum(w.bodies());
  int touching = 0;
  for (int i = 0; i < 240; ++i) {
    w.step(1.0 / 240.0, Budget::unlimited());
    if (!w.contacts().empty()) ++touching;
  }
  ASSERT_GT(touching, 0);
  const std::vector<BodyState>& b = w.bodies();
  EXPECT_LE((linearMomentum(b) - p0).norm(), 1e-9 * p0.norm());
  EXPECT_LE(b[0].linear_velocity.x(), b[1].linear_velocity.x());  // they separated
  // e = 0.5, m2 = 3 m1: relative speed 3 -> 1.5 m/s apart.
  EXPECT_NEAR(b[1].linear_velocity.x() - b[0].linear_velocity.x(), 1.5, 0.05);
}

double cradleEnergyKept(const ResponseOptions& response, double* highest_ratio) {
  Scene scene = newtonsCradle(5, 2.0, response);
  const std::vector<BodyState>& b = scene.world->bodies();
  double e0 = 0.0;
  for (const std::size_t i : scene.movers) e0 += kineticEnergy(b[i]);
  double highest = e0;
  run(scene, [&](const World& w, int) {
    double e = 0.0;
    for (const std::size_t i : scene.movers) e += kineticEnergy(w.bodies()[i]);
    highest = std::max(highest, e);
  });
  double e = 0.0;
  for (const std::size_t i : scene.movers) e += kineticEnergy(b[i]);
  *highest_ratio = highest / e0;
  return e / e0;
}

// Restitution comes first, in the default's waves: the soft step keeps the
// cradle's energy as the default solver does, and the last ball leaves.
TEST(SoftStep, NewtonsCradleKeepsItsEnergyAsTheDefaultDoes) {
  double highest_default = 0.0, highest_soft = 0.0;
  const double kept_default = cradleEnergyKept(ResponseOptions{}, &highest_default);
  const double kept_soft = cradleEnergyKept(soft(), &highest_soft);
  EXPECT_GE(kept_soft, kept_default - 0.01);
  EXPECT_LE(highest_soft, 1.0 + 1e-9);
  Scene scene = newtonsCradle(5, 2.0, soft());
  run(scene);
  const std::vector<BodyState>& b = scene.world->bodies();
  EXPECT_NEAR(b[scene.movers.back()].linear_velocity.x(), 1.0, 0.01);
  for (std::size_t k = 0; k + 1 < scene.movers.size(); ++k) EXPECT_NEAR(b[scene.movers[k]].linear_velocity.norm(), 0.0, 0.01);
}

TEST(SoftStep, SameBitsAtOneAndTwoThreads) {
  for (const SceneKind kind : {SceneKind::CornerDrift, SceneKind::Rockfall}) {
    const auto make = [&](int threads) {
      WorldConfig config;
      config.threads = threads;
      config.response = soft();
      config.response.solver_task_manifolds = 4;  // stages split into tasks from a few manifolds
      SceneParams params;
      params.entities = 100;
      return std::move(makeSceneWorld(kind, params, config).world);
    };
    World one = make(1);
    World two = make(2);
    std::size_t contacts = 0;
    for (int t = 0; t < 300; ++t) {
      one.step(1.0 / 60.0, Budget::unlimited());
      two.step(1.0 / 60.0, Budget::unlimited());
      contacts += one.contacts().size();
      ASSERT_TRUE(sameState(one, two)) << toString(kind) << " tick " << t;
    }
    EXPECT_GT(contacts, 0u);
  }
}

}  // namespace
}  // namespace stc::stability
