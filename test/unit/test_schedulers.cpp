// Schedulers: each one's defining order under a sphere-test budget, identical
// results with an unlimited budget, zero budget, no perception, no allocation.
// PairTests are built directly from preset sphere-trees and poses (no World).
#include "deadline.hpp"
#include "pair_test.hpp"
#include "scheduler.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>
#include <numeric>
#include <random>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

// Counts heap allocations so a test can assert a warm run makes none.
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
// std::stable_sort's buffer comes from the nothrow form: it must come from
// malloc too, as the delete above frees it (AddressSanitizer caught the mismatch).
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace stc {
namespace {

constexpr SchedulerKind kAllKinds[] = {SchedulerKind::RoundRobin, SchedulerKind::Sequential,
                                       SchedulerKind::PerceptualSequential,
                                       SchedulerKind::PriorityQueues};
constexpr double kDepth = 8.0;  // metres in front of the default camera

// One rock shape (4-level tree, 0.8 m across) and pairs of rocks in front of the
// default camera (origin, looking along +z, 1280x720, 60 deg).
class SchedulerTest : public ::testing::Test {
 protected:
  // One tree for the whole suite: building it is the slow part.
  static void SetUpTestSuite() {
    PresetParams params;
    params.resolution = 16;
    params.voxel_size = 0.05;
    params.seed = 3;
    const VoxelShape shape = makePreset("rock", params);
    tree_ = SphereTree::build(shape, computeMassProperties(shape, 1.0).centre_of_mass);
  }
  void SetUp() override {
    ASSERT_GE(tree_.levelCount(), 3);
    camera_.setCamera(Camera{});
  }

  // Pair centres along the image's middle row at pixels u.
  std::vector<Vec3> rowAt(const std::vector<double>& us) const {
    std::vector<Vec3> out;
    for (double u : us) out.push_back(atPixel(u, 360.0));
    return out;
  }

  // World point at pixel (u, v) and depth kDepth.
  Vec3 atPixel(double u, double v) const {
    return Vec3((u - 640.0) * kDepth / camera_.focalPx(), (v - 360.0) * kDepth / camera_.focalPx(),
                kDepth);
  }

  // Pair i: centre `centres[i]`; relative pose drawn from seed `shapes[i]`.
  // Pairs that separate at the roots are redrawn so every pair needs >= 2 steps.
  void build(const std::vector<Vec3>& centres, const std::vector<unsigned>& shapes) {
    poses_.assign(2 * centres.size(), Pose{});
    tests_.assign(centres.size(), PairTest{});
    pair_bodies_.clear();
    for (std::uint32_t i = 0; i < centres.size(); ++i) pair_bodies_.push_back({2 * i, 2 * i + 1});
    for (std::size_t i = 0; i < centres.size(); ++i) {
      std::mt19937 rng(shapes[i]);
      std::uniform_real_distribution<double> unit(-1.0, 1.0);
      for (;;) {
        Vec3 axis(unit(rng), unit(rng), 0.3 * unit(rng));
        axis.normalize();
        const double distance = 0.55 + 0.3 * (0.5 + 0.5 * unit(rng));
        poses_[2 * i].position = centres[i] - 0.5 * distance * axis;
        poses_[2 * i + 1].position = centres[i] + 0.5 * distance * axis;
        poses_[2 * i].orientation = Quat(Eigen::AngleAxisd(3.0 * unit(rng), Vec3::UnitZ()) *
                                         Eigen::AngleAxisd(3.0 * unit(rng), Vec3::UnitX()));
        poses_[2 * i + 1].orientation = Quat(Eigen::AngleAxisd(3.0 * unit(rng), Vec3::UnitY()));
        resetPair(i);
        tests_[i].step();
        if (!tests_[i].resolved()) break;
      }
    }
    resetAll();
  }

  void resetPair(std::size_t i) {
    tests_[i].reset(PairBody{static_cast<EntityId>(2 * i), &tree_, &poses_[2 * i]},
                    PairBody{static_cast<EntityId>(2 * i + 1), &tree_, &poses_[2 * i + 1]});
  }
  void resetAll() {
    for (std::size_t i = 0; i < tests_.size(); ++i) resetPair(i);
  }

  ScheduleStats runWith(Scheduler& s, const Budget& budget, bool perceive = true) {
    resetAll();
    BudgetTracker tracker(budget);
    return s.run(tests_, tests_.size(), PairBodies{pair_bodies_.data(), poses_.size()},
                 perceive ? &camera_ : nullptr, tracker);
  }

  // Runs with budgets of one more step each time (a run under budget b is a
  // prefix of the unlimited run), recording the order in which pairs resolve
  // and the step counts at each interruption.
  std::vector<std::size_t> finishOrder(Scheduler& s, bool perceive = true,
                                       std::vector<std::vector<int>>* steps_at_stop = nullptr) {
    std::vector<std::size_t> order;
    std::vector<bool> done(tests_.size(), false);
    std::int64_t budget = 0;
    for (int guard = 0; guard < 100000; ++guard) {
      const ScheduleStats stats = runWith(s, Budget::ofSphereTests(budget), perceive);
      for (std::size_t i = 0; i < tests_.size(); ++i) {
        if (tests_[i].resolved() && !done[i]) {
          done[i] = true;
          order.push_back(i);
        }
      }
      if (!stats.interrupted) break;
      if (steps_at_stop) {
        std::vector<int> steps;
        for (const PairTest& t : tests_) steps.push_back(t.resolved() ? -1 : t.stepsDone());
        steps_at_stop->push_back(steps);
      }
      budget = stats.sphere_tests + 1;
    }
    return order;
  }

  static SphereTree tree_;
  Perception camera_;
  std::vector<Pose> poses_;
  std::vector<PairTest> tests_;
  std::vector<std::array<std::uint32_t, 2>> pair_bodies_;  // pair i joins bodies 2i and 2i+1
};

SphereTree SchedulerTest::tree_;

TEST_F(SchedulerTest, UnlimitedBudgetGivesIdenticalResultsForAllFour) {
  build(rowAt({100, 300, 500, 700, 900, 1100, 640, 200}),
        {1, 2, 3, 4, 5, 6, 7, 8});
  camera_.setFixation(Vec2(900, 300));
  std::vector<PairStatus> reference;
  std::vector<std::int64_t> reference_tests;
  for (SchedulerKind kind : kAllKinds) {
    auto s = makeScheduler(SchedulerOptions{kind, 4, 4.0});
    const ScheduleStats stats = runWith(*s, Budget::unlimited());
    EXPECT_FALSE(stats.interrupted) << toString(kind);
    std::int64_t total = 0;
    std::vector<PairStatus> statuses;
    std::vector<std::int64_t> per_pair;
    for (const PairTest& t : tests_) {
      EXPECT_TRUE(t.resolved()) << toString(kind);
      statuses.push_back(t.status());
      per_pair.push_back(t.sphereTests());
      total += t.sphereTests();
    }
    EXPECT_EQ(stats.sphere_tests, total) << toString(kind);
    if (reference.empty()) {
      reference = statuses;
      reference_tests = per_pair;
    } else {
      EXPECT_EQ(statuses, reference) << toString(kind);
      EXPECT_EQ(per_pair, reference_tests) << toString(kind);
    }
  }
  // The set is not trivial: both outcomes occur.
  EXPECT_NE(std::count(reference.begin(), reference.end(), PairStatus::Colliding), 0);
  EXPECT_NE(std::count(reference.begin(), reference.end(), PairStatus::Separate), 0);
}

TEST_F(SchedulerTest, ZeroBudgetStepsNothing) {
  build(rowAt({300, 640, 900}), {1, 2, 3});
  camera_.setFixation(Vec2(640, 360));
  for (SchedulerKind kind : kAllKinds) {
    auto s = makeScheduler(SchedulerOptions{kind, 4, 4.0});
    for (const Budget& budget : {Budget::ofSphereTests(0), Budget::ofSeconds(0.0)}) {
      const ScheduleStats stats = runWith(*s, budget);
      EXPECT_EQ(stats.sphere_tests, 0) << toString(kind);
      EXPECT_TRUE(stats.interrupted) << toString(kind);
      for (const PairTest& t : tests_) EXPECT_EQ(t.stepsDone(), 0) << toString(kind);
    }
  }
}

TEST_F(SchedulerTest, BudgetStopsBetweenStepsAndIsChargedEachStep) {
  build(rowAt({100, 300, 500, 700, 900, 1100}), {1, 2, 3, 4, 5, 6});
  camera_.setFixation(Vec2(640, 360));
  for (SchedulerKind kind : kAllKinds) {
    auto s = makeScheduler(SchedulerOptions{kind, 4, 4.0});
    const std::int64_t total = runWith(*s, Budget::unlimited()).sphere_tests;
    for (std::int64_t budget : {std::int64_t{1}, total / 3, total / 2}) {
      const ScheduleStats stats = runWith(*s, Budget::ofSphereTests(budget));
      EXPECT_GE(stats.sphere_tests, budget) << toString(kind);
      EXPECT_LT(stats.sphere_tests, total) << toString(kind);
      EXPECT_TRUE(stats.interrupted) << toString(kind);
      std::int64_t spent = 0;
      for (const PairTest& t : tests_) spent += t.sphereTests();
      EXPECT_EQ(spent, stats.sphere_tests) << toString(kind);
    }
  }
}

TEST_F(SchedulerTest, SequentialFinishesPairsInListOrder) {
  build(rowAt({1100, 900, 700, 500, 300, 100}), {1, 2, 3, 4, 5, 6});
  camera_.setFixation(Vec2(100, 360));  // must not matter
  auto s = makeScheduler(SchedulerOptions{SchedulerKind::Sequential, 4, 4.0});
  std::vector<std::vector<int>> stops;
  const auto order = finishOrder(*s, true, &stops);
  std::vector<std::size_t> expected(tests_.size());
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_EQ(order, expected);
  // At every interruption: a resolved prefix, one pair in progress, the rest untouched.
  for (const auto& steps : stops) {
    const auto first_open = std::find_if(steps.begin(), steps.end(), [](int n) { return n >= 0; });
    ASSERT_NE(first_open, steps.end());
    for (auto it = steps.begin(); it != first_open; ++it) EXPECT_EQ(*it, -1);
    for (auto it = first_open + 1; it != steps.end(); ++it) EXPECT_EQ(*it, 0);
  }
}

TEST_F(SchedulerTest, RoundRobinKeepsStepCountsWithinOne) {
  build(rowAt({100, 300, 500, 700, 900, 1100, 640}),
        {11, 12, 13, 14, 15, 16, 17});
  auto s = makeScheduler(SchedulerOptions{SchedulerKind::RoundRobin, 4, 4.0});
  std::vector<std::vector<int>> stops;
  finishOrder(*s, false, &stops);
  ASSERT_GT(stops.size(), tests_.size());
  for (const auto& steps : stops) {
    int lo = 1 << 30, hi = -1;
    for (int n : steps) {
      if (n < 0) continue;  // resolved
      lo = std::min(lo, n);
      hi = std::max(hi, n);
    }
    ASSERT_GE(hi, 0);
    EXPECT_LE(hi - lo, 1);
  }
}

TEST_F(SchedulerTest, PriorityQueuesFinishThePairsNearestTheFixationFirst) {
  // Same relative geometry for every pair; list order is farthest-first, so
  // round-robin finishes the far pairs first and priority queues must not.
  const std::vector<double> us = {1150, 900, 650, 400, 150};
  build(rowAt(us), {5, 5, 5, 5, 5});
  camera_.setFixation(Vec2(150, 360));
  for (double cost_exponent : {0.0, 1.0}) {
    auto pq = makeScheduler(SchedulerOptions{SchedulerKind::PriorityQueues, 5, 8.0, cost_exponent});
    EXPECT_EQ(finishOrder(*pq), (std::vector<std::size_t>{4, 3, 2, 1, 0})) << cost_exponent;
  }
  auto rr = makeScheduler(SchedulerOptions{SchedulerKind::RoundRobin, 4, 4.0});
  EXPECT_EQ(finishOrder(*rr), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
}

TEST_F(SchedulerTest, PriorityQueuesServeTheTopQueueBeforeLowerOnes) {
  const std::vector<double> us = {1150, 900, 650, 400, 150, 160};
  build(rowAt(us), {5, 6, 7, 8, 9, 10});
  camera_.setFixation(Vec2(150, 360));
  auto pq = makeScheduler(SchedulerOptions{SchedulerKind::PriorityQueues, 5, 8.0, 0.0});
  // The two pairs at the fixation are stepped before any far pair is touched.
  std::vector<std::vector<int>> stops;
  finishOrder(*pq, true, &stops);
  for (const auto& steps : stops) {
    const bool near_open = steps[4] >= 0 || steps[5] >= 0;
    if (near_open) {
      EXPECT_EQ(steps[0], 0);
      EXPECT_EQ(steps[1], 0);
    }
  }
}

// A pair's priority is measured once per run: f(e, g) with e its bodies'
// mean eccentricity and g the distance of its root spheres' centres, in
// pixels. With the paper's f (no cost) a pair's queue then never changes, so
// no pair is stepped while a pair of a higher bin is unresolved. The bins are
// computed here from Perception::gazeWeight (std::exp), independently of the
// scheduler's own exp.
TEST_F(SchedulerTest, PriorityQueuesBinEachPairOnceByItsRootsGap) {
  // Pairs on the line of sight through the fixation (every body's weight 1)
  // whose bodies are further apart down the list: the gap decides the bins,
  // the highest last in the list.
  build(rowAt({640, 640, 640, 640, 640, 640}), {1, 2, 3, 4, 5, 6});
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    const Vec3 centre = atPixel(640, 360);
    const Vec3 axis = Vec3::UnitZ();
    const double distance = 0.3 * std::pow(1.6, static_cast<double>(i));
    poses_[2 * i].position = centre - 0.5 * distance * axis;
    poses_[2 * i + 1].position = centre + 0.5 * distance * axis;
  }
  resetAll();
  camera_.setFixation(Vec2(640, 360));
  constexpr int kQueues = 16;
  std::vector<double> f(tests_.size());
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    const Perception::GazeWeight a = camera_.gazeWeight(poses_[2 * i].position);
    const Perception::GazeWeight b = camera_.gazeWeight(poses_[2 * i + 1].position);
    const double g = (poses_[2 * i].apply(tree_.root().centre) - poses_[2 * i + 1].apply(tree_.root().centre)).norm();
    f[i] = std::sqrt(a.weight * b.weight * a.px_per_metre * b.px_per_metre) * g;
  }
  const double fmax = *std::max_element(f.begin(), f.end());
  std::vector<int> bin(tests_.size());
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    bin[i] = std::clamp(kQueues + static_cast<int>(std::floor(std::log2(f[i] / fmax))), 0, kQueues - 1);
  }
  ASSERT_GE(std::set<int>(bin.begin(), bin.end()).size(), 3u);  // the bins have an order to keep

  // Pairs take their first step by bin, highest first, and in list order in a bin.
  std::vector<std::size_t> expected(tests_.size());
  std::iota(expected.begin(), expected.end(), 0);
  std::stable_sort(expected.begin(), expected.end(), [&](std::size_t x, std::size_t y) { return bin[x] > bin[y]; });
  auto pq = makeScheduler(SchedulerOptions{SchedulerKind::PriorityQueues, kQueues, 2.0, 0.0});
  std::vector<std::vector<int>> stops;
  finishOrder(*pq, true, &stops);
  std::vector<std::size_t> first_steps;
  for (const auto& steps : stops) {
    for (std::size_t i = 0; i < steps.size(); ++i) {
      if (steps[i] != 0 && std::find(first_steps.begin(), first_steps.end(), i) == first_steps.end()) {
        first_steps.push_back(i);
      }
    }
  }
  EXPECT_EQ(first_steps, expected);
}

