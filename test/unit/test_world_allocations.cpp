// Counting allocator test: World::step allocates nothing on the heap once
// warm. Global operator new is replaced by one that counts while a flag is
// set; a few hundred moving entities are stepped until every pool has grown
// to its working size, then N more ticks must allocate exactly nothing.
#include "physics.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <random>

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace stc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Entities on a jittered lattice, packed so neighbours overlap, each moving
// and turning back and forth: velocities flip every `half_period` ticks, so
// the pair set keeps changing but the scene returns to where it was.
World movingWorld(int per_side, SchedulerKind scheduler, int threads = 1) {
  WorldConfig config;
  config.scheduler.kind = scheduler;
  config.threads = threads;
  World w(config);
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 0.05;
  const ShapeId shapes[] = {w.addShape("cube", makePreset("cube", p)),
                            w.addShape("rock", makePreset("rock", p)),
                            w.addShape("ring", makePreset("ring", p)),
                            w.addShape("rod", makePreset("rod", p)),
                            w.addShape("sphere", makePreset("sphere", p))};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> pick(0, 4);
  for (int i = 0; i < per_side; ++i)
    for (int j = 0; j < per_side; ++j)
      for (int k = 0; k < per_side; ++k) {
        EntitySpec s;
        s.shape = shapes[pick(rng)];
        s.pose.position = Vec3(i, j, k) * 0.42 + 0.03 * Vec3(u(rng), u(rng), u(rng));
        s.pose.orientation = Quat(Eigen::AngleAxisd(kPi * u(rng), Vec3(u(rng), u(rng), 1).normalized()));
        s.linear_velocity = 0.3 * Vec3(u(rng), u(rng), u(rng));
        s.angular_velocity = 2.0 * Vec3(u(rng), u(rng), u(rng));
        w.addEntity(s);
      }
  Camera cam;
  cam.camera_to_world.position = Vec3(0.4 * per_side / 2, 0.4 * per_side / 2, -4.0);  // looks along +z
  w.perception().setCamera(cam);
  w.perception().setFixation(Vec2(640, 360));
  return w;
}

struct TickTotals {
  long warm_allocations = 0;  // while warming up: the pools grow (shows the counter works)
  long allocations = 0;       // over the counted ticks
  std::size_t broad_pairs = 0, unresolved = 0, colliding = 0;
};

TickTotals countAllocations(World& w, const Budget& budget, int warm_ticks, int counted_ticks) {
  const int half_period = 25;
  auto tick = [&](int t, TickTotals* run) {
    if (t % half_period == 0) {
      for (BodyState& b : w.bodies()) {
        b.linear_velocity = -b.linear_velocity;
        b.angular_velocity = -b.angular_velocity;
      }
    }
    const TickReport r = w.step(0.01, budget);
    if (run) {
      run->broad_pairs += r.detection.broad_pairs;
      run->unresolved += r.detection.unresolved;
      run->colliding += r.detection.colliding;
    }
  };
  TickTotals run;
  g_allocations = 0;
  g_counting = true;
  for (int t = 0; t < warm_ticks; ++t) tick(t, nullptr);
  run.warm_allocations = g_allocations;
  g_allocations = 0;
  for (int t = warm_ticks; t < warm_ticks + counted_ticks; ++t) tick(t, &run);
  g_counting = false;
  run.allocations = g_allocations;
  return run;
}

