#include "sphere_tree_collision/ros/entity_state_publisher.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/entity_display.hpp"

#include <sphere_tree_collision/EntityList.h>

namespace stc_ros {
namespace {

const std::string& frameOf(const EntityStatePublisher::Frames& frames, stc::EntityId id, std::string& fallback) {
  const auto it = frames.find(id);
  if (it != frames.end()) return it->second;
  fallback = entityFrame(id, "");
  return fallback;
}

}  // namespace

void EntityStatePublisher::advertise(ros::NodeHandle& private_nh, const std::string& world_frame,
                                     std::uint64_t beats_per_list) {
  world_frame_ = world_frame;
  beats_per_list_ = beats_per_list;
  list_pub_ = private_nh.advertise<sphere_tree_collision::EntityList>("entities", 1, true);
  states_pub_ = private_nh.advertise<sphere_tree_collision::EntityStates>("entity_states", 10);
  changed_ = true;
}

void EntityStatePublisher::publishListIfChanged(const stc::World& world, const Frames& frames, const ros::Time& stamp,
                                                std::uint64_t beat) {
  if (!changed_ || !list_pub_) return;
  if (last_list_beat_ && beat < *last_list_beat_ + beats_per_list_) return;  // sent at the next beat due
  changed_ = false;
  last_list_beat_ = beat;
  sphere_tree_collision::EntityList list;
  list.header.stamp = stamp;
  list.header.frame_id = world_frame_;
  const auto& ids = world.entityIds();
  list.entities.resize(ids.size());
  std::string fallback;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    auto& e = list.entities[i];
    e.id = ids[i];
    e.name = world.bodyNames()[i];
    e.frame = frameOf(frames, ids[i], fallback);
    e.shape = world.shape(world.bodyShapes()[i]).key;
    e.is_static = world.bodies()[i].is_static;
    e.inertia = toInertiaMsg(world.bodies()[i]);
  }
  list_pub_.publish(list);
}

void EntityStatePublisher::publishStates(const stc::World& world, const Frames& frames, const ros::Time& stamp) {
  if (!states_pub_ || states_pub_.getNumSubscribers() == 0) return;
  auto& m = states_msg_;
  m.header.stamp = stamp;
  m.header.frame_id = world_frame_;
  const auto& ids = world.entityIds();
  const auto& bodies = world.bodies();
  const std::size_t n = ids.size();
  m.names.resize(n);
  m.ids.resize(n);
  m.poses.resize(n);
  m.twists.resize(n);
  std::string fallback;
  for (std::size_t i = 0; i < n; ++i) {
    m.names[i] = frameOf(frames, ids[i], fallback);
    m.ids[i] = ids[i];
    m.poses[i] = toPoseMsg(bodies[i].pose);
    m.twists[i].linear = toVector3Msg(bodies[i].linear_velocity);
    m.twists[i].angular = toVector3Msg(bodies[i].angular_velocity);
  }
  states_pub_.publish(m);
}

void EntityStatePublisher::releaseMemory() {
  states_msg_.names.shrink_to_fit();
  states_msg_.ids.shrink_to_fit();
  states_msg_.poses.shrink_to_fit();
  states_msg_.twists.shrink_to_fit();
}

}  // namespace stc_ros
