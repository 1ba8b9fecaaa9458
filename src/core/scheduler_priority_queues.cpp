// Priority-queue scheduling (paper 3.4.3). The perceptual model only picks
// one of K queues; inside a queue pairs go round-robin; the highest non-empty
// queue is always served next. A pair stepped by a pass over a queue is
// re-measured and moves to the back of another queue when its priority
// crossed a bin edge; that queue is served once the pass is over.
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
// - After a step, g is the paper's estimate: the distance of the centres of
//   an intersecting sphere pair (the frontier's first), times the pair's
//   pixels per metre (queued beside its index), and c the exact tests of the
//   next step: both kept by the PairTest as it steps. The re-measure
//   is done right after the step, while the PairTest is in cache: two
//   multiplies and the bin, which for the defaults is read off the exponents
//   of g x scale / fmax and of c, with no divide (O(1); other options: the
//   priority, then K - 1 branch-free comparisons with the bin edges). No
//   projection after the start. A pass is compiled per bin rule, so nothing
//   is decided per step but the bin.
//   (Measured against the reach r_a + r_b of that pair, which this used
//   before: the centre distance also tells a deep overlap, likely a real
//   contact whose gap is 0, from a shallow one, and left 5-15 % less true P
//   at equal sphere tests; docs/error_vs_runtime.md.)
// - Queue 0 is the end of the line: its pairs (the rest, and weight 0 when a
//   body is behind the camera) go round-robin and are not re-measured (a
//   step rarely raises a priority: the spheres shrink and the cost grows).
// - Queues are vectors reused across runs: appending is O(1), a pass
//   compacts the pairs that stay in place, and nothing is sorted. A pass prefetches the
//   PairTests it will step (a queue is in no memory order).
// Without a fixation, with one queue, or without the pairs' body indices,
// every pair sits in queue 0: plain round-robin in list order, and no
// projection work.
#include "scheduler_detail.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

