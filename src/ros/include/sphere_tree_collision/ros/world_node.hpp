// WorldNode: the ROS face of one stc::World. Loads the scene, ticks the World
// on its TickClock (wall clock, /clock, or its own physics time), turns input
// messages and service calls (WorldServices) into World calls (rejecting bad ones
// by field name, counted in tick_stats) and World state into messages. Every
// algorithm lives in the core; this class is glue only. Single-threaded: all
// callbacks run from one spinner, so no locking. No callback throws: whatever
// escapes is logged, counted (tick_stats.callback_errors) and the node goes on.
#pragma once

#include "sphere_tree_collision/ros/entity_state_publisher.hpp"
#include "sphere_tree_collision/ros/error_report.hpp"
#include "sphere_tree_collision/ros/live_tuning.hpp"
#include "sphere_tree_collision/ros/marker_publisher.hpp"
#include "sphere_tree_collision/ros/node_diagnostics.hpp"
#include "sphere_tree_collision/ros/node_params.hpp"
#include "sphere_tree_collision/ros/perception_camera_info.hpp"
#include "sphere_tree_collision/ros/tick_budget_rule.hpp"
#include "sphere_tree_collision/ros/tick_clock.hpp"
#include "sphere_tree_collision/ros/world_control.hpp"
#include "sphere_tree_collision/ros/world_services.hpp"
#include "sphere_tree_collision/world.hpp"

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <sphere_tree_collision/ContactArray.h>
#include <sphere_tree_collision/Despawn.h>
#include <sphere_tree_collision/GazePoint.h>
#include <sphere_tree_collision/Quarantined.h>
#include <sphere_tree_collision/SpawnEntity.h>
#include <sphere_tree_collision/TickStats.h>
#include <std_msgs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <optional>
#include <string>
#include <unordered_map>

namespace stc_ros {

class WorldNode final : public WorldControl {
 public:
  // Throws stc::InputError naming the parameter or scene field: the caller
  // reports it and exits non-zero rather than run on a guess.
  WorldNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

  // One tick: camera, gaze expiry, World::step, quarantined bodies forgotten,
  // tick_stats / contacts / tf, and the markers' turn (MarkerPublisher). Never throws.
  void tick();

  const stc::World& world() const { return world_; }
  std::uint64_t tickCount() const override { return tick_; }

  // What the services (WorldControl) and the input topics do. The throwing
  // ones throw stc::InputError naming the message field and change nothing.
  stc::EntityId spawnEntity(const sphere_tree_collision::SpawnEntity& msg) override;  // pose in ~world_frame
  void despawnEntity(stc::EntityId id, const std::string& name) override;              // by name unless empty
  void clearWorld() override;
  std::string saveWorld(const std::string& file) override;
  void resetWorld() override;  // the start scene again (~scene); ticks and physics time go on
  void setPaused(bool paused) override;
  bool paused() const override { return paused_; }
  // Paused: n more ticks; returns the tick number reached after them.
  std::uint64_t queueSteps(std::uint32_t n) override;
  const std::string& frameOf(stc::EntityId id) const override { return frames_.at(id); }
  const std::string& worldFrame() const override { return params_.world_frame; }
  void publishEntityList() override { entity_states_.publishListIfChanged(world_, frames_, clock_.now(), beats_); }

 private:
  static constexpr const char* kAutosaveFile = "autosave.yaml";
  // Every ~autosave_period of physics time (whole ticks, at least one), the
  // world goes to kAutosaveFile in ~save_dir as ~save writes it: a crash
  // loses at most one period. A failed save is logged and the ticks go on.
  void autosave();
  // The world as a scene file `file` in ~save_dir, written atomically; its path.
  std::string writeWorld(const std::string& file);
  enum class Input { Spawn, Despawn, Gaze, ClickedPoint };
  void onSpawn(const sphere_tree_collision::SpawnEntity& msg);
  void onDespawn(const sphere_tree_collision::Despawn& msg);
  void onClear(const std_msgs::Empty& msg);
  void onGaze(const sphere_tree_collision::GazePoint& msg);
  void onClickedPoint(const geometry_msgs::PointStamped& msg);
  void reject(Input input, const std::string& field, const std::string& reason);
  // In a catch (...) after the InputError one: anything else is a rejection too.
  void rejectUnexpected(Input input);
  // Runs a timer or connection callback; logs and counts what it throws.
  template <typename F>
  void guarded(const char* what, F&& callback);
  void runTick();
  void releaseFreedMemory();
  void onQuarantined(const stc::QuarantinedEntity& q, const ros::Time& stamp);
  void onBroken(const stc::BrokenEntity& broken);
  bool despawnPieces(const std::string& name);
  // Drops what the node keeps of an entity the world no longer has.
  void forget(stc::EntityId id, stc::ShapeId shape, bool is_static);

