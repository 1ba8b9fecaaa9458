// The perception camera as a ROS camera. The core's camera (stc::Camera) is an
// ideal pinhole: square pixels, principal point at the image centre, no
// distortion. Here it becomes a sensor_msgs/CameraInfo and back:
// - PerceptionCameraInfo publishes the camera the World uses, latched on
//   ~camera_info (again whenever it changes), and, with ~camera_info_topic,
//   takes the camera's image size and field of view from that topic (the pose
//   still comes from the parameters or tf).
#pragma once

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/world.hpp"

#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>

#include <string>

namespace stc_ros {

sensor_msgs::CameraInfo toCameraInfo(const stc::Perception& perception, const std::string& frame);

// `camera` with the image size and field of view of `info` (read through
// image_geometry::PinholeCameraModel); its pose is kept. Throws
// stc::InputError naming the CameraInfo field ("width", "height", "K", "D")
// when the core's pinhole cannot be that camera.
stc::Camera withIntrinsicsOf(const sensor_msgs::CameraInfo& info, const stc::Camera& camera);

class PerceptionCameraInfo {
 public:
  // `world` (its perception camera) must outlive this. `frame`: the camera's tf
  // frame, the CameraInfo's frame_id. `source_topic` "": the parameters' camera.
  PerceptionCameraInfo(ros::NodeHandle& nh, ros::NodeHandle& private_nh, stc::World& world, std::string frame,
                       const std::string& source_topic);

 private:
  void publish();
  void onCameraInfo(const sensor_msgs::CameraInfo& msg);

  stc::World& world_;
  std::string frame_;
  ros::Publisher pub_;
  ros::Subscriber sub_;
};

}  // namespace stc_ros
