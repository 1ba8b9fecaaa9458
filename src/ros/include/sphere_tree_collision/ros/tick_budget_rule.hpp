// The whole-tick budget the world node gives World::step (~tick_budget), kept
// free of ROS so a gtest checks it exactly (test/unit/test_tick_budget_rule.cpp).
//   ~tick_budget > 0   that many ms, every tick;
//   ~tick_budget = 0   (the default) the tick period less the node's own work of a
//                      tick, measured every tick: so the whole tick, publishing
//                      included, fits in 1/~rate;
//   ~tick_budget = -1  none: the step runs to its end.
// docs/ros_interface.md says the same for users.
#pragma once

namespace stc_ros {

constexpr double kNoTickBudget = -1.0;  // ~tick_budget: none

// ~tick_budget (ms) as the node accepts it: finite, and > 0, 0 or -1. Throws
// stc::InputError("tick_budget") otherwise (NaN, inf, other negatives: a sign
// typo is not read as "none").
double checkedTickBudgetMs(double ms);

// The least share of the period the step is given under ~tick_budget 0. When the
// node's publishing alone takes most of the period the rate is lost whatever the
// step does; cutting the step to nothing would then only cost physics.
constexpr double kMinStepShareOfPeriod = 0.25;

// The step's budget under ~tick_budget 0: period - publish, within
// [kMinStepShareOfPeriod x period, period]. Seconds.
double periodLessPublishing(double period_s, double publish_s);

// The budget for stc::Budget::tick_seconds (s; +inf: none) from ~tick_budget
// (checked), the tick period and the measured publish cost.
double tickBudgetSeconds(double tick_budget_ms, double period_s, double publish_s);

// The node's own work of a tick (all of runTick but World::step: camera tf,
// stats, contacts, tf, markers, entity states), smoothed. An exponential mean
// over about kPublishSmoothingTicks ticks: the mean is what holds the rate, since
// markers and entity states cost one tick in several and the tick timer makes up
// a late tick in the next ones (a recent maximum would give every tick the
// marker tick's cost). Each sample counts for at most one period: one stall
// (a swap, a burst of subscribers) cannot starve the step for seconds.
class PublishCost {
 public:
  static constexpr double kPublishSmoothingTicks = 30.0;

  void add(double seconds, double period_s);
  double seconds() const { return smoothed_s_; }  // 0 before the first tick

 private:
  double smoothed_s_ = 0.0;
};

}  // namespace stc_ros
