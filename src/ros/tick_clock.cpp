#include "sphere_tree_collision/ros/tick_clock.hpp"

#include "sphere_tree_collision/types.hpp"

#include <rosgraph_msgs/Clock.h>

namespace stc_ros {
namespace {

constexpr double kRealTimeWindowSeconds = 1.0;

}  // namespace

double checkedStampAge(const ros::Time& stamp, const ros::Time& now, double max_age, double max_ahead,
                       const std::string& limit) {
  const double age = stamp.isZero() ? 0.0 : now.toSec() - stamp.toSec();
  if (age > max_age) {
    throw stc::InputError("header.stamp", "stale: " + std::to_string(age) + " s old (" + limit + ")");
  }
  if (-age > max_ahead) {
    throw stc::InputError("header.stamp", "in the future by " + std::to_string(-age) + " s (" + limit + ")");
  }
  return age;
}

TickClock::TickClock(ros::NodeHandle& nh, bool publish_clock)
    : publish_clock_(publish_clock), follows_clock_(!publish_clock && ros::Time::isSimTime()) {
  if (publish_clock_) clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
}

void TickClock::start(ros::NodeHandle& nh, double period, std::function<void()> tick) {
  if (follows_clock_) {
    // From the first /clock on: a timer started at time 0 would fire once for 0 + period.
    ros::Time::waitForValid();
    ros_timer_ = nh.createTimer(ros::Duration(period), [this, tick](const ros::TimerEvent& e) {
      due_ = e.current_expected;
      tick();
    });
  } else {
    steady_timer_ = nh.createSteadyTimer(ros::WallDuration(period), [tick](const ros::SteadyTimerEvent&) { tick(); });
  }
}

ros::Time TickClock::beginTick(double dt) {
  const ros::WallTime wall = ros::WallTime::now();
  physics_s_ += dt;
  if (!window_open_) {  // measured from the first tick on
    window_open_ = true;
    window_wall_ = wall;
    window_physics_s_ = physics_s_;
  }
  const double wall_s = (wall - window_wall_).toSec();
  // The first window reports as it fills; later ones once complete.
  if (wall_s > 0.0 && (first_window_ || wall_s >= kRealTimeWindowSeconds)) {
    real_time_factor_ = (physics_s_ - window_physics_s_) / wall_s;
  }
  if (wall_s >= kRealTimeWindowSeconds) {
    first_window_ = false;
    window_wall_ = wall;
    window_physics_s_ = physics_s_;
  }
  if (follows_clock_) return due_;
  if (!publish_clock_) return ros::Time::now();
  rosgraph_msgs::Clock clock;
  clock.clock.fromSec(physics_s_);
  clock_pub_.publish(clock);
  return clock.clock;
}

ros::Time TickClock::now() const {
  if (publish_clock_) return ros::Time().fromSec(physics_s_);
  return ros::Time::now();
}

}  // namespace stc_ros
