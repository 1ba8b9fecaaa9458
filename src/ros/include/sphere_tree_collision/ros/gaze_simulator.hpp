// GazeSimulator: stands in for an eye tracker. Publishes GazePoint (pixels of
// the world node's perception camera) at a fixed rate:
//   fixed     one pixel (~pixel, default the image centre)
//   circle    round the image centre (~circle_radius px, ~circle_period s)
//   saccades  the core GazeModel: a new seeded pixel every ~saccade_period s
//   follow    the projection of tf frame ~target (an entity's frame), clamped
//             onto the image; the last pixel while the frame is missing
//   active    the fastest-moving entity on the image (<~world_node>/entity_states,
//             extrapolated to now), as a viewer's eye is drawn to motion: it
//             stays on its rock while that one moves at least ~switch_ratio of
//             the fastest's speed, and on the last place it saw when nothing
//             moves faster than ~min_speed (m/s)
// The camera (image size, projection, tf frame) is the world node's
// perception camera as it publishes it on <~world_node>/camera_info; the
// camera pose for follow comes from tf (the world node publishes it as
// "perception_camera", or its ~camera_frame).
#pragma once

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/gaze_model.hpp"

#include <image_geometry/pinhole_camera_model.h>
#include <ros/ros.h>
#include <sphere_tree_collision/EntityStates.h>
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
  enum class Mode { Fixed, Circle, Saccades, Follow, Active };
  void publish();
  std::optional<stc::Vec2> followPixel();
  std::optional<stc::Vec2> activePixel(const ros::Time& now);

  ros::NodeHandle nh_;
  Mode mode_ = Mode::Saccades;
  image_geometry::PinholeCameraModel camera_;
  int width_ = 0, height_ = 0;  // the camera's image, pixels
  std::string camera_frame_, target_;
  stc::Vec2 pixel_;
  double circle_radius_ = 0.0, circle_period_ = 4.0;
  std::unique_ptr<stc::GazeModel> model_;  // fixed and saccades
  std::optional<stc::Vec2> last_follow_;
  ros::Time follow_stamp_;  // tf stamp of the target pose last_follow_ projects
  // active: the latest entity states, the entity looked at (its id), the rules' figures.
  sphere_tree_collision::EntityStates::ConstPtr states_;
  ros::Subscriber states_sub_;
  std::optional<std::uint32_t> active_id_;
  double min_speed_ = 0.3, switch_ratio_ = 0.5;
  ros::Time start_;  // stamp of the first message
  std::unique_ptr<tf2_ros::Buffer> tf_;
  std::unique_ptr<tf2_ros::TransformListener> listener_;
  ros::Publisher pub_;
  ros::SteadyTimer timer_;
};

}  // namespace stc_ros
