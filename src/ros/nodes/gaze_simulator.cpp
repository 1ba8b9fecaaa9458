// gaze_simulator: publishes GazePoint like an eye tracker would. See
// src/ros/include/sphere_tree_collision/ros/gaze_simulator.hpp and docs/ros_interface.md.
#include "sphere_tree_collision/ros/gaze_simulator.hpp"
#include "sphere_tree_collision/ros/run_node.hpp"

int main(int argc, char** argv) {
  return stc_ros::runNode<stc_ros::GazeSimulator>(argc, argv, "gaze_simulator");
}
