// The world node's whole-tick budget (~tick_budget, tick_budget_rule.hpp): the
// default gives the step the period less the measured publishing, within its
// clamp; an explicit value overrides it; -1 is none; bad values name the parameter.
#include "sphere_tree_collision/ros/tick_budget_rule.hpp"

#include "sphere_tree_collision/types.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace stc_ros {

TEST(TickBudgetRule, DefaultIsThePeriodLessPublishingWithinItsClamp) {
  const double period = 1.0 / 60.0;
  EXPECT_DOUBLE_EQ(tickBudgetSeconds(0.0, period, 0.004), period - 0.004);
  EXPECT_DOUBLE_EQ(tickBudgetSeconds(0.0, period, 0.0), period);  // nothing measured yet
  EXPECT_DOUBLE_EQ(tickBudgetSeconds(0.0, period, 0.9 * period), kMinStepShareOfPeriod * period);  // floor
  EXPECT_GT(tickBudgetSeconds(0.0, period, 10.0), 0.0);
}

TEST(TickBudgetRule, AnExplicitValueOverridesAndMinusOneIsNone) {
  EXPECT_DOUBLE_EQ(tickBudgetSeconds(16.7, 1.0 / 60.0, 0.004), 0.0167);
  EXPECT_DOUBLE_EQ(tickBudgetSeconds(50.0, 1.0 / 60.0, 0.004), 0.050);  // may exceed the period
  EXPECT_EQ(tickBudgetSeconds(kNoTickBudget, 1.0 / 60.0, 0.004), std::numeric_limits<double>::infinity());
}

TEST(TickBudgetRule, BadValuesAreRejectedNamingTheParameter) {
  for (double bad : {std::nan(""), std::numeric_limits<double>::infinity(), -16.7, -0.5, -2.0}) {
    try {
      checkedTickBudgetMs(bad);
      FAIL() << bad << " accepted";
    } catch (const stc::InputError& e) {
      EXPECT_EQ(e.field(), "tick_budget");
    }
    EXPECT_THROW(tickBudgetSeconds(bad, 1.0 / 60.0, 0.0), stc::InputError);
  }
  EXPECT_EQ(checkedTickBudgetMs(0.0), 0.0);
  EXPECT_EQ(checkedTickBudgetMs(-1.0), -1.0);
}

TEST(TickBudgetRule, PublishCostIsASmoothedMeanOfSamplesClampedToThePeriod) {
  const double period = 0.02;
  PublishCost cost;
  EXPECT_EQ(cost.seconds(), 0.0);
  for (int i = 0; i < 2000; ++i) cost.add(0.005, period);
  EXPECT_NEAR(cost.seconds(), 0.005, 1e-12);  // a steady cost is learnt exactly
  PublishCost stalled;
  stalled.add(10.0, period);  // one stall counts as one period
  EXPECT_DOUBLE_EQ(stalled.seconds(), period / PublishCost::kPublishSmoothingTicks);
  PublishCost odd;
  odd.add(std::nan(""), period);
  odd.add(-1.0, period);
  EXPECT_EQ(odd.seconds(), 0.0);
  // One marker tick in six: the mean, not the peak.
  PublishCost spiky;
  for (int i = 0; i < 6000; ++i) spiky.add(i % 6 == 0 ? 0.012 : 0.0, period);
  EXPECT_NEAR(spiky.seconds(), 0.002, 0.0005);
}

}  // namespace stc_ros
