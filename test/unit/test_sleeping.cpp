// Sleeping islands (islands.hpp): a pile that comes to rest sleeps, keeps its
// poses exactly and costs no sphere test; a moving body, a spawn, a despawn,
// a change of gravity, an edit and World::wake wake it; with sleeping off
// nothing changes; bad thresholds are rejected naming the field.
#include "contact_solver.hpp"
#include "dynamics.hpp"
#include "physics.hpp"
#include "sphere_tree_collision/gaze_model.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <vector>


namespace stc {
namespace {

constexpr double kDt = 1.0 / 60.0;
constexpr int kSettleTicks = 900;  // 15 s: the pile is asleep long before
constexpr int kBigPile = 1500;     // rocks: one island that a few creeping rocks keep awake

using Pile = SceneWorld;

// Cubes falling into a pile in a closed box (scenes.hpp CubeBox).
Pile cubePile(bool sleeping = true, int count = 27) {
  WorldConfig config;
  config.sleeping.enabled = sleeping;
  SceneParams params;
  params.entities = count;
  params.resolution = 4;
  return makeSceneWorld(SceneKind::CubeBox, params, config);
}

// Steps until every mover sleeps; returns the ticks it took (-1: never).
int settle(World& world, std::size_t movers, int max_ticks = kSettleTicks) {
  for (int t = 1; t <= max_ticks; ++t) {
    if (world.step(kDt, Budget::unlimited()).bodies.sleeping == movers) return t;
  }
  return -1;
}

Pile settledPile() {
  Pile pile = cubePile();
  EXPECT_GT(settle(pile.world, pile.spec.movers.size()), 0);
  return pile;
}

std::size_t indexOf(const World& world, EntityId id) { return *world.indexOf(id); }

// Top of the pile: the highest mover's centre.
double highestMover(const Pile& pile) {
  double z = -1e9;
  for (EntityId id : pile.spec.movers) z = std::max(z, pile.world.bodies()[indexOf(pile.world, id)].pose.position.z());
  return z;
}

TEST(Sleeping, WithoutAResponseNothingSleepsAndEveryPairReportsItsContacts) {
  // Detection alone (the node's ~response false): bodies at rest keep being
  // tested, so overlapping ones report contacts tick after tick.
  Pile pile = cubePile();
  WorldConfig config = pile.world.config();
  ResponseOptions off = config.response;
  off.enabled = false;
  World& world = pile.world;
  for (int t = 0; t < 240; ++t) world.step(kDt, Budget::unlimited());  // under gravity, no response: they fall
  world.setResponse(off);
  for (BodyState& b : world.bodies()) {  // hold them where they are, overlapping the floor or not
    b.linear_velocity.setZero();
    b.angular_velocity.setZero();
  }
  world.setGravity(Vec3::Zero());
  std::size_t contacts = 0;
  for (int t = 0; t < 120; ++t) {
    const TickReport r = world.step(kDt, Budget::unlimited());
    EXPECT_EQ(r.bodies.sleeping, 0u);
    if (t == 0) contacts = r.response.contacts;
    EXPECT_EQ(r.response.contacts, contacts);  // nothing moves: the same contacts every tick
  }
  EXPECT_GT(contacts, 0u);
}

TEST(Sleeping, TurningTheResponseOffWakesEveryIsland) {
  Pile pile = settledPile();
  World& world = pile.world;
  ResponseOptions off = world.config().response;
  off.enabled = false;
  world.setResponse(off);
  for (EntityId id : pile.spec.movers) EXPECT_FALSE(world.isSleeping(id));
  EXPECT_EQ(world.step(kDt, Budget::unlimited()).bodies.sleeping, 0u);
}

TEST(Sleeping, PileComesToRestSleepsAndCostsNoSphereTest) {
  Pile pile = settledPile();
  World& world = pile.world;
  std::vector<Pose> poses;
  for (const BodyState& b : world.bodies()) poses.push_back(b.pose);
  for (int t = 0; t < 120; ++t) {
    const TickReport r = world.step(kDt, Budget::unlimited());
    EXPECT_EQ(r.bodies.sleeping, pile.spec.movers.size());
    EXPECT_EQ(r.detection.sphere_tests, 0);  // sleeping-sleeping and sleeping-static pairs are not tested
    EXPECT_EQ(r.response.contacts, 0u);      // nor solved
  }
  for (std::size_t i = 0; i < world.bodies().size(); ++i) {
    const BodyState& b = world.bodies()[i];
    EXPECT_EQ(b.pose.position, poses[i].position);  // exactly
    EXPECT_EQ(b.pose.orientation.coeffs(), poses[i].orientation.coeffs());
    EXPECT_TRUE(b.linear_velocity.isZero(0.0));
    EXPECT_TRUE(b.angular_velocity.isZero(0.0));
  }
  for (EntityId id : pile.spec.walls) EXPECT_FALSE(world.isSleeping(id));  // static bodies never do
  for (EntityId id : pile.spec.movers) EXPECT_TRUE(world.isSleeping(id));
}

TEST(Sleeping, OffChangesNothingAndOnIsBitIdenticalUntilTheFirstSleep) {
  Pile on = cubePile(true), off = cubePile(false);
  int compared = 0;
  for (int t = 0; t < kSettleTicks; ++t) {
    const TickReport r_on = on.world.step(kDt, Budget::unlimited());
    const TickReport r_off = off.world.step(kDt, Budget::unlimited());
    EXPECT_EQ(r_off.bodies.sleeping, 0u);
    if (r_on.bodies.sleeping != 0) break;
    ++compared;
    for (std::size_t i = 0; i < on.world.bodies().size(); ++i) {
      ASSERT_EQ(on.world.bodies()[i].pose.position, off.world.bodies()[i].pose.position) << "tick " << t;
      ASSERT_EQ(on.world.bodies()[i].linear_velocity, off.world.bodies()[i].linear_velocity) << "tick " << t;
    }
  }
  EXPECT_GT(compared, 30);  // the pile fell and moved before anything slept
  // Off: the settled pile still tests its pairs every tick.
  EXPECT_GT(off.world.step(kDt, Budget::unlimited()).detection.sphere_tests, 0);
}

// A heavy ball 1 m above the pile's last mover, falling at `speed`.
EntityId dropBall(Pile& pile, double speed) {
  World& world = pile.world;
  PresetParams p;
  p.resolution = 4;
  p.voxel_size = 0.1;
  EntitySpec ball;
  ball.shape = world.addShape("test_ball", makePreset("sphere", p));
  const Vec3 top = world.bodies()[indexOf(world, pile.spec.movers.back())].pose.position;
  ball.pose.position = Vec3(top.x(), top.y(), highestMover(pile) + 1.0);
  ball.linear_velocity = Vec3(0.0, 0.0, -speed);
  ball.density = 4000.0;
  return world.addEntity(ball);
}

TEST(Sleeping, BallDroppedOnTheSleepingPileWakesItAndEverythingRestsSupported) {
  Pile pile = settledPile();
  World& world = pile.world;
  const EntityId ball_id = dropBall(pile, 3.0);
  std::size_t fewest_asleep = pile.spec.movers.size();
  for (int t = 0; t < 60; ++t)
    fewest_asleep = std::min(fewest_asleep, world.step(kDt, Budget::unlimited()).bodies.sleeping);
  EXPECT_LT(fewest_asleep, pile.spec.movers.size());  // the hit woke the island it hit
  // Everything comes to rest again, the ball on the pile, nothing through the floor.
  EXPECT_GT(settle(world, pile.spec.movers.size() + 1), 0);
  const double ball_z = world.bodies()[indexOf(world, ball_id)].pose.position.z();
  EXPECT_GT(ball_z, pile.spec.bounds.min.z());
  for (EntityId id : pile.spec.movers) EXPECT_GE(world.bodies()[indexOf(world, id)].pose.position.z(), pile.spec.bounds.min.z());
  // Nothing sleeps in mid-air: woken with gravity on, the settled bodies stay where they are.
  std::vector<Vec3> rest;
  for (const BodyState& b : world.bodies()) rest.push_back(b.pose.position);
  world.setGravity(world.config().gravity);
  EXPECT_EQ(world.step(kDt, Budget::unlimited()).bodies.sleeping, 0u);
  for (int t = 0; t < 30; ++t) world.step(kDt, Budget::unlimited());
  // In half a second of free fall a floating body drops 1.2 m. A body that
  // fell asleep on a slope, held by a neighbour that slept before it (held
  // as static then), may slide a few centimetres once both wake: here one
  // cube 3.7 cm and three it pushes 1-2 cm, the rest under a millimetre.
  std::vector<double> moved;
  for (std::size_t i = 0; i < rest.size(); ++i) moved.push_back((world.bodies()[i].pose.position - rest[i]).norm());
  std::sort(moved.begin(), moved.end());
  EXPECT_LT(moved.back(), 0.1);               // m: nothing fell
  EXPECT_LT(moved[moved.size() / 2], 1e-3);   // m: the pile as a whole stays put
  // and the momentum of the resting world is that of bodies at rest.
  EXPECT_LT(linearMomentum(world.bodies()).norm(), 0.05 * 9.81 * kDt * 4000.0);
}

TEST(Sleeping, FastBallDoesNotTunnelThroughTheSleepingPile) {
  Pile pile = settledPile();
  World& world = pile.world;
  const EntityId ball_id = dropBall(pile, 40.0);  // 0.67 m a tick: its swept box reaches the pile
  double lowest = 1e9;
  std::size_t fewest_asleep = pile.spec.movers.size();
  for (int t = 0; t < 60; ++t) {
    fewest_asleep = std::min(fewest_asleep, world.step(kDt, Budget::unlimited()).bodies.sleeping);
    lowest = std::min(lowest, world.bodies()[indexOf(world, ball_id)].pose.position.z());
  }
  EXPECT_LT(fewest_asleep, pile.spec.movers.size());
  EXPECT_GT(lowest, pile.spec.bounds.min.z());  // never through the floor under the pile
  for (EntityId id : pile.spec.movers) EXPECT_GE(world.bodies()[indexOf(world, id)].pose.position.z(), pile.spec.bounds.min.z());
}

// A body spawned just above the pile's last mover, its box overlapping.
void expectSpawnWakes(bool is_static) {
  Pile pile = settledPile();
  World& world = pile.world;
  const std::size_t top = indexOf(world, pile.spec.movers.back());
  EntitySpec spawn;
  spawn.shape = world.bodyShapes()[top];
  spawn.pose.position = world.bodies()[top].pose.position + Vec3(0.0, 0.0, 0.45);
  spawn.is_static = is_static;
  world.addEntity(spawn);
  world.step(kDt, Budget::unlimited());
  EXPECT_FALSE(world.isSleeping(pile.spec.movers.back()));
}

TEST(Sleeping, SpawnOverlappingTheSleepingPileWakesIt) { expectSpawnWakes(false); }

TEST(Sleeping, StaticSpawnOverlappingTheSleepingPileWakesIt) { expectSpawnWakes(true); }

TEST(Sleeping, DespawnWakesItsIslandAndWhatItTouched) {
  Pile pile = settledPile();
  World& world = pile.world;
  // The lowest mover holds others up.
  EntityId lowest = pile.spec.movers.front();
  for (EntityId id : pile.spec.movers) {
    if (world.bodies()[indexOf(world, id)].pose.position.z() < world.bodies()[indexOf(world, lowest)].pose.position.z()) lowest = id;
  }
  const std::size_t before = world.step(kDt, Budget::unlimited()).bodies.sleeping;
  ASSERT_TRUE(world.removeEntity(lowest));
  std::size_t awake = 0;
  for (EntityId id : pile.spec.movers) awake += id != lowest && !world.isSleeping(id) ? 1 : 0;
  EXPECT_GT(awake, 0u);
  EXPECT_LT(world.step(kDt, Budget::unlimited()).bodies.sleeping, before - 1);
}

TEST(Sleeping, ChangeOfGravityWakesAllAndBadGravityChangesNothing) {
  Pile pile = settledPile();
  World& world = pile.world;
  EXPECT_THROW(world.setGravity(Vec3(0.0, 0.0, 1e9)), InputError);
  for (EntityId id : pile.spec.movers) EXPECT_TRUE(world.isSleeping(id));
  world.setGravity(Vec3(2.0, 0.0, -9.81));
  for (EntityId id : pile.spec.movers) EXPECT_FALSE(world.isSleeping(id));
  EXPECT_EQ(world.config().gravity, Vec3(2.0, 0.0, -9.81));
  world.step(kDt, Budget::unlimited());
  double vx = 0.0;
  for (EntityId id : pile.spec.movers) vx += world.bodies()[indexOf(world, id)].linear_velocity.x();
  EXPECT_GT(vx, 0.0);  // the new gravity acts
}

TEST(Sleeping, EditThroughBodiesAndWakeWakeTheIsland) {
  Pile pile = settledPile();
  World& world = pile.world;
  const EntityId id = pile.spec.movers.back();
  world.bodies()[indexOf(world, id)].linear_velocity = Vec3(0.0, 0.0, 2.0);
  world.step(kDt, Budget::unlimited());
  EXPECT_FALSE(world.isSleeping(id));
  EXPECT_GT(world.bodies()[indexOf(world, id)].pose.position.z(), 0.0);

  Pile other = settledPile();
  const EntityId woken = other.spec.movers.front();
  EXPECT_TRUE(other.world.wake(woken));
  EXPECT_FALSE(other.world.isSleeping(woken));
  EXPECT_FALSE(other.world.wake(kInvalidEntity));
}

// A sleeper is not looked at again at the end of a tick it slept through
// (World::quarantine): an edit to a bad state is still caught by the check
// at the start of the next step, before anything touches it.
TEST(Sleeping, SleeperEditedToANonFiniteStateIsQuarantinedBeforeItTouchesAnything) {
  Pile pile = settledPile();
  World& world = pile.world;
  const EntityId id = pile.spec.movers.front();
  world.bodies()[indexOf(world, id)].linear_velocity.x() = std::numeric_limits<double>::quiet_NaN();
  const TickReport report = world.step(kDt, Budget::unlimited());
  EXPECT_EQ(report.bodies.quarantined, 1u);
  EXPECT_FALSE(world.indexOf(id).has_value());
  for (const BodyState& body : world.bodies()) {
    ASSERT_TRUE(body.pose.position.allFinite() && body.linear_velocity.allFinite());
  }
  for (int t = 0; t < 30; ++t) world.step(kDt, Budget::unlimited());
  for (const BodyState& body : world.bodies()) ASSERT_TRUE(body.pose.position.allFinite());
}

// Woken, a pile starts from the impulses it fell asleep with, however long
// it slept (a cold start made woken rocks sag and wake their neighbours):
// the first solve after World::wake finds last impulses for its contacts,
// and the pile, woken whole under the same gravity, stays put.
TEST(Sleeping, WokenPileStartsFromTheImpulsesItFellAsleepWith) {
  Pile pile = settledPile();
  World& world = pile.world;
  for (int t = 0; t < 60; ++t) world.step(kDt, Budget::unlimited());  // a second asleep
  for (EntityId id : pile.spec.movers) ASSERT_TRUE(world.isSleeping(id));
  std::vector<Vec3> before;
  for (EntityId id : pile.spec.movers) before.push_back(world.bodies()[indexOf(world, id)].pose.position);
  ASSERT_TRUE(world.wake(pile.spec.movers.front()));
  world.step(kDt, Budget::unlimited());
  const SolveStats& solve = physicsReport(world).solve;
  ASSERT_GT(solve.contacts, 0u);
  EXPECT_GE(static_cast<double>(solve.warm_started), 0.9 * static_cast<double>(solve.contacts));
  for (int t = 0; t < 29; ++t) world.step(kDt, Budget::unlimited());  // half a second
  double moved = 0.0;
  for (std::size_t k = 0; k < before.size(); ++k) {
    moved = std::max(moved, (world.bodies()[indexOf(world, pile.spec.movers[k])].pose.position - before[k]).norm());
  }
  EXPECT_LT(moved, 1e-3) << "m: the most a woken cube moved";
}

// Work a tick does, counted: pair tests set up, sphere tests run, contacts solved.
double workOf(const World& world, const TickReport& r) {
  return static_cast<double>(world.pairCount()) + static_cast<double>(r.detection.sphere_tests) +
         static_cast<double>(r.response.contacts);
}

TEST(Sleeping, RockPileSettlesSleepsWholeAndThenCostsAlmostNothing) {
  // 500 rocks down the ravine into one touching pile (issue 9: a settled pile
  // of 5,000 under 2 ms a tick; bench_settle measures that one).
  SceneParams params;
  params.entities = 500;
  auto [world, spec] = makeSceneWorld(SceneKind::Rockfall, params);
  constexpr int kHalfSecond = 30;
  std::vector<std::vector<Vec3>> recent(kHalfSecond);  // positions of the last half second of ticks
  // Its busiest tick awake. The pile sleeps island by island: the last
  // island awake can be one rock (since the position-level shock sweep
  // resolves the pile's overlaps, rocks that only grazed it part from it).
  double awake_work = 0.0;
  int asleep_at = -1;
  for (int t = 1; t <= 1800 && asleep_at < 0; ++t) {  // 30 s
    const TickReport r = world.step(kDt, Budget::unlimited());
    if (r.bodies.sleeping == spec.movers.size()) {
      asleep_at = t;
      break;
    }
    awake_work = std::max(awake_work, workOf(world, r));
    std::vector<Vec3>& slot = recent[static_cast<std::size_t>(t % kHalfSecond)];
    slot.clear();
    for (const BodyState& b : world.bodies()) slot.push_back(b.pose.position);
  }
  ASSERT_GT(asleep_at, kHalfSecond) << "the pile never slept whole";
  EXPECT_GT(awake_work, 1000.0);  // a pile: thousands of pairs and contacts
  // It fell asleep at rest: over its last half second awake no rock went
  // anywhere (a rock falling for that time drops 1.2 m; one creeping at the
  // old 0.05 m/s threshold goes 2.5 cm).
  const std::vector<Vec3>& half_second_before = recent[static_cast<std::size_t>(asleep_at % kHalfSecond)];
  double moved = 0.0;
  for (std::size_t i = 0; i < half_second_before.size(); ++i) {
    moved = std::max(moved, (world.bodies()[i].pose.position - half_second_before[i]).norm());
  }
  EXPECT_LT(moved, 0.01);
  // Asleep it costs almost nothing and stays exactly where it is.
  std::vector<Pose> poses;
  for (const BodyState& b : world.bodies()) poses.push_back(b.pose);
  for (int t = 0; t < 60; ++t) {
    const TickReport r = world.step(kDt, Budget::unlimited());
    EXPECT_EQ(r.bodies.sleeping, spec.movers.size());
    EXPECT_LE(workOf(world, r), 0.01 * awake_work);
  }
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(world.bodies()[i].pose.position, poses[i].position);
    EXPECT_EQ(world.bodies()[i].pose.orientation.coeffs(), poses[i].orientation.coeffs());
  }
  // Woken whole under the same gravity, nothing falls (the woken solve
  // starts cold, without the impulses that held the pile: it sags a few
  // centimetres, as it did with the rest test by velocity; docs/sleeping.md)
  // and the pile falls asleep again.
  world.setGravity(spec.gravity);
  for (int t = 0; t < kHalfSecond; ++t) world.step(kDt, Budget::unlimited());
  moved = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) moved = std::max(moved, (world.bodies()[i].pose.position - poses[i].position).norm());
  EXPECT_LT(moved, 0.1);
  EXPECT_GT(settle(world, spec.movers.size(), 600), 0);
}

