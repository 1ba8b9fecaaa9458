#include "sphere_tree_collision/ros/world_node.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/entity_display.hpp"
#include "sphere_tree_collision/ros/mesh_resource.hpp"
#include "sphere_tree_collision/scene/scene_file.hpp"
#include "sphere_tree_collision/ros/tick_fields.hpp"
#include "sphere_tree_collision/perception_ray.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <optional>

namespace stc_ros {
namespace {

const char* const kInputTopics[] = {"spawn", "despawn", "gaze", "clicked_point"};
const Rgba kWallColor{0.55f, 0.57f, 0.6f, 1.0f};

// ~save's file: a plain name in ~save_dir, never a path (no '/', so nothing
// outside the folder; no leading '.', so no hidden or '..' files).
void validateSaveFileName(const std::string& file) {
  if (file.size() > 128) throw stc::InputError("file", "longer than 128 characters");
  for (char c : file) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) throw stc::InputError("file", "'" + file + "' may hold only letters, digits, '_', '-' and '.' (a name in ~save_dir)");
  }
  const std::string suffix = ".yaml";
  if (file[0] == '.' || file.size() <= suffix.size() || file.compare(file.size() - suffix.size(), suffix.size(), suffix) != 0) {
    throw stc::InputError("file", "'" + file + "' must end with .yaml and not start with '.'");
  }
}

// A path or a .yaml name is a scene file; anything else names a built-in scene.
bool isSceneFile(const std::string& scene) {
  const auto endsWith = [&](const std::string& suffix) {
    return scene.size() >= suffix.size() && scene.compare(scene.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return scene.find('/') != std::string::npos || endsWith(".yaml") || endsWith(".yml");
}

stc::Camera cameraAt(const CameraParams& params, const stc::Pose& pose) {
  stc::Camera camera;
  camera.camera_to_world = pose;
  camera.width = params.width;
  camera.height = params.height;
  camera.fov_y_deg = params.fov_y_deg;
  return camera;
}

// What an exception caught by catch (...) says.
std::string causeOf(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "an exception that is not a std::exception";
  }
}

bool isFinite(const stc::Contact& c) {
  return c.point.allFinite() && c.normal.allFinite() && std::isfinite(c.depth) && std::isfinite(c.gap_bound) &&
         std::isfinite(c.priority);
}

// Unknown names are warned about first: a typo may be why a value is missing.
NodeParams readParamsWarningUnknown(const ros::NodeHandle& private_nh) {
  for (const std::string& name : unknownParams(private_nh)) {
    ROS_WARN("unknown parameter ~%s is ignored", name.c_str());
  }
  return readNodeParams(private_nh);
}

}  // namespace

