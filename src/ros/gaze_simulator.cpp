#include "sphere_tree_collision/ros/gaze_simulator.hpp"

#include "sphere_tree_collision/ros/param_reading.hpp"

#include <ros/topic.h>
#include <sensor_msgs/CameraInfo.h>
#include <sphere_tree_collision/GazePoint.h>

#include <algorithm>
#include <cmath>

namespace stc_ros {
namespace {

using stc::InputError;

}  // namespace

GazeSimulator::GazeSimulator(ros::NodeHandle nh, ros::NodeHandle pnh) : nh_(nh) {
  // What needs no image is checked first: a bad parameter ends the node at
  // once, not after the world node's camera arrives (or never does).
  const std::string mode = paramOr<std::string>(pnh, "mode", "saccades");
  if (mode != "fixed" && mode != "saccades" && mode != "circle" && mode != "follow" && mode != "active") {
    throw InputError("mode", "unknown value '" + mode + "' (expected one of: fixed, circle, saccades, follow, active)");
  }
  const double rate = positiveParam(pnh, "rate", 30.0);
  if (mode == "follow") {
    target_ = paramOr<std::string>(pnh, "target", "");
    if (target_.empty()) throw InputError("target", "follow needs the tf frame of an entity");
  }
  if (mode == "active") {
    min_speed_ = positiveParam(pnh, "min_speed", min_speed_);
    switch_ratio_ = positiveParam(pnh, "switch_ratio", switch_ratio_);
    if (switch_ratio_ > 1.0) throw InputError("switch_ratio", "must be in (0, 1]");
  }

  // The world node's perception camera, as it publishes it (latched): the
  // image for every mode, its tf frame and projection for follow.
  const std::string world_node = paramOr<std::string>(pnh, "world_node", "collision_world");
  const std::string topic = ros::names::append(world_node, "camera_info");
  ROS_INFO("gaze_simulator: waiting for the perception camera on %s", nh_.resolveName(topic).c_str());
  const auto info = ros::topic::waitForMessage<sensor_msgs::CameraInfo>(topic, nh_);
  if (!info) throw InputError("world_node", "no CameraInfo on " + nh_.resolveName(topic) + " before shutdown");
  if (!camera_.fromCameraInfo(*info) || info->width == 0 || info->height == 0) {
    throw InputError("world_node", "the CameraInfo on " + nh_.resolveName(topic) + " has no image");
  }
  width_ = static_cast<int>(info->width);
  height_ = static_cast<int>(info->height);
  camera_frame_ = info->header.frame_id;
  const stc::Vec2 centre(0.5 * width_, 0.5 * height_);

  std::vector<double> pixel{centre.x(), centre.y()};
  if (pnh.hasParam("pixel") && (!pnh.getParam("pixel", pixel) || pixel.size() != 2)) {
    throw InputError("pixel", "expected [x, y] in pixels");
  }
  pixel_ = stc::Vec2(pixel[0], pixel[1]);
  if (mode == "fixed" || mode == "saccades") {
    stc::GazeParams gp;
    gp.mode = mode == "fixed" ? stc::GazeMode::Fixed : stc::GazeMode::Saccades;
    gp.pixel = pixel_;
    gp.saccade_period_s = positiveParam(pnh, "saccade_period", gp.saccade_period_s);
    gp.seed = static_cast<std::uint32_t>(paramOr<int>(pnh, "seed", 1));
    model_ = std::make_unique<stc::GazeModel>(gp);
    mode_ = mode == "fixed" ? Mode::Fixed : Mode::Saccades;
    if (mode_ == Mode::Fixed && !(pixel_.x() >= 0 && pixel_.y() >= 0 && pixel_.x() <= width_ &&
                                  pixel_.y() <= height_)) {
      throw InputError("pixel", "must lie on the image");
    }
  } else if (mode == "circle") {
    mode_ = Mode::Circle;
    circle_radius_ = positiveParam(pnh, "circle_radius", 0.3 * height_);
    circle_period_ = positiveParam(pnh, "circle_period", circle_period_);
    if (circle_radius_ > 0.5 * std::min(width_, height_)) {
      throw InputError("circle_radius", "the circle must fit the image");
    }
  } else {  // follow (its target is checked above) and active
    mode_ = mode == "follow" ? Mode::Follow : Mode::Active;
    if (camera_frame_.empty()) throw InputError("mode", mode + " needs the camera in tf (world node ~published_camera_frame)");
    tf_ = std::make_unique<tf2_ros::Buffer>();
    listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_, nh_);
    if (mode_ == Mode::Active) {
      states_sub_ = nh_.subscribe<sphere_tree_collision::EntityStates>(
          ros::names::append(world_node, "entity_states"), 1,
          [this](const sphere_tree_collision::EntityStates::ConstPtr& m) { states_ = m; });
    }
  }

  pub_ = nh_.advertise<sphere_tree_collision::GazePoint>("gaze", 10);
  timer_ = nh_.createSteadyTimer(ros::WallDuration(1.0 / rate), [this](const ros::SteadyTimerEvent&) { publish(); });
  ROS_INFO("gaze_simulator: %s at %.1f Hz on a %dx%d image", mode.c_str(), rate, width_, height_);
}

