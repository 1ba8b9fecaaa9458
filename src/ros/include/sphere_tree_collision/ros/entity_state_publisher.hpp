// EntityStatePublisher: what a client needs to name and follow entities.
//   ~entities (EntityList, latched): id, name, frame, shape key, static flag of each
//     entity, republished after entities were added or removed, at most once every
//     `beats_per_list` beats of the node's timer (~entities_rate), however fast
//     the world changes: a flood of spawns costs one list per period, not one each;
//   ~entity_states (EntityStates): poses and twists of all entities, shaped like
//     gazebo_msgs/ModelStates, built only while subscribed.
#pragma once

#include "sphere_tree_collision/world.hpp"

#include <ros/ros.h>
#include <sphere_tree_collision/EntityStates.h>

#include <cstdint>
#include <optional>
#include <string>
#include <unordered_map>

namespace stc_ros {

class EntityStatePublisher {
 public:
  using Frames = std::unordered_map<stc::EntityId, std::string>;

  void advertise(ros::NodeHandle& private_nh, const std::string& world_frame, std::uint64_t beats_per_list);
  // An entity was added or removed: the list goes out at the next publishListIfChanged
  // that comes `beats_per_list` beats or more after the last list.
  void markChanged() { changed_ = true; }
  // `beat`: the node's timer callbacks so far (ticks, and callbacks while paused).
  void publishListIfChanged(const stc::World& world, const Frames& frames, const ros::Time& stamp,
                            std::uint64_t beat);
  void publishStates(const stc::World& world, const Frames& frames, const ros::Time& stamp);
  // After a large removal: the states buffer cut to what it holds.
  void releaseMemory();

 private:
  std::string world_frame_;
  bool changed_ = true;
  std::uint64_t beats_per_list_ = 1;
  std::optional<std::uint64_t> last_list_beat_;  // none: no list sent yet
  ros::Publisher list_pub_, states_pub_;
  sphere_tree_collision::EntityStates states_msg_;  // reused: no allocation per message once warm
};

}  // namespace stc_ros