WorldNode::WorldNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : nh_(nh), pnh_(private_nh), params_(readParamsWarningUnknown(private_nh)), clock_(nh_, params_.publish_clock) {
  const stc::Pose camera_pose = loadScene();
  world_.perception().setCamera(cameraAt(params_.camera, camera_pose));
  if (!params_.camera.frame.empty()) {
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh_);
  } else if (!params_.camera.published_frame.empty()) {
    // Companion nodes (gaze_simulator's follow mode) and users find the camera in tf.
    geometry_msgs::TransformStamped t;
    t.header.stamp = ros::Time::now();
    t.header.frame_id = params_.world_frame;
    t.child_frame_id = params_.camera.published_frame;
    t.transform.translation = toVector3Msg(camera_pose.position);
    t.transform.rotation = toQuaternionMsg(camera_pose.orientation);
    camera_tf_ = t;
  }
  // One latched /tf_static message holds every static frame, the camera's and
  // the static entities'; it is sent again whole when they change.
  if (camera_tf_ || params_.publish_tf) {
    tf_static_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf_static", 100, true);
    publishStaticFrames(ros::Time::now());
  }
  camera_info_ = std::make_unique<PerceptionCameraInfo>(
      nh_, pnh_, world_, params_.camera.frame.empty() ? params_.camera.published_frame : params_.camera.frame,
      params_.camera.info_topic);
  budget_ = params_.budget(publish_cost_.seconds());
  dt_ = 1.0 / params_.rate;
  if (!params_.error_report.empty()) error_report_ = std::make_unique<ErrorReport>(params_.error_report);
  markers_ = std::make_unique<MarkerPublisher>(
      pnh_, params_, world_, EntityLooks{colors_, frames_}, [this] { return gazePoint(); },
      [this](const char* what, const std::function<void()>& callback) { guarded(what, callback); });
  quarantined_pub_ = pnh_.advertise<sphere_tree_collision::Quarantined>("quarantined", 100);
  contacts_pub_ = pnh_.advertise<sphere_tree_collision::ContactArray>("contacts", 10);
  // The node's topics are private (~name); /tf and /clicked_point are the shared ones.
  // tick_stats last but /tf: smoke.test waits for tick_stats, then expects the rest advertised.
  stats_pub_ = pnh_.advertise<sphere_tree_collision::TickStats>("tick_stats", 10);
  if (params_.publish_tf) tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);
  // A burst of spawns or despawns up to ~max_entities waits whole for the spinner:
  // a shorter queue drops the oldest while a long tick runs (a flood of 10,000
  // lost 4,700 with 1,000 here).
  const auto flood_queue = static_cast<std::uint32_t>(params_.world.max_entities);
  spawn_sub_ = pnh_.subscribe("spawn", flood_queue, &WorldNode::onSpawn, this);
  despawn_sub_ = pnh_.subscribe("despawn", flood_queue, &WorldNode::onDespawn, this);
  clear_sub_ = pnh_.subscribe("clear", 10, &WorldNode::onClear, this);
  gaze_sub_ = pnh_.subscribe("gaze", 10, &WorldNode::onGaze, this);
  clicked_sub_ = nh_.subscribe("/clicked_point", 10, &WorldNode::onClickedPoint, this);

  ticks_per_states_ = ticksPerMessage(params_.rate, params_.entity_states_rate);
  entity_states_.advertise(pnh_, params_.world_frame, ticksPerMessage(params_.rate, params_.entities_rate));
  services_ = std::make_unique<WorldServices>(pnh_, *this);
  clock_.start(nh_, dt_, [this] { tick(); });
  ROS_INFO("collision_world_node: %zu entities from %s, %.1f Hz, scheduler %s, budget %s ms / %s sphere tests, "
           "tick budget %s ms",
           world_.entityCount(), params_.scene.empty() ? "the default scene" : params_.scene.c_str(),
           params_.rate, stc::toString(params_.world.scheduler.kind),
           params_.detection_budget_ms < 0 ? "none" : std::to_string(params_.detection_budget_ms).c_str(),
           params_.sphere_test_budget < 0 ? "no limit" : std::to_string(params_.sphere_test_budget).c_str(),
           params_.tick_budget_ms > 0   ? std::to_string(params_.tick_budget_ms).c_str()
           : params_.tick_budget_ms == 0 ? "1/~rate less publishing"
                                         : "none");
  diagnostics_ = std::make_unique<NodeDiagnostics>(nh_, pnh_, params_);
  tuning_ = std::make_unique<LiveTuning>(pnh_, params_, [this](const NodeParams& next) { retune(next); });
  services_->start();  // last: nothing after it can throw
}

void WorldNode::retune(const NodeParams& next) {
  world_.setScheduler(next.world.scheduler);  // the only step that can throw: first
  world_.setResponse(next.world.response);  // checked by applyTunable already
  world_.setUnresolvedPolicy(next.world.unresolved_policy);
  budget_ = next.budget(publish_cost_.seconds());
  markers_->retune(next);
  diagnostics_->retune(next);
  params_ = next;
}

void WorldNode::remember(stc::EntityId id, const std::string& name, const std::optional<Rgba>& color) {
  colors_[id] = color ? *color : paletteColor(id);
  frames_[id] = entityFrame(id, name);
  entity_states_.markChanged();
  const auto index = world_.indexOf(id);
  if (index && world_.bodies()[*index].is_static) static_frames_changed_ = true;
}

