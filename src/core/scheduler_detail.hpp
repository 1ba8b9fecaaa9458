// Private to the scheduler sources: the four Scheduler classes and the one
// helper they share (a step that obeys the budget and is timed as work).
#pragma once

#include "scheduler.hpp"

#include <array>
#include <chrono>
#include <cstdint>
#include <utility>
#include <vector>


namespace stc::detail {

// Overhead = the decision work of a run, timed block by block: building the
// order (perception, sorting, queue binning) and re-queueing after each pass.
// The loop that calls PairTest::step() and checks the budget is counted as
// testing. Blocks, not steps, are timed: a clock read costs as much as several
// sphere tests here, so timing every step would become the overhead it measures.
class OverheadClock {
 public:
  using Clock = std::chrono::steady_clock;
  void start() { started_ = Clock::now(); }
  void stop() { total_ += Clock::now() - started_; }
  double seconds() const { return std::chrono::duration<double>(total_).count(); }

 private:
  Clock::time_point started_{};
  Clock::duration total_{0};
};

// Times one in kEvery blocks and scales the total up by the block count: an
// unbiased estimate for many short blocks (the re-queueing after each pass)
// at a quarter of the clock reads.
class SampledClock {
 public:
  static constexpr std::uint32_t kEvery = 4;
  // Which block of every kEvery is timed; vary it from run to run so blocks
  // that come in a fixed order each run are all sampled.
  explicit SampledClock(std::uint32_t phase = 0) : blocks_(phase % kEvery), first_(blocks_) {}
  void start() {
    timing_ = blocks_++ % kEvery == 0;
    if (timing_) started_ = OverheadClock::Clock::now();
  }
  void stop() {
    if (!timing_) return;
    total_ += OverheadClock::Clock::now() - started_;
    ++timed_;
  }
  double seconds() const {
    if (timed_ == 0) return 0.0;
    return std::chrono::duration<double>(total_).count() * (blocks_ - first_) / timed_;
  }

 private:
  OverheadClock::Clock::time_point started_{};
  OverheadClock::Clock::duration total_{0};
  std::uint32_t blocks_ = 0, first_ = 0, timed_ = 0;
  bool timing_ = false;
};

// One step of `test` if the budget allows; false when the budget is exhausted.
inline bool budgetedStep(PairTest& test, BudgetTracker& budget, ScheduleStats& stats) {
  if (budget.exhausted()) return false;
  const int tests = test.step();
  budget.charge(tests);
  stats.sphere_tests += tests;
  return true;
}

inline bool perceptionActive(const Perception* perception) {
  return perception != nullptr && perception->hasFixation();
}

// Hubbard: one level for every unresolved pair in list order, then again.
class RoundRobinScheduler final : public Scheduler {
 public:
  ScheduleStats run(PairTest* tests, std::size_t count, const PairBodies& bodies,
                    const Perception* perception, BudgetTracker& budget) override;

 private:
  std::vector<std::uint32_t> active_;  // unresolved pairs, list order; capacity reused
};

// Pairs resolved fully one by one. With `sort_by_priority` (and a fixation)
// the order is the perceptual priority f(e, g) at the start of the run,
// highest first (ties: list order); without, list order.
class SequentialScheduler final : public Scheduler {
 public:
  explicit SequentialScheduler(bool sort_by_priority) : sort_by_priority_(sort_by_priority) {}
  ScheduleStats run(PairTest* tests, std::size_t count, const PairBodies& bodies,
                    const Perception* perception, BudgetTracker& budget) override;

 private:
  bool sort_by_priority_;
  std::vector<std::pair<double, std::uint32_t>> order_;  // (priority, pair); capacity reused
};

// K queues, highest first; round-robin inside a queue; the perceptual model
// only picks the queue (see scheduler_priority_queues.cpp for the bins).
class PriorityQueueScheduler final : public Scheduler {
 public:
  explicit PriorityQueueScheduler(const SchedulerOptions& options);
  ScheduleStats run(PairTest* tests, std::size_t count, const PairBodies& bodies,
                    const Perception* perception, BudgetTracker& budget) override;

 private:
  // A body's projection, made once per run however many pairs share the body.
  struct BodyGaze {
    Vec3 root_centre = Vec3::Zero();  // its tree's root sphere's centre, world frame
    // exp(-e / 200) * sqrt(pixels per metre), e the eccentricity of its
    // origin: a pair's weight x pixels per metre is the product of its two
    // bodies' (0 behind the camera).
    double root_scale = 0.0;
    std::uint32_t run = 0;  // the run that made it
  };
  // Measures every unresolved pair, sets the bins from the largest priority, queues them.
  void binAll(PairTest* tests, std::size_t count, const PairBodies& bodies,
              const Perception& perception);
  double perCost(double x, int cost) const;
  int binOf(double share) const;
  // How a stepped pair is binned (scheduler_priority_queues.cpp): by the
  // exponent (the defaults), by the edges (other options), not at all (queue 0).
  struct ExponentBin;
  struct EdgeBin;
  struct StayBin;
  template <typename BinAfterStep>
  bool serveQueues(BudgetTracker& budget, SampledClock& requeue, BinAfterStep binAfterStep);
  template <typename BinAfterStep>
  bool servePass(int q, BudgetTracker& budget, BinAfterStep binAfterStep);

  // A queued pair (its PairTest's address: no index arithmetic per step) and
  // its priority over the run's largest at a cost of one sphere test:
  // divided by the cost of its next step (kept by the PairTest), its
  // priority as a share of the largest. All a re-bin needs.
  struct Queued {
    PairTest* test = nullptr;
    double share = 0.0;
  };
  // A measured pair before the bins are known.
  struct Measured {
    std::uint32_t pair = 0;
    double priority = 0.0;
  };

  static constexpr std::size_t kMaxQueues = 64;  // validateSchedulerOptions
  int queue_count_;
  double cost_exponent_;
  bool binary_bins_;  // queue_ratio 2: a share's bin is read off its exponent
  // Queue q ([0] lowest .. [K-1] highest) is slots_[q * stride_, ends_[q]);
  // stride_ = pairs + 1. The ends are kept as pointers from run to run of a
  // pass (a mover is one store and one add). Storage reused across runs.
  std::vector<Queued> slots_;
  std::size_t stride_ = 0;
  std::array<Queued*, kMaxQueues> ends_{};
  Queued* queueBegin(int q) { return slots_.data() + static_cast<std::size_t>(q) * stride_; }
  // Bins a factor 2 apart: the queue of a share x of the largest priority by
  // x's biased IEEE exponent (clamped to the queues). Other ratios: the
  // share at the bottom of each queue.
  std::array<std::uint8_t, 2048> bin_of_exponent_{};
  std::vector<double> lower_share_;
  // A body to project this run.
  struct Unseen {
    std::uint32_t body = 0;
    const PairBody* of = nullptr;
  };
  // Capacity reused: per body, its projection; per unresolved pair, its
  // measure; the bodies to project.
  std::vector<BodyGaze> gaze_;
  std::uint32_t run_ = 0;
  std::vector<Measured> measured_;
  std::vector<Unseen> unseen_;
};

}  // namespace stc::detail
