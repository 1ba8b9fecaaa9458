// collision_world_node: one stc::World ticking over ROS. See docs/ros_interface.md.
#include "sphere_tree_collision/ros/run_node.hpp"
#include "sphere_tree_collision/ros/world_node.hpp"

int main(int argc, char** argv) {
  return stc_ros::runNode<stc_ros::WorldNode>(argc, argv, "collision_world_node");
}