stc::Pose WorldNode::loadScene() {
  stc::WorldConfig config = params_.world;
  stc::Pose camera_pose = stc::opticalLookAt(params_.camera.position, params_.camera.look_at);
  if (params_.scene.empty() || isSceneFile(params_.scene)) {
    stc::Scene scene;
    try {
      scene = params_.scene.empty() ? stc::parseSceneYaml(stc::defaultSceneYaml()) : stc::loadSceneYaml(params_.scene);
    } catch (const stc::InputError& e) {
      throw stc::InputError(e.field() == "scene" ? "scene" : "scene " + e.field(), e.reason());
    }
    config.gravity = params_.gravity ? *params_.gravity : scene.gravity;
    try {
      world_ = stc::World(config);  // checks the scene's gravity against ~max_gravity
    } catch (const stc::InputError& e) {
      throw stc::InputError("scene " + e.field(), e.reason());
    }
    std::vector<stc::EntityId> ids;
    try {
      ids = stc::addScene(world_, scene, params_.defaults, resolveMeshResource);
    } catch (const stc::InputError& e) {
      throw stc::InputError("scene " + e.field(), e.reason());
    }
    for (std::size_t i = 0; i < ids.size(); ++i) {
      remember(ids[i], scene.entities[i].request.spec.name, scene.entities[i].request.color);
    }
    return camera_pose;
  }

  // A built-in scene of the core (scenes.hpp), by name.
  stc::SceneKind kind{};
  try {
    kind = stc::parseScene(params_.scene);
  } catch (const stc::InputError& e) {
    throw stc::InputError("scene", e.reason() + ", or a YAML file path");
  }
  config.gravity = params_.gravity ? *params_.gravity : stc::sceneGravity(kind);
  world_ = stc::World(config);
  stc::SceneParams scene_params;
  scene_params.entities = params_.scene_entities;
  scene_params.seed = params_.scene_seed;
  scene_params.entity_size = params_.scene_entity_size;
  stc::SceneSpec spec;
  try {
    spec = stc::populateScene(world_, kind, scene_params);
  } catch (const stc::InputError& e) {
    const std::string field = e.field() == "entities" ? "scene_entities" : e.field() == "entity_size" ? "entity_size" : e.field();
    throw stc::InputError(field, e.reason() + " (scene " + params_.scene + ")");
  }
  for (stc::EntityId id : spec.walls) remember(id, "", kWallColor);
  for (stc::EntityId id : spec.movers) remember(id, "", std::nullopt);
  return params_.camera.pose_given ? camera_pose : spec.camera.camera_to_world;
}

// ---------------------------------------------------------------------------------
// Tick

template <typename F>
void WorldNode::guarded(const char* what, F&& callback) {
  try {
    callback();
  } catch (...) {
    ++callback_errors_;
    ROS_ERROR_THROTTLE(5.0, "%s failed: %s (%llu caught so far; the node goes on)", what,
                       causeOf(std::current_exception()).c_str(), static_cast<unsigned long long>(callback_errors_));
  }
}

void WorldNode::tick() {
  ++beats_;
  if (paused_ && steps_pending_ == 0) {
    guarded("entity list", [this] { publishEntityList(); });  // inputs still change the world while paused
    releaseFreedMemory();
    return;
  }
  if (steps_pending_ > 0) --steps_pending_;
  guarded("tick", [this] { runTick(); });
  releaseFreedMemory();
}

// After the world shrank to half its peak, by at least 1,000 entities (at the
// end of a tick: this tick's buffers are sized for what is left), the arrays
// and messages sized for the peak are cut to size, and glibc hands the freed
// heap back (it keeps it for the process otherwise). A flood of 10,000
// spawns and despawns left the resident set at 2.7 x its level before with
// neither, 2.0-2.1 x with malloc_trim alone (docs/results.md). The heap is
// trimmed again kRetrimTicks later: by then the messages of the peak (the
// latched entity list, the publishers' queues) were replaced and freed.
void WorldNode::releaseFreedMemory() {
  constexpr std::size_t kMinDrop = 1000;
  constexpr std::uint32_t kRetrimTicks = 10;
  if (retrim_in_ > 0 && --retrim_in_ == 0) malloc_trim(0);
  const std::size_t n = world_.entityCount();
  peak_entities_ = std::max(peak_entities_, n);
  if (peak_entities_ < n + kMinDrop || 2 * n > peak_entities_) return;
  peak_entities_ = n;
  retrim_in_ = kRetrimTicks;
  world_.releaseMemory();
  markers_->releaseMemory();
  entity_states_.releaseMemory();
  contacts_msg_.contacts.shrink_to_fit();
  tf_msg_.transforms.shrink_to_fit();
  colors_.rehash(0);
  frames_.rehash(0);
  malloc_trim(0);
}

