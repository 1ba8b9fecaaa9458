// collision_world_node: one stc::World ticking over ROS. See docs/ros_interface.md.
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/world_node.hpp"

#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "collision_world_node");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<stc_ros::WorldNode> node;
  try {
    node = std::make_unique<stc_ros::WorldNode>(nh, pnh);
  } catch (const stc::InputError& e) {
    // A bad parameter or scene is reported by name; running on a guess would hide it.
    ROS_FATAL("invalid ~%s: %s", e.field().c_str(), stc_ros::reasonOf(e).c_str());
    return 1;
  }
  ros::spin();
  return 0;
}
