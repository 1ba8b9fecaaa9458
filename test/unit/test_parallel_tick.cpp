// The parallel tick (WorldConfig::threads): validated; at an unlimited budget
// the same poses and contacts bit for bit whatever the thread count; with a
// sphere-test budget the same bits run after run; each chunk of the narrow
// phase runs the scheduler over its pairs under its share of the budget; the
// deadline stops every worker. No timing is asserted: budgets are counts, and
// the deadline runs on a fake clock.
#include "contact_partition.hpp"
#include "deadline.hpp"
#include "narrow_chunks.hpp"
#include "pair_test.hpp"
#include "physics.hpp"
#include "same_state.hpp"
#include "scheduler.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "workers.hpp"
#include "world_access.hpp"

#include "world_refuses.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
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

const SceneKind kScenes[] = {SceneKind::CornerDrift, SceneKind::Rockfall, SceneKind::PackedBox};

TEST(ParallelTick, ThreadsAreValidatedAndResolved) {
  for (const int bad : {-1, kMaxThreads + 1, 1 << 30}) {
    WorldConfig config;
    config.threads = bad;
    EXPECT_TRUE(worldRefuses(config, "threads")) << "threads = " << bad;
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
    std::size_t contacts = 0, most_bounced = 0;
    for (int t = 0; t < kTicks; ++t) {
      const TickReport r1 = one.step(1.0 / 60.0, Budget::unlimited());
      most_bounced = std::max(most_bounced, physicsReport(one).solve.bounced);
      const TickReport r2 = two.step(1.0 / 60.0, Budget::unlimited());
      const TickReport r4 = four.step(1.0 / 60.0, Budget::unlimited());
      ASSERT_TRUE(sameState(one, two)) << toString(kind) << " 1 vs 2 threads, tick " << t;
      ASSERT_TRUE(sameState(one, four)) << toString(kind) << " 1 vs 4 threads, tick " << t;
      ASSERT_EQ(r1.detection.sphere_tests, r2.detection.sphere_tests) << toString(kind) << " tick " << t;
      ASSERT_EQ(r1.detection.sphere_tests, r4.detection.sphere_tests) << toString(kind) << " tick " << t;
      contacts += r1.response.contacts;
    }
    EXPECT_GT(contacts, 0u) << toString(kind);  // the bodies did touch
    // Restitution waves big enough for the team (16 rows a stage at 4
    // manifolds a task) bounced too, and gave the same bits.
    EXPECT_GT(most_bounced, 16u) << toString(kind);
  }
}