// Under a budget that leaves pairs unresolved (the deterministic form of a
// tick budget: sphere tests), their contacts are their frontier's, mostly the
// root spheres. Pushed apart by those unproven overlaps, the pile flowed and
// never rested: with 10,000 sphere tests a tick, 246 of 300 rocks moved more
// than 2 cm in the 8th second and 18 slept (docs/error_vs_runtime.md).
TEST(Sleeping, PileUnderASphereTestBudgetHoldsTogetherAndStartsToSleep) {
  SceneParams params;
  params.entities = 300;
  WorldConfig config;
  config.scheduler.kind = SchedulerKind::PriorityQueues;
  auto [world, spec] = makeSceneWorld(SceneKind::Rockfall, params, config);
  GazeParams gp;
  gp.mode = GazeMode::Saccades;
  gp.seed = 3;
  GazeModel gaze(gp);
  const Budget budget = Budget::ofSphereTests(10000);
  constexpr int kTicks = 480;  // 8 s
  std::vector<Vec3> second_before_end;
  std::size_t unresolved = 0;
  for (int t = 0; t < kTicks; ++t) {
    if (t == kTicks - 60) {
      for (EntityId id : spec.movers) second_before_end.push_back(world.bodies()[*world.indexOf(id)].pose.position);
    }
    world.perception().setFixation(gaze.fixationAt(t * kDt, world));
    unresolved += world.step(kDt, budget).detection.unresolved_accepted;
  }
  EXPECT_GT(unresolved, 100u * kTicks) << "the budget leaves pairs unresolved";
  std::size_t moving = 0, asleep = 0;
  for (std::size_t k = 0; k < spec.movers.size(); ++k) {
    const Vec3& p = world.bodies()[*world.indexOf(spec.movers[k])].pose.position;
    moving += (p - second_before_end[k]).norm() > 0.02 ? 1 : 0;
    asleep += world.isSleeping(spec.movers[k]) ? 1 : 0;
  }
  EXPECT_LE(moving, spec.movers.size() / 4) << "the pile flows";
  EXPECT_GE(asleep, spec.movers.size() / 3);
}

