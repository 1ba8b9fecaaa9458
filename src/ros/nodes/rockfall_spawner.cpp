// rockfall_spawner: rocks dropping into the ravine at a set rate. See
// include/sphere_tree_collision/ros/rockfall_spawner.hpp and docs/ros_interface.md.
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/rockfall_spawner.hpp"

#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "rockfall_spawner");
  // Kept for the whole run: when the last NodeHandle goes, ROS shuts down
  // (and a start-up error could no longer be logged).
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<stc_ros::RockfallSpawner> node;
  try {
    node = std::make_unique<stc_ros::RockfallSpawner>(nh, pnh);
  } catch (const stc::InputError& e) {
    ROS_FATAL("rockfall_spawner: invalid ~%s: %s", e.field().c_str(), stc_ros::reasonOf(e).c_str());
    return 1;
  }
  ros::spin();
  return 0;
}