TEST_F(SchedulerTest, CostAwarePriorityGivesAFarPairItsCheapRootTestEarly) {
  // Same geometry, one whose full test is expensive (>= 5 steps, >= 150 sphere
  // tests); the far pair is 500 px from the fixation (f about 150x lower).
  unsigned seed = 1;
  for (; seed < 200; ++seed) {
    build(rowAt({150}), {seed});
    while (!tests_[0].resolved()) tests_[0].step();
    if (tests_[0].stepsDone() >= 5 && tests_[0].sphereTests() >= 150) break;
  }
  ASSERT_LT(seed, 200u);
  build(rowAt({150, 650}), {seed, seed});
  camera_.setFixation(Vec2(150, 360));
  auto far_stepped_while_near_open = [&](double cost_exponent) {
    SchedulerOptions o;
    o.kind = SchedulerKind::PriorityQueues;
    o.queue_count = 16;
    o.queue_ratio = 2.0;
    o.cost_exponent = cost_exponent;
    auto s = makeScheduler(o);
    std::vector<std::vector<int>> stops;
    const auto order = finishOrder(*s, true, &stops);
    EXPECT_EQ(order, (std::vector<std::size_t>{0, 1}));  // the near pair still finishes first
    for (const auto& steps : stops) {
      if (steps[0] >= 0 && steps[1] > 0) return true;
    }
    return false;
  };
  // The paper's f: the far pair waits until the near one is resolved.
  EXPECT_FALSE(far_stepped_while_near_open(0.0));
  // Per sphere test: once the near pair's steps cost tens of tests, the far
  // pair's 1-test root step is worth more.
  EXPECT_TRUE(far_stepped_while_near_open(1.0));
}

