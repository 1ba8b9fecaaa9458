// RockfallSpawner: the paper's scenario as a stream of spawn messages. Drops a
// rock at ~rate per second at a random point of the box [~region_min,
// ~region_max] (by default above the upper ravine of the built-in "rockfall"
// scene), moving downhill at ~speed along ~direction, tumbling. Rock shapes
// cycle through ~shape_count seeds so the world shares their trees. Beyond
// ~max_rocks the oldest rock is despawned; after ~count drops (0: never) it
// stops, and the pile comes to rest. Breaking is not modelled.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <ros/ros.h>

#include <deque>
#include <random>
#include <string>

namespace stc_ros {

class RockfallSpawner {
 public:
  // Throws stc::InputError naming the parameter.
  RockfallSpawner(ros::NodeHandle nh, ros::NodeHandle private_nh);

 private:
  void drop();

  stc::Vec3 region_min_, region_max_, direction_;
  double speed_ = 1.0, size_ = 0.4, density_ = 2500.0, restitution_ = 0.3, friction_ = 0.6;
  double strength_ = 0.0;  // ~strength, N s: 0 = unbreakable
  int resolution_ = 8, shape_count_ = 4, max_rocks_ = 60;
  std::uint32_t seed_ = 1;
  std::uint64_t dropped_ = 0;
  std::uint64_t count_ = 0;  // rocks to drop in all (0: no end)
  std::deque<std::string> live_;  // names of the rocks spawned, oldest first
  std::mt19937 random_;
  ros::Publisher spawn_, despawn_;
  ros::SteadyTimer timer_;
};

}  // namespace stc_ros