namespace stc::detail {
namespace {

// A queue holds pairs in no memory order, so the hardware does not see the
// next PairTest coming: ask for it a few steps ahead (a step reads most of it).
constexpr std::size_t kPrefetchAhead = 4;

}  // namespace

PriorityQueueScheduler::PriorityQueueScheduler(const SchedulerOptions& options)
    : queue_count_(options.queue_count),
      log_ratio_(std::log(options.queue_ratio)),
      cost_exponent_(options.cost_exponent),
      sizes_(static_cast<std::size_t>(options.queue_count)),
      lower_edge_(static_cast<std::size_t>(options.queue_count)),
      binary_bins_(options.queue_ratio == 2.0) {}

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

// The bin of a priority: how many bin edges it reaches. With a ratio of 2
// (the default) that is read off the exponent of f / fmax: O(1), no branch
// per edge and no logarithm. Other ratios count the edges it reaches,
// branch-free (a step moves a priority by several bins, so walking the edges
// from the old bin would mispredict a branch at each).
inline int PriorityQueueScheduler::binOf(double priority) const {
  if (!(priority > 0.0)) return 0;
  if (binary_bins_) {
    // floor(log2(f / fmax)) from the IEEE exponent; subnormal ratios land in
    // queue 0, ratios >= 1 (a priority above the start's largest) at the top.
    const double x = priority * inverse_reference_;
    std::uint64_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    const int exponent = static_cast<int>((bits >> 52) & 0x7ff) - 1023;
    return std::clamp(queue_count_ + exponent, 0, queue_count_ - 1);
  }
  int q = 0;
  for (int e = 1; e < queue_count_; ++e) q += priority >= lower_edge_[static_cast<std::size_t>(e)];
  return q;
}

// The bin of a stepped pair with bins a factor 2 apart and the priority per
// sphere test (the defaults): floor(log2(y / c)) of y = g x scale / fmax,
// found without dividing: the exponents' difference, less one when y's
// mantissa is below c's. Its constants are copied in, so they stay in
// registers across the steps (a step could write to the scheduler, for all
// the compiler knows).
struct PriorityQueueScheduler::ExponentBin {
  double inverse_reference;
  int queue_count;
  int operator()(const PairTest& test, float scale) const {
    // g >= 0: x = 0 has exponent bits 0 and lands in queue 0 by the clamp.
    const double x = test.frontierGap() * scale * inverse_reference;
    const double c = static_cast<double>(test.nextStepTests());
    std::uint64_t xb, cb;
    std::memcpy(&xb, &x, sizeof xb);
    std::memcpy(&cb, &c, sizeof cb);
    constexpr std::uint64_t kMantissa = (std::uint64_t{1} << 52) - 1;
    const int exponent = static_cast<int>(xb >> 52) - static_cast<int>(cb >> 52) - ((xb & kMantissa) < (cb & kMantissa));
    return std::clamp(queue_count + exponent, 0, queue_count - 1);
  }
};

// Any other ratio or cost exponent: the priority, then its bin.
struct PriorityQueueScheduler::EdgeBin {
  const PriorityQueueScheduler* scheduler;
  int operator()(const PairTest& test, float scale) const {
    return scheduler->binOf(scheduler->perCost(test.frontierGap() * scale, test.nextStepTests()));
  }
};

// Queue 0 is not re-measured.
struct PriorityQueueScheduler::StayBin {
  int operator()(const PairTest& /*test*/, float /*scale*/) const { return 0; }
};

PriorityQueueScheduler::QueueEnds PriorityQueueScheduler::queueEnds() {
  QueueEnds ends{};
  for (std::size_t k = 0; k < sizes_.size(); ++k) ends[k] = slots_.data() + k * stride_ + sizes_[k];
  return ends;
}

void PriorityQueueScheduler::setEnds(const QueueEnds& ends) {
  for (std::size_t k = 0; k < sizes_.size(); ++k) {
    sizes_[k] = static_cast<std::size_t>(ends[k] - (slots_.data() + k * stride_));
  }
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
  // Storage in locals: the projection of a body is an opaque call, after
  // which members would be read again.
  double* const priority = priorities_.data();
  float* const scale = scale_.data();
  double reference = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    priority[i] = -1.0;  // resolved: not queued
    if (tests[i].resolved()) continue;
    tests[i].trackFrontierGap();  // its steps keep g for the re-measure
    const BodyGaze& a = gazeOf(bodies.of_pair[i][0], tests[i].bodyA(), perception);
    const BodyGaze& b = gazeOf(bodies.of_pair[i][1], tests[i].bodyB(), perception);
    const double weight = a.root_weight * b.root_weight;
    scale[i] = static_cast<float>(a.root_scale * b.root_scale);
    // Before any step: g = the projected distance of the entity origins, c = 1.
    const double f = weight == 0.0 ? 0.0 : weight * (a.pixel - b.pixel).norm();
    priority[i] = f;
    reference = std::max(reference, f);
  }
  // Queue q >= 1 holds f >= fmax / r^(K - q).
  inverse_reference_ = reference > 0.0 ? 1.0 / reference : 0.0;
  lower_edge_[0] = 0.0;
  for (int q = 1; q < queue_count_; ++q) {
    lower_edge_[static_cast<std::size_t>(q)] = reference * std::exp(-(queue_count_ - q) * log_ratio_);
  }
  QueueEnds ends = queueEnds();
  for (std::size_t i = 0; i < count; ++i) {
    if (priority[i] < 0.0) continue;
    // Field by field: a Queued built on the stack and copied whole stalls on
    // store forwarding (two 4-byte writes read back as one 8-byte load).
    Queued*& end = ends[static_cast<std::size_t>(binOf(priority[i]))];
    end->pair = static_cast<std::uint32_t>(i);
    end->scale = scale[i];
    ++end;
  }
  setEnds(ends);
}