// Found by fuzz_gaze: with every pair far off to the side of the fixation
// the largest priority is subnormal, so 1 / fmax is infinite and a pair whose
// priority underflowed to 0 got a share of 0 * inf = NaN, a bin past the
// queues, and a write through a null queue end. Every pair must still be
// queued and resolved as round-robin resolves it.
TEST_F(SchedulerTest, PriorityQueuesServePairsWhoseLargestPriorityIsSubnormal) {
  build(rowAt({640 + 72000, 640 + 80000}), {5, 6});
  camera_.setFixation(Vec2(640, 360));
  // log f, from Perception's pixels (not the scheduler's arithmetic): the
  // weight exp(-e / 100) of the bodies' mean eccentricity, times pixels per
  // metre, times the gap of the root centres.
  auto log_priority = [&](std::size_t i) {
    const Perception::GazeWeight a = camera_.gazeWeight(poses_[2 * i].position);
    const Perception::GazeWeight b = camera_.gazeWeight(poses_[2 * i + 1].position);
    const double mean_e = 0.5 * ((a.pixel - Vec2(640, 360)).norm() + (b.pixel - Vec2(640, 360)).norm());
    const double g = (poses_[2 * i].apply(tree_.root().centre) - poses_[2 * i + 1].apply(tree_.root().centre)).norm();
    return -mean_e / 100.0 + 0.5 * std::log(a.px_per_metre * b.px_per_metre) + std::log(g);
  };
  const double log_smallest_normal = std::log(std::numeric_limits<double>::min());
  const double log_smallest_subnormal = std::log(std::numeric_limits<double>::denorm_min());
  ASSERT_LT(log_priority(0), log_smallest_normal - 1.0);     // the largest is subnormal
  ASSERT_GT(log_priority(0), log_smallest_subnormal + 1.0);  // but not 0
  ASSERT_LT(log_priority(1), log_smallest_subnormal - 1.0);  // the other underflows to 0

  auto rr = makeScheduler(SchedulerOptions{SchedulerKind::RoundRobin, 4, 4.0});
  const ScheduleStats reference = runWith(*rr, Budget::unlimited());
  std::vector<int> steps;
  for (const PairTest& t : tests_) steps.push_back(t.stepsDone());
  for (double ratio : {2.0, 8.0}) {
    for (double cost_exponent : {0.0, 1.0}) {
      auto pq = makeScheduler(SchedulerOptions{SchedulerKind::PriorityQueues, 16, ratio, cost_exponent});
      const ScheduleStats stats = runWith(*pq, Budget::unlimited());
      EXPECT_TRUE(stats.used_perception);
      EXPECT_FALSE(stats.interrupted);
      EXPECT_EQ(stats.sphere_tests, reference.sphere_tests) << ratio << " " << cost_exponent;
      for (std::size_t i = 0; i < tests_.size(); ++i) {
        EXPECT_TRUE(tests_[i].resolved()) << i;
        EXPECT_EQ(tests_[i].stepsDone(), steps[i]) << i;
      }
    }
  }
}

