// Round-robin (Hubbard 1995): every unresolved pair descends one level, in
// list order, then the pass repeats, so at any interruption the step counts of
// the pairs still unresolved differ by at most one.
#include "scheduler_detail.hpp"

namespace stc::detail {

ScheduleStats RoundRobinScheduler::run(PairTest* tests, std::size_t count,
                                       const PairBodies& /*bodies*/, const Perception* /*perception*/,
                                       BudgetTracker& budget) {
  ScheduleStats stats;
  OverheadClock overhead;
  overhead.start();
  active_.clear();
  for (std::size_t i = 0; i < count; ++i) {
    if (!tests[i].resolved()) active_.push_back(static_cast<std::uint32_t>(i));
  }
  overhead.stop();
  while (!active_.empty()) {
    // One pass; resolved pairs are compacted out in place, order kept.
    std::size_t kept = 0;
    for (std::size_t r = 0; r < active_.size(); ++r) {
      PairTest& test = tests[active_[r]];
      if (!budgetedStep(test, budget, stats)) {
        stats.interrupted = true;
        stats.overhead_seconds = overhead.seconds();
        return stats;
      }
      if (!test.resolved()) active_[kept++] = active_[r];
    }
    active_.resize(kept);
  }
  stats.overhead_seconds = overhead.seconds();
  return stats;
}

}  // namespace stc::detail
