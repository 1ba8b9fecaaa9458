#include "sphere_tree_collision/ros/tick_budget_rule.hpp"

#include "sphere_tree_collision/types.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc_ros {

double checkedTickBudgetMs(double ms) {
  if (!std::isfinite(ms) || (ms < 0.0 && ms != kNoTickBudget)) {
    throw stc::InputError("tick_budget", "must be finite: > 0 ms, 0 for 1/~rate less the node's publishing, or -1 for none");
  }
  return ms;
}

double periodLessPublishing(double period_s, double publish_s) {
  return std::clamp(period_s - publish_s, kMinStepShareOfPeriod * period_s, period_s);
}

double tickBudgetSeconds(double tick_budget_ms, double period_s, double publish_s) {
  checkedTickBudgetMs(tick_budget_ms);
  if (tick_budget_ms > 0.0) return tick_budget_ms * 1e-3;
  if (tick_budget_ms == kNoTickBudget) return std::numeric_limits<double>::infinity();
  return periodLessPublishing(period_s, publish_s);
}

void PublishCost::add(double seconds, double period_s) {
  const double sample = seconds > period_s ? period_s : seconds > 0.0 ? seconds : 0.0;  // NaN: 0
  smoothed_s_ += (sample - smoothed_s_) / kPublishSmoothingTicks;
}

}  // namespace stc_ros