void WorldNode::setPaused(bool paused) {
  paused_ = paused;
  steps_pending_ = 0;
}

std::uint64_t WorldNode::queueSteps(std::uint32_t n) {
  steps_pending_ += n;
  return tick_ + steps_pending_;
}

void WorldNode::runTick() {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const ros::Time now = clock_.beginTick(dt_);
  if (camera_from_tf_ || tf_buffer_) updateCameraFromTf();
  expireGaze(now);
  budget_ = params_.budget(publish_cost_.seconds());  // ~tick_budget 0: 1/~rate less the node's own work
  const Clock::time_point step_start = Clock::now();
  const stc::TickReport report = world_.step(dt_, budget_);
  const Clock::time_point step_end = Clock::now();
  ++tick_;
  for (const stc::BrokenEntity& b : world_.broken()) onBroken(b);
  for (const stc::QuarantinedEntity& q : world_.quarantined()) onQuarantined(q, now);
  autosave();  // before tick_stats: a reader that sees the tick finds its autosave written
  publishStats(report, now);
  if (error_report_) {
    error_report_->write(stats_msg_, world_.perception().fixation());
  }
  publishContacts(now);
  publishTf(now);
  markers_->onTick(tick_, report, now);
  entity_states_.publishListIfChanged(world_, frames_, now, beats_);
  if (tick_ % ticks_per_states_ == 0) entity_states_.publishStates(world_, frames_, now);
  ROS_INFO_THROTTLE(1.0,
                    "tick %llu: %zu entities, %zu broad pairs, %zu colliding, %zu unresolved (%zu accepted), "
                    "%lld sphere tests, %zu contacts, %.2f ms, gaze %s, %llu rejected inputs",
                    static_cast<unsigned long long>(tick_), report.bodies.entities, report.detection.broad_pairs,
                    report.detection.colliding, report.detection.unresolved, report.detection.unresolved_accepted,
                    static_cast<long long>(report.detection.sphere_tests), report.response.contacts,
                    report.phases.total_s * 1e3, world_.perception().hasFixation() ? "on" : "off",
                    static_cast<unsigned long long>(rejected_[0] + rejected_[1] + rejected_[2] + rejected_[3]));
  // Everything of the tick but the step is the node's own work (mostly publishing).
  publish_cost_.add(std::chrono::duration<double>((step_start - start) + (Clock::now() - step_end)).count(), dt_);
}

void WorldNode::onQuarantined(const stc::QuarantinedEntity& q, const ros::Time& stamp) {
  const auto frame = frames_.find(q.id);
  const std::string name = frame != frames_.end() ? frame->second : entityFrame(q.id, q.name);
  const bool left = q.reason == stc::Quarantine::LeftWorld;
  ++(left ? left_world_total_ : quarantined_total_);
  last_quarantine_ = name + ": " + stc::toString(q.reason);
  if (left) {
    ROS_INFO_THROTTLE(1.0, "removed %s: left the world (|coordinate| > ~world_extent %g m)", name.c_str(),
                      params_.world.limits.world_extent);
  } else {
    ROS_WARN_THROTTLE(1.0, "quarantined %s: %s (%llu so far)", name.c_str(), stc::toString(q.reason),
                      static_cast<unsigned long long>(quarantined_total_));
  }
  if (quarantined_pub_.getNumSubscribers() > 0) {
    sphere_tree_collision::Quarantined msg;
    msg.header.stamp = stamp;
    msg.header.frame_id = params_.world_frame;
    msg.id = q.id;
    msg.frame = name;
    msg.reason = stc::toString(q.reason);
    quarantined_pub_.publish(msg);
  }
  forget(q.id, q.shape, false);  // static bodies never move, so are never quarantined
}

