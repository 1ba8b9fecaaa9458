// Priority-queue scheduling (paper 3.4.3). The perceptual model only picks
// one of K queues; inside a queue pairs go round-robin; the highest non-empty
// queue is always served next. After each step a pair's estimate is refined,
// so it is re-measured and moves queue when its priority crossed a bin edge.
//
// Bins are log-scale, relative to the largest priority fmax at the start of
// the run (scale-free: camera distance, resolution and scene size do not
// matter): queue K-1 holds f >= fmax / r, queue K-2 holds f >= fmax / r^2, ...,
// queue 0 the rest, including f = 0 (behind the camera). A pair whose f rose
// above fmax stays in the top queue. A pass over a queue is finished before
// a higher queue that filled meanwhile is served (no preemption mid-pass).
// Without a fixation every pair sits in one queue: plain round-robin in list order.
#include "scheduler_detail.hpp"

#include <algorithm>
#include <cmath>

namespace stc::detail {

PriorityQueueScheduler::PriorityQueueScheduler(const SchedulerOptions& options)
    : queue_count_(options.queue_count),
      inv_log_ratio_(1.0 / std::log(options.queue_ratio)),
      queues_(static_cast<std::size_t>(options.queue_count)) {}

int PriorityQueueScheduler::queueOf(double priority, double reference) const {
  const int top = queue_count_ - 1;
  if (!(priority > 0.0) || !(reference > 0.0)) return 0;
  if (priority >= reference) return top;
  // Bin k = floor(log_r(fmax / f)) counted down from the top queue.
  const double k = std::floor(std::log(reference / priority) * inv_log_ratio_);
  return k >= top ? 0 : top - static_cast<int>(k);
}

ScheduleStats PriorityQueueScheduler::run(std::vector<PairTest>& tests, std::size_t count,
                                          const Perception* perception, BudgetTracker& budget) {
  RunTimer timer;
  ScheduleStats stats;
  for (auto& q : queues_) q.clear();
  stats.used_perception = perceptionActive(perception);

  double reference = 0.0;
  if (stats.used_perception) {
    // Measure every pair once; fmax is known only after all are measured.
    priorities_.clear();
    for (std::size_t i = 0; i < count; ++i) {
      const double f = tests[i].resolved() ? 0.0 : perception->measure(tests[i]).priority;
      priorities_.push_back(f);
      reference = std::max(reference, f);
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (tests[i].resolved()) continue;
      queues_[static_cast<std::size_t>(queueOf(priorities_[i], reference))].push_back(
          static_cast<std::uint32_t>(i));
    }
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      if (!tests[i].resolved()) queues_[0].push_back(static_cast<std::uint32_t>(i));
    }
  }

  for (;;) {
    int q = queue_count_ - 1;
    while (q >= 0 && queues_[static_cast<std::size_t>(q)].empty()) --q;
    if (q < 0) break;  // everything resolved
    auto& queue = queues_[static_cast<std::size_t>(q)];
    // One round-robin pass; pairs that stay are compacted in place, order kept;
    // pairs that move are appended to their new queue (never this one).
    const std::size_t pass = queue.size();
    std::size_t kept = 0;
    for (std::size_t r = 0; r < pass; ++r) {
      const std::uint32_t index = queue[r];
      PairTest& test = tests[index];
      if (!timer.step(test, budget, stats)) {
        stats.interrupted = true;
        stats.overhead_seconds = timer.overheadSeconds();
        return stats;
      }
      if (test.resolved()) continue;
      const int moved = stats.used_perception ? queueOf(perception->measure(test).priority, reference) : q;
      if (moved == q) {
        queue[kept++] = index;
      } else {
        queues_[static_cast<std::size_t>(moved)].push_back(index);
      }
    }
    queue.resize(kept);
  }
  stats.overhead_seconds = timer.overheadSeconds();
  return stats;
}

}  // namespace stc::detail