TEST(Sleeping, BigPileThatAFewRocksKeepAwakeSleepsAlmostWholeAndStaysPut) {
  // 1,500 rocks make one island that a few creeping rocks keep awake
  // (bench_settle's restless count; docs/sleeping.md): the rested part of it
  // sleeps around them, a body alone, and a creeping rock wakes the sleepers
  // it reaches, so the count asleep goes up and down by a few per cent.
  SceneParams params;
  params.entities = kBigPile;
  auto [world, spec] = makeSceneWorld(SceneKind::Rockfall, params);
  const std::size_t most = spec.movers.size() * 95 / 100;
  std::size_t asleep = 0;
  for (int t = 0; t < 1500 && asleep < most; ++t)
    asleep = world.step(kDt, Budget::unlimited()).bodies.sleeping;  // 25 s
  ASSERT_GE(asleep, most);
  // It stays put: a second later the rocks asleep now are where they were
  // (awake or not: a woken one settles again, at most a few of them, one in
  // a hundred, slipped to a new rest, less than a voxel away), the energy
  // has not grown and nine in ten stayed asleep throughout.
  std::vector<Vec3> at_sleep;
  std::vector<bool> was_asleep;
  for (const EntityId id : spec.movers) {
    at_sleep.push_back(world.bodies()[indexOf(world, id)].pose.position);
    was_asleep.push_back(world.isSleeping(id));
  }
  const double energy = totalEnergy(world.bodies(), spec.gravity, kDt);
  std::size_t fewest_asleep = asleep;
  for (int t = 0; t < 60; ++t)
    fewest_asleep = std::min(fewest_asleep, world.step(kDt, Budget::unlimited()).bodies.sleeping);
  EXPECT_GE(fewest_asleep, spec.movers.size() * 90 / 100);
  double moved = 0.0;
  std::size_t slipped = 0;  // moved more than 1 cm
  for (std::size_t k = 0; k < spec.movers.size(); ++k) {
    if (!was_asleep[k]) continue;
    const double d = (world.bodies()[indexOf(world, spec.movers[k])].pose.position - at_sleep[k]).norm();
    moved = std::max(moved, d);
    if (d > 0.01) ++slipped;
  }
  EXPECT_LE(slipped, asleep / 100);
  EXPECT_LT(moved, params.entity_size / params.resolution);
  EXPECT_LE(totalEnergy(world.bodies(), spec.gravity, kDt), energy + 1e-6 * std::abs(energy));
}

TEST(Sleeping, BadThresholdsAreRejectedNamingTheField) {
  const auto field = [](SleepOptions sleeping) {
    WorldConfig config;
    config.sleeping = sleeping;
    try {
      World world(config);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string();
  };
  SleepOptions s;
  s.linear_speed = -1.0;
  EXPECT_EQ(field(s), "sleeping.linear_speed");
  s = SleepOptions{};
  s.linear_speed = std::nan("");
  EXPECT_EQ(field(s), "sleeping.linear_speed");
  s = SleepOptions{};
  s.time_to_sleep = std::numeric_limits<double>::infinity();
  EXPECT_EQ(field(s), "sleeping.time_to_sleep");
  EXPECT_EQ(field(SleepOptions{}), "");
}

}  // namespace
}  // namespace stc
