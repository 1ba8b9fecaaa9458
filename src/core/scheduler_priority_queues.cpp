// Priority-queue scheduling (paper 3.4.3). The perceptual model only picks
// one of K queues; inside a queue pairs go round-robin; the highest non-empty
// queue is always served next. A pair stepped by a pass over a queue moves to
// the back of another queue when its priority crossed a bin edge; that queue
// is served once the pass is over.
//
// Priority: f(e, g) / c^a, c the sphere tests of the pair's next step (see
// SchedulerOptions::cost_exponent; a = 0 is the paper's f). Bins are
// log-scale, relative to the largest priority fmax at the start of the run
// (scale-free: camera distance, resolution and scene size do not matter):
// queue K-1 holds f >= fmax / r, queue K-2 holds f >= fmax / r^2, ..., queue 0
// the rest, including f = 0 (behind the camera). A pass over a queue is
// finished before a higher queue that filled meanwhile is served.
//
// f(e, g) is measured once per run, and the queue changes with the cost
// alone (issue 11, docs/error_vs_runtime.md):
// - g is the paper's estimate for the roots, the distance of the root
//   spheres' centres, in pixels. Re-measured after each step for the
//   frontier (as this did before), g cost a third of the bookkeeping and
//   left no less true P at equal sphere tests (measured: as much or less, on
//   both scenes); c is what changes a pair's worth per sphere test as it
//   descends (a level multiplies it by up to 8 per intersecting pair).
// - Each body is projected once per run, not each pair (a body is in five or
//   more pairs in a pile), in a loop of its own with no library call (exp by
//   a polynomial). A pair's weight exp(-e/100) takes e as the mean of its
//   bodies' eccentricities (the midpoint's is at most that), so it is the
//   product of two per-body factors exp(-e_body/200); its pixels per metre
//   the geometric mean of its bodies'.
// - A queued pair carries its f / fmax; after a step its bin is that over c,
//   the exact tests of the next step, which the PairTest keeps: a divide and
//   a table look-up by the exponent for the defaults (other options: K - 1
//   branch-free comparisons with the bin edges). No projection after the
//   start, nothing for the PairTest to keep, and a pass is compiled per bin
//   rule, so nothing is decided per step but the bin.
// - Queue 0 is the end of the line: its pairs (the rest, and weight 0 when a
//   body is behind the camera) go round-robin and are not re-binned (the
//   cost only grows).
// - Queues are flat storage reused across runs, their ends kept as pointers:
//   appending is one store and one add, a pass compacts the pairs that stay
//   in place, and nothing is sorted. A queue entry holds the PairTest's
//   address, and a pass prefetches the PairTests it will step (a queue is in
//   no memory order).
// Without a fixation, with one queue, or without the pairs' body indices,
// every pair sits in queue 0: plain round-robin in list order, and no
// projection work.
#include "scheduler_detail.hpp"

#include "grow_capacity.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

