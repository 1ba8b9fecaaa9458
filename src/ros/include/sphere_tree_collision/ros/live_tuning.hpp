// LiveTuning: the world node's dynamic_reconfigure server (cfg/World.cfg) in its
// private namespace: budgets, scheduler, queues, unresolved policy, response,
// solver iterations, marker levels, voxels, marker rate and gaze timeout. A new
// configuration is checked by applyTunable, the check the start-up parameters
// pass. A valid one is handed to `apply`; an invalid one is refused whole: the
// reason is logged and the client gets back the configuration that was kept.
#pragma once

#include "sphere_tree_collision/ros/node_params.hpp"

#include <boost/thread/recursive_mutex.hpp>
#include <dynamic_reconfigure/server.h>
#include <ros/node_handle.h>
#include <sphere_tree_collision/WorldConfig.h>

#include <functional>

namespace stc_ros {

class LiveTuning {
 public:
  // Puts the new parameters into effect; may throw stc::InputError (then refused).
  using Apply = std::function<void(const NodeParams& next)>;

  // `current` is the node's parameters (read after each change, so it must
  // outlive this); the server starts from them, not from its cfg defaults.
  LiveTuning(const ros::NodeHandle& private_nh, const NodeParams& current, Apply apply);

 private:
  void onReconfigure(sphere_tree_collision::WorldConfig& config, std::uint32_t level);

  const NodeParams& current_;
  Apply apply_;
  boost::recursive_mutex mutex_;  // the server's; all callbacks run on one spinner anyway
  dynamic_reconfigure::Server<sphere_tree_collision::WorldConfig> server_;
};

}  // namespace stc_ros