// The pieces of a broken body get its colour and frames of their own names
// (markers and tf follow them as any entity); the parent's markers go.
void WorldNode::onBroken(const stc::BrokenEntity& broken) {
  const auto color = colors_.find(broken.id);
  const std::optional<Rgba> parent_color =
      color != colors_.end() ? std::optional<Rgba>(color->second) : std::nullopt;
  for (const stc::EntityId piece : broken.pieces) {
    const auto index = world_.indexOf(piece);
    if (index) remember(piece, world_.bodyNames()[*index], parent_color);  // a piece may be quarantined already
  }
  forget(broken.id, broken.shape, false);
}

void WorldNode::forget(stc::EntityId id, stc::ShapeId shape, bool is_static) {
  markers_->entityRemoved(id, shape, is_static);
  colors_.erase(id);
  frames_.erase(id);
  entity_states_.markChanged();
  if (is_static) static_frames_changed_ = true;
}

void WorldNode::updateCameraFromTf() {
  try {
    const auto t = tf_buffer_->lookupTransform(params_.world_frame, params_.camera.frame, ros::Time(0));
    stc::Camera camera = world_.perception().camera();  // its size may come from ~camera_info_topic
    camera.camera_to_world = toPose(t.transform);
    world_.perception().setCamera(camera);
    if (!camera_from_tf_) ROS_INFO("camera pose now from tf frame '%s'", params_.camera.frame.c_str());
    camera_from_tf_ = true;
  } catch (const tf2::TransformException& e) {
    ROS_WARN_THROTTLE(5.0, "camera frame '%s' not in tf (%s): using %s", params_.camera.frame.c_str(), e.what(),
                      camera_from_tf_ ? "its last pose" : "~camera_position / ~camera_look_at");
  } catch (const stc::InputError& e) {
    ROS_WARN_THROTTLE(5.0, "camera frame '%s' rejected: %s", params_.camera.frame.c_str(), e.what());
  }
}

void WorldNode::expireGaze(const ros::Time& now) {
  if (world_.perception().hasFixation() && now.toSec() > gaze_expiry_s_) world_.perception().clearFixation();
}

void WorldNode::publishStats(const stc::TickReport& r, const ros::Time& stamp) {
  sphere_tree_collision::TickStats& s = stats_msg_;  // built every tick: diagnostics read it too
  s.header.stamp = stamp;
  s.header.frame_id = params_.world_frame;
  s.tick = tick_;
  fillFromReport(r, s);
  s.budget_ms = std::isfinite(budget_.seconds) ? budget_.seconds * 1e3 : -1.0;  // nothing non-finite is published
  s.budget_sphere_tests = params_.sphere_test_budget;
  s.scheduler = stc::toString(params_.world.scheduler.kind);
  s.period_ms = dt_ * 1e3;
  s.publish_ms = publish_cost_.seconds() * 1e3;  // not yet this tick's: the figure its budget came from
  s.rejected_spawn = rejected_[0];
  s.rejected_despawn = rejected_[1];
  s.rejected_gaze = rejected_[2];
  s.rejected_clicked_point = rejected_[3];
  s.rejected_inputs = rejected_[0] + rejected_[1] + rejected_[2] + rejected_[3];
  s.last_rejection = last_rejection_;
  s.gaze_active = world_.perception().hasFixation();
  s.quarantined_total = quarantined_total_;
  s.left_world_total = left_world_total_;
  s.last_quarantine = last_quarantine_;
  s.callback_errors = callback_errors_;
  s.physics_time = clock_.physicsSeconds();
  s.real_time_factor = clock_.realTimeFactor();
  s.paused = paused_;
  diagnostics_->onTick(s);
  if (stats_pub_.getNumSubscribers() > 0) stats_pub_.publish(s);
}