namespace stc::detail {
namespace {

// A queue holds pairs in no memory order, so the hardware does not see the
// next PairTest coming: ask for it a few steps ahead (a step reads most of it).
constexpr std::size_t kPrefetchAhead = 4;

// The biased IEEE exponent of x (0 for 0 and subnormals, 2047 for infinity
// and NaN); the sign is dropped, so it always indexes a 2048-entry table.
inline unsigned biasedExponent(double x) {
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  return static_cast<unsigned>(bits >> 52) & 0x7FFu;
}

// 2^x for x <= 0 (0 below -1022), within 3e-13 of it and monotone, with no
// library call (std::exp took 76 instructions a body, a sixth of the set-up,
// and a call in the projection loop would keep its values in memory).
// 2^x = 2^n 2^(-1/2) 2^t, n = x rounded toward 0, t = x - n + 1/2 in
// (-1/2, 1/2], 2^t by its Taylor series to degree 10, whose coefficients
// (ln 2)^k / k! are made by the compiler (a divide per term, left to run
// time, made this loop the set-up's slowest).
struct Exp2Series {
  double c[11];
  constexpr Exp2Series() : c() {
    c[0] = 1.0;
    for (int k = 1; k <= 10; ++k) c[k] = c[k - 1] * 0.69314718055994531 / k;
  }
};
constexpr Exp2Series kExp2Series;

inline double exp2NonPositive(double x) {
  if (!(x > -1022.0)) return 0.0;
  const int n = static_cast<int>(x);
  const double t = x - n + 0.5;
  double p = kExp2Series.c[10];
  for (int k = 9; k >= 0; --k) p = p * t + kExp2Series.c[k];  // unrolled by the compiler
  const std::uint64_t bits = static_cast<std::uint64_t>(n + 1023) << 52;
  double two_n;
  std::memcpy(&two_n, &bits, sizeof two_n);
  return two_n * 0.70710678118654752 * p;
}

}  // namespace

PriorityQueueScheduler::PriorityQueueScheduler(const SchedulerOptions& options)
    : queue_count_(options.queue_count),
      cost_exponent_(options.cost_exponent),
      binary_bins_(options.queue_ratio == 2.0),
      lower_share_(static_cast<std::size_t>(options.queue_count)) {
  // x in [2^-(K-q), 2^-(K-q-1)) is queue q; below 2^-(K-1) (and 0) queue 0;
  // 1 and above (a priority over the start's largest) the top queue.
  for (unsigned e = 0; e < bin_of_exponent_.size(); ++e) {
    bin_of_exponent_[e] = static_cast<std::uint8_t>(std::clamp(queue_count_ + static_cast<int>(e) - 1023, 0,
                                                               queue_count_ - 1));
  }
  // Queue q >= 1 holds x >= r^-(K - q).
  const double log_ratio = std::log(options.queue_ratio);
  for (int q = 1; q < queue_count_; ++q) {
    lower_share_[static_cast<std::size_t>(q)] = std::exp(-(queue_count_ - q) * log_ratio);
  }
}

inline double PriorityQueueScheduler::perCost(double x, int cost) const {
  if (cost_exponent_ == 0.0 || x == 0.0 || cost <= 1) return x;
  return cost_exponent_ == 1.0 ? x / cost : x / std::pow(static_cast<double>(cost), cost_exponent_);
}

// The bin of a priority as a share x of the run's largest: with a ratio of 2
// (the default) read off x's exponent, O(1), no branch per edge and no
// logarithm. Other ratios count the edges x reaches, branch-free (a step moves
// a priority by several bins, so walking the edges from the old bin would
// mispredict a branch at each).
inline int PriorityQueueScheduler::binOf(double share) const {
  if (binary_bins_) return bin_of_exponent_[biasedExponent(share)];
  if (!(share > 0.0)) return 0;
  int q = 0;
  for (int e = 1; e < queue_count_; ++e) q += share >= lower_share_[static_cast<std::size_t>(e)];
  return q;
}

// The bin of a stepped pair with bins a factor 2 apart and the priority per
// sphere test (the defaults): the exponent of share / c, looked up. The
// table's address is copied in, so it stays in a register across the steps
// (a step could write to the scheduler, for all the compiler knows).
struct PriorityQueueScheduler::ExponentBin {
  const std::uint8_t* bin_of_exponent;
  int operator()(const PairTest& test, double share) const {
    // share >= 0: 0 has exponent 0 and lands in queue 0.
    return bin_of_exponent[biasedExponent(share / test.nextStepTests())];
  }
};

// Any other ratio or cost exponent: the priority, then its bin.
struct PriorityQueueScheduler::EdgeBin {
  const PriorityQueueScheduler* scheduler;
  int operator()(const PairTest& test, double share) const {
    return scheduler->binOf(scheduler->perCost(share, test.nextStepTests()));
  }
};

// Queue 0 is not re-binned.
struct PriorityQueueScheduler::StayBin {
  int operator()(const PairTest& /*test*/, double /*share*/) const { return 0; }
};

void PriorityQueueScheduler::binAll(PairTest* tests, std::size_t count,
                                    const PairBodies& bodies, const Perception& perception) {
  if (gaze_.size() < bodies.body_count) gaze_.resize(bodies.body_count);
  if (++run_ == 0) {  // the stamp wrapped: forget every body's projection
    for (BodyGaze& g : gaze_) g.run = 0;
    run_ = 1;
  }
  if (measured_.size() < count) measured_.resize(count);
  if (unseen_.size() < 2 * count) unseen_.resize(2 * count);
  // Storage in locals: the loops below keep them in registers.
  const std::uint32_t run = run_;
  BodyGaze* const gaze = gaze_.data();
  Measured* const measured = measured_.data();
  Unseen* const unseen = unseen_.data();
  const std::array<std::uint32_t, 2>* const of_pair = bodies.of_pair;

  // The unresolved pairs, and the bodies of theirs not yet projected.
  std::size_t n = 0, fresh = 0;
  for (std::size_t i = 0; i < count; ++i) {
    PairTest& test = tests[i];
    if (test.resolved()) continue;
    const std::uint32_t a = of_pair[i][0], b = of_pair[i][1];
    if (gaze[a].run != run) {
      gaze[a].run = run;
      unseen[fresh++] = Unseen{a, &test.bodyA()};
    }
    if (gaze[b].run != run) {
      gaze[b].run = run;
      unseen[fresh++] = Unseen{b, &test.bodyB()};
    }
    measured[n++].pair = static_cast<std::uint32_t>(i);
  }
  // Each body projected once, in a loop of its own (the projections'
  // latencies overlap, and no pair waits on one).
  // Root weight exp(-e / 200) = 2^(-e / (200 ln 2)); 0 behind the camera.
  const Vec2 fixation = *perception.fixation();
  constexpr double kPerPixel = -1.0 / (200.0 * 0.69314718055994531);
  for (std::size_t k = 0; k < fresh; ++k) {
    const PairBody& body = *unseen[k].of;
    const Perception::GazeWeight gw = perception.pixelAndScale(body.pose->position);
    BodyGaze& g = gaze[unseen[k].body];
    g.root_centre = body.pose->apply(body.tree->root().centre);
    const double root_weight =
        gw.px_per_metre > 0.0 ? exp2NonPositive(kPerPixel * (gw.pixel - fixation).norm()) : 0.0;
    g.root_scale = root_weight * std::sqrt(gw.px_per_metre);
  }
  // Each pair's priority at a cost of one sphere test, for the whole run:
  // g = the distance of the root spheres' centres (the paper's estimate for
  // the roots) in pixels.
  double reference = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t i = measured[k].pair;
    const BodyGaze& a = gaze[of_pair[i][0]];
    const BodyGaze& b = gaze[of_pair[i][1]];
    const double f = a.root_scale * b.root_scale * (a.root_centre - b.root_centre).norm();
    // Finite (and so is every share): a pose far enough out to overflow the
    // gap is worth nothing to the eye.
    measured[k].priority = f <= std::numeric_limits<double>::max() ? f : 0.0;
    reference = std::max(reference, measured[k].priority);
  }
  // Priorities from here on are shares of the largest, in [0, 1]. A divide,
  // not a multiply by 1 / reference: a subnormal largest (a far, small scene
  // under a wide camera) has an infinite inverse, and 0 times that is a NaN
  // with no bin (found by fuzz_gaze).
  Queued** const ends = ends_.data();
  for (std::size_t k = 0; k < n; ++k) {
    const double share = reference > 0.0 ? measured[k].priority / reference : 0.0;
    assert(share >= 0.0 && share <= 1.0);
    Queued*& end = ends[binOf(share)];
    end->test = tests + measured[k].pair;
    end->share = share;
    ++end;
  }
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
  const auto queues = static_cast<std::size_t>(queue_count_);
  stride_ = count + 1;
  if (slots_.size() < stride_ * queues) resizeRewritten(slots_, stride_ * queues);
  for (int q = 0; q < queue_count_; ++q) ends_[static_cast<std::size_t>(q)] = queueBegin(q);
  stats.used_perception = perceptionActive(perception) && queue_count_ > 1 && bodies.of_pair != nullptr;
  if (stats.used_perception) {
    binAll(tests, count, bodies, *perception);
  } else {
    Queued* end = ends_[0];
    for (std::size_t i = 0; i < count; ++i) {
      if (tests[i].resolved()) continue;
      end->test = &tests[i];
      end->share = 0.0;
      ++end;
    }
    ends_[0] = end;
  }
  overhead.stop();

