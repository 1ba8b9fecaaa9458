// /use_sim_time: the test is the clock. Every tick is stamped with a time the
// test published, exactly one period (0.1 s) of that clock after the last, and
// none runs ahead of the clock.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <rosgraph_msgs/Clock.h>
#include <sphere_tree_collision/TickStats.h>

#include <set>

namespace {

constexpr double kDt = 0.1;  // sim_time.test: ~rate 10

TEST(SimTime, TicksFollowTheClock) {
  ros::NodeHandle nh;
  ros::Publisher clock_pub = nh.advertise<rosgraph_msgs::Clock>("/clock", 100);
  stc_test::Recorder<sphere_tree_collision::TickStats> stats(nh, "/collision_world/tick_stats", 1000);
  stats.keep_all = true;
  std::set<std::uint64_t> published;
  rosgraph_msgs::Clock clock;
  clock.clock = ros::Time(1000, 0);
  const auto publish = [&] {
    clock_pub.publish(clock);
    published.insert(clock.clock.toNSec());
  };
  const ros::Duration step(kDt / 4);
  // Until the node listens and ticks (it starts at the first /clock, ticks when it moves).
  ASSERT_TRUE(stc_test::spinUntil([&] {
    publish();
    clock.clock += step;
    return stats.count() > 0;
  }, stc_test::kLivenessSeconds));
  // Then 6 s of sim time in quarter ticks, each published once the node has
  // ticked up to one period before it: a loaded machine slows the test, never
  // makes the node skip a period.
  const ros::Time end = clock.clock + ros::Duration(6.0);
  while (clock.clock < end) {
    clock.clock += step;
    publish();
    ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.header.stamp + ros::Duration(kDt) >= clock.clock; },
                                    stc_test::kLivenessSeconds))
        << "last tick stamped " << stats.last.header.stamp << ", clock at " << clock.clock;
  }

  const auto& ticks = stats.all;
  ASSERT_GE(ticks.size(), 60u);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    EXPECT_EQ(published.count(ticks[i].header.stamp.toNSec()), 1u) << "tick " << ticks[i].tick << " at " << ticks[i].header.stamp;
    EXPECT_NEAR(ticks[i].physics_time, ticks[i].tick * kDt, 1e-9 * ticks[i].tick);
    if (i == 0) continue;
    // One tick per period of the clock: none skipped, none extra.
    EXPECT_EQ(ticks[i].tick, ticks[i - 1].tick + 1);
    EXPECT_NEAR((ticks[i].header.stamp - ticks[i - 1].header.stamp).toSec(), kDt, 1e-9) << "tick " << ticks[i].tick;
  }
  EXPECT_LE(ticks.back().header.stamp, end);  // never ahead of the clock
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "sim_time_test"); }
