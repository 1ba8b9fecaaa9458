// main() of every node: init, construct the node class from the node handles,
// report a bad parameter by name and exit 1, else spin.
#pragma once

#include "sphere_tree_collision/ros/conversions.hpp"

#include <ros/ros.h>

#include <memory>

namespace stc_ros {

template <typename Node>
int runNode(int argc, char** argv, const char* name) {
  ros::init(argc, argv, name);
  // Kept for the whole run: when the last NodeHandle goes, ROS shuts down
  // (and a start-up error could no longer be logged).
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  std::unique_ptr<Node> node;
  try {
    node = std::make_unique<Node>(nh, pnh);
  } catch (const stc::InputError& e) {
    // Running on a guess would hide the mistake.
    ROS_FATAL("%s: invalid ~%s: %s", name, e.field().c_str(), e.reason().c_str());
    return 1;
  }
  ros::spin();
  return 0;
}

}  // namespace stc_ros
