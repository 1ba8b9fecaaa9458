// The soft step (ResponseOptions::solver = soft, ContactSolver::solveSoft):
// the stiff scenes of the default solver's suite (stability_scenes.hpp) with
// the soft step, stored velocity against real motion, momentum, the cradle's
// energy, the same bits at 1 and 2 threads.
#include "cube_overlap.hpp"
#include "same_state.hpp"
#include "stability_scenes.hpp"
#include "stepping_clock.hpp"

#include "contact_solver.hpp"
#include "deadline.hpp"
#include "dynamics.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

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

// corner_drift's 40 rocks on their way into the corner (45 ticks in), and a
// ball falling free high above them, with the soft step.
World cornerWithAFreeBall() {
  WorldConfig config;
  config.response = soft();
  SceneParams params;
  params.entities = 40;
  World w = std::move(makeSceneWorld(SceneKind::CornerDrift, params, config).world);
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 0.05;
  EntitySpec ball;
  ball.shape = w.addShape("free_sphere", makePreset("sphere", p));
  ball.pose.position = Vec3(0.0, 0.0, 40.0);
  w.addEntity(ball);
  for (int t = 0; t < 45; ++t) w.step(1.0 / 60.0, Budget::unlimited());
  return w;
}

// A body with no contact moved the whole tick: it stores v0 + g dt, and its
// fall beyond v0 dt is along g, between a half and a whole g dt^2 (one
// substep falls g dt^2, many nearly g dt^2 / 2). One moved only part of the
// tick falls short.
void expectMovedTheWholeTick(const BodyState& before, const BodyState& after, const Vec3& gravity, double dt) {
  EXPECT_LE((after.linear_velocity - (before.linear_velocity + gravity * dt)).norm(), 1e-9);
  const Vec3 down = gravity.normalized();
  const Vec3 fall = after.pose.position - before.pose.position - before.linear_velocity * dt;
  EXPECT_GE(fall.dot(down), 0.5 * gravity.norm() * dt * dt - 1e-12);
  EXPECT_LE(fall.dot(down), gravity.norm() * dt * dt + 1e-12);
  EXPECT_LE((fall - fall.dot(down) * down).norm(), 1e-12);
}

// The soft step under a deadline on a fake clock (every read costs 1 ms, so
// the first substep is priced at 1 ms and the cut is the same on any machine
// under any load), on the rocks' contacts of one tick: a spent deadline gives
// one substep (two passes), more time never fewer, the substeps that do not
// fit merge into fewer, longer ones, a far deadline gives every one (a
// deadline of 1e12 s included: left / each is past any int), and
// max_iterations caps them. Whatever the cut, the rocks' state stays finite
// and the free ball moves the whole tick.
TEST(SoftStep, TheSolveBudgetCutsSubstepsAndTheBodiesStillMoveTheWholeTick) {
  constexpr double kDt = 1.0 / 60.0;
  World w = cornerWithAFreeBall();
  const Vec3 gravity = sceneGravity(SceneKind::CornerDrift);
  const std::vector<BodyState> start = w.bodies();
  w.step(kDt, Budget::unlimited());
  ASSERT_GT(w.contacts().size(), 20u);
  // The poses the tick's contacts were found at: integrate's prediction.
  std::vector<BodyState> predicted = start;
  IntegrationOptions integration;
  integration.gravity = gravity;
  integration.gyroscopic = soft().gyroscopic;
  std::vector<Pose> start_poses;
  std::vector<Vec3> start_v, start_w;
  for (BodyState& b : predicted) {
    start_poses.push_back(b.pose);
    start_v.push_back(b.linear_velocity);
    start_w.push_back(b.angular_velocity);
    if (b.is_static) continue;
    integratePosition(b, integration, kDt);
    integrateVelocity(b, integration, kDt);
  }
  const ContactSolver::TickStart tick_start{&start_poses, &start_v, &start_w, nullptr};
  const auto solveWithin = [&](const SolveBudget& budget) {
    std::vector<BodyState> bodies = predicted;
    std::vector<Contact> contacts = w.contacts();
    ContactSolver solver;
    const SolveStats stats = solver.solveSoft(bodies, contacts, soft(), kDt, tick_start, budget);
    for (const BodyState& b : bodies) {
      EXPECT_TRUE(allFinite(b.pose.position) && allFinite(b.linear_velocity) && allFinite(b.angular_velocity));
    }
    expectMovedTheWholeTick(start.back(), bodies.back(), gravity, kDt);
    return stats.velocity_passes;
  };
  const int full = solveWithin(SolveBudget{});
  EXPECT_EQ(full, 2 * soft().substeps);
  int previous = 0;
  for (const double seconds_left : {0.0, 0.0025, 0.0045, 0.0065, 1000.0, 1e12}) {
    SCOPED_TRACE(seconds_left);
    const SecondsClock clock = steppingClock(1e-3);
    SolveBudget budget;
    budget.deadline = Deadline(&clock, seconds_left);
    const int passes = solveWithin(budget);
    EXPECT_GE(passes, previous);
    previous = passes;
    // Read at 0 ms (passed?), 1 (the first substep's start) and 2 (its end):
    // what is left at 2 ms buys a substep a millisecond, the rest of the tick
    // in at least one more.
    if (seconds_left == 0.0) EXPECT_EQ(passes, 2);
    if (seconds_left == 0.0025) EXPECT_EQ(passes, 4);
    if (seconds_left == 0.0045) EXPECT_EQ(passes, 6);
    if (seconds_left >= 0.0065) EXPECT_EQ(passes, full);
  }
  for (const int cap : {0, 1, 2, 3}) {
    SolveBudget budget;
    budget.max_iterations = cap;
    EXPECT_EQ(solveWithin(budget), 2 * std::max(cap, 1)) << cap;
  }
}