TEST_F(SchedulerTest, PerceptualSequentialFinishesInPriorityOrder) {
  build(rowAt({100, 300, 500, 700, 900, 1100, 640, 200}),
        {21, 22, 23, 24, 25, 26, 27, 28});
  camera_.setFixation(Vec2(700, 300));
  std::vector<std::pair<double, std::size_t>> by_priority;
  for (std::size_t i = 0; i < tests_.size(); ++i) {
    by_priority.emplace_back(-camera_.measure(tests_[i]).priority, i);
  }
  std::sort(by_priority.begin(), by_priority.end());
  std::vector<std::size_t> expected;
  for (const auto& [p, i] : by_priority) expected.push_back(i);
  std::vector<std::size_t> list_order(tests_.size());
  std::iota(list_order.begin(), list_order.end(), 0);
  ASSERT_NE(expected, list_order);  // the sort has something to do

  auto s = makeScheduler(SchedulerOptions{SchedulerKind::PerceptualSequential, 4, 4.0});
  EXPECT_EQ(finishOrder(*s), expected);
}

TEST_F(SchedulerTest, WithoutPerceptionTheModelIsNotUsedAndListOrderHolds) {
  build(rowAt({1100, 900, 700, 500, 300, 100}), {1, 2, 3, 4, 5, 6});
  auto seq = makeScheduler(SchedulerOptions{SchedulerKind::Sequential, 4, 4.0});
  auto pseq = makeScheduler(SchedulerOptions{SchedulerKind::PerceptualSequential, 4, 4.0});
  auto rr = makeScheduler(SchedulerOptions{SchedulerKind::RoundRobin, 4, 4.0});
  auto pq = makeScheduler(SchedulerOptions{SchedulerKind::PriorityQueues, 4, 4.0});
  // No fixation set: the camera exists but perception is inactive.
  EXPECT_FALSE(runWith(*pseq, Budget::unlimited(), true).used_perception);
  EXPECT_FALSE(runWith(*pq, Budget::unlimited(), true).used_perception);
  EXPECT_FALSE(runWith(*pq, Budget::unlimited(), false).used_perception);
  EXPECT_EQ(finishOrder(*pseq, true), finishOrder(*seq, true));
  EXPECT_EQ(finishOrder(*pq, false), finishOrder(*rr, false));
  camera_.setFixation(Vec2(100, 360));
  EXPECT_TRUE(runWith(*pq, Budget::unlimited(), true).used_perception);
  {  // without the pairs' body indices there is nothing to project per body
    resetAll();
    BudgetTracker tracker(Budget::unlimited());
    EXPECT_FALSE(pq->run(tests_, tests_.size(), PairBodies{}, &camera_, tracker).used_perception);
  }
  EXPECT_TRUE(runWith(*pseq, Budget::unlimited(), true).used_perception);
  EXPECT_FALSE(runWith(*rr, Budget::unlimited(), true).used_perception);
}

