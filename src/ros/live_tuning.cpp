#include "sphere_tree_collision/ros/live_tuning.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"

namespace stc_ros {
namespace {

using sphere_tree_collision::WorldConfig;

// TunableParams and WorldConfig spell the parameters alike; only the marker
// levels differ (a list, text in dynamic_reconfigure).
template <typename From, typename To>
void copyAlike(const From& from, To& to) {
  to.detection_budget = from.detection_budget;
  to.sphere_test_budget = from.sphere_test_budget;
  to.tick_budget = from.tick_budget;
  to.scheduler = from.scheduler;
  to.queue_count = from.queue_count;
  to.queue_ratio = from.queue_ratio;
  to.unresolved_policy = from.unresolved_policy;
  to.response = from.response;
  to.solver_iterations = from.solver_iterations;
  to.show_voxels = from.show_voxels;
  to.marker_rate = from.marker_rate;
  to.gaze_timeout = from.gaze_timeout;
}

WorldConfig configOf(const TunableParams& t) {
  WorldConfig c = WorldConfig::__getDefault__();  // and its groups
  copyAlike(t, c);
  c.marker_levels = formatMarkerLevels(t.marker_levels);
  return c;
}

TunableParams tunableOf(const WorldConfig& c) {
  TunableParams t;
  copyAlike(c, t);
  t.marker_levels = parseMarkerLevels(c.marker_levels);
  return t;
}

}  // namespace

LiveTuning::LiveTuning(const ros::NodeHandle& private_nh, const NodeParams& current, Apply apply)
    : current_(current), apply_(std::move(apply)), server_(mutex_, private_nh) {
  // The server read the parameter server and its cfg defaults; the node's
  // parameters, already checked, are the truth.
  server_.updateConfig(configOf(tunableOf(current_)));
  server_.setCallback([this](WorldConfig& config, std::uint32_t level) { onReconfigure(config, level); });
}

void LiveTuning::onReconfigure(WorldConfig& config, std::uint32_t /*level*/) {
  try {
    NodeParams next = current_;
    applyTunable(tunableOf(config), next);
    apply_(next);
    ROS_INFO("reconfigured: scheduler %s, detection budget %g ms, %d sphere tests, tick budget %g ms",
             config.scheduler.c_str(), config.detection_budget, config.sphere_test_budget, config.tick_budget);
  } catch (const stc::InputError& e) {
    ROS_ERROR("reconfigure refused: ~%s: %s (the configuration is unchanged)", e.field().c_str(), e.reason().c_str());
    config = configOf(tunableOf(current_));  // what the server keeps and answers
  }
}

}  // namespace stc_ros
