// gaze_simulator: publishes GazePoint like an eye tracker would. See
// include/sphere_tree_collision/ros/gaze_simulator.hpp and docs/ros_interface.md.
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/gaze_simulator.hpp"

#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "gaze_simulator");
  // Kept for the whole run: when the last NodeHandle goes, ROS shuts down
  // (and a start-up error could no longer be logged).
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<stc_ros::GazeSimulator> node;
  try {
    node = std::make_unique<stc_ros::GazeSimulator>(nh, pnh);
  } catch (const stc::InputError& e) {
    ROS_FATAL("gaze_simulator: invalid ~%s: %s", e.field().c_str(), stc_ros::reasonOf(e).c_str());
    return 1;
  }
  ros::spin();
  return 0;
}