TEST_F(SchedulerTest, WarmRunsDoNotAllocate) {
  build(rowAt({100, 300, 500, 700, 900, 1100, 640, 200}),
        {1, 2, 3, 4, 5, 6, 7, 8});
  camera_.setFixation(Vec2(640, 360));
  for (SchedulerKind kind : kAllKinds) {
    auto s = makeScheduler(SchedulerOptions{kind, 4, 4.0});
    runWith(*s, Budget::unlimited());
    runWith(*s, Budget::unlimited());
    const long before = g_allocations.load();
    const ScheduleStats stats = runWith(*s, Budget::unlimited());
    runWith(*s, Budget::ofSphereTests(stats.sphere_tests / 2));
    EXPECT_EQ(g_allocations.load() - before, 0) << toString(kind);
  }
}

// The scene stepped `ticks` full ticks, its poses copied into a World of it
// with the response off: a snapshot the schedulers step over (dt 0) again
// and again.
World snapshotOf(SceneKind kind, const SceneParams& params, int ticks) {
  auto [sim, spec] = makeSceneWorld(kind, params);
  for (int i = 0; i < ticks; ++i) sim.step(spec.dt, Budget::unlimited());
  WorldConfig still;
  still.response.enabled = false;
  World eval = std::move(makeSceneWorld(kind, params, still).world);
  for (std::size_t i = 0; i < sim.entityCount(); ++i) eval.bodies()[i].pose = sim.bodies()[i].pose;
  return eval;
}

