// Priority-queue scheduling (paper 3.4.3). The perceptual model only picks
// one of K queues; inside a queue pairs go round-robin; the highest non-empty
// queue is always served next. After each pass over a queue, the pairs it
// stepped are re-measured (their estimates refined) and move queue when their
// priority crossed a bin edge.
//
// Priority: f(e, g) / c^a, c the sphere tests of the pair's next step (see
// SchedulerOptions::cost_exponent; a = 0 is the paper's f). Bins are
// log-scale, relative to the largest priority fmax at the start of the run
// (scale-free: camera distance, resolution and scene size do not matter):
// queue K-1 holds f >= fmax / r, queue K-2 holds f >= fmax / r^2, ..., queue 0
// the rest, including f = 0 (behind the camera). A pass over a queue is
// finished before a higher queue that filled meanwhile is served.
//
// Measuring a pair: f = g exp(-e/100) with the eccentricity weight exp(-e/100)
// and the pixels per metre of its centre of collision at the start of the run
// (the centre moves by less than the pair's size on screen while it refines;
// a bin spans a factor r). g before any step is the paper's estimate, the
// projected distance of the entity origins. After a step it is the reach
// r_a + r_b of an intersecting frontier pair, in pixels: an upper bound of the
// paper's g (the distance of two intersecting centres is at most their reach)
// that costs two loads instead of two rotations and two projections per step,
// and schedules as well or better (docs/error_vs_runtime.md).
// Without a fixation every pair sits in one queue: plain round-robin in list order.
#include "scheduler_detail.hpp"

#include <algorithm>
#include <cmath>

