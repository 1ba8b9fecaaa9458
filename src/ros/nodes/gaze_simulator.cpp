// gaze_simulator: publishes GazePoint like an eye tracker would. See
// include/sphere_tree_collision/ros/gaze_simulator.hpp and docs/ros_interface.md.
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/gaze_simulator.hpp"

#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "gaze_simulator");
  std::unique_ptr<stc_ros::GazeSimulator> node;
  try {
    node = std::make_unique<stc_ros::GazeSimulator>(ros::NodeHandle(), ros::NodeHandle("~"));
  } catch (const stc::InputError& e) {
    ROS_FATAL("gaze_simulator: invalid ~%s: %s", e.field().c_str(), stc_ros::reasonOf(e).c_str());
    return 1;
  }
  ros::spin();
  return 0;
}
