// EntityStatePublisher: what a client needs to name and follow entities.
//   ~entities (EntityList, latched): id, name, frame, shape key, static flag of each
//     entity, republished after entities were added or removed;
//   ~entity_states (EntityStates): poses and twists of all entities, shaped like
//     gazebo_msgs/ModelStates, built only while subscribed.
#pragma once

#include "sphere_tree_collision/world.hpp"

#include <ros/ros.h>
#include <sphere_tree_collision/EntityStates.h>

#include <string>
#include <unordered_map>

namespace stc_ros {

class EntityStatePublisher {
 public:
  using Frames = std::unordered_map<stc::EntityId, std::string>;

  void advertise(ros::NodeHandle& private_nh, const std::string& world_frame);
  // An entity was added or removed: the list goes out at the next publishListIfChanged.
  void markChanged() { changed_ = true; }
  void publishListIfChanged(const stc::World& world, const Frames& frames, const ros::Time& stamp);
  void publishStates(const stc::World& world, const Frames& frames, const ros::Time& stamp);

 private:
  std::string world_frame_;
  bool changed_ = true;
  ros::Publisher list_pub_, states_pub_;
  sphere_tree_collision::EntityStates states_msg_;  // reused: no allocation per message once warm
};

}  // namespace stc_ros