  // The budget counts the sphere tests; the loop does not.
  const std::int64_t spent_before = budget.spentTests();
  if (!stats.used_perception) {  // every pair in queue 0
    stats.interrupted = !serveQueues(budget, requeue, StayBin{});
  } else if (binary_bins_ && cost_exponent_ == 1.0) {
    stats.interrupted = !serveQueues(budget, requeue, ExponentBin{bin_of_exponent_.data()});
  } else {
    stats.interrupted = !serveQueues(budget, requeue, EdgeBin{this});
  }
  stats.sphere_tests = budget.spentTests() - spent_before;
  stats.overhead_seconds = overhead.seconds() + requeue.seconds();
  return stats;
}

// The highest non-empty queue, one pass over it, until all are empty (true)
// or the budget ends (false).
template <typename BinAfterStep>
bool PriorityQueueScheduler::serveQueues(BudgetTracker& budget, SampledClock& requeue,
                                         BinAfterStep binAfterStep) {
  requeue.start();  // choosing the next queue is decision work too
  for (;;) {
    int q = queue_count_ - 1;
    while (q >= 0 && ends_[static_cast<std::size_t>(q)] == queueBegin(q)) --q;
    requeue.stop();
    if (q < 0) return true;  // everything resolved
    const bool finished = q > 0 ? servePass(q, budget, binAfterStep) : servePass(q, budget, StayBin{});
    if (!finished) return false;
    requeue.start();
  }
}