// Through the World: a tick whose budget is spent before the solve runs one
// substep, a far budget all of them, and the free ball moves the whole tick
// (or, held by its island's level, stays where it was).
TEST(SoftStep, ATickBudgetReachesTheSoftStep) {
  constexpr double kDt = 1.0 / 60.0;
  const Vec3 gravity = sceneGravity(SceneKind::CornerDrift);
  int passes[2] = {0, 0};
  for (const int far : {0, 1}) {
    World w = cornerWithAFreeBall();
    w.setClock(steppingClock(1e-4));
    const BodyState before = w.bodies().back();
    const TickReport report = w.step(kDt, Budget::ofTickSeconds(far ? 1e6 : 0.0));
    ASSERT_GT(report.response.contacts, 0u);
    passes[far] = report.response.velocity_passes;
    if (w.responseLevel(w.entityIds().back()) == ResponseLevel::Full) {
      expectMovedTheWholeTick(before, w.bodies().back(), gravity, kDt);
    } else {
      EXPECT_EQ(w.bodies().back().pose.position, before.pose.position);
    }
  }
  EXPECT_EQ(passes[0], 2);
  EXPECT_EQ(passes[1], 2 * soft().substeps);
}

// The swept test put a body back at its first hit; nothing else stops it
// this tick (no contact at all), yet in no substep does it go further along
// its path than the hit, and it keeps no speed onward along it. Sideways it
// is free: a hit holds back only what would pass through.
TEST(SoftStep, ABodyTheSweepPutBackGoesNoFurtherAlongItsPath) {
  constexpr double kDt = 1.0 / 60.0;
  BodyState body;
  body.inv_mass = 1.0;
  body.inv_inertia_body = Mat3::Identity();
  refreshWorldInertia(body);
  const Vec3 start(0.0, 0.0, 1.0);
  const Vec3 velocity(-30.0, 0.0, -30.0);       // along the path, towards what it hit
  const Vec3 hit = start + 0.25 * kDt * velocity;  // put back a quarter of the tick along it
  body.pose.position = hit;
  body.linear_velocity = velocity + Vec3(0.0, 5.0, 0.0);  // and sideways, which no hit stops
  std::vector<BodyState> bodies{body};
  std::vector<Contact> contacts;
  const std::vector<Pose> start_poses{Pose{start, Quat::Identity()}};
  const std::vector<Vec3> start_v{body.linear_velocity}, start_w{Vec3::Zero()};
  const std::vector<std::uint32_t> held{0};
  ContactSolver solver;
  const ResponseOptions options = soft();
  solver.solveSoft(bodies, contacts, options, kDt, ContactSolver::TickStart{&start_poses, &start_v, &start_w, &held});
  const Vec3 direction = velocity.normalized();
  const BodyState& b = bodies[0];
  EXPECT_NEAR((b.pose.position - start).dot(direction), (hit - start).norm(), 1e-12);
  EXPECT_NEAR(b.linear_velocity.dot(direction), 0.0, 1e-12);
  EXPECT_NEAR(b.linear_velocity.y(), 5.0, 1e-12);
  EXPECT_GT(b.pose.position.y(), 0.0);  // it moved sideways
  // Not held, the same body flies the whole tick.
  std::vector<BodyState> free{body};
  solver.solveSoft(free, contacts, options, kDt, ContactSolver::TickStart{&start_poses, &start_v, &start_w, nullptr});
  EXPECT_NEAR((free[0].pose.position - start).dot(direction), kDt * velocity.norm(), 1e-9);
}

// cube_box as built (1,000 cubes falling onto a floor into a pile), with the
// soft step, its first 2 s: the swept test holds back cubes landing on
// others, and the substeps then keep them near where it put them: at the
// end of every tick no two cubes overlap by more than a voxel (test_continuous
// asks the same of the default solver). Before a held cube was kept from
// going further, the substeps took it on through the cube it hit: 0.38 m,
// nearly a cube's half side, of overlap.
TEST(SoftStep, CubeBoxCubesStayNearlyWhereTheSweepPutThem) {
  constexpr double kVoxel = 0.05;
  WorldConfig config;
  config.response = soft();
  SceneWorld scene = makeSceneWorld(SceneKind::CubeBox, SceneParams{}, config);
  World& w = scene.world;
  const CubeOverlapRun run = deepestCubeOverlap(w, 120, 1.0 / 60.0, 0.2);
  EXPECT_GT(run.held_back, 0);
  EXPECT_LT(run.deepest, 1.5 * kVoxel);
}

}  // namespace
}  // namespace stc::stability
