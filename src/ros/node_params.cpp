#include "sphere_tree_collision/ros/node_params.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/param_reading.hpp"

#include <climits>
#include <cmath>
#include <set>

namespace stc_ros {
namespace {

using stc::InputError;

// Every private parameter the node reads; others are reported as unknown.
const std::set<std::string>& knownParams() {
  static const std::set<std::string> kNames{
      "scene", "scene_entities", "scene_seed", "entity_size", "world_frame", "rate", "marker_rate", "marker_levels", "marker_mode", "marker_keyframe_period", "show_voxels", "static_tree_markers", "publish_tf",
      "max_contact_markers", "contact_marker_size", "detection_budget", "sphere_test_budget", "tick_budget", "scheduler", "queue_count", "queue_ratio",
      "unresolved_policy", "max_entities", "max_voxels", "tree_levels", "sphere_fit", "gravity",
      "response", "solver_iterations", "gaze_timeout", "default_resolution", "camera_frame", "published_camera_frame",
      "camera_position", "camera_look_at", "camera_width", "camera_height", "camera_fov_y",
      "max_speed", "max_spin", "world_extent", "min_density", "max_density", "max_friction", "max_gravity",
      "min_voxel_size", "max_voxel_size", "entity_states_rate", "publish_clock",
      "min_piece_voxels", "small_pieces"};
  return kNames;
}

// Re-raises a core parse error under the parameter's own name.
template <typename F>
auto parsed(const std::string& name, F&& parse) {
  try {
    return parse();
  } catch (const InputError& e) {
    throw InputError(name, reasonOf(e));
  }
}

}  // namespace

stc::Budget NodeParams::budget() const {
  stc::Budget b;
  if (detection_budget_ms >= 0.0) b.seconds = detection_budget_ms * 1e-3;
  if (sphere_test_budget >= 0) b.sphere_tests = sphere_test_budget;
  if (tick_budget_ms > 0.0) b.tick_seconds = tick_budget_ms * 1e-3;
  return b;
}

NodeParams readNodeParams(const ros::NodeHandle& nh) {
  NodeParams p;
  readParam(nh, "scene", p.scene);
  p.scene_entities = intParamIn(nh, "scene_entities", p.scene_entities, 0, 1000000);
  p.scene_seed = static_cast<std::uint32_t>(intParamIn(nh, "scene_seed", static_cast<int>(p.scene_seed), 0, INT_MAX));
  p.scene_entity_size = positiveParam(nh, "entity_size", p.scene_entity_size);
  readParam(nh, "world_frame", p.world_frame);
  if (p.world_frame.empty()) throw InputError("world_frame", "must not be empty");
  p.rate = positiveParam(nh, "rate", p.rate);
  if (p.rate > 10000.0 || p.rate < 0.01) throw InputError("rate", "must be in [0.01, 10000] Hz");
  p.marker_rate = positiveParam(nh, "marker_rate", p.marker_rate);
  p.entity_states_rate = positiveParam(nh, "entity_states_rate", p.entity_states_rate);
  readParam(nh, "publish_clock", p.publish_clock);
  if (readParam(nh, "marker_levels", p.marker_levels)) {
    for (int level : p.marker_levels) {
      if (level < 0 || level > 7) throw InputError("marker_levels", "levels must be in [0, 7]");
    }
  }
  readParam(nh, "show_voxels", p.show_voxels);
  readParam(nh, "static_tree_markers", p.static_tree_markers);
  readParam(nh, "publish_tf", p.publish_tf);
  p.marker_keyframe_period = nonNegativeParam(nh, "marker_keyframe_period", p.marker_keyframe_period);
  std::string mode = "auto";
  readParam(nh, "marker_mode", mode);
  if (mode == "full" || (mode == "auto" && !p.publish_tf)) {
    p.marker_mode = NodeParams::MarkerMode::Full;
  } else if (mode == "incremental" || mode == "auto") {
    if (!p.publish_tf) throw InputError("marker_mode", "incremental markers move with tf: it needs ~publish_tf");
    p.marker_mode = NodeParams::MarkerMode::Incremental;
  } else {
    throw InputError("marker_mode", "unknown value '" + mode + "' (expected one of: auto, incremental, full)");
  }
  p.max_contact_markers = intParamIn(nh, "max_contact_markers", p.max_contact_markers, 0, 1000000);
  p.contact_marker_size = positiveParam(nh, "contact_marker_size", p.contact_marker_size);

  readParam(nh, "detection_budget", p.detection_budget_ms);
  if (std::isnan(p.detection_budget_ms)) throw InputError("detection_budget", "is NaN");
  int sphere_tests = -1;
  if (readParam(nh, "sphere_test_budget", sphere_tests)) p.sphere_test_budget = sphere_tests;
  if (p.sphere_test_budget < -1) throw InputError("sphere_test_budget", "must be >= 0, or -1 for none");
  p.tick_budget_ms = nonNegativeParam(nh, "tick_budget", p.tick_budget_ms);

  std::string name = "priority_queues";
  readParam(nh, "scheduler", name);
  p.world.scheduler.kind = parsed("scheduler", [&] { return stc::parseScheduler(name); });
  p.world.scheduler.queue_count = intParamIn(nh, "queue_count", p.world.scheduler.queue_count, 1, 64);
  p.world.scheduler.queue_ratio = positiveParam(nh, "queue_ratio", p.world.scheduler.queue_ratio);
  stc::validateSchedulerOptions(p.world.scheduler);  // its fields are named as the parameters
  name = "accept";
  readParam(nh, "unresolved_policy", name);
  p.world.unresolved_policy = parsed("unresolved_policy", [&] { return stc::parseUnresolvedPolicy(name); });
  name = "tight";
  readParam(nh, "sphere_fit", name);
  p.world.tree.fit = parsed("sphere_fit", [&] { return stc::parseSphereFit(name); });
  p.world.tree.max_levels = intParamIn(nh, "tree_levels", p.world.tree.max_levels, 1, 8);
  // Fracture of bodies spawned with a strength (docs/fracture.md).
  p.world.fracture.min_piece_voxels =
      intParamIn(nh, "min_piece_voxels", p.world.fracture.min_piece_voxels, 1, INT_MAX);
  name = "attach";
  readParam(nh, "small_pieces", name);
  p.world.fracture.small_pieces = parsed("small_pieces", [&] { return stc::parseSmallPieces(name); });

  p.world.max_entities = static_cast<std::size_t>(
      intParamIn(nh, "max_entities", static_cast<int>(p.world.max_entities), 1, 10000000));
  int max_voxels = static_cast<int>(p.world.voxel_limits.max_voxels);
  p.world.voxel_limits.max_voxels = intParamIn(nh, "max_voxels", max_voxels, 1, 1 << 30);
  stc::PhysicalLimits& limits = p.world.limits;
  limits.max_speed = positiveParam(nh, "max_speed", limits.max_speed);
  limits.max_spin = positiveParam(nh, "max_spin", limits.max_spin);
  limits.world_extent = positiveParam(nh, "world_extent", limits.world_extent);
  limits.min_density = positiveParam(nh, "min_density", limits.min_density);
  limits.max_density = positiveParam(nh, "max_density", limits.max_density);
  limits.max_friction = positiveParam(nh, "max_friction", limits.max_friction);
  limits.max_gravity = positiveParam(nh, "max_gravity", limits.max_gravity);
  stc::validateLimits(limits);  // its fields are named as the parameters
  stc::VoxelLimits& voxels = p.world.voxel_limits;
  voxels.min_voxel_size = positiveParam(nh, "min_voxel_size", voxels.min_voxel_size);
  voxels.max_voxel_size = positiveParam(nh, "max_voxel_size", voxels.max_voxel_size);
  if (voxels.min_voxel_size > voxels.max_voxel_size) {
    throw InputError("min_voxel_size", "is above ~max_voxel_size " + std::to_string(voxels.max_voxel_size));
  }
  p.gravity = vec3Param(nh, "gravity");
  if (p.gravity) stc::validateGravity(*p.gravity, limits);
  readParam(nh, "response", p.world.response.enabled);
  p.world.response.iterations = intParamIn(nh, "solver_iterations", p.world.response.iterations, 1, 1000);
  parsed("solver_iterations", [&] { stc::validateResponseOptions(p.world.response); return 0; });

  p.gaze_timeout = positiveParam(nh, "gaze_timeout", p.gaze_timeout);
  int resolution = static_cast<int>(p.default_resolution);
  p.default_resolution = static_cast<std::uint32_t>(intParamIn(nh, "default_resolution", resolution, 1, 4096));

  readParam(nh, "camera_frame", p.camera.frame);
  readParam(nh, "published_camera_frame", p.camera.published_frame);
  if (auto v = vec3Param(nh, "camera_position")) {
    p.camera.position = *v;
    p.camera.pose_given = true;
  }
  if (auto v = vec3Param(nh, "camera_look_at")) {
    p.camera.look_at = *v;
    p.camera.pose_given = true;
  }
  p.camera.width = intParamIn(nh, "camera_width", p.camera.width, 1, 100000);
  p.camera.height = intParamIn(nh, "camera_height", p.camera.height, 1, 100000);
  p.camera.fov_y_deg = positiveParam(nh, "camera_fov_y", p.camera.fov_y_deg);
  if (p.camera.fov_y_deg < 0.01 || p.camera.fov_y_deg >= 180.0) {
    throw InputError("camera_fov_y", "must be in [0.01, 180) degrees");
  }
  parsed("camera_look_at", [&] { return stc::opticalLookAt(p.camera.position, p.camera.look_at); });
  return p;
}

std::vector<std::string> unknownParams(const ros::NodeHandle& nh) {
  std::vector<std::string> all, unknown;
  nh.getParamNames(all);
  const std::string prefix = nh.getNamespace() + "/";
  for (const std::string& full : all) {
    if (full.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = full.substr(prefix.size());
    const std::string top = rest.substr(0, rest.find('/'));
    if (knownParams().count(top) == 0) unknown.push_back(top);
  }
  return unknown;
}

}  // namespace stc_ros
