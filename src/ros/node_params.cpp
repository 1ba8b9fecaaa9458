#include "sphere_tree_collision/ros/node_params.hpp"

#include "sphere_tree_collision/mesh_loader.hpp"
#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/param_reading.hpp"
#include "sphere_tree_collision/ros/tick_budget_rule.hpp"

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <cmath>
#include <set>
#include <sstream>

namespace stc_ros {
namespace {

using stc::InputError;

// Every private parameter the node reads; others are reported as unknown.
const std::set<std::string>& knownParams() {
  static const std::set<std::string> kNames{
      "scene", "scene_entities", "scene_seed", "entity_size", "world_frame", "rate", "marker_rate", "marker_levels", "marker_mode", "marker_keyframe_period", "show_voxels", "static_tree_markers", "static_voxel_markers", "publish_tf",
      "max_contact_markers", "contact_marker_size", "detection_budget", "sphere_test_budget", "tick_budget", "scheduler", "queue_count", "queue_ratio",
      "unresolved_policy", "max_entities", "max_voxels", "tree_levels", "sphere_fit", "gravity",
      "response", "solver_iterations", "gaze_timeout", "default_resolution", "default_density", "default_voxel_size", "camera_frame", "published_camera_frame",
      "camera_position", "camera_look_at", "camera_width", "camera_height", "camera_fov_y",
      "max_speed", "max_spin", "world_extent", "min_density", "max_density", "max_friction", "max_gravity",
      "min_voxel_size", "max_voxel_size", "entity_states_rate", "entities_rate", "publish_clock", "error_report",
      "min_piece_voxels", "small_pieces", "strength_exponent", "threads", "reuse_tolerance", "solver",
      "diagnostic_period", "camera_info_topic", "mesh_roots", "max_mesh_bytes", "max_mesh_vertices",
      "max_mesh_triangles", "save_dir", "autosave_period"};  // diagnostic_period: read by diagnostic_updater
  return kNames;
}

// Re-raises a core parse error under the parameter's own name.
template <typename F>
auto parsed(const std::string& name, F&& parse) {
  try {
    return parse();
  } catch (const InputError& e) {
    throw InputError(name, e.reason());
  }
}

}  // namespace

std::string defaultSaveDir() {
  const char* ros_home = std::getenv("ROS_HOME");
  if (ros_home != nullptr && ros_home[0] == '/') return std::string(ros_home) + "/sphere_tree_collision";
  const char* home = std::getenv("HOME");
  if (home != nullptr && home[0] == '/') return std::string(home) + "/.ros/sphere_tree_collision";
  return "/tmp/sphere_tree_collision";
}

stc::Budget NodeParams::budget(double publish_s) const {
  stc::Budget b;
  if (detection_budget_ms >= 0.0) b.seconds = detection_budget_ms * 1e-3;
  if (sphere_test_budget >= 0) b.sphere_tests = sphere_test_budget;
  b.tick_seconds = tickBudgetSeconds(tick_budget_ms, 1.0 / rate, publish_s);
  return b;
}

std::uint64_t ticksPerMessage(double tick_rate, double message_rate) {
  return std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::lround(tick_rate / message_rate)));
}

TunableParams tunableOf(const NodeParams& p) {
  TunableParams t;
  t.detection_budget = p.detection_budget_ms;
  t.sphere_test_budget = static_cast<int>(p.sphere_test_budget);
  t.tick_budget = p.tick_budget_ms;
  t.scheduler = stc::toString(p.world.scheduler.kind);
  t.queue_count = p.world.scheduler.queue_count;
  t.queue_ratio = p.world.scheduler.queue_ratio;
  t.unresolved_policy = stc::toString(p.world.unresolved_policy);
  t.response = p.world.response.enabled;
  t.solver_iterations = p.world.response.iterations;
  t.marker_levels = p.marker_levels;
  t.show_voxels = p.show_voxels;
  t.marker_rate = p.marker_rate;
  t.gaze_timeout = p.gaze_timeout;
  return t;
}

