// Live tuning through the dynamic_reconfigure client: a new scheduler and
// budgets show in tick_stats from one tick on and in every tick after it; an
// invalid configuration is refused with an ERROR naming the parameter, the
// client gets the kept configuration back, and the world keeps ticking with it.
#include "rostest_util.hpp"

#include <dynamic_reconfigure/client.h>
#include <gtest/gtest.h>
#include <rosgraph_msgs/Log.h>
#include <sphere_tree_collision/TickStats.h>
#include <sphere_tree_collision/WorldConfig.h>

#include <ros/callback_queue.h>

#include <algorithm>
#include <memory>

namespace {

using sphere_tree_collision::TickStats;
using sphere_tree_collision::WorldConfig;
using stc_test::kLivenessSeconds;
using stc_test::Recorder;
using stc_test::spinUntil;

class LiveTuningTest : public ::testing::Test {
 protected:
  LiveTuningTest() : stats_(nh_, "/collision_world/tick_stats", 1000), rosout_(nh_, "/rosout", 1000) {
    stats_.keep_all = true;
    rosout_.keep_all = true;
    client_nh_.setCallbackQueue(&client_queue_);
    client_ = std::make_unique<dynamic_reconfigure::Client<WorldConfig>>("/collision_world", client_nh_);
    client_spinner_.start();  // the client waits for parameter_updates on its own thread
  }

  // Spins until a tick numbered at least `tick` has been seen.
  void waitForTick(std::uint64_t tick) {
    ASSERT_TRUE(spinUntil([&] { return stats_.count() > 0 && stats_.last.tick >= tick; }, kLivenessSeconds))
        << "no tick_stats of tick " << tick;
  }

  // Sends `config` through the client; returns what the server answered.
  WorldConfig reconfigure(WorldConfig config) {
    EXPECT_TRUE(client_->setConfiguration(config)) << "set_parameters call failed";
    return config;
  }

  bool loggedError(const std::string& text) const {
    return std::any_of(rosout_.all.begin(), rosout_.all.end(), [&](const rosgraph_msgs::Log& log) {
      return log.level == rosgraph_msgs::Log::ERROR && log.msg.find(text) != std::string::npos;
    });
  }

  ros::NodeHandle nh_;
  Recorder<TickStats> stats_;
  Recorder<rosgraph_msgs::Log> rosout_;
  ros::CallbackQueue client_queue_;
  ros::NodeHandle client_nh_{"/collision_world"};
  ros::AsyncSpinner client_spinner_{1, &client_queue_};
  std::unique_ptr<dynamic_reconfigure::Client<WorldConfig>> client_;
};

TEST_F(LiveTuningTest, SchedulerAndBudgetsChangeFromOneTickOnAndInvalidConfigsAreRefused) {
  waitForTick(3);
  WorldConfig start;
  ASSERT_TRUE(client_->getCurrentConfiguration(start, ros::Duration(kLivenessSeconds)));
  // The server starts from the node's start-up parameters, not its cfg defaults.
  EXPECT_EQ(start.scheduler, "priority_queues");
  EXPECT_EQ(start.marker_levels, "1,2");
  EXPECT_DOUBLE_EQ(start.detection_budget, 8.0);

  WorldConfig wanted = start;
  wanted.scheduler = "round_robin";
  wanted.sphere_test_budget = 123;
  wanted.detection_budget = 5.0;
  wanted.queue_count = 4;
  const WorldConfig answer = reconfigure(wanted);
  EXPECT_EQ(answer.scheduler, "round_robin");
  EXPECT_EQ(answer.sphere_test_budget, 123);
  std::string on_server;
  EXPECT_TRUE(ros::param::get("/collision_world/scheduler", on_server));
  EXPECT_EQ(on_server, "round_robin");

  // From one tick on, every tick runs the new configuration.
  ASSERT_TRUE(spinUntil([&] { return stats_.last.scheduler == "round_robin"; }, kLivenessSeconds));
  const auto first_new = std::find_if(stats_.all.begin(), stats_.all.end(),
                                      [](const TickStats& s) { return s.scheduler == "round_robin"; });
  ASSERT_NE(first_new, stats_.all.begin()) << "no tick before the change was seen";
  const std::uint64_t switched = first_new->tick;
  waitForTick(switched + 5);
  std::uint64_t previous_tick = 0;
  ros::Time previous_stamp;
  for (const TickStats& s : stats_.all) {
    EXPECT_GT(s.tick, previous_tick);
    EXPECT_GT(s.header.stamp, previous_stamp);
    previous_tick = s.tick;
    previous_stamp = s.header.stamp;
    if (s.tick < switched) {
      EXPECT_EQ(s.scheduler, "priority_queues") << "tick " << s.tick;
      EXPECT_EQ(s.budget_sphere_tests, -1) << "tick " << s.tick;
      EXPECT_DOUBLE_EQ(s.budget_ms, 8.0) << "tick " << s.tick;
    } else {
      EXPECT_EQ(s.scheduler, "round_robin") << "tick " << s.tick;
      EXPECT_EQ(s.budget_sphere_tests, 123) << "tick " << s.tick;
      EXPECT_DOUBLE_EQ(s.budget_ms, 5.0) << "tick " << s.tick;
      EXPECT_LE(s.sphere_tests, 123) << "tick " << s.tick;
    }
  }

  // Invalid: refused whole (the valid scheduler change with it), reason logged.
  struct Invalid {
    const char* field;
    WorldConfig config;
  };
  std::vector<Invalid> invalid(4, Invalid{"", answer});
  invalid[0].field = "queue_ratio";
  invalid[0].config.queue_ratio = 0.5;
  invalid[1].field = "scheduler";
  invalid[1].config.scheduler = "fastest";
  invalid[2].field = "marker_levels";
  invalid[2].config.marker_levels = "1,x";
  invalid[3].field = "solver_iterations";
  invalid[3].config.solver_iterations = 0;
  for (Invalid& bad : invalid) {
    if (std::string(bad.field) != "scheduler") bad.config.scheduler = "sequential";
    const WorldConfig kept = reconfigure(bad.config);
    EXPECT_EQ(kept.scheduler, "round_robin") << bad.field;
    EXPECT_DOUBLE_EQ(kept.queue_ratio, answer.queue_ratio) << bad.field;
    EXPECT_EQ(kept.marker_levels, answer.marker_levels) << bad.field;
    EXPECT_EQ(kept.solver_iterations, answer.solver_iterations) << bad.field;
    const std::string expected = std::string("reconfigure refused: ~") + bad.field;
    EXPECT_TRUE(spinUntil([&] { return loggedError(expected); }, kLivenessSeconds)) << "no ERROR '" << expected << "'";
  }
  EXPECT_TRUE(ros::param::get("/collision_world/scheduler", on_server));
  EXPECT_EQ(on_server, "round_robin");

  // The world keeps ticking, with the configuration it kept.
  const std::uint64_t after = stats_.last.tick;
  stats_.clear();
  waitForTick(after + 5);
  for (const TickStats& s : stats_.all) {
    EXPECT_EQ(s.scheduler, "round_robin") << "tick " << s.tick;
    EXPECT_EQ(s.budget_sphere_tests, 123) << "tick " << s.tick;
  }
}

}  // namespace

int main(int argc, char** argv) { return stc_test::runTests(argc, argv, "live_tuning_test"); }
