// Budget: the steady clock and the narrow-phase-only tracker.
#include "sphere_tree_collision/budget.hpp"

#include <algorithm>
#include <chrono>

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

}  // namespace stc
