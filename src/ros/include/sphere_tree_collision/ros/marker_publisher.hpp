// MarkerPublisher: the world node's marker topics, `markers` (the scene) and
// `error_bounds` (the proven gap bound of each contact accepted unresolved,
// ErrorBoundMarkers). Decides when an array goes out (every
// round(~rate / ~marker_rate) ticks, each topic only while subscribed),
// and, in incremental mode, what each subscriber already has: entities sent,
// removals and a clear not yet sent, a snapshot for each new subscriber and a
// keyframe to all every ~marker_keyframe_period. MarkerBuilder makes the
// markers; this class does the bookkeeping (as costmap_2d's publisher keeps
// it out of the costmap). The node calls onTick once per tick and tells it
// what left the world.
#pragma once

#include "sphere_tree_collision/ros/error_bound_markers.hpp"
#include "sphere_tree_collision/ros/marker_builder.hpp"
#include "sphere_tree_collision/ros/node_params.hpp"
#include "sphere_tree_collision/world.hpp"

#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace stc_ros {

// What the node keeps per entity that the World does not: colour and tf frame.
struct EntityLooks {
  const std::unordered_map<stc::EntityId, Rgba>& colors;
  const std::unordered_map<stc::EntityId, std::string>& frames;
};

class MarkerPublisher {
 public:
  using GazeSource = std::function<std::optional<stc::Vec3>()>;
  // Runs a callback from outside the tick (a subscriber connecting), catching
  // and counting what it throws.
  using Guard = std::function<void(const char* what, const std::function<void()>& callback)>;

  // Advertises `markers` and `error_bounds` on nh. world and looks must outlive this.
  MarkerPublisher(ros::NodeHandle& nh, const NodeParams& params, const stc::World& world, EntityLooks looks,
                  GazeSource gaze, Guard guard);

  // After tick number `tick` (1 for the first), whose report is `report`:
  // arrays when it is a marker tick.
  void onTick(std::uint64_t tick, const stc::TickReport& report, const ros::Time& stamp);
  // An entity left the world (despawn, quarantine): its markers go with the next array.
  void entityRemoved(stc::EntityId id, stc::ShapeId shape, bool is_static);
  // The world was cleared: the next array starts with DELETEALL.
  void worldCleared();
  // Live tuning: marker rate, levels and voxels shown. New levels or voxels
  // redraw every entity (the next array starts with DELETEALL).
  void retune(const NodeParams& next);
  // After a large removal: the message buffers cut to what they hold.
  void releaseMemory();

 private:
  void publish(const ros::Time& stamp);
  void publishBounds(const stc::TickReport& report, const ros::Time& stamp);
  // Incremental mode: the whole scene (DELETEALL first), to one new subscriber
  // or, as a keyframe, to every subscriber (then it resets what is pending).
  void sendSnapshot(const ros::SingleSubscriberPublisher& subscriber);
  void buildSnapshot(const ros::Time& stamp, bool for_everyone, visualization_msgs::MarkerArray& out);

  const stc::World& world_;
  EntityLooks looks_;
  GazeSource gaze_;
  NodeParams::MarkerMode mode_;
  double keyframe_period_s_;
  std::uint64_t ticks_per_marker_ = 1;

  MarkerBuilder builder_;
  MarkerOptions options_;
  // Incremental mode: entities whose geometry every subscriber has, removals
  // not yet sent, and a clear not yet sent.
  struct Removed {
    stc::EntityId id;
    stc::ShapeId shape;
    bool is_static;
  };
  std::unordered_set<stc::EntityId> sent_;
  std::vector<Removed> removed_;
  bool cleared_ = false;
  ros::WallTime last_keyframe_;
  ros::Time last_stamp_;  // of the last tick: a snapshot shows its state (physics time with ~publish_clock)
  std::vector<Rgba> colors_by_index_;  // full mode: scratch
  visualization_msgs::MarkerArray msg_;  // reused: no allocation per tick once warm
  ros::Publisher pub_;

  ErrorBoundMarkers bounds_;
  ErrorBoundOptions bound_options_;
  visualization_msgs::MarkerArray bounds_msg_;
  ros::Publisher bounds_pub_;
};

}  // namespace stc_ros