ScheduleStats PriorityQueueScheduler::run(PairTest* tests, std::size_t count,
                                          const PairBodies& bodies, const Perception* perception,
                                          BudgetTracker& budget) {
  ScheduleStats stats;
  OverheadClock overhead;  // the set-up: measuring and binning every pair
  SampledClock requeue(run_);  // choosing the queue to serve after each pass
  overhead.start();
  // Each queue has room for every pair and one more (see the pass below);
  // the storage only grows, with the pair count.
  stride_ = count + 1;
  if (slots_.size() < stride_ * sizes_.size()) slots_.resize(stride_ * sizes_.size());
  std::fill(sizes_.begin(), sizes_.end(), 0);
  stats.used_perception = perceptionActive(perception) && queue_count_ > 1 && bodies.of_pair != nullptr;
  if (stats.used_perception) {
    binAll(tests, count, bodies, *perception);
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      if (tests[i].resolved()) continue;
      Queued& entry = slotEnd(0);
      entry.pair = static_cast<std::uint32_t>(i);
      entry.scale = 0.0f;
      ++sizes_[0];
    }
  }
  overhead.stop();

  if (!stats.used_perception) {  // every pair in queue 0
    serveQueues(tests, budget, stats, requeue, StayBin{});
  } else if (binary_bins_ && cost_exponent_ == 1.0) {
    serveQueues(tests, budget, stats, requeue, ExponentBin{inverse_reference_, queue_count_});
  } else {
    serveQueues(tests, budget, stats, requeue, EdgeBin{this});
  }
  stats.overhead_seconds = overhead.seconds() + requeue.seconds();
  return stats;
}

// The highest non-empty queue, one pass over it, until all are empty or the
// budget ends.
template <typename BinAfterStep>
void PriorityQueueScheduler::serveQueues(PairTest* tests, BudgetTracker& budget, ScheduleStats& stats,
                                         SampledClock& requeue, BinAfterStep binAfterStep) {
  requeue.start();  // choosing the next queue is decision work too
  for (;;) {
    int q = queue_count_ - 1;
    while (q >= 0 && sizes_[static_cast<std::size_t>(q)] == 0) --q;
    requeue.stop();
    if (q < 0) return;  // everything resolved
    const bool finished = q > 0 ? servePass(q, tests, budget, stats, binAfterStep)
                                : servePass(q, tests, budget, stats, StayBin{});
    if (!finished) {
      stats.interrupted = true;
      return;
    }
    requeue.start();
  }
}

// One round-robin pass over queue q; false when the budget ended it. A pair
// still unresolved is re-measured as soon as it is stepped (its gap estimate
// and next cost are in cache then): it stays, in order, compacted in place,
// or goes to the back of its new queue, which is not served before this pass
// ends. No branch on the outcome (it is a coin toss to predict): the entry is
// written both at the compaction point and at the end of its new queue, and
// only one of the two counts. Writing past this queue's end is what the spare
// slot is for, and the compaction point is never ahead of the pass. The
// queues' ends are held in locals: a step could write to the scheduler, for
// all the compiler knows, so members would be read again after each.
template <typename BinAfterStep>
bool PriorityQueueScheduler::servePass(int q, PairTest* tests, BudgetTracker& budget, ScheduleStats& stats,
                                       BinAfterStep binAfterStep) {
  QueueEnds ends = queueEnds();  // a mover is one store and one add
  const auto qi = static_cast<std::size_t>(q);
  Queued* const queue = slots_.data() + qi * stride_;
  const std::size_t size = sizes_[qi];
  std::size_t kept = 0;
  bool finished = true;
  for (std::size_t r = 0; r < size; ++r) {
    if (r + kPrefetchAhead < size) tests[queue[r + kPrefetchAhead].pair].prefetchForStep();
    const Queued entry = queue[r];
    PairTest& test = tests[entry.pair];
    if (!budgetedStep(test, budget, stats)) {
      finished = false;
      break;
    }
    if (test.resolved()) continue;
    const auto moved = static_cast<std::size_t>(binAfterStep(test, entry.scale));
    const bool stays = moved == qi;
    queue[kept] = entry;
    kept += stays;
    *ends[moved] = entry;
    ends[moved] += !stays;
  }
  setEnds(ends);
  sizes_[qi] = kept;
  return finished;
}

}  // namespace stc::detail