void applyTunable(const TunableParams& t, NodeParams& params) {
  NodeParams p = params;
  if (std::isnan(t.detection_budget)) throw InputError("detection_budget", "is NaN");
  p.detection_budget_ms = t.detection_budget;
  if (t.sphere_test_budget < -1) throw InputError("sphere_test_budget", "must be >= 0, or -1 for none");
  p.sphere_test_budget = t.sphere_test_budget;
  p.tick_budget_ms = checkedTickBudgetMs(t.tick_budget);

  p.world.scheduler.kind = parsed("scheduler", [&] { return stc::parseScheduler(t.scheduler); });
  p.world.scheduler.queue_count = requireIn("queue_count", t.queue_count, 1, 64);
  p.world.scheduler.queue_ratio = requirePositive("queue_ratio", t.queue_ratio);
  stc::validateSchedulerOptions(p.world.scheduler);  // its fields are named as the parameters
  p.world.unresolved_policy = parsed("unresolved_policy", [&] { return stc::parseUnresolvedPolicy(t.unresolved_policy); });

  p.world.response.enabled = t.response;
  p.world.response.iterations = requireIn("solver_iterations", t.solver_iterations, 1, 1000);
  parsed("solver_iterations", [&] { stc::validateResponseOptions(p.world.response); return 0; });

  for (int level : t.marker_levels) {
    if (level < 0 || level > 7) throw InputError("marker_levels", "levels must be in [0, 7]");
  }
  p.marker_levels = t.marker_levels;
  p.show_voxels = t.show_voxels;
  p.marker_rate = requirePositive("marker_rate", t.marker_rate);
  p.gaze_timeout = requirePositive("gaze_timeout", t.gaze_timeout);
  params = std::move(p);
}