// The cheaper bookkeeping changes only the order of steps: with no budget
// every scheduler leaves every pair of a real scene in the same state after
// the same sphere tests, with the same contacts (round-robin's code is the
// reference: it has no bookkeeping to change).
TEST(SchedulerSceneTest, UnlimitedBudgetGivesRoundRobinsResultsOnBothScenes) {
  for (const auto& [kind, entities, ticks] : {std::tuple{SceneKind::PackedBox, 125, 20},
                                              std::tuple{SceneKind::Rockfall, 60, 60}}) {
    SceneParams params;
    params.entities = entities;
    World eval = snapshotOf(kind, params, ticks);
    const auto fixation = eval.perception().project(eval.bodies()[eval.entityCount() / 2].pose.position);
    ASSERT_TRUE(fixation && eval.perception().onScreen(*fixation)) << toString(kind);
    eval.perception().setFixation(*fixation);

    std::vector<PairStatus> reference;
    std::vector<std::int64_t> reference_tests;
    std::size_t reference_contacts = 0;
    for (SchedulerKind scheduler : kAllKinds) {
      SchedulerOptions options;
      options.kind = scheduler;
      eval.setScheduler(options);
      const TickReport report = eval.step(0.0, Budget::unlimited());
      EXPECT_FALSE(report.detection.interrupted);
      std::vector<PairStatus> statuses;
      std::vector<std::int64_t> tests;
      for (std::size_t i = 0; i < eval.pairCount(); ++i) {
        statuses.push_back(pairTests(eval)[i].status());
        tests.push_back(pairTests(eval)[i].sphereTests());
      }
      if (reference.empty()) {
        reference = statuses;
        reference_tests = tests;
        reference_contacts = eval.contacts().size();
        continue;
      }
      EXPECT_EQ(statuses, reference) << toString(kind) << " " << toString(scheduler);
      EXPECT_EQ(tests, reference_tests) << toString(kind) << " " << toString(scheduler);
      EXPECT_EQ(eval.contacts().size(), reference_contacts) << toString(kind) << " " << toString(scheduler);
    }
    EXPECT_GT(std::count(reference.begin(), reference.end(), PairStatus::Colliding), 10) << toString(kind);
    EXPECT_GT(std::count(reference.begin(), reference.end(), PairStatus::Separate), 10) << toString(kind);
  }
}