TEST(WorldAllocations, SteadyStateTicksDoNotAllocate) {
  for (SchedulerKind kind : {SchedulerKind::RoundRobin, SchedulerKind::Sequential,
                             SchedulerKind::PerceptualSequential, SchedulerKind::PriorityQueues}) {
    World w = movingWorld(7, kind);  // 343 entities
    // The fake clock (10 us a read) from the first tick: what the World learns
    // of its phases' costs carries over into the tick-budget run, so a real
    // clock before it would make that run differ from one run to the next.
    auto now = std::make_shared<double>(0.0);
    w.setClock([now] { return *now += 1e-5; });
    // Warm up over two full back-and-forth periods, then count over one more.
    const TickTotals unlimited = countAllocations(w, Budget::unlimited(), 100, 50);
    EXPECT_GT(unlimited.warm_allocations, 0) << toString(kind);
    EXPECT_EQ(unlimited.allocations, 0) << toString(kind) << ", unlimited budget";
    EXPECT_GT(unlimited.broad_pairs, 0u);
    EXPECT_GT(unlimited.colliding, 0u);
    // Interrupted ticks (unresolved pairs accepted, perception measured) too.
    const TickTotals interrupted = countAllocations(w, Budget::ofSphereTests(2000), 100, 50);
    EXPECT_EQ(interrupted.allocations, 0) << toString(kind) << ", 2000 sphere tests";
    EXPECT_GT(interrupted.unresolved, 0u);
    // A tick budget on the fake clock: the narrow phase gets what is left,
    // the solver refines while it fits.
    const TickTotals ticked = countAllocations(w, Budget::ofTickSeconds(2e-3), 100, 50);
    EXPECT_EQ(ticked.allocations, 0) << toString(kind) << ", tick budget";
    EXPECT_GT(ticked.unresolved, 0u);
  }
}

// Two threads: the chunks' schedulers, arenas and contact builders, the
// solver's blocks and the team keep their capacity too. The fake clock is read by both
// threads: an atomic count of 10 us steps.
TEST(WorldAllocations, ParallelTicksDoNotAllocate) {
  World w = movingWorld(7, SchedulerKind::PriorityQueues, 2);
  ASSERT_EQ(w.threads(), 2);
  const TickTotals unlimited = countAllocations(w, Budget::unlimited(), 100, 50);
  EXPECT_EQ(unlimited.allocations, 0) << "unlimited budget";
  EXPECT_GT(unlimited.colliding, 0u);
  const TickTotals interrupted = countAllocations(w, Budget::ofSphereTests(2000), 100, 50);
  EXPECT_EQ(interrupted.allocations, 0) << "2000 sphere tests";
  EXPECT_GT(interrupted.unresolved, 0u);
  auto reads = std::make_shared<std::atomic<std::int64_t>>(0);
  w.setClock([reads] { return 1e-5 * static_cast<double>(++*reads); });
  const TickTotals ticked = countAllocations(w, Budget::ofTickSeconds(2e-3), 100, 50);
  EXPECT_EQ(ticked.allocations, 0) << "tick budget";
  EXPECT_GT(ticked.unresolved, 0u);
}

// The first immovable body in contact, after ticks without one: the order
// from the ground gets its first seeds and the shock propagation its first
// levels. Those buffers are sized by the bodies and the rows, not by the
// levels of the tick that first has them: a scene without static bodies in
// which a body falls asleep (held as static) or is given infinite mass
// allocates nothing for it (a sleeper appearing in the counted ticks made
// ParallelTicksDoNotAllocate fail now and then on a loaded machine).
TEST(WorldAllocations, AFirstImmovableBodyAllocatesNothing) {
  World w = movingWorld(5, SchedulerKind::PriorityQueues);  // 125 entities, none static
  const TickTotals warm = countAllocations(w, Budget::unlimited(), 100, 20);
  ASSERT_EQ(warm.allocations, 0);
  ASSERT_GT(warm.colliding, 0u);
  for (std::size_t i = 0; i < w.bodies().size(); i += 5) {  // every fifth body: infinite mass
    w.bodies()[i].inv_mass = 0.0;
    w.bodies()[i].inv_inertia_body.setZero();
    w.bodies()[i].inv_inertia_world.setZero();
  }
  const TickTotals run = countAllocations(w, Budget::unlimited(), 0, 20);
  EXPECT_EQ(run.allocations, 0);
  EXPECT_GT(run.colliding, 0u);
  EXPECT_GT(physicsReport(w).solve.contacts, 0u);
}

