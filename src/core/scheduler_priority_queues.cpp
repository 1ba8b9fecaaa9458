// Priority-queue scheduling (paper 3.4.3). The perceptual model only picks
// one of K queues; inside a queue pairs go round-robin; the highest non-empty
// queue is always served next. After each pass over a queue, the pairs it
// stepped are re-measured and move queue when their priority crossed a bin edge.
//
// Priority: f(e, g) / c^a, c the sphere tests of the pair's next step (see
// SchedulerOptions::cost_exponent; a = 0 is the paper's f). Bins are
// log-scale, relative to the largest priority fmax at the start of the run
// (scale-free: camera distance, resolution and scene size do not matter):
// queue K-1 holds f >= fmax / r, queue K-2 holds f >= fmax / r^2, ..., queue 0
// the rest, including f = 0 (behind the camera). A pass over a queue is
// finished before a higher queue that filled meanwhile is served.
//
// The bookkeeping is kept to a few operations per step (issue 11,
// docs/error_vs_runtime.md):
// - Each body is projected once per run, not each pair (a body is in five or
//   more pairs in a pile). A pair's weight exp(-e/100) takes e as the mean of
//   its bodies' eccentricities (the midpoint's is at most that), so it is the
//   product of two per-body factors exp(-e_body/200); its pixels per metre
//   the geometric mean of its bodies'. g before any step is the paper's
//   estimate, the projected distance of the entity origins.
// - After a step, g is the reach r_a + r_b of a frontier sphere pair times the
//   pair's pixels per metre, and c the exact tests of the next step: both kept
//   by the PairTest as it steps and copied beside the queued index. A
//   re-measure is a multiply, a divide and K - 1 branch-free comparisons with
//   the bin edges; no projection after the start.
//   (The reach is an upper bound of the paper's g: the distance of two
//   intersecting centres is at most their reach.)
// - Queue 0 is the end of the line: its pairs (the rest, and weight 0 when a
//   body is behind the camera) go round-robin and are not re-measured (a
//   step rarely raises a priority: the reach shrinks and the cost grows).
// - Queues are vectors reused across runs: appending is O(1), a pass
//   compacts in place, and nothing is sorted. A pass prefetches the
//   PairTests it will step (a queue is in no memory order).
// Without a fixation, with one queue, or without the pairs' body indices,
// every pair sits in queue 0: plain round-robin in list order, and no
// projection work.
#include "scheduler_detail.hpp"

#include <algorithm>
#include <cmath>

namespace stc::detail {
namespace {

// A queue holds pairs in no memory order, so the hardware does not see the
// next PairTest coming: ask for it a few steps ahead (a step reads most of it).
constexpr std::size_t kPrefetchAhead = 4;
inline void prefetch(const PairTest& test) {
  const char* p = reinterpret_cast<const char*>(&test);
  for (std::size_t offset = 0; offset < sizeof(PairTest); offset += 64) __builtin_prefetch(p + offset);
}

}  // namespace

PriorityQueueScheduler::PriorityQueueScheduler(const SchedulerOptions& options)
    : queue_count_(options.queue_count),
      log_ratio_(std::log(options.queue_ratio)),
      cost_exponent_(options.cost_exponent),
      queues_(static_cast<std::size_t>(options.queue_count)),
      lower_edge_(static_cast<std::size_t>(options.queue_count)) {}

inline const PriorityQueueScheduler::BodyGaze& PriorityQueueScheduler::gazeOf(
    std::uint32_t body, const PairBody& pair_body, const Perception& perception) {
  BodyGaze& gaze = gaze_[body];
  if (gaze.run == run_) return gaze;
  const Perception::GazeWeight gw = perception.gazeWeight(pair_body.pose->position);
  gaze.pixel = gw.pixel;
  gaze.root_weight = std::sqrt(gw.weight);
  gaze.root_scale = gaze.root_weight * std::sqrt(gw.px_per_metre);
  gaze.run = run_;
  return gaze;
}

inline double PriorityQueueScheduler::perCost(double f, int cost) const {
  if (cost_exponent_ == 0.0 || f == 0.0 || cost <= 1) return f;
  return cost_exponent_ == 1.0 ? f / cost : f / std::pow(static_cast<double>(cost), cost_exponent_);
}

// The bin of a priority: how many bin edges it reaches. No logarithm and no
// branch per edge: a step moves a priority by several bins, so walking the
// edges from the old bin mispredicts a branch at each.
inline int PriorityQueueScheduler::binOf(double priority) const {
  if (!(priority > 0.0)) return 0;
  int q = 0;
  for (int e = 1; e < queue_count_; ++e) q += priority >= lower_edge_[static_cast<std::size_t>(e)];
  return q;
}

void PriorityQueueScheduler::binAll(PairTest* tests, std::size_t count,
                                    const PairBodies& bodies, const Perception& perception) {
  if (gaze_.size() < bodies.body_count) gaze_.resize(bodies.body_count);
  if (++run_ == 0) {  // the stamp wrapped: forget every body's projection
    for (BodyGaze& g : gaze_) g.run = 0;
    run_ = 1;
  }
  priorities_.resize(count);
  scale_.resize(count);
  double reference = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    priorities_[i] = 0.0;
    scale_[i] = 0.0;
    if (tests[i].resolved()) continue;
    const BodyGaze& a = gazeOf(bodies.of_pair[i][0], tests[i].bodyA(), perception);
    const BodyGaze& b = gazeOf(bodies.of_pair[i][1], tests[i].bodyB(), perception);
    const double weight = a.root_weight * b.root_weight;
    scale_[i] = static_cast<float>(a.root_scale * b.root_scale);
    // Before any step: g = the projected distance of the entity origins, c = 1.
    priorities_[i] = weight == 0.0 ? 0.0 : weight * (a.pixel - b.pixel).norm();
    reference = std::max(reference, priorities_[i]);
  }
  // Queue q >= 1 holds f >= fmax / r^(K - q).
  lower_edge_[0] = 0.0;
  for (int q = 1; q < queue_count_; ++q) {
    lower_edge_[static_cast<std::size_t>(q)] = reference * std::exp(-(queue_count_ - q) * log_ratio_);
  }
  for (std::size_t i = 0; i < count; ++i) {
    if (tests[i].resolved()) continue;
    queues_[static_cast<std::size_t>(binOf(priorities_[i]))].push_back(
        Queued{static_cast<std::uint32_t>(i), scale_[i], 0.0f, 1});
  }
}