namespace stc::detail {

PriorityQueueScheduler::PriorityQueueScheduler(const SchedulerOptions& options)
    : queue_count_(options.queue_count),
      log_ratio_(std::log(options.queue_ratio)),
      cost_exponent_(options.cost_exponent),
      queues_(static_cast<std::size_t>(options.queue_count)),
      lower_edge_(static_cast<std::size_t>(options.queue_count)) {}

// What a re-measure needs from a pair, in constant time from its frontier
// (the intersecting sphere pairs of its last step), represented by its first
// pair (the frontier is one tree level, so its pairs are alike):
// - cost: the sphere tests of the next step: 1 before any step (root against
//   root); then frontier size x the children of the node the first pair will
//   be tested against (a leaf's partner's under the unequal-height rule, else
//   the mean of the two);
// - reach: r_a + r_b of that pair (0 before any step).
PriorityQueueScheduler::Refined PriorityQueueScheduler::refine(const PairTest& test) {
  Refined out;
  const SpherePairSpan frontier = test.lastPairs();
  if (test.stepsDone() == 0 || frontier.empty()) return out;
  const SphereNode& na = test.bodyA().tree->node(frontier[0].a);
  const SphereNode& nb = test.bodyB().tree->node(frontier[0].b);
  out.reach = na.radius + nb.radius;
  const double children = na.child_count == 0   ? nb.child_count
                          : nb.child_count == 0 ? na.child_count
                                                : 0.5 * (na.child_count + nb.child_count);
  out.cost = std::max(1.0, children * static_cast<double>(frontier.size()));
  return out;
}

double PriorityQueueScheduler::perCost(double f, double cost) const {
  if (cost_exponent_ == 0.0 || f == 0.0) return f;
  return cost_exponent_ == 1.0 ? f / cost : f / std::pow(cost, cost_exponent_);
}

// Priority of a pair now: g (see the top of the file) times its eccentricity weight, per cost.
double PriorityQueueScheduler::remeasure(const PairTest& test, const Perception& perception,
                                         double weight, double px_per_metre) const {
  if (weight == 0.0) return 0.0;
  const Refined r = refine(test);
  double g = r.reach * px_per_metre;
  if (r.reach == 0.0) {  // before any step: the projected distance of the entity origins
    const Vec3& a = test.bodyA().pose->position;
    const Vec3& b = test.bodyB().pose->position;
    const auto pa = perception.project(a);
    const auto pb = perception.project(b);
    g = (pa && pb) ? (*pa - *pb).norm() : (a - b).norm() * px_per_metre;
  }
  return perCost(g * weight, r.cost);
}

// Initial binning: k = floor(log_r(fmax / f)) counted down from the top queue.
int PriorityQueueScheduler::binOf(double priority, double reference) const {
  const int top = queue_count_ - 1;
  if (!(priority > 0.0) || !(reference > 0.0)) return 0;
  if (priority >= reference) return top;
  const double k = std::floor(std::log(reference / priority) / log_ratio_);
  return k >= top ? 0 : top - static_cast<int>(k);
}

// Re-binning from the current queue: estimates move by a bin or two per step,
// so walking the edges beats a logarithm.
int PriorityQueueScheduler::rebin(double priority, int from) const {
  int q = from;
  while (q + 1 < queue_count_ && priority >= lower_edge_[static_cast<std::size_t>(q + 1)]) ++q;
  while (q > 0 && priority < lower_edge_[static_cast<std::size_t>(q)]) --q;
  return q;
}

ScheduleStats PriorityQueueScheduler::run(std::vector<PairTest>& tests, std::size_t count,
                                          const Perception* perception, BudgetTracker& budget) {
  ScheduleStats stats;
  OverheadClock overhead;  // the set-up: measuring and binning every pair
  SampledClock requeue;    // the re-measuring after each pass
  overhead.start();
  for (auto& q : queues_) q.clear();
  stats.used_perception = perceptionActive(perception);

  if (stats.used_perception) {
    // Measure every pair once; fmax is known only after all are measured.
    weight_.resize(count);
    scale_.resize(count);
    priorities_.resize(count);
    double reference = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
      if (tests[i].resolved()) {
        priorities_[i] = 0.0;
        continue;
      }
      const Perception::GazeWeight gw = perception->gazeWeight(tests[i].centreOfCollision());
      weight_[i] = gw.weight;
      scale_[i] = gw.px_per_metre;
      priorities_[i] = remeasure(tests[i], *perception, gw.weight, gw.px_per_metre);
      reference = std::max(reference, priorities_[i]);
    }
    // Queue q >= 1 holds f >= fmax / r^(K - q).
    lower_edge_[0] = 0.0;
    for (int q = 1; q < queue_count_; ++q) {
      lower_edge_[static_cast<std::size_t>(q)] = reference * std::exp(-(queue_count_ - q) * log_ratio_);
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (tests[i].resolved()) continue;
      queues_[static_cast<std::size_t>(binOf(priorities_[i], reference))].push_back(
          static_cast<std::uint32_t>(i));
    }
  } else {
    for (std::size_t i = 0; i < count; ++i) {
      if (!tests[i].resolved()) queues_[0].push_back(static_cast<std::uint32_t>(i));
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
      PairTest& test = tests[queue[r]];
      if (!budgetedStep(test, budget, stats)) {
        out_of_budget = true;
        break;
      }
      if (!test.resolved()) queue[kept++] = queue[r];
    }
    if (out_of_budget) {
      stats.interrupted = true;
      break;
    }
    queue.resize(kept);
    requeue.start();
    if (!stats.used_perception) continue;
    // Re-measure what the pass refined; movers go to the back of their new queue.
    kept = 0;
    for (std::size_t r = 0; r < queue.size(); ++r) {
      const std::uint32_t index = queue[r];
      const double f = remeasure(tests[index], *perception, weight_[index], scale_[index]);
      const int moved = rebin(f, q);
      if (moved == q) {
        queue[kept++] = index;
      } else {
        queues_[static_cast<std::size_t>(moved)].push_back(index);
      }
    }
    queue.resize(kept);
  }
  stats.overhead_seconds = overhead.seconds() + requeue.seconds();
  return stats;
}

}  // namespace stc::detail
