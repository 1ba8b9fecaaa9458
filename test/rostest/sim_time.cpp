// /use_sim_time: the test is the clock. Every tick is stamped with a time the
// test published, exactly one period (0.1 s) of that clock after the last, and
// none runs ahead of the clock.
#include "rostest_util.hpp"

#include <gtest/gtest.h>
#include <rosgraph_msgs/Clock.h>
#include <sphere_tree_collision/TickStats.h>

#include <set>
#include <vector>

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
  const ros::Duration step(kDt / 4);
  // Every value of the clock is published, in steps, with none skipped: a tick
  // is due at a whole period after the last, and that instant must be one the
  // test published (the node stamps a tick with the time it was due).
  const auto publishNext = [&] {
    clock.clock += step;
    clock_pub.publish(clock);
    published.insert(clock.clock.toNSec());
  };
  // Until the node listens and ticks (it starts at the first /clock, ticks when it moves).
  ASSERT_TRUE(stc_test::spinUntil([&] {
    publishNext();
    return stats.count() > 0;
  }, stc_test::kLivenessSeconds));
  // Then 6 s of sim time in quarter ticks, each published once the node has
  // ticked up to one period before it: a loaded machine slows the test, never
  // makes the node skip a period.
  // Before the node's first tick the clock runs ahead unpaced, and a timer
  // that falls behind skips what it missed: the period is judged from here on.
  const ros::Time paced_from = clock.clock;
  const ros::Time end = clock.clock + ros::Duration(6.0);
  while (clock.clock < end) {
    publishNext();
    ASSERT_TRUE(stc_test::spinUntil([&] { return stats.last.header.stamp + ros::Duration(kDt) >= clock.clock; },
                                    stc_test::kLivenessSeconds))
        << "last tick stamped " << stats.last.header.stamp << ", clock at " << clock.clock;
  }

  const auto& all = stats.all;
  for (const auto& t : all) {
    EXPECT_EQ(published.count(t.header.stamp.toNSec()), 1u) << "tick " << t.tick << " at " << t.header.stamp;
    EXPECT_NEAR(t.physics_time, t.tick * kDt, 1e-9 * t.tick);
  }
  std::vector<sphere_tree_collision::TickStats> ticks;  // of the paced clock
  for (const auto& t : all) {
    if (t.header.stamp > paced_from) ticks.push_back(t);
  }
  ASSERT_GE(ticks.size(), 55u);
  for (std::size_t i = 1; i < ticks.size(); ++i) {
    // One tick per period of the clock: none skipped, none extra.
    EXPECT_EQ(ticks[i].tick, ticks[i - 1].tick + 1);
    EXPECT_NEAR((ticks[i].header.stamp - ticks[i - 1].header.stamp).toSec(), kDt, 1e-9) << "tick " << ticks[i].tick;
  }
  EXPECT_LE(ticks.back().header.stamp, end);  // never ahead of the clock
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "sim_time_test"); }
