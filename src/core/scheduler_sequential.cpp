// Sequential and perceptually sorted sequential scheduling (paper 3.4.3):
// each pair is resolved fully before the next one starts. The perceptual
// variant first sorts the pairs by f(e, g) of their current estimate.
#include "scheduler_detail.hpp"

#include <algorithm>

namespace stc::detail {

ScheduleStats SequentialScheduler::run(PairTest* tests, std::size_t count,
                                       const PairBodies& /*bodies*/, const Perception* perception,
                                       BudgetTracker& budget) {
  ScheduleStats stats;
  OverheadClock overhead;
  overhead.start();
  order_.clear();
  stats.used_perception = sort_by_priority_ && perceptionActive(perception);
  if (stats.used_perception) {
    for (std::size_t i = 0; i < count; ++i) {
      // f(e, g) = g exp(-e/100), without the rest of measure() (bound, visibility).
      const Perception::GazeWeight gw = perception->gazeWeight(tests[i].centreOfCollision());
      const double f = gw.weight == 0.0 ? 0.0 : gw.weight * perception->projectedGap(tests[i], gw.px_per_metre);
      order_.emplace_back(f, static_cast<std::uint32_t>(i));
    }
    // Highest priority first; equal priorities keep list order (deterministic, no allocation).
    std::sort(order_.begin(), order_.end(), [](const auto& x, const auto& y) {
      return x.first > y.first || (x.first == y.first && x.second < y.second);
    });
  } else {
    for (std::size_t i = 0; i < count; ++i) order_.emplace_back(0.0, static_cast<std::uint32_t>(i));
  }
  overhead.stop();

  for (std::size_t k = 0; k < order_.size(); ++k) {
    PairTest& test = tests[order_[k].second];
    while (!test.resolved()) {
      if (!budgetedStep(test, budget, stats)) {
        // Interrupted only if something is left: this pair is unresolved by the loop condition.
        stats.interrupted = true;
        stats.overhead_seconds = overhead.seconds();
        return stats;
      }
    }
  }
  stats.overhead_seconds = overhead.seconds();
  return stats;
}

}  // namespace stc::detail
