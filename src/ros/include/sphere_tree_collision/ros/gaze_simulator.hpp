// GazeSimulator: stands in for an eye tracker. Publishes GazePoint (pixels of
// the world node's perception camera) at a fixed rate:
//   fixed     one pixel (~pixel, default the image centre)
//   circle    round the image centre (~circle_radius px, ~circle_period s)
//   saccades  the core GazeModel: a new seeded pixel every ~saccade_period s
//   follow    the projection of tf frame ~target (an entity's frame), clamped
//             onto the image; the last pixel while the frame is missing
// Image size and field of view are read from the world node's parameters
// (~world_node), the camera pose for follow from tf (the world node publishes
// it as "perception_camera", or its ~camera_frame).
#pragma once

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <optional>
#include <string>

namespace stc_ros {

class GazeSimulator {
 public:
  // Throws stc::InputError naming the parameter.
  GazeSimulator(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  enum class Mode { Fixed, Circle, Saccades, Follow };
  void publish();
  std::optional<stc::Vec2> followPixel();

  ros::NodeHandle nh_;
  Mode mode_ = Mode::Saccades;
  stc::Camera camera_;
  std::string world_frame_, camera_frame_, target_;
  stc::Vec2 pixel_;
  double circle_radius_ = 0.0, circle_period_ = 4.0;
  std::unique_ptr<stc::GazeModel> model_;  // fixed and saccades
  std::optional<stc::Vec2> last_follow_;
  ros::Time follow_stamp_;  // tf stamp of the target pose last_follow_ projects
  ros::Time start_;  // stamp of the first message
  std::unique_ptr<tf2_ros::Buffer> tf_;
  std::unique_ptr<tf2_ros::TransformListener> listener_;
  ros::Publisher pub_;
  ros::SteadyTimer timer_;
};

}  // namespace stc_ros
