#include "sphere_tree_collision/ros/perception_camera_info.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"

#include <image_geometry/pinhole_camera_model.h>

#include <algorithm>
#include <cmath>

namespace stc_ros {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Principal point this close to the image centre (pixels), fx this close to fy
// (relative): the same camera as the core's pinhole for any gaze purpose.
constexpr double kCentreTolerancePx = 0.5;
constexpr double kSquareTolerance = 1e-6;

}  // namespace

sensor_msgs::CameraInfo toCameraInfo(const stc::Perception& perception, const std::string& frame) {
  const stc::Camera& camera = perception.camera();
  sensor_msgs::CameraInfo info;
  info.header.frame_id = frame;
  info.width = static_cast<std::uint32_t>(camera.width);
  info.height = static_cast<std::uint32_t>(camera.height);
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  const double f = perception.focalPx();
  const double cx = 0.5 * camera.width, cy = 0.5 * camera.height;
  info.K = {f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0};
  info.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  info.P = {f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return info;
}

stc::Camera withIntrinsicsOf(const sensor_msgs::CameraInfo& info, const stc::Camera& camera) {
  if (info.width == 0 || info.width > 1u << 16) throw stc::InputError("width", "must be in [1, 65536] pixels");
  if (info.height == 0 || info.height > 1u << 16) throw stc::InputError("height", "must be in [1, 65536] pixels");
  if (std::any_of(info.D.begin(), info.D.end(), [](double d) { return d != 0.0; })) {
    throw stc::InputError("D", "distortion is not modelled: give a rectified camera (all zero)");
  }
  image_geometry::PinholeCameraModel model;
  try {
    model.fromCameraInfo(info);
  } catch (const std::exception& e) {
    throw stc::InputError("K", e.what());
  }
  const double fx = model.fx(), fy = model.fy();
  if (!(fy > 0.0) || !std::isfinite(fy)) throw stc::InputError("K", "fy must be finite and > 0");
  if (!(std::abs(fx - fy) <= kSquareTolerance * fy)) {
    throw stc::InputError("K", "pixels must be square (fx = fy), got fx " + std::to_string(fx) + ", fy " + std::to_string(fy));
  }
  const cv::Size size = model.fullResolution();
  if (!(std::abs(model.cx() - 0.5 * size.width) <= kCentreTolerancePx) ||
      !(std::abs(model.cy() - 0.5 * size.height) <= kCentreTolerancePx)) {
    throw stc::InputError("K", "the principal point must be the image centre (" + std::to_string(0.5 * size.width) +
                                   ", " + std::to_string(0.5 * size.height) + ")");
  }
  stc::Camera out = camera;
  out.width = size.width;
  out.height = size.height;
  out.fov_y_deg = 2.0 * std::atan(0.5 * size.height / fy) * 180.0 / kPi;
  try {
    stc::validateCamera(out);
  } catch (const stc::InputError& e) {
    throw stc::InputError("K", e.reason());
  }
  return out;
}

PerceptionCameraInfo::PerceptionCameraInfo(ros::NodeHandle& nh, ros::NodeHandle& private_nh, stc::World& world,
                                           std::string frame, const std::string& source_topic)
    : world_(world), frame_(std::move(frame)) {
  pub_ = private_nh.advertise<sensor_msgs::CameraInfo>("camera_info", 1, true);
  publish();
  // A queue of 10, not 1: with 1, roscpp dropped the CameraInfo that followed a refused one (camera_info.test).
  if (!source_topic.empty()) sub_ = nh.subscribe(source_topic, 10, &PerceptionCameraInfo::onCameraInfo, this);
}

void PerceptionCameraInfo::publish() {
  sensor_msgs::CameraInfo info = toCameraInfo(world_.perception(), frame_);
  info.header.stamp = ros::Time::now();
  pub_.publish(info);
}

void PerceptionCameraInfo::onCameraInfo(const sensor_msgs::CameraInfo& msg) {
  try {
    const stc::Camera& current = world_.perception().camera();
    const stc::Camera next = withIntrinsicsOf(msg, current);
    if (next.width == current.width && next.height == current.height && next.fov_y_deg == current.fov_y_deg) return;
    world_.perception().setCamera(next);
    ROS_INFO("perception camera from %s: %dx%d, %.3f deg vertical field of view", sub_.getTopic().c_str(), next.width,
             next.height, next.fov_y_deg);
    publish();
  } catch (const stc::InputError& e) {
    ROS_ERROR("rejected camera_info message: %s: %s (the camera is unchanged)", e.field().c_str(),
              e.reason().c_str());
  }
}

}  // namespace stc_ros