// World::timeTeamLoops only reads clocks: the same bits as a world that does
// not time. Its figures are consistent with each other and with the tick
// (no threshold on any duration): loops ran, the calling thread's wait lies
// within its time in the loops, and that within the tick as timed around
// step(); off, or with one thread, they stay zero.
TEST(ParallelTick, TimedTeamLoopsAddUpWithinTheTickAndChangeNoBits) {
  World plain = sceneWorld(SceneKind::CornerDrift, 2);
  World timed = sceneWorld(SceneKind::CornerDrift, 2);
  World alone = sceneWorld(SceneKind::CornerDrift, 1);
  timed.timeTeamLoops(true);
  alone.timeTeamLoops(true);
  std::uint64_t loops = 0;
  for (int t = 0; t < 120; ++t) {
    const TickReport off = plain.step(1.0 / 60.0, Budget::unlimited());
    const auto start = std::chrono::steady_clock::now();
    const TickReport on = timed.step(1.0 / 60.0, Budget::unlimited());
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const TickReport one = alone.step(1.0 / 60.0, Budget::unlimited());
    ASSERT_TRUE(sameState(plain, timed)) << "tick " << t;
    EXPECT_EQ(off.phases.team_loops, 0u);
    EXPECT_EQ(off.phases.team_loop_s, 0.0);
    EXPECT_EQ(one.phases.team_loops, 0u);
    EXPECT_EQ(one.phases.team_loop_s, 0.0);
    EXPECT_GE(on.phases.team_wait_s, 0.0) << "tick " << t;
    EXPECT_LE(on.phases.team_wait_s, on.phases.team_loop_s) << "tick " << t;
    EXPECT_LE(on.phases.team_loop_s, wall) << "tick " << t;
    EXPECT_EQ(on.phases.team_loops == 0, on.phases.team_loop_s == 0.0) << "tick " << t;
    loops += on.phases.team_loops;
  }
  EXPECT_GT(loops, 120u);  // more than one a tick (the narrow phase alone runs chunks on the team)
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
        interrupted = interrupted || r.detection.interrupted;
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
        const PairTest& done = pairTests(w)[i];
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
        const PairTest& done = pairTests(w)[i];
        ASSERT_EQ(done.status(), again[i - first].status()) << "tick " << t << " pair " << i;
        ASSERT_EQ(done.stepsDone(), again[i - first].stepsDone()) << "tick " << t << " pair " << i;
        ASSERT_EQ(done.sphereTests(), again[i - first].sphereTests()) << "tick " << t << " pair " << i;
        largest = std::max(largest, done.sphereTests());
      }
      overshoot_bound += largest;
      if (stats.interrupted) checked_interrupted = true;
    }
    EXPECT_EQ(r.detection.sphere_tests, total) << "tick " << t;
    // The shares sum to the budget. As with one thread, a chunk stops at the
    // first step that finds its share spent; the step that crosses it
    // finishes, so a chunk passes its share by less than one step.
    EXPECT_LE(r.detection.sphere_tests, budget + overshoot_bound) << "tick " << t;
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
  const std::int64_t unlimited = w.step(1.0 / 60.0, Budget::unlimited()).detection.sphere_tests;
  w.setClock(atomicSteppingClock(1e-6));
  // Spent as the narrow phase starts: no chunk tests anything.
  TickReport r = w.step(1.0 / 60.0, Budget::ofSeconds(0.0));
  EXPECT_TRUE(r.detection.interrupted);
  EXPECT_EQ(r.detection.sphere_tests, 0);
  // Every pair is left unresolved but those whose contacts are carried over
  // (reuse_tolerance, on by default): they need no sphere test.
  EXPECT_EQ(r.detection.unresolved + r.detection.reused, w.pairCount());
  // Passed a few clock reads in: every chunk stops with pairs left.
  r = w.step(1.0 / 60.0, Budget::ofSeconds(2e-5));
  EXPECT_TRUE(r.detection.interrupted);
  EXPECT_LT(r.detection.sphere_tests, unlimited / 2);
  for (std::size_t k = 0; k < w.narrowChunks(); ++k) {
    const auto [first, last] = chunkRange(w.pairCount(), k, w.narrowChunks());
    std::size_t unresolved = 0;
    for (std::size_t i = first; i < last; ++i) unresolved += !pairTests(w)[i].resolved();
    EXPECT_GT(unresolved, 0u) << "chunk " << k << " ran on past the deadline";
  }
}


// The solver's blocks (contact_partition.hpp): bodies on a grid of nx x ny x
// nz at unit spacing, a group between each pair of neighbours along x, y and
// z, and one from each body of the bottom layer to a static floor.
struct GridGroups {
  std::vector<BodyState> bodies;
  std::vector<SolverGroup> groups;
};

GridGroups gridGroups(int nx, int ny, int nz) {
  GridGroups g;
  const auto index = [&](int x, int y, int z) { return static_cast<std::uint32_t>((z * ny + y) * nx + x); };
  g.bodies.resize(static_cast<std::size_t>(nx * ny * nz) + 1);
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        g.bodies[index(x, y, z)].pose.position = Vec3(x, y, z);
        if (x > 0) g.groups.push_back({index(x - 1, y, z), index(x, y, z)});
        if (y > 0) g.groups.push_back({index(x, y - 1, z), index(x, y, z)});
        if (z > 0) g.groups.push_back({index(x, y, z - 1), index(x, y, z)});
        if (z == 0) g.groups.push_back({SolverGroup::kStatic, index(x, y, z)});
      }
    }
  }
  g.bodies.back().is_static = true;  // the floor (never named: groups say kStatic)
  return g;
}