// One round-robin pass over queue q; false when the budget ended it. A pair
// still unresolved is re-binned as soon as it is stepped (its next cost is
// in cache then): it stays, in order, compacted in place,
// or goes to the back of its new queue, which is not served before this pass
// ends. No branch on the outcome (it is a coin toss to predict): the entry is
// written both at the compaction point and at the end of its new queue, and
// only one of the two moves on. Writing past this queue's end is what the
// spare slot is for, and the compaction point is never ahead of the pass.
template <typename BinAfterStep>
bool PriorityQueueScheduler::servePass(int q, BudgetTracker& budget, BinAfterStep binAfterStep) {
  Queued** const ends = ends_.data();  // a step could write to the scheduler: no member is cached
  const auto qi = static_cast<std::size_t>(q);
  Queued* kept = queueBegin(q);
  Queued* const end = ends[qi];
  bool finished = true;
  for (Queued* read = kept; read != end; ++read) {
    if (read + kPrefetchAhead < end) read[kPrefetchAhead].test->prefetchForStep();
    PairTest& test = *read->test;
    if (budget.exhausted()) {
      finished = false;
      break;
    }
    budget.charge(test.step());
    if (test.resolved()) continue;
    const Queued entry = *read;
    const auto moved = static_cast<std::size_t>(binAfterStep(test, entry.share));
    const bool stays = moved == qi;
    *kept = entry;
    kept += stays;
    *ends[moved] = entry;
    ends[moved] += !stays;
  }
  ends[qi] = kept;
  return finished;
}

}  // namespace stc::detail
