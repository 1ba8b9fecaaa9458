// The parallel tick (WorldConfig::threads): validated; at an unlimited budget
// the same poses and contacts bit for bit whatever the thread count; with a
// sphere-test budget the same bits run after run; each chunk of the narrow
// phase runs the scheduler over its pairs under its share of the budget; the
// deadline stops every worker. No timing is asserted: budgets are counts, and
// the deadline runs on a fake clock.
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace stc {
namespace {

constexpr int kTicks = 300;
constexpr int kEntities = 100;

World sceneWorld(SceneKind kind, WorldConfig config) {
  SceneParams params;
  params.entities = kEntities;
  return std::move(makeSceneWorld(kind, params, config).world);
}

World sceneWorld(SceneKind kind, int threads) {
  WorldConfig config;
  config.threads = threads;
  // Solver colours split into tasks from a few manifolds up: at 100 bodies
  // the default (512) would leave every colour on the calling thread.
  config.response.solver_task_manifolds = 4;
  return sceneWorld(kind, config);
}

// Bit-identical: every double compared with ==, none within a tolerance.
::testing::AssertionResult sameState(const World& x, const World& y) {
  if (x.entityCount() != y.entityCount()) return ::testing::AssertionFailure() << "entity counts differ";
  for (std::size_t i = 0; i < x.entityCount(); ++i) {
    const BodyState& a = x.bodies()[i];
    const BodyState& b = y.bodies()[i];
    if (x.entityIds()[i] != y.entityIds()[i] || a.pose.position != b.pose.position ||
        a.pose.orientation.coeffs() != b.pose.orientation.coeffs() || a.linear_velocity != b.linear_velocity ||
        a.angular_velocity != b.angular_velocity) {
      return ::testing::AssertionFailure() << "body " << i << " differs";
    }
  }
  const std::vector<Contact>& cx = x.contacts();
  const std::vector<Contact>& cy = y.contacts();
  if (cx.size() != cy.size()) return ::testing::AssertionFailure() << "contact counts " << cx.size() << " " << cy.size();
  for (std::size_t k = 0; k < cx.size(); ++k) {
    const Contact& a = cx[k];
    const Contact& b = cy[k];
    if (a.a != b.a || a.b != b.b || a.point != b.point || a.normal != b.normal || a.separation != b.separation ||
        a.gap_bound != b.gap_bound || a.resolved != b.resolved || a.normal_impulse != b.normal_impulse ||
        a.friction_impulse != b.friction_impulse) {
      return ::testing::AssertionFailure() << "contact " << k << " differs";
    }
  }
  return ::testing::AssertionSuccess();
}

const SceneKind kScenes[] = {SceneKind::CornerDrift, SceneKind::Rockfall, SceneKind::PackedBox};

TEST(ParallelTick, ThreadsAreValidatedAndResolved) {
  for (const int bad : {-1, kMaxThreads + 1, 1 << 30}) {
    WorldConfig config;
    config.threads = bad;
    try {
      World w(config);
      ADD_FAILURE() << "accepted threads = " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "threads");
    }
  }
  WorldConfig config;
  config.threads = 0;
  EXPECT_GE(World(config).threads(), 1);  // every core
  config.threads = 3;
  const World three(config);
  EXPECT_EQ(three.threads(), 3);
  EXPECT_EQ(three.narrowChunks(), 3u);
  EXPECT_EQ(World().threads(), 1);  // the default: the calling thread alone
}

TEST(ParallelTick, UnlimitedBudgetGivesTheSameBitsWhateverTheThreadCount) {
  for (const SceneKind kind : kScenes) {
    World one = sceneWorld(kind, 1);
    World two = sceneWorld(kind, 2);
    World four = sceneWorld(kind, 4);
    std::size_t contacts = 0;
    for (int t = 0; t < kTicks; ++t) {
      const TickReport r1 = one.step(1.0 / 60.0, Budget::unlimited());
      const TickReport r2 = two.step(1.0 / 60.0, Budget::unlimited());
      const TickReport r4 = four.step(1.0 / 60.0, Budget::unlimited());
      ASSERT_TRUE(sameState(one, two)) << toString(kind) << " 1 vs 2 threads, tick " << t;
      ASSERT_TRUE(sameState(one, four)) << toString(kind) << " 1 vs 4 threads, tick " << t;
      ASSERT_EQ(r1.sphere_tests, r2.sphere_tests) << toString(kind) << " tick " << t;
      ASSERT_EQ(r1.sphere_tests, r4.sphere_tests) << toString(kind) << " tick " << t;
      contacts += r1.contacts;
    }
    EXPECT_GT(contacts, 0u) << toString(kind);  // the bodies did touch
  }
}

TEST(ParallelTick, SphereTestBudgetGivesTheSameBitsRunAfterRun) {
  for (const SceneKind kind : kScenes) {
    for (const int threads : {2, 4}) {
      World first = sceneWorld(kind, threads);
      World again = sceneWorld(kind, threads);
      first.perception().setFixation(Vec2(640, 360));
      again.perception().setFixation(Vec2(640, 360));
      const Budget budget = Budget::ofSphereTests(1500);
      bool interrupted = false;
      for (int t = 0; t < kTicks; ++t) {
        const TickReport r = first.step(1.0 / 60.0, budget);
        again.step(1.0 / 60.0, budget);
        interrupted = interrupted || r.interrupted;
        ASSERT_TRUE(sameState(first, again)) << toString(kind) << " " << threads << " threads, tick " << t;
      }
      EXPECT_TRUE(interrupted) << toString(kind) << ": the budget never bit";
    }
  }
}

// Each chunk's pairs, tested again on their own with a fresh scheduler of
// the World's kind under the chunk's share, end exactly as the World left
// them: the chunk ran the scheduler unchanged (priority queues: highest
// queue first, test_schedulers checks that order) over its own pairs. The
// response is off, so the poses the tests saw are the poses after the tick.
TEST(ParallelTick, EachChunkRunsTheSchedulerOverItsPairsWithinItsShare) {
  WorldConfig config;
  config.threads = 2;
  config.response.enabled = false;
  World w = sceneWorld(SceneKind::CornerDrift, config);
  w.perception().setFixation(Vec2(400, 300));
  for (int t = 0; t < 60; ++t) w.step(1.0 / 60.0, Budget::unlimited());  // into the pile

  const std::int64_t budget = 1200;
  bool checked_interrupted = false;
  for (int t = 0; t < 20; ++t) {
    const TickReport r = w.step(1.0 / 60.0, Budget::ofSphereTests(budget));
    std::int64_t total = 0;
    std::int64_t overshoot_bound = 0;  // a step per chunk, none costs more than its pair's whole test
    for (std::size_t k = 0; k < w.narrowChunks(); ++k) {
      const auto [first, last] = chunkRange(w.pairCount(), k, w.narrowChunks());
      std::vector<PairTest> again(last - first);
      std::vector<std::array<std::uint32_t, 2>> bodies(last - first);
      for (std::size_t i = first; i < last; ++i) {
        const PairTest& done = w.pairTests()[i];
        again[i - first].reset(done.bodyA(), done.bodyB());
        bodies[i - first] = {static_cast<std::uint32_t>(*w.indexOf(done.bodyA().id)),
                             static_cast<std::uint32_t>(*w.indexOf(done.bodyB().id))};
      }
      const std::unique_ptr<Scheduler> scheduler = makeScheduler(config.scheduler);
      BudgetTracker tracker(chunkShare(budget, k, w.narrowChunks()), Deadline());
      const ScheduleStats stats = scheduler->run(again, again.size(), PairBodies{bodies.data(), w.entityCount()},
                                                 &w.perception(), tracker);
      total += stats.sphere_tests;
      std::int64_t largest = 0;
      for (std::size_t i = first; i < last; ++i) {
        const PairTest& done = w.pairTests()[i];
        ASSERT_EQ(done.status(), again[i - first].status()) << "tick " << t << " pair " << i;
        ASSERT_EQ(done.stepsDone(), again[i - first].stepsDone()) << "tick " << t << " pair " << i;
        ASSERT_EQ(done.sphereTests(), again[i - first].sphereTests()) << "tick " << t << " pair " << i;
        largest = std::max(largest, done.sphereTests());
      }
      overshoot_bound += largest;
      if (stats.interrupted) checked_interrupted = true;
    }
    EXPECT_EQ(r.sphere_tests, total) << "tick " << t;
    // The shares sum to the budget. As with one thread, a chunk stops at the
    // first step that finds its share spent; the step that crosses it
    // finishes, so a chunk passes its share by less than one step.
    EXPECT_LE(r.sphere_tests, budget + overshoot_bound) << "tick " << t;
  }
  EXPECT_TRUE(checked_interrupted);
}

// A fake clock read by every worker: each read is one microsecond later.
SecondsClock atomicSteppingClock(double step) {
  auto reads = std::make_shared<std::atomic<std::int64_t>>(0);
  return [reads, step] { return step * static_cast<double>((*reads)++); };
}

TEST(ParallelTick, TheDeadlineStopsEveryWorker) {
  World w = sceneWorld(SceneKind::CornerDrift, 2);
  for (int t = 0; t < 60; ++t) w.step(1.0 / 60.0, Budget::unlimited());
  const std::int64_t unlimited = w.step(1.0 / 60.0, Budget::unlimited()).sphere_tests;
  w.setClock(atomicSteppingClock(1e-6));
  // Spent as the narrow phase starts: no chunk tests anything.
  TickReport r = w.step(1.0 / 60.0, Budget::ofSeconds(0.0));
  EXPECT_TRUE(r.interrupted);
  EXPECT_EQ(r.sphere_tests, 0);
  EXPECT_EQ(r.unresolved, w.pairCount());
  // Passed a few clock reads in: every chunk stops with pairs left.
  r = w.step(1.0 / 60.0, Budget::ofSeconds(2e-5));
  EXPECT_TRUE(r.interrupted);
  EXPECT_LT(r.sphere_tests, unlimited / 2);
  for (std::size_t k = 0; k < w.narrowChunks(); ++k) {
    const auto [first, last] = chunkRange(w.pairCount(), k, w.narrowChunks());
    std::size_t unresolved = 0;
    for (std::size_t i = first; i < last; ++i) unresolved += !w.pairTests()[i].resolved();
    EXPECT_GT(unresolved, 0u) << "chunk " << k << " ran on past the deadline";
  }
}

}  // namespace
}  // namespace stc