std::vector<int> parseMarkerLevels(const std::string& text) {
  std::string spaced = text;  // "1,2", "1 2" and "[1, 2]" alike
  std::replace_if(spaced.begin(), spaced.end(), [](char c) { return c == ',' || c == '[' || c == ']'; }, ' ');
  std::vector<int> levels;
  std::istringstream in(spaced);
  std::string token;
  while (in >> token) {
    std::size_t used = 0;
    int level = -1;
    try {
      level = std::stoi(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size()) throw InputError("marker_levels", "'" + token + "' is not a level number");
    levels.push_back(level);
  }
  return levels;
}

std::string formatMarkerLevels(const std::vector<int>& levels) {
  std::string text;
  for (int level : levels) text += (text.empty() ? "" : ",") + std::to_string(level);
  return text;
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
  p.entity_states_rate = positiveParam(nh, "entity_states_rate", p.entity_states_rate);
  p.entities_rate = positiveParam(nh, "entities_rate", p.entities_rate);
  readParam(nh, "publish_clock", p.publish_clock);
  readParam(nh, "static_tree_markers", p.static_tree_markers);
  readParam(nh, "static_voxel_markers", p.static_voxel_markers);
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

  TunableParams t = tunableOf(p);  // the defaults
  readParam(nh, "detection_budget", t.detection_budget);
  readParam(nh, "sphere_test_budget", t.sphere_test_budget);
  readParam(nh, "tick_budget", t.tick_budget);
  readParam(nh, "scheduler", t.scheduler);
  readParam(nh, "queue_count", t.queue_count);
  readParam(nh, "queue_ratio", t.queue_ratio);
  readParam(nh, "unresolved_policy", t.unresolved_policy);
  readParam(nh, "response", t.response);
  readParam(nh, "solver_iterations", t.solver_iterations);
  std::string levels;  // a list, or text once live tuning has written it back
  if (nh.getParam("marker_levels", levels)) {
    t.marker_levels = parseMarkerLevels(levels);
  } else {
    readParam(nh, "marker_levels", t.marker_levels);
  }
  readParam(nh, "show_voxels", t.show_voxels);
  readParam(nh, "marker_rate", t.marker_rate);
  readParam(nh, "gaze_timeout", t.gaze_timeout);
  applyTunable(t, p);

  std::string name = "tight";
  readParam(nh, "sphere_fit", name);
  p.world.tree.fit = parsed("sphere_fit", [&] { return stc::parseSphereFit(name); });
  p.world.tree.max_levels = intParamIn(nh, "tree_levels", p.world.tree.max_levels, 1, 8);
  // Fracture of bodies spawned with a strength (docs/fracture.md).
  p.world.fracture.min_piece_voxels =
      intParamIn(nh, "min_piece_voxels", p.world.fracture.min_piece_voxels, 1, INT_MAX);
  name = "attach";
  readParam(nh, "small_pieces", name);
  p.world.fracture.small_pieces = parsed("small_pieces", [&] { return stc::parseSmallPieces(name); });
  p.world.fracture.strength_exponent = nonNegativeParam(nh, "strength_exponent", p.world.fracture.strength_exponent);

  // Threads of the tick: 0 = every core; checked as WorldConfig::threads is.
  readParam(nh, "threads", p.world.threads);
  stc::validateThreads(p.world.threads);
  // A resting pair's contacts carried over (0 = off; docs/response.md).
  double reuse = p.world.response.reuse_tolerance;
  readParam(nh, "reuse_tolerance", reuse);
  if (!(reuse >= 0.0 && reuse <= 1.0)) throw InputError("reuse_tolerance", "must be in [0, 1]");
  p.world.response.reuse_tolerance = reuse;
  std::string solver = stc::toString(p.world.response.solver);
  readParam(nh, "solver", solver);
  p.world.response.solver = parsed("solver", [&] { return stc::parseSolverKind(solver); });
  p.world.max_entities = static_cast<std::size_t>(
      intParamIn(nh, "max_entities", static_cast<int>(p.world.max_entities), 1, 10000000));
  // Folders file:// and path meshes may be read from (none: package:// only).
  std::vector<std::string> roots;
  readParam(nh, "mesh_roots", roots);
  p.world.mesh_roots = stc::canonicalMeshRoots(roots, "mesh_roots");
  // The one folder ~save writes into (a file name, never a path: docs/ros_interface.md).
  p.save_dir = defaultSaveDir();
  readParam(nh, "save_dir", p.save_dir);
  stc::validateText(p.save_dir, "save_dir");
  if (p.save_dir.empty() || p.save_dir[0] != '/') throw InputError("save_dir", "must be an absolute path");
  readParam(nh, "autosave_period", p.autosave_period);
  if (!std::isfinite(p.autosave_period) || p.autosave_period < 0.0) {
    throw InputError("autosave_period", "must be a finite number of seconds >= 0 (0: no autosave)");
  }
  stc::MeshLimits& mesh = p.world.mesh_limits;  // what a mesh file may hold (docs/meshes.md)
  mesh.max_mesh_bytes = intParamIn(nh, "max_mesh_bytes", static_cast<int>(mesh.max_mesh_bytes), 1, INT_MAX);
  mesh.max_mesh_vertices =
      intParamIn(nh, "max_mesh_vertices", static_cast<int>(mesh.max_mesh_vertices), 1, INT_MAX);
  mesh.max_mesh_triangles =
      intParamIn(nh, "max_mesh_triangles", static_cast<int>(mesh.max_mesh_triangles), 1, INT_MAX);
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
  readParam(nh, "error_report", p.error_report);  // opened (and so checked) by ErrorReport
  p.defaults.resolution = intParamIn(nh, "default_resolution", p.defaults.resolution, 1, 4096);
  p.defaults.density = positiveParam(nh, "default_density", p.defaults.density);
  if (!(p.defaults.density >= limits.min_density && p.defaults.density <= limits.max_density)) {
    throw InputError("default_density", "must be within [~min_density, ~max_density]");
  }
  p.defaults.voxel_size = positiveParam(nh, "default_voxel_size", p.defaults.voxel_size);
  try {
    stc::validateVoxelSize(p.defaults.voxel_size, voxels);
  } catch (const InputError& e) {
    throw InputError("default_voxel_size", e.reason());
  }

  readParam(nh, "camera_frame", p.camera.frame);
  readParam(nh, "published_camera_frame", p.camera.published_frame);
  readParam(nh, "camera_info_topic", p.camera.info_topic);
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