ScheduleStats PriorityQueueScheduler::run(PairTest* tests, std::size_t count,
                                          const PairBodies& bodies, const Perception* perception,
                                          BudgetTracker& budget) {
  ScheduleStats stats;
  OverheadClock overhead;  // the set-up: measuring and binning every pair
  SampledClock requeue(run_);  // the re-measuring after each pass
  overhead.start();
  for (auto& q : queues_) q.clear();
  stats.used_perception = perceptionActive(perception) && queue_count_ > 1 && bodies.of_pair != nullptr;
  if (stats.used_perception) {
    binAll(tests, count, bodies, *perception);
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      if (!tests[i].resolved()) queues_[0].push_back(Queued{static_cast<std::uint32_t>(i), 0.0f, 0.0f, 1});
    }
  }
  overhead.stop();

  requeue.start();  // choosing the next queue is decision work too
  for (;;) {
    int q = queue_count_ - 1;
    while (q >= 0 && queues_[static_cast<std::size_t>(q)].empty()) --q;
    requeue.stop();
    if (q < 0) break;  // everything resolved
    auto& queue = queues_[static_cast<std::size_t>(q)];
    // One round-robin pass; pairs still unresolved are compacted in place, order kept.
    std::size_t kept = 0;
    bool out_of_budget = false;
    for (std::size_t r = 0; r < queue.size(); ++r) {
      if (r + kPrefetchAhead < queue.size()) prefetch(tests[queue[r + kPrefetchAhead].pair]);
      PairTest& test = tests[queue[r].pair];
      if (!budgetedStep(test, budget, stats)) {
        out_of_budget = true;
        break;
      }
      if (test.resolved()) continue;
      Queued& entry = queue[kept++];
      entry = queue[r];
      entry.reach = static_cast<float>(test.frontierReach());
      entry.cost = test.nextStepTests();
    }
    if (out_of_budget) {
      stats.interrupted = true;
      break;
    }
    queue.resize(kept);
    requeue.start();
    if (!stats.used_perception || q == 0) continue;
    // Re-measure what the pass refined; movers go to the back of their new queue.
    kept = 0;
    for (std::size_t r = 0; r < queue.size(); ++r) {
      const Queued entry = queue[r];
      const int moved = binOf(perCost(static_cast<double>(entry.reach) * entry.scale, entry.cost));
      if (moved == q) {
        queue[kept++] = entry;
      } else {
        queues_[static_cast<std::size_t>(moved)].push_back(entry);
      }
    }
    queue.resize(kept);
  }
  stats.overhead_seconds = overhead.seconds() + requeue.seconds();
  return stats;
}

}  // namespace stc::detail
