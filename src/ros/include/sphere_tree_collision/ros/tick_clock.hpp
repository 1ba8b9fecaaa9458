// TickClock: when the world node ticks and what time its messages carry.
//   - default: a steady (wall) timer at ~rate, stamps from ros::Time::now();
//   - /use_sim_time: a ROS-time timer, so ticks follow /clock (none while /clock stands;
//     ticking starts at the first /clock), each stamped with the clock time it was due at;
//   - ~publish_clock: a steady timer at ~rate, stamps in physics time (ticks x dt from 0),
//     which the clock also publishes on /clock before each tick's messages. The node
//     then never reads /clock itself: it is the source.
// It also measures the real-time factor (physics time advanced / wall time).
#pragma once

#include <ros/ros.h>

#include <functional>
#include <string>

namespace stc_ros {

// A message's header.stamp checked against `now`: its age in seconds (now -
// stamp; a zero stamp means "now": 0). Throws InputError("header.stamp") when
// it is older than `max_age` or ahead by more than `max_ahead` s, the message
// ending with `limit` (e.g. "~gaze_timeout 0.5 s"). In doubles: ros::Time and
// ros::Duration arithmetic throws near the ends of their range (stamp.sec =
// 4294967295, "Duration is out of dual 32-bit range"); a double difference
// never does. The one guard of the gaze topic and ~spawn's tf stamp.
double checkedStampAge(const ros::Time& stamp, const ros::Time& now, double max_age, double max_ahead,
                       const std::string& limit);

class TickClock {
 public:
  TickClock(ros::NodeHandle& nh, bool publish_clock);

  // Calls `tick` every `period` s of the clock above (with /use_sim_time: waits for /clock).
  void start(ros::NodeHandle& nh, double period, std::function<void()> tick);
  // Advances physics time by dt and returns the stamp of that tick (published on
  // /clock first with ~publish_clock).
  ros::Time beginTick(double dt);
  // "Now" for stamps and ages outside a tick (gaze stamps, marker snapshots).
  ros::Time now() const;

  double physicsSeconds() const { return physics_s_; }
  // Over the last completed second of wall time (until then: since the first tick).
  double realTimeFactor() const { return real_time_factor_; }
  bool publishesClock() const { return publish_clock_; }
  bool followsClock() const { return follows_clock_; }

 private:
  bool publish_clock_;
  bool follows_clock_;  // /use_sim_time without ~publish_clock
  double physics_s_ = 0.0;
  ros::Publisher clock_pub_;
  ros::SteadyTimer steady_timer_;
  ros::Timer ros_timer_;
  ros::Time due_;  // /use_sim_time: when the current tick was due
  // Real-time factor window: wall and physics time at its start.
  bool window_open_ = false, first_window_ = true;
  ros::WallTime window_wall_;
  double window_physics_s_ = 0.0;
  double real_time_factor_ = 0.0;
};

}  // namespace stc_ros
