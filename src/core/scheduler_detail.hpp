// Private to the scheduler sources: the four Scheduler classes and the one
// helper they share (a step that obeys the budget and is timed as work).
#pragma once

#include "sphere_tree_collision/scheduler.hpp"

#include <chrono>
#include <cstdint>
#include <utility>
#include <vector>

#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

namespace stc::detail {

// Splits one run's wall time into "stepping PairTests" and "everything else"
// (perception, sorting, queue moves, loop and budget checks): overhead.
// Steps are timed with the time-stamp counter (a few ns per read) so that
// timing each step does not itself become the overhead it measures; the
// counter is converted to seconds by the run's own steady_clock span.
class RunTimer {
 public:
  RunTimer() : wall_start_(std::chrono::steady_clock::now()), tick_start_(ticks()) {}

  // One step of `test` if the budget allows; false when the budget is exhausted.
  bool step(PairTest& test, BudgetTracker& budget, ScheduleStats& stats) {
    if (budget.exhausted()) return false;
    const std::uint64_t t0 = ticks();
    const int tests = test.step();
    step_ticks_ += ticks() - t0;
    budget.charge(tests);
    stats.sphere_tests += tests;
    return true;
  }

  double overheadSeconds() const {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
    const std::uint64_t total = ticks() - tick_start_;
    if (total == 0 || step_ticks_ >= total) return 0.0;
    return wall * (1.0 - static_cast<double>(step_ticks_) / static_cast<double>(total));
  }

 private:
  static std::uint64_t ticks() {
#if defined(__x86_64__) || defined(__i386__)
    return __rdtsc();
#else
    return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
  }

  std::chrono::steady_clock::time_point wall_start_;
  std::uint64_t tick_start_;
  std::uint64_t step_ticks_ = 0;
};

inline bool perceptionActive(const Perception* perception) {
  return perception != nullptr && perception->hasFixation();
}

// Hubbard: one level for every unresolved pair in list order, then again.
class RoundRobinScheduler final : public Scheduler {
 public:
  ScheduleStats run(std::vector<PairTest>& tests, std::size_t count, const Perception* perception,
                    BudgetTracker& budget) override;

 private:
  std::vector<std::uint32_t> active_;  // unresolved pairs, list order; capacity reused
};

// Pairs resolved fully one by one. With `sort_by_priority` (and a fixation)
// the order is the perceptual priority f(e, g) at the start of the run,
// highest first (ties: list order); without, list order.
class SequentialScheduler final : public Scheduler {
 public:
  explicit SequentialScheduler(bool sort_by_priority) : sort_by_priority_(sort_by_priority) {}
  ScheduleStats run(std::vector<PairTest>& tests, std::size_t count, const Perception* perception,
                    BudgetTracker& budget) override;

 private:
  bool sort_by_priority_;
  std::vector<std::pair<double, std::uint32_t>> order_;  // (priority, pair); capacity reused
};

// K queues, highest first; round-robin inside a queue; the perceptual model
// only picks the queue (see priority_queue_scheduler.cpp for the bins).
class PriorityQueueScheduler final : public Scheduler {
 public:
  explicit PriorityQueueScheduler(const SchedulerOptions& options);
  ScheduleStats run(std::vector<PairTest>& tests, std::size_t count, const Perception* perception,
                    BudgetTracker& budget) override;

  // Queue of a priority given the run's reference (largest initial) priority.
  int queueOf(double priority, double reference) const;

 private:
  int queue_count_;
  double inv_log_ratio_;
  std::vector<std::vector<std::uint32_t>> queues_;  // [0] lowest .. [K-1] highest; capacity reused
  std::vector<double> priorities_;                  // initial f per pair; capacity reused
};

}  // namespace stc::detail