TEST(ContactPartition, BlocksOfOneStageShareNoMovableBody) {
  for (const auto& [nx, ny, nz] : {std::array<int, 3>{64, 4, 3}, std::array<int, 3>{12, 12, 12}, std::array<int, 3>{5, 30, 2}}) {
    const GridGroups g = gridGroups(nx, ny, nz);
    ContactPartition partition;
    partition.assign(g.groups, g.bodies);
    ASSERT_GT(partition.slabs(), 1u) << nx << "x" << ny << "x" << nz;
    const std::vector<std::uint32_t>& block = partition.blocks();
    ASSERT_EQ(block.size(), g.groups.size());
    // Per stage, the block that last wrote each body: another block of the
    // same stage must not touch it.
    std::vector<std::int64_t> owner(g.bodies.size());
    std::size_t crossing = 0;
    for (std::uint32_t stage = 0; stage < ContactPartition::kStages; ++stage) {
      std::fill(owner.begin(), owner.end(), -1);
      for (std::size_t k = 0; k < g.groups.size(); ++k) {
        ASSERT_LT(block[k], partition.blockCount());
        if (partition.stageOf(block[k]) != stage) continue;
        if (stage > 0) ++crossing;
        for (const std::uint32_t body : {g.groups[k].a, g.groups[k].b}) {
          if (body == SolverGroup::kStatic) continue;
          if (owner[body] == -1) owner[body] = block[k];
          EXPECT_EQ(owner[body], block[k]) << "body " << body << " in two blocks of stage " << stage;
        }
      }
    }
    EXPECT_EQ(crossing, partition.crossing());
    EXPECT_LE(static_cast<double>(crossing), ContactPartition::kMaxCrossingShare * static_cast<double>(g.groups.size()));
  }
}

TEST(ContactPartition, SlabsFollowTheLongAxisAndStayThickEnough) {
  // A long row: the most slabs; within a slab the groups keep their order.
  const GridGroups row = gridGroups(400, 2, 2);
  ContactPartition partition;
  partition.assign(row.groups, row.bodies);
  EXPECT_EQ(partition.slabs(), ContactPartition::kMaxSlabs);
  for (std::size_t k = 0; k < row.groups.size(); ++k) {
    if (partition.stageOf(partition.blocks()[k]) != 0) continue;
    const double x = row.bodies[row.groups[k].b].pose.position.x();
    const std::uint32_t slab = partition.blocks()[k];
    EXPECT_NEAR(x, (slab + 0.5) * 400.0 / ContactPartition::kMaxSlabs, 400.0 / ContactPartition::kMaxSlabs) << k;
  }
  // A cube 8 bodies wide (1,408 groups): 16 or 8 slabs would be a body
  // thick or less and put the 448 groups along x (32 %) across the cuts; 4
  // slabs of two bodies put the 3 x 64 groups at their cuts.
  const GridGroups cube = gridGroups(8, 8, 8);
  partition.assign(cube.groups, cube.bodies);
  EXPECT_EQ(partition.slabs(), 4u);
  EXPECT_EQ(partition.crossing(), 3u * 64u);
  // Too few groups for two slabs, and bodies all at one point: one block.
  const GridGroups few = gridGroups(4, 4, 1);
  ASSERT_LT(few.groups.size(), 2 * ContactPartition::kMinGroupsPerSlab);
  partition.assign(few.groups, few.bodies);
  EXPECT_EQ(partition.slabs(), 1u);
  GridGroups point = gridGroups(30, 30, 1);
  for (BodyState& b : point.bodies) b.pose.position = Vec3(1.0, 2.0, 3.0);
  partition.assign(point.groups, point.bodies);
  EXPECT_EQ(partition.slabs(), 1u);
  for (const std::uint32_t b : partition.blocks()) EXPECT_EQ(b, 0u);
}