void WorldNode::publishContacts(const ros::Time& stamp) {
  if (contacts_pub_.getNumSubscribers() == 0) return;
  const auto& contacts = world_.contacts();
  contacts_msg_.header.stamp = stamp;
  contacts_msg_.header.frame_id = params_.world_frame;
  contacts_msg_.contacts.resize(contacts.size());
  std::size_t n = 0;
  for (const stc::Contact& c : contacts) {
    if (!isFinite(c)) continue;  // nothing non-finite is published
    auto& m = contacts_msg_.contacts[n++];
    m.entity_a = c.a;
    m.entity_b = c.b;
    m.name_a = frames_[c.a];
    m.name_b = frames_[c.b];
    m.point = toPointMsg(c.point);
    m.normal = toVector3Msg(c.normal);
    m.depth = c.depth;
    m.gap_bound = c.gap_bound;
    m.level = c.level;
    m.resolved = c.resolved;
    m.priority = c.priority;
  }
  contacts_msg_.contacts.resize(n);
  contacts_pub_.publish(contacts_msg_);
}

// Entity i's frame into t; false (t untouched) for a pose that is not finite
// (quarantine removed every such body: this only guards the topics).
bool WorldNode::entityTransform(std::size_t i, const ros::Time& stamp, geometry_msgs::TransformStamped& t) {
  const stc::BodyState& body = world_.bodies()[i];
  if (!body.pose.position.allFinite() || !body.pose.orientation.coeffs().allFinite()) return false;
  t.header.stamp = stamp;
  t.header.frame_id = params_.world_frame;
  t.child_frame_id = frames_[world_.entityIds()[i]];
  t.transform.translation = toVector3Msg(body.pose.position);
  t.transform.rotation = toQuaternionMsg(body.pose.orientation);
  return true;
}

// Moving entities on /tf each tick; the static ones on /tf_static, once and
// again when a static entity comes or goes (they never move): rviz spent 15 %
// of its time on the ~340 static walls' frames of the demo sent every tick.
void WorldNode::publishTf(const ros::Time& stamp) {
  if (static_frames_changed_) publishStaticFrames(stamp);
  if (!params_.publish_tf || tf_pub_.getNumSubscribers() == 0) return;
  const auto& bodies = world_.bodies();
  tf_msg_.transforms.resize(bodies.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (!bodies[i].is_static && entityTransform(i, stamp, tf_msg_.transforms[n])) ++n;
  }
  tf_msg_.transforms.resize(n);
  if (n != 0) tf_pub_.publish(tf_msg_);
}

void WorldNode::publishStaticFrames(const ros::Time& stamp) {
  static_frames_changed_ = false;
  if (!tf_static_pub_) return;
  tf2_msgs::TFMessage msg;
  if (camera_tf_) msg.transforms.push_back(*camera_tf_);
  if (params_.publish_tf) {
    geometry_msgs::TransformStamped t;
    for (std::size_t i = 0; i < world_.entityCount(); ++i) {
      if (world_.bodies()[i].is_static && entityTransform(i, stamp, t)) msg.transforms.push_back(t);
    }
  }
  tf_static_pub_.publish(msg);  // latched: a listener that comes later gets it too
}

std::optional<stc::Vec3> WorldNode::gazePoint() const { return stc::gazeTarget(world_); }

// ---------------------------------------------------------------------------------
// Inputs

void WorldNode::reject(Input input, const std::string& field, const std::string& reason) {
  const auto k = static_cast<std::size_t>(input);
  ++rejected_[k];
  last_rejection_ = std::string(kInputTopics[k]) + ": " + field + ": " + reason;
  ROS_ERROR("rejected %s message: %s: %s", kInputTopics[k], field.c_str(), reason.c_str());
}

void WorldNode::rejectUnexpected(Input input) {
  reject(input, "message", causeOf(std::current_exception()));
}

stc::EntityId WorldNode::spawnEntity(const sphere_tree_collision::SpawnEntity& msg) {
  const bool is_preset = !msg.preset.empty() || !msg.mesh_resource.empty();  // sized by resolution, not dims
  try {
    stc::EntityRequest request = toEntityRequest(msg);
    const std::string name = request.spec.name;
    const std::optional<Rgba> color = request.color;
    const stc::EntityId id = stc::addRequest(world_, std::move(request), params_.defaults, resolveMeshResource);
    remember(id, name, color);
    ROS_DEBUG("spawned entity %u (%s)", id, frames_[id].c_str());
    return id;
  } catch (const stc::InputError& e) {
    throw stc::InputError(spawnFieldOf(e.field(), is_preset), e.reason());
  }
}