  // Sets the fixation from a pixel stamped `stamp` (zero: now), or throws InputError.
  void setFixation(double x, double y, const ros::Time& stamp, const char* x_field, const char* y_field);
  void updateCameraFromTf();
  void expireGaze(const ros::Time& now);
  std::optional<stc::Vec3> gazePoint() const;  // where the gaze ray first meets the scene
  void remember(stc::EntityId id, const std::string& name, const std::optional<Rgba>& color);
  // Fills world_ from ~scene (YAML file, built-in scene name, or the default);
  // returns the camera pose to use when no tf frame gives one.
  stc::Pose loadScene();
  // Live tuning: checked parameters in effect from the next tick on.
  void retune(const NodeParams& next);

  void publishStats(const stc::TickReport& report, const ros::Time& stamp);
  void publishContacts(const ros::Time& stamp);
  void publishTf(const ros::Time& stamp);
  void publishStaticFrames(const ros::Time& stamp);
  bool entityTransform(std::size_t index, const ros::Time& stamp, geometry_msgs::TransformStamped& t);

  ros::NodeHandle nh_, pnh_;
  NodeParams params_;
  TickClock clock_;
  stc::World world_;
  stc::Budget budget_;  // this tick's (the tick budget follows publish_cost_ under ~tick_budget 0)
  PublishCost publish_cost_;  // the node's own work a tick
  double dt_ = 0.0;
  std::uint64_t tick_ = 0;
  std::uint64_t ticks_per_states_ = 1;
  std::size_t peak_entities_ = 0;  // most entities since memory was last handed back
  std::uint32_t retrim_in_ = 0;    // ticks to the heap's second trim after a release
  std::uint64_t beats_ = 0;  // timer callbacks: ticks and those while paused (~entities' rate)
  bool paused_ = false;
  std::uint64_t steps_pending_ = 0;  // paused: ticks ~step still asks for
  EntityStatePublisher entity_states_;
  std::unique_ptr<WorldServices> services_;

  // Per entity, by id: what the World does not keep.
  std::unordered_map<stc::EntityId, Rgba> colors_;
  std::unordered_map<stc::EntityId, std::string> frames_;

  // Gaze: valid until gaze_expiry_s_ (stamp of the last fixation + gaze_timeout),
  // seconds as a double: ros::Time arithmetic throws near the ends of its range.
  double gaze_expiry_s_ = 0.0;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;  // only with ~camera_frame
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  bool camera_from_tf_ = false;
  std::optional<geometry_msgs::TransformStamped> camera_tf_;  // on /tf_static, without ~camera_frame
  bool static_frames_changed_ = true;  // /tf_static is sent again at the next tick
  std::unique_ptr<PerceptionCameraInfo> camera_info_;  // ~camera_info, and ~camera_info_topic

  // Rejected inputs, total and per topic.
  std::uint64_t rejected_[4] = {0, 0, 0, 0};
  std::string last_rejection_;
  // Removed by the world at the end of a tick, and exceptions caught.
  std::uint64_t quarantined_total_ = 0, left_world_total_ = 0, callback_errors_ = 0;
  std::string last_quarantine_;

  std::unique_ptr<MarkerPublisher> markers_;  // made once the scene is loaded
  std::unique_ptr<ErrorReport> error_report_;  // with ~error_report only
  // Reused message buffers: no allocation per tick once warm.
  sphere_tree_collision::ContactArray contacts_msg_;
  tf2_msgs::TFMessage tf_msg_;
  sphere_tree_collision::TickStats stats_msg_;

  ros::Publisher contacts_pub_, stats_pub_, tf_pub_, tf_static_pub_, quarantined_pub_;
  ros::Subscriber spawn_sub_, despawn_sub_, clear_sub_, gaze_sub_, clicked_sub_;
  std::unique_ptr<LiveTuning> tuning_;
  std::unique_ptr<NodeDiagnostics> diagnostics_;
};

}  // namespace stc_ros