// Turning four times faster (8 rad/s), the long shapes' far ends move more
// than half a leaf radius a tick: those bodies go through the swept test
// after the broad phase every tick, which allocates nothing either.
TEST(WorldAllocations, SweptTicksDoNotAllocate) {
  World w = movingWorld(5, SchedulerKind::PriorityQueues);  // 125 entities
  for (BodyState& b : w.bodies()) b.angular_velocity *= 4.0;
  const TickTotals run = countAllocations(w, Budget::unlimited(), 100, 50);
  EXPECT_EQ(run.allocations, 0);
  EXPECT_GT(physicsReport(w).sweep.fast_bodies, 0u);
  EXPECT_GT(physicsReport(w).sweep.pairs, 0u);
}

// A pile still forming: its contacts reach a new high most ticks, and the
// buffers sized by them grow geometrically, so few of those ticks allocate
// (24 of 84; the narrow phase's arena grows by a block at a time). Grown to the exact count (as the solver's rows once were: a
// 10,000-cube pile copied and page-faulted 45 MB of them a tick), all 86 did.
TEST(WorldAllocations, AFormingPileAllocatesInFewTicks) {
  SceneParams params;
  params.entities = 343;
  SceneWorld scene = makeSceneWorld(SceneKind::CubeBox, params);
  std::size_t high = 0;
  int new_highs = 0, allocating = 0;
  for (int t = 0; t < 240; ++t) {
    g_allocations = 0;
    g_counting = true;
    const TickReport r = scene.world.step(scene.spec.dt, Budget::unlimited());
    g_counting = false;
    if (t < 30 || r.response.contacts <= high) {  // the first ticks: every pool's first growth
      high = std::max(high, r.response.contacts);
      continue;
    }
    high = r.response.contacts;
    ++new_highs;
    allocating += g_allocations > 0 ? 1 : 0;
  }
  EXPECT_GE(new_highs, 40);  // the pile did form over the counted ticks
  EXPECT_LE(allocating, new_highs / 2);
}

// Contacts carried over (ResponseOptions::reuse_tolerance): a pile at rest
// (sleeping off, so its pairs stay in the tick) whose top cube is set
// spinning now and then, so its pairs go from reused to built and back; the
// cache's entries, points and index keep their capacity.
TEST(WorldAllocations, ReusedContactsDoNotAllocate) {
  for (const int threads : {1, 2}) {
    SceneParams params;
    params.entities = 125;
    WorldConfig config;
    config.threads = threads;
    config.sleeping.enabled = false;
    config.response.reuse_tolerance = 0.05;
    SceneWorld scene = makeSceneWorld(SceneKind::CubeBox, params, config);
    for (int t = 0; t < 300; ++t) scene.world.step(scene.spec.dt, Budget::unlimited());
    // The pile is at rest by now, every pair carried over: the topmost cube
    // is set spinning now and then, so its pairs are built again. A cube, not
    // the box's lid: a static body is never moved, and its pairs stay carried.
    std::size_t top = *scene.world.indexOf(scene.spec.movers.front());
    for (const EntityId id : scene.spec.movers) {
      const std::size_t i = *scene.world.indexOf(id);
      if (scene.world.bodies()[i].pose.position.z() > scene.world.bodies()[top].pose.position.z()) top = i;
    }
    std::size_t reused = 0, colliding = 0;
    g_allocations = 0;
    g_counting = true;
    for (int t = 0; t < 60; ++t) {
      if (t % 10 == 0) scene.world.bodies()[top].angular_velocity = Vec3(0.0, 0.0, 2.0);
      const TickReport r = scene.world.step(scene.spec.dt, Budget::unlimited());
      reused += r.detection.reused;
      colliding += r.detection.colliding;
    }
    g_counting = false;
    EXPECT_EQ(g_allocations, 0) << threads << " threads";
    EXPECT_GT(reused, 0u) << threads << " threads";
    EXPECT_LT(reused, colliding) << threads << " threads: some pairs are built too";
  }
}

}  // namespace
}  // namespace stc
