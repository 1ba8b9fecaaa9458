// rockfall_spawner: rocks dropping into the ravine at a set rate. See
// src/ros/include/sphere_tree_collision/ros/rockfall_spawner.hpp and docs/ros_interface.md.
#include "sphere_tree_collision/ros/rockfall_spawner.hpp"
#include "sphere_tree_collision/ros/run_node.hpp"

int main(int argc, char** argv) {
  return stc_ros::runNode<stc_ros::RockfallSpawner>(argc, argv, "rockfall_spawner");
}