void WorldNode::onSpawn(const sphere_tree_collision::SpawnEntity& msg) {
  try {
    spawnEntity(msg);
  } catch (const stc::InputError& e) {
    reject(Input::Spawn, e.field(), e.reason());
  } catch (...) {
    rejectUnexpected(Input::Spawn);
  }
}

void WorldNode::despawnEntity(stc::EntityId requested, const std::string& name) {
  std::optional<stc::EntityId> id;
  if (!name.empty()) {
    id = world_.findByName(name);
    if (!id && despawnPieces(name)) return;
    if (!id) throw stc::InputError("name", "no entity named '" + name + "'");
  } else {
    id = requested;
  }
  const auto index = world_.indexOf(*id);
  if (!index) throw stc::InputError("id", "no entity with id " + std::to_string(requested));
  const stc::ShapeId shape = world_.bodyShapes()[*index];
  const bool is_static = world_.bodies()[*index].is_static;
  world_.removeEntity(*id);
  forget(*id, shape, is_static);
}

// The name of a broken body despawns its pieces (named <name>/piece<k>, and
// theirs in turn): the rockfall spawner despawns its oldest rock by name.
bool WorldNode::despawnPieces(const std::string& name) {
  const std::string prefix = name + "/piece";
  std::vector<stc::EntityId> pieces;
  for (std::size_t i = 0; i < world_.entityCount(); ++i) {
    if (world_.bodyNames()[i].compare(0, prefix.size(), prefix) == 0) pieces.push_back(world_.entityIds()[i]);
  }
  for (const stc::EntityId piece : pieces) {
    const std::size_t index = *world_.indexOf(piece);
    const stc::ShapeId shape = world_.bodyShapes()[index];
    world_.removeEntity(piece);
    forget(piece, shape, false);  // pieces are never static
  }
  return !pieces.empty();
}

void WorldNode::onDespawn(const sphere_tree_collision::Despawn& msg) {
  try {
    despawnEntity(msg.id, msg.name);
  } catch (const stc::InputError& e) {
    reject(Input::Despawn, e.field(), e.reason());
  } catch (...) {
    rejectUnexpected(Input::Despawn);
  }
}

void WorldNode::onClear(const std_msgs::Empty&) {
  guarded("clear", [this] { clearWorld(); });
}

void WorldNode::clearWorld() {
  ROS_INFO("clear: removing %zu entities", world_.entityCount());
  world_.clear();
  colors_.clear();
  frames_.clear();
  markers_->worldCleared();
  entity_states_.markChanged();
  static_frames_changed_ = true;
}

void WorldNode::resetWorld() {
  // ~scene as the parameter server holds it now: set to a saved world, ~reset loads that.
  const std::string start_scene = params_.scene;
  std::string scene = params_.scene;
  pnh_.getParam("scene", scene);
  stc::validateText(scene, "scene");
  // Built beside the world it replaces: a scene that fails to load changes nothing.
  stc::World before = std::move(world_);
  auto colors_before = std::move(colors_);
  auto frames_before = std::move(frames_);
  colors_.clear();
  frames_.clear();
  params_.scene = scene;
  stc::Pose camera_pose;
  try {
    camera_pose = loadScene();  // a new World: the camera is set again (tf overrides it next tick)
  } catch (...) {
    world_ = std::move(before);
    colors_ = std::move(colors_before);
    frames_ = std::move(frames_before);
    params_.scene = start_scene;
    throw;
  }
  markers_->worldCleared();
  entity_states_.markChanged();
  static_frames_changed_ = true;
  world_.perception().setCamera(cameraAt(params_.camera, camera_pose));
  ROS_INFO("reset: %zu entities of %s", world_.entityCount(), scene.empty() ? "the default scene" : scene.c_str());
}

void WorldNode::autosave() {
  if (!(params_.autosave_period > 0.0)) return;
  const auto every = std::max<long long>(1, std::llround(params_.autosave_period / dt_));
  if (tick_ % static_cast<std::uint64_t>(every) != 0) return;
  guarded("autosave", [this] { writeWorld(kAutosaveFile); });
}