std::optional<stc::Vec2> GazeSimulator::followPixel() {
  try {
    // The target in the camera's optical frame, projected by the camera's own model.
    const auto target = tf_->lookupTransform(camera_frame_, target_, ros::Time(0));
    const auto& p = target.transform.translation;
    if (p.z > stc::Perception::kNearDepth) {
      const cv::Point2d pixel = camera_.project3dToPixel(cv::Point3d(p.x, p.y, p.z));
      follow_stamp_ = target.header.stamp;
      last_follow_ = stc::Vec2(std::clamp(pixel.x, 0.0, static_cast<double>(width_)),
                               std::clamp(pixel.y, 0.0, static_cast<double>(height_)));
    }
  } catch (const tf2::TransformException& e) {
    ROS_WARN_THROTTLE(5.0, "gaze_simulator: cannot follow '%s': %s", target_.c_str(), e.what());
  }
  return last_follow_;
}

std::optional<stc::Vec2> GazeSimulator::activePixel(const ros::Time& now) {
  if (!states_) return last_follow_;
  const auto& m = *states_;
  geometry_msgs::TransformStamped to_camera;
  try {
    to_camera = tf_->lookupTransform(camera_frame_, m.header.frame_id, ros::Time(0));
  } catch (const tf2::TransformException& e) {
    ROS_WARN_THROTTLE(5.0, "gaze_simulator: no camera pose for active: %s", e.what());
    return last_follow_;
  }
  const auto& t = to_camera.transform;
  const stc::Quat q(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
  const stc::Vec3 origin(t.translation.x, t.translation.y, t.translation.z);
  // Where each entity is now (its last state moved on at its velocity), and
  // where that is on the image; entities off the image are not candidates.
  const double ahead = std::clamp((now - m.header.stamp).toSec(), 0.0, 0.5);
  struct Seen {
    double speed = -1.0;
    stc::Vec2 pixel;
    std::size_t index = 0;
  };
  Seen fastest, current;
  for (std::size_t i = 0; i < m.poses.size() && i < m.twists.size() && i < m.ids.size(); ++i) {
    const auto& p = m.poses[i].position;
    const auto& v = m.twists[i].linear;
    const stc::Vec3 velocity(v.x, v.y, v.z);
    const stc::Vec3 c = q * (stc::Vec3(p.x, p.y, p.z) + ahead * velocity) + origin;
    if (!(c.z() > stc::Perception::kNearDepth)) continue;
    const cv::Point2d px = camera_.project3dToPixel(cv::Point3d(c.x(), c.y(), c.z()));
    if (!(px.x >= 0 && px.y >= 0 && px.x <= width_ && px.y <= height_)) continue;
    const Seen seen{velocity.norm(), stc::Vec2(px.x, px.y), i};
    if (seen.speed > fastest.speed) fastest = seen;
    if (active_id_ && m.ids[i] == *active_id_) current = seen;
  }
  // Stay on the rock looked at while it moves about as fast as the fastest
  // (no flicker between two falling together); else go to the fastest; with
  // nothing moving, rest on the last one seen (the pile).
  const bool keep = current.speed >= 0.0 &&
                    (current.speed >= switch_ratio_ * fastest.speed || fastest.speed < min_speed_);
  if (keep) {
    last_follow_ = current.pixel;
  } else if (fastest.speed >= min_speed_) {
    active_id_ = m.ids[fastest.index];
    last_follow_ = fastest.pixel;
  }
  if (last_follow_) follow_stamp_ = now;
  return last_follow_;
}

void GazeSimulator::publish() {
  // The pixel is a function of the stamp the message carries (time since the
  // first message), so a subscriber can check the motion from stamps alone.
  const ros::Time stamp = ros::Time::now();
  if (start_.isZero()) start_ = stamp;
  const double t = (stamp - start_).toSec();
  std::optional<stc::Vec2> pixel;
  switch (mode_) {
    case Mode::Fixed:
    case Mode::Saccades: {
      static const stc::World kNoWorld;  // fixed and saccades never look at the world
      pixel = model_->fixationAt(t, kNoWorld);
      break;
    }
    case Mode::Circle: {
      const double a = 2.0 * M_PI * t / circle_period_;
      pixel = stc::Vec2(0.5 * width_ + circle_radius_ * std::cos(a), 0.5 * height_ + circle_radius_ * std::sin(a));
      break;
    }
    case Mode::Follow:
      pixel = followPixel();
      break;
    case Mode::Active:
      pixel = activePixel(stamp);
      break;
  }
  if (!pixel) return;
  sphere_tree_collision::GazePoint msg;
  // Follow: the instant the target was where the viewer looks (its tf stamp).
  msg.header.stamp = mode_ == Mode::Follow ? follow_stamp_ : stamp;
  msg.header.frame_id = camera_frame_;
  msg.x = pixel->x();
  msg.y = pixel->y();
  pub_.publish(msg);
}

}  // namespace stc_ros