// Priority queues find a pair's bin two ways: from the exponent of f / fmax
// when the bins are a factor 2 apart (the default), by comparing with each bin
// edge otherwise. The two must bin alike: under budgets that interrupt the
// run, a ratio of 2 and one a hair above it step every pair of a real scene alike.
TEST(SchedulerSceneTest, PriorityQueuesBinAlikeByExponentAndByEdges) {
  SceneParams params;
  params.entities = 125;
  World eval = snapshotOf(SceneKind::PackedBox, params, 20);
  const auto fixation = eval.perception().project(eval.bodies()[eval.entityCount() / 2].pose.position);
  ASSERT_TRUE(fixation && eval.perception().onScreen(*fixation));
  eval.perception().setFixation(*fixation);
  const std::int64_t total = eval.step(0.0, Budget::unlimited()).detection.sphere_tests;

  auto stepsUnder = [&](double ratio, std::int64_t budget) {
    SchedulerOptions options;  // priority queues, 16 queues, cost exponent 1
    options.queue_ratio = ratio;
    eval.setScheduler(options);
    eval.step(0.0, Budget::ofSphereTests(budget));
    std::vector<std::int64_t> tests;
    for (std::size_t i = 0; i < eval.pairCount(); ++i) tests.push_back(pairTests(eval)[i].sphereTests());
    return tests;
  };
  for (double share : {0.02, 0.1, 0.3}) {
    const auto budget = static_cast<std::int64_t>(share * static_cast<double>(total));
    const auto by_exponent = stepsUnder(2.0, budget);
    EXPECT_EQ(by_exponent, stepsUnder(2.0 + 1e-12, budget)) << share;
    EXPECT_NE(by_exponent, stepsUnder(4.0, budget)) << share;  // the bins matter at this budget
  }
}

TEST(SchedulerOptionsTest, BadOptionsNameTheField) {
  auto field = [](SchedulerOptions o) {
    try {
      makeScheduler(o);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("<no throw>");
  };
  EXPECT_EQ(field(SchedulerOptions{SchedulerKind::PriorityQueues, 0, 4.0}), "queue_count");
  EXPECT_EQ(field(SchedulerOptions{SchedulerKind::PriorityQueues, 4, 1.0}), "queue_ratio");
  EXPECT_EQ(field(SchedulerOptions{SchedulerKind::PriorityQueues, 4, std::nan("")}), "queue_ratio");
  EXPECT_EQ(field(SchedulerOptions{SchedulerKind::PriorityQueues, 4, 2.0, -1.0}), "cost_exponent");
  EXPECT_EQ(field(SchedulerOptions{SchedulerKind::RoundRobin, 4, 4.0}), "<no throw>");
}

}  // namespace
}  // namespace stc
