// The collision_world_node's parameters, read and validated in one place.
// Every parameter is documented (name, default, meaning) in docs/ros_interface.md.
#pragma once

#include "sphere_tree_collision/scene/entity_request.hpp"
#include "sphere_tree_collision/world.hpp"

#include <ros/node_handle.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace stc_ros {

struct CameraParams {
  std::string frame;                                // tf frame (optical: z forward, x right, y down); "" = use pose below
  stc::Vec3 position = stc::Vec3(0.0, -2.6, 1.55);   // world frame, used without a frame or while tf has none
  stc::Vec3 look_at = stc::Vec3(0.0, 0.0, 0.5);
  std::string published_frame = "perception_camera";  // camera pose on /tf_static when not from tf; "" = off
  std::string info_topic;  // sensor_msgs/CameraInfo giving size and field of view; "" = the parameters below
  bool pose_given = false;  // camera_position or camera_look_at set: a built-in scene's camera is not used
  int width = 1280;
  int height = 720;
  double fov_y_deg = 60.0;
};

struct NodeParams {
  std::string scene;                 // YAML file, built-in scene name, or "" = embedded default
  std::string save_dir;              // ~save writes files here only (absolute; made on the first save)
  double autosave_period = 0.0;      // s of physics time between saves to ~save_dir/autosave.yaml (0: none)
  int scene_entities = 0;            // built-in scenes: movable entities (0: the scene's default)
  std::uint32_t scene_seed = 1;      // built-in scenes
  double scene_entity_size = 0.4;    // built-in scenes: metres
  std::string world_frame = "world";
  double rate = 60.0;                // Hz, ticks
  double marker_rate = 10.0;         // Hz
  double entity_states_rate = 10.0;  // Hz, ~entity_states (only while subscribed)
  double entities_rate = 10.0;       // Hz, ~entities at most (only when the entity set changed)
  bool publish_clock = false;        // ticks on the wall clock, stamps with physics time, which goes on /clock
  std::vector<int> marker_levels{1, 2};
  // incremental: entity geometry sent once per entity, frame-locked in its tf
  // frame (new subscribers get a snapshot); full: everything re-sent in the
  // world frame at every marker tick. auto = incremental when ~publish_tf.
  enum class MarkerMode { Incremental, Full } marker_mode = MarkerMode::Incremental;
  double marker_keyframe_period = 2.0;  // s, incremental mode: full snapshot this often (0: never)
  bool show_voxels = true;
  bool static_tree_markers = true;
  bool static_voxel_markers = true;  // false: static entities drawn as the box around their voxels
  bool publish_tf = true;
  int max_contact_markers = 2000;
  double contact_marker_size = 0.04;  // m
  double detection_budget_ms = 8.0;  // < 0: none
  std::int64_t sphere_test_budget = -1;  // < 0: none
  double tick_budget_ms = 0.0;       // whole tick (integrate .. response); 0: 1/rate less publishing, -1: none (tick_budget_rule.hpp)
  double gaze_timeout = 0.5;         // s
  // ~default_resolution, ~default_density, ~default_voxel_size: what spawns and
  // scene entries left at 0 (or out) get.
  stc::RequestDefaults defaults;
  std::optional<stc::Vec3> gravity;  // overrides the scene's
  std::string error_report;          // CSV file, a row per tick (ErrorReport); "" = none
  stc::WorldConfig world;            // scheduler, policy, tree, limits, response
  CameraParams camera;

  // The step's budgets, the tick's with the node's publishing measured at publish_s.
  stc::Budget budget(double publish_s) const;
};

// What may change while the node runs (dynamic_reconfigure, cfg/World.cfg),
// as the parameters spell it. Start-up and live tuning both go through
// applyTunable: one check for both.
struct TunableParams {
  double detection_budget;  // ms
  int sphere_test_budget;
  double tick_budget;  // ms
  std::string scheduler;
  int queue_count;
  double queue_ratio;
  std::string unresolved_policy;
  bool response;
  int solver_iterations;
  std::vector<int> marker_levels;
  bool show_voxels;
  double marker_rate;  // Hz
  double gaze_timeout;  // s
};
TunableParams tunableOf(const NodeParams& params);
// Checks `t` and writes it into `params`; throws stc::InputError named after
// the parameter and leaves `params` unchanged.
void applyTunable(const TunableParams& t, NodeParams& params);
// ~marker_levels as text ("1,2" or "1 2"), as dynamic_reconfigure carries it;
// throws InputError("marker_levels").
std::vector<int> parseMarkerLevels(const std::string& text);
std::string formatMarkerLevels(const std::vector<int>& levels);

// Throws stc::InputError whose field is the parameter name (e.g. "rate").
NodeParams readNodeParams(const ros::NodeHandle& private_nh);

// ~save_dir's default: $ROS_HOME/sphere_tree_collision, else
// $HOME/.ros/sphere_tree_collision (where ROS keeps its own files).
std::string defaultSaveDir();

// A message every this many ticks: round(tick rate / message rate), at least 1
// (markers, entity states).
std::uint64_t ticksPerMessage(double tick_rate, double message_rate);

// Private parameters the node does not know (likely typos), for a warning.
std::vector<std::string> unknownParams(const ros::NodeHandle& private_nh);

}  // namespace stc_ros
