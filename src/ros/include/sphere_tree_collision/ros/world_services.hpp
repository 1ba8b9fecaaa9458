// WorldServices: the world node's services, in its private namespace. Each answers
// success and, on failure, "<field>: <reason>"; nothing changes on failure.
//   ~spawn (Spawn): the spawn topic's path, with the pose and twist in header.frame_id
//     (tf to ~world_frame); answers the id and tf frame. It is served on a thread of
//     its own, so its wait for tf never holds the ticks; the spawn itself is made on
//     the node's spinner, between ticks, as every other change to the world.
//   ~despawn (DespawnEntity): by name, else by id.
//   ~clear, ~pause, ~unpause, ~reset (std_srvs/Trigger): reset rebuilds the start scene
//     (~scene as the parameter server holds it at the call: a saved world, say).
//   ~save (SaveWorld): the world as a scene file in ~save_dir, written atomically.
//   ~step (Step): while paused, queues n ticks and answers at once with the tick
//     number tick_stats reaches when they are done.
#pragma once

#include "sphere_tree_collision/ros/world_control.hpp"

#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <ros/spinner.h>
#include <sphere_tree_collision/DespawnEntity.h>
#include <sphere_tree_collision/SaveWorld.h>
#include <sphere_tree_collision/Spawn.h>
#include <sphere_tree_collision/Step.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace stc_ros {


class WorldServices {
 public:
  // Advertises the services; ~spawn's thread is started by start(), once the
  // node is whole (a call must not wait on a node that never spins).
  WorldServices(ros::NodeHandle& private_nh, WorldControl& node);
  ~WorldServices();
  void start() { spawn_spinner_.start(); }

 private:
  bool spawn(sphere_tree_collision::Spawn::Request& req, sphere_tree_collision::Spawn::Response& res);
  bool despawn(sphere_tree_collision::DespawnEntity::Request& req, sphere_tree_collision::DespawnEntity::Response& res);
  bool clear(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool pause(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool unpause(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool reset(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool step(sphere_tree_collision::Step::Request& req, sphere_tree_collision::Step::Response& res);
  bool save(sphere_tree_collision::SaveWorld::Request& req, sphere_tree_collision::SaveWorld::Response& res);
  // The request's entity with its pose and twist in ~world_frame; throws InputError("header.frame_id").
  sphere_tree_collision::SpawnEntity inWorldFrame(const sphere_tree_collision::Spawn::Request& req);
  // Runs `work` on the node's spinner, between ticks, and waits for it; throws
  // what `work` threw, or when the node stops first. For the services served
  // on their own thread.
  void onTickThread(std::function<void()> work) const;

  WorldControl& node_;
  const std::string world_frame_;  // the node's, copied: read on ~spawn's thread
  std::atomic<bool> stopping_{false};
  // Created at the first spawn in another frame: the node's own /tf is not read otherwise.
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::WallTime tf_since_;  // when the listener above started
  ros::CallbackQueue spawn_queue_;  // ~spawn's calls, served by spawn_spinner_
  std::vector<ros::ServiceServer> servers_;
  ros::AsyncSpinner spawn_spinner_;  // last: stopped first, before the servers and the queue go
};

}  // namespace stc_ros