std::string WorldNode::saveWorld(const std::string& file) {
  const std::string path = writeWorld(file);
  ROS_INFO("save: %zu entities to %s", world_.entityCount(), path.c_str());
  return path;
}

std::string WorldNode::writeWorld(const std::string& file) {
  const std::string name = file.empty() ? "world.yaml" : file;
  validateSaveFileName(name);
  std::error_code error;
  std::filesystem::create_directories(params_.save_dir, error);
  if (error) throw stc::InputError("file", "cannot make ~save_dir '" + params_.save_dir + "': " + error.message());
  const std::string path = params_.save_dir + "/" + name;
  // Spawns and despawns since the last tick into the broad phase first, so
  // the file holds its pairs in their order (docs/ros_interface.md, Saved worlds).
  world_.settleBroadPhase();
  const std::string yaml = stc::writeSceneYaml(world_, [this](stc::EntityId id) -> std::optional<Rgba> {
    const auto color = colors_.find(id);
    return color == colors_.end() ? std::nullopt : std::optional<Rgba>(color->second);
  });
  stc::writeFileAtomically(path, yaml, "file");
  return path;
}

void WorldNode::setFixation(double x, double y, const ros::Time& stamp, const char* x_field, const char* y_field) {
  const stc::Camera& camera = world_.perception().camera();
  if (!std::isfinite(x)) throw stc::InputError(x_field, "not finite");
  if (!std::isfinite(y)) throw stc::InputError(y_field, "not finite");
  if (x < 0.0 || x > camera.width) {
    throw stc::InputError(x_field, "off screen: " + std::to_string(x) + " outside [0, " + std::to_string(camera.width) + "]");
  }
  if (y < 0.0 || y > camera.height) {
    throw stc::InputError(y_field, "off screen: " + std::to_string(y) + " outside [0, " + std::to_string(camera.height) + "]");
  }
  const ros::Time now = clock_.now();
  const double timeout = params_.gaze_timeout;
  const double age = checkedStampAge(stamp, now, timeout, timeout,
                                     "~gaze_timeout " + std::to_string(timeout) + " s");
  world_.perception().setFixation(stc::Vec2(x, y));
  gaze_expiry_s_ = now.toSec() - age + timeout;
}

void WorldNode::onGaze(const sphere_tree_collision::GazePoint& msg) {
  try {
    setFixation(msg.x, msg.y, msg.header.stamp, "x", "y");
  } catch (const stc::InputError& e) {
    reject(Input::Gaze, e.field(), e.reason());
  } catch (...) {
    rejectUnexpected(Input::Gaze);
  }
}

void WorldNode::onClickedPoint(const geometry_msgs::PointStamped& msg) {
  try {
    stc::Vec3 point = toEigen(msg.point);
    if (!point.allFinite()) throw stc::InputError("point", "not finite");
    if (!msg.header.frame_id.empty() && msg.header.frame_id != params_.world_frame) {
      if (!tf_buffer_) {
        throw stc::InputError("header.frame_id", "'" + msg.header.frame_id + "' is not ~world_frame '" +
                                                     params_.world_frame + "' (no tf listener without ~camera_frame)");
      }
      try {
        const auto t = tf_buffer_->lookupTransform(params_.world_frame, msg.header.frame_id, ros::Time(0));
        point = toPose(t.transform).apply(point);
      } catch (const tf2::TransformException& e) {
        throw stc::InputError("header.frame_id", e.what());
      }
    }
    const double extent = params_.world.limits.world_extent;
    if (!(point.cwiseAbs().maxCoeff() <= extent)) {  // in the world frame, after tf
      throw stc::InputError("point", "a coordinate is beyond ~world_extent " + std::to_string(extent) + " m");
    }
    const auto pixel = world_.perception().project(point);
    if (!pixel) throw stc::InputError("point", "behind the camera");
    setFixation(pixel->x(), pixel->y(), ros::Time(0), "point", "point");
  } catch (const stc::InputError& e) {
    reject(Input::ClickedPoint, e.field(), e.reason());
  } catch (...) {
    rejectUnexpected(Input::ClickedPoint);
  }
}

}  // namespace stc_ros
