// Budget: the steady clock and the narrow phase's tracker (deadline.hpp).
#include "deadline.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

namespace stc {

double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

BudgetTracker::BudgetTracker(const Budget& budget, std::int64_t check_every)
    : BudgetTracker(budget.sphere_tests,
                    Deadline(nullptr, budget.seconds < std::numeric_limits<double>::infinity()
                                          ? steadySeconds() + std::max(budget.seconds, 0.0)
                                          : budget.seconds),
                    check_every) {}

namespace {

// Least steady-clock seconds that kReads reads of `read` took, over kBatches batches.
template <typename Read>
double leastBatchSeconds(const Read& read) {
  constexpr int kBatches = 4, kReads = 16;
  double least = std::numeric_limits<double>::infinity();
  volatile double sink = 0.0;  // keeps the reads
  for (int b = 0; b < kBatches; ++b) {
    const double start = steadySeconds();
    for (int r = 0; r < kReads; ++r) sink = sink + read();
    least = std::min(least, steadySeconds() - start);
  }
  return least;
}

}  // namespace

std::int64_t checkEveryFor(const SecondsClock& clock) {
  const double steady = leastBatchSeconds(steadySeconds);
  const double own = leastBatchSeconds(clock);
  // Within twice the steady clock's cost it is as cheap (the tests' fake
  // clocks are): a timing's noise must not change a deterministic run.
  if (!(steady > 0.0) || !(own > 2.0 * steady)) return BudgetTracker::kDefaultCheckEvery;
  const double scaled = static_cast<double>(BudgetTracker::kDefaultCheckEvery) * own / steady;
  return static_cast<std::int64_t>(std::min(scaled, static_cast<double>(kMostCheckEvery)));
}

}  // namespace stc