// Team (workers.hpp): each block of a loop runs exactly once, on some member;
// the workers' own loops and a nested withTeam use the running team; a throw
// leaves the workers usable. Counts only, no timing.
TEST(Team, EveryBlockRunsOnceAndTheWorkersLoopsJoinTheTeam) {
  for (const int threads : {2, 4}) {
    Workers workers(threads);
    const std::vector<std::size_t> counts = {0, 1, 2, 3, 17, Team::kMaxBlocks, 150};  // 150: three rounds
    std::vector<int> runs(150, 0);  // block k writes only runs[k]
    std::vector<int> indices(1000, 0);
    constexpr int kCalls = 50;
    for (int call = 0; call < kCalls; ++call) {
      workers.withTeam([&](Team& team) {
        EXPECT_EQ(team.members(), threads);
        for (const std::size_t count : counts) {
          for (const Team::Claim claim : {Team::Claim::OwnShareWhole, Team::Claim::Balanced}) {
            team.forBlocks(count, [&](std::size_t k, std::size_t end) {
              EXPECT_EQ(end, k + 1);
              ++runs[k];
            }, claim);
          }
        }
        workers.forEach(indices.size(), 10, [&](std::size_t begin, std::size_t end) {
          for (std::size_t i = begin; i < end; ++i) ++indices[i];
        });
        workers.forChunks(5, [&](std::size_t k, std::size_t) { ++runs[k]; });
        workers.withTeam([&](Team& inner) { EXPECT_EQ(&inner, &team); });
      });
    }
    for (std::size_t k = 0; k < runs.size(); ++k) {
      const int loops = static_cast<int>(std::count_if(counts.begin(), counts.end(), [&](std::size_t c) { return c > k; }));
      EXPECT_EQ(runs[k], kCalls * (2 * loops + (k < 5 ? 1 : 0))) << "block " << k << ", " << threads << " threads";
    }
    for (const int n : indices) EXPECT_EQ(n, kCalls);
  }
}

// Balanced: a member stuck in its first block does not keep the rest of its
// share; the other member, done with its own, takes it from the end.
TEST(Team, ABalancedLoopLetsAFreeMemberTakeTheRestOfABusyOnesShare) {
  Workers workers(2);
  constexpr std::size_t kBlocks = 8;  // member 0's share: 0-3
  std::array<std::atomic<int>, kBlocks> ran_on_caller{};
  std::atomic<bool> last_of_share_done{false};
  const std::thread::id caller = std::this_thread::get_id();
  workers.withTeam([&](Team& team) {
    team.forBlocks(kBlocks, [&](std::size_t k, std::size_t) {
      if (k == 0) {
        // Waits for block 3, which only the other member can run now. The
        // bound only keeps a broken claim from hanging the suite.
        const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (!last_of_share_done.load() && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
      }
      ran_on_caller[k] = std::this_thread::get_id() == caller ? 1 : 0;
      if (k == 3) last_of_share_done = true;
    }, Team::Claim::Balanced);
  });
  EXPECT_TRUE(last_of_share_done.load());
  // Whoever ran block 0 (the caller, unless it lost its core that long) had
  // to see block 3 done first; the caller runs its share in order, so block 3
  // was the other member's.
  EXPECT_EQ(ran_on_caller[3].load(), 0) << "block 3 waited for its own member";
}

TEST(Team, AThrowLeavesTheWorkersUsable) {
  Workers workers(2);
  std::vector<int> runs(8, 0);
  EXPECT_THROW(workers.withTeam([&](Team& team) {
    team.forBlocks(runs.size(), [&](std::size_t k, std::size_t) { ++runs[k]; });
    throw InputError("test", "thrown inside the team");
  }),
               InputError);
  workers.withTeam([&](Team& team) { team.forBlocks(runs.size(), [&](std::size_t k, std::size_t) { ++runs[k]; }); });
  workers.forChunks(runs.size(), [&](std::size_t k, std::size_t) { ++runs[k]; });  // outside a team: TBB
  for (const int n : runs) EXPECT_EQ(n, 3);
}

}  // namespace
}  // namespace stc
