// Island levels (island_levels.hpp): under a limited response the islands
// that do not fit are held still, pose and momentum kept exactly; the island
// nearest the gaze runs first; none waits for ever; a moving body that reaches
// a held island joins it to the tick; a scene under a budget that cannot fit
// every island stays plausible. Deterministic: Budget::response_contacts, no clock.
#include "dynamics.hpp"
#include "island_levels.hpp"
#include "plausibility.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace stc {
namespace {

constexpr double kDt = 1.0 / 60.0;
constexpr int kStacks = 6;
constexpr double kSpacing = 2.0;  // m between stacks: their boxes never meet

// kStacks stacks of two 0.4 m cubes on one static floor along x, 2 m apart:
// kStacks islands (a static floor joins none). The top cube of each slides
// and spins a little, so each island has momentum. A camera looks at the row.
struct Row {
  World world;
  std::vector<std::array<EntityId, 2>> stacks;
};

Row makeRow() {
  WorldConfig config;
  config.gravity = Vec3(0, 0, -9.81);
  config.sleeping.enabled = false;  // the islands stay awake: what is held is the level's doing
  Row row{World(config), {}};
  World& w = row.world;
  const ShapeId floor = w.addShape("floor", VoxelShape::create(64, 8, 1, 0.25, std::vector<std::uint8_t>(512, 1)));
  const ShapeId cube = w.addShape("cube", VoxelShape::create(4, 4, 4, 0.1, std::vector<std::uint8_t>(64, 1)));
  EntitySpec ground;
  ground.shape = floor;
  ground.is_static = true;
  ground.pose.position = Vec3(0.0, 0.0, -0.125);  // top face at z = 0
  w.addEntity(ground);
  for (int s = 0; s < kStacks; ++s) {
    const double x = (s - 0.5 * (kStacks - 1)) * kSpacing;
    EntitySpec bottom;
    bottom.shape = cube;
    bottom.pose.position = Vec3(x, 0.0, 0.2);
    EntitySpec top = bottom;
    top.pose.position = Vec3(x, 0.0, 0.6);
    top.linear_velocity = Vec3(0.1, 0.05, 0.0);
    top.angular_velocity = Vec3(0.0, 0.0, 0.5);
    row.stacks.push_back({w.addEntity(bottom), w.addEntity(top)});
  }
  Camera camera;
  camera.camera_to_world = opticalLookAt(Vec3(0.0, -12.0, 2.0), Vec3(0.0, 0.0, 0.3));
  w.perception().setCamera(camera);
  // Unlimited ticks: the stacks settle into their contacts (the islands).
  for (int t = 0; t < 10; ++t) w.step(kDt, Budget::unlimited());
  return row;
}

// The gaze on stack `s`.
void lookAt(Row& row, int s) {
  const BodyState& b = row.world.bodies()[*row.world.indexOf(row.stacks[s][1])];
  row.world.perception().setFixation(*row.world.perception().project(b.pose.position));
}

ResponseLevel levelOf(const Row& row, int s) { return row.world.responseLevel(row.stacks[s][0]); }

std::vector<BodyState> stackBodies(const Row& row, int s) {
  return {row.world.bodies()[*row.world.indexOf(row.stacks[s][0])],
          row.world.bodies()[*row.world.indexOf(row.stacks[s][1])]};
}

// Room for no island but the first: one island a tick.
const Budget kOneIsland = Budget::ofResponseContacts(0);

TEST(IslandLevels, UnlimitedTicksApplyNoLevel) {
  Row row = makeRow();
  const TickReport r = row.world.step(kDt, Budget::unlimited());
  EXPECT_FALSE(r.response.levels.used);
  EXPECT_EQ(r.response.levels.bodies_held, 0u);
  for (int s = 0; s < kStacks; ++s) EXPECT_EQ(levelOf(row, s), ResponseLevel::Full);
}

TEST(IslandLevels, HeldIslandKeepsPoseVelocitiesAndMomentumExactly) {
  Row row = makeRow();
  lookAt(row, 0);
  std::vector<std::vector<BodyState>> before;
  for (int s = 0; s < kStacks; ++s) before.push_back(stackBodies(row, s));
  const TickReport r = row.world.step(kDt, kOneIsland);
  ASSERT_TRUE(r.response.levels.used);
  EXPECT_EQ(r.response.levels.islands_full, 1u);
  EXPECT_EQ(r.response.levels.islands_held, static_cast<std::size_t>(kStacks - 1));
  EXPECT_EQ(r.response.levels.bodies_held, static_cast<std::size_t>(2 * (kStacks - 1)));
  EXPECT_EQ(r.response.levels.islands_joined, 0u);
  int held = 0;
  for (int s = 0; s < kStacks; ++s) {
    if (levelOf(row, s) != ResponseLevel::Held) continue;
    ++held;
    EXPECT_EQ(row.world.responseLevel(row.stacks[s][1]), ResponseLevel::Held);
    const std::vector<BodyState> after = stackBodies(row, s);
    for (int k = 0; k < 2; ++k) {
      SCOPED_TRACE(testing::Message() << "stack " << s << " body " << k);
      EXPECT_EQ(after[k].pose.position, before[s][k].pose.position);
      EXPECT_EQ(after[k].pose.orientation.coeffs(), before[s][k].pose.orientation.coeffs());
      EXPECT_EQ(after[k].linear_velocity, before[s][k].linear_velocity);
      EXPECT_EQ(after[k].angular_velocity, before[s][k].angular_velocity);
      EXPECT_FALSE(after[k].is_static);  // released after the tick
    }
    EXPECT_EQ(linearMomentum(after), linearMomentum(before[s]));
    EXPECT_EQ(angularMomentum(after), angularMomentum(before[s]));
    EXPECT_GT(linearMomentum(after).norm(), 0.0);  // there was momentum to keep
  }
  EXPECT_EQ(held, kStacks - 1);
  // Held islands build no contacts: only the stepped stack's are there.
  for (const Contact& c : row.world.contacts()) {
    EXPECT_NE(row.world.responseLevel(c.a), ResponseLevel::Held);
    EXPECT_NE(row.world.responseLevel(c.b), ResponseLevel::Held);
  }
}

TEST(IslandLevels, TheIslandNearestTheGazeRunsFirst) {
  for (const int gazed : {1, 4}) {
    SCOPED_TRACE(gazed);
    Row row = makeRow();
    lookAt(row, gazed);
    const TickReport r = row.world.step(kDt, kOneIsland);
    EXPECT_GT(r.response.levels.held_priority, 0.0);
    for (int s = 0; s < kStacks; ++s) {
      EXPECT_EQ(levelOf(row, s), s == gazed ? ResponseLevel::Full : ResponseLevel::Held) << "stack " << s;
    }
  }
}

TEST(IslandLevels, EveryIslandGetsItsTurn) {
  Row row = makeRow();
  lookAt(row, 2);  // the gaze stays on one stack: the others must still run
  std::vector<int> last_run(kStacks, 0), longest(kStacks, 0);
  constexpr int kTicks = 120;
  for (int t = 1; t <= kTicks; ++t) {
    const TickReport r = row.world.step(kDt, kOneIsland);
    EXPECT_LE(r.response.levels.most_ticks_held, IslandLevels::kMostTicksHeld);
    for (int s = 0; s < kStacks; ++s) {
      if (levelOf(row, s) != ResponseLevel::Full) continue;
      longest[s] = std::max(longest[s], t - last_run[s]);
      last_run[s] = t;
    }
  }
  for (int s = 0; s < kStacks; ++s) {
    SCOPED_TRACE(s);
    longest[s] = std::max(longest[s], kTicks + 1 - last_run[s]);
    std::printf("stack %d: longest gap between runs %d ticks\n", s, longest[s]);
    EXPECT_LE(longest[s], IslandLevels::kMostTicksHeld + 1);
    EXPECT_GT(last_run[s], 0);
  }
  // The gazed stack runs more often than the others, and each of them runs
  // within about the ticks it takes aging to reach the gaze's priority.
  for (int s = 0; s < kStacks; ++s) EXPECT_LE(longest[2], longest[s]);
  for (int s = 0; s < kStacks; ++s) EXPECT_LE(longest[s], static_cast<int>(1.0 / IslandLevels::kAgingPerTick) + kStacks);
}

TEST(IslandLevels, AMovingBodyThatReachesAHeldIslandJoinsIt) {
  Row row = makeRow();
  World& w = row.world;
  // A cube flying at stack 3 from 0.6 m away: its box meets the stack's
  // this tick. The gaze is on it, so it is the island that runs; the stacks
  // do not fit and would all be held, but stack 3 is reached.
  const BodyState target = w.bodies()[*w.indexOf(row.stacks[3][1])];
  EntitySpec thrown;
  thrown.shape = *w.findShape("cube");
  thrown.pose.position = target.pose.position - Vec3(0.6, 0.0, 0.0);
  thrown.linear_velocity = Vec3(6.0, 0.0, 0.0);
  const EntityId id = w.addEntity(thrown);
  w.step(kDt, Budget::unlimited());  // contacts again after the addition
  w.perception().setFixation(*w.perception().project(w.bodies()[*w.indexOf(id)].pose.position));
  const Pose stack_pose = w.bodies()[*w.indexOf(row.stacks[3][1])].pose;
  const TickReport r = w.step(kDt, kOneIsland);
  EXPECT_EQ(w.responseLevel(id), ResponseLevel::Full);
  EXPECT_EQ(levelOf(row, 3), ResponseLevel::Full);
  EXPECT_EQ(r.response.levels.islands_joined, 1u);
  EXPECT_EQ(r.response.levels.islands_full, 2u);
  // Joined, it was integrated and solved with the thrown cube: it moved.
  EXPECT_NE(w.bodies()[*w.indexOf(row.stacks[3][1])].pose.position, stack_pose.position);
  // The far stacks stayed held.
  EXPECT_EQ(levelOf(row, 0), ResponseLevel::Held);
  EXPECT_EQ(levelOf(row, 5), ResponseLevel::Held);
}

// A rockfall under a response budget that fits a fraction of its islands:
// plausible as test_budget_plausibility asks of any budget. Windows of
// stored against real speed are of ticks a rock was stepped (in its held
// ticks its time stood), and no held rock is ever in a contact.
TEST(IslandLevels, ARockfallThatCannotFitEveryIslandStaysPlausible) {
  SceneParams params;
  params.entities = 300;
  SceneWorld scene = makeSceneWorld(SceneKind::Rockfall, params);
  truth::PlausibilityCheck check(scene.world, scene.spec);
  std::size_t held_ticks = 0, walls = 0;
  for (int t = 0; t < 600; ++t) {
    const TickReport r = scene.world.step(scene.spec.dt, Budget::ofResponseContacts(150));
    held_ticks += r.response.levels.bodies_held;
    // No held body is in a contact: none was met as a wall.
    for (const Contact& c : scene.world.contacts()) {
      walls += scene.world.responseLevel(c.a) == ResponseLevel::Held || scene.world.responseLevel(c.b) == ResponseLevel::Held;
    }
    check.tick(scene.world, scene.spec.dt);
  }
  const truth::Plausibility f = check.finish(scene.world);
  std::printf("rockfall 300 at 150 contacts a tick: %s; %zu body-ticks held\n", truth::describe(f).c_str(), held_ticks);
  EXPECT_GT(held_ticks, 0u);  // the budget held islands
  EXPECT_EQ(walls, 0u);
  EXPECT_EQ(f.non_finite, 0u);
  EXPECT_EQ(f.outside, 0u);
  EXPECT_EQ(f.too_fast, 0u) << "max speed " << f.max_speed << " m/s, a fall allows " << f.fall_speed;
  // As test_budget_plausibility asks of any budget (7 of 5,514 windows off
  // by up to 0.036 m/s).
  EXPECT_LT(f.worst_window_excess, 0.05) << f.bad_windows << " windows off";
  EXPECT_LE(f.sink_p99_voxels, 1.0);
  EXPECT_LT(f.max_sink, f.plate_thickness);  // none through a plate
}

}  // namespace
}  // namespace stc
