#include "sphere_tree_collision/ros/marker_builder.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"

#include <algorithm>
#include <array>

namespace stc_ros {
namespace {

using visualization_msgs::Marker;

// Spheres whose radii differ by less than this ratio share one SPHERE_LIST,
// drawn at the group's largest radius (never smaller than the true sphere).
constexpr double kRadiusGroupRatio = 1.03;
// Coarse levels fainter than fine ones, so two levels drawn together both read.
float levelAlpha(int level) { return level <= 1 ? 0.3f : 0.5f; }
constexpr double kVoxelFill = 0.94;  // cubes a little smaller than the voxel: the grid shows
constexpr int kContactClasses = 4;   // contact sphere sizes, by priority relative to the tick's largest

std_msgs::ColorRGBA rgba(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

// One hue per level, so neighbouring levels read apart.
std_msgs::ColorRGBA levelColor(int level) {
  static const std::array<std::array<float, 3>, 8> kHues{{{1.0f, 1.0f, 1.0f},
                                                          {0.25f, 0.55f, 1.0f},
                                                          {0.1f, 1.0f, 0.75f},
                                                          {1.0f, 0.8f, 0.1f},
                                                          {1.0f, 0.3f, 0.3f},
                                                          {0.7f, 0.3f, 1.0f},
                                                          {0.2f, 0.9f, 0.9f},
                                                          {0.9f, 0.5f, 0.8f}}};
  const auto& h = kHues[static_cast<std::size_t>(level) % kHues.size()];
  return rgba(h[0], h[1], h[2], levelAlpha(level));
}

const std_msgs::ColorRGBA kResolvedColor = rgba(0.2f, 0.9f, 0.2f, 1.0f);
const std_msgs::ColorRGBA kUnresolvedColor = rgba(1.0f, 0.45f, 0.0f, 1.0f);
const std_msgs::ColorRGBA kGazeColor = rgba(1.0f, 0.1f, 0.9f, 0.9f);

void setPose(Marker& m, const stc::Pose& pose) {
  m.pose.position = toPointMsg(pose.position);
  m.pose.orientation = toQuaternionMsg(pose.orientation);
}

int contactClass(double priority, double max_priority) {
  if (!(max_priority > 0.0)) return 0;
  const double ratio = priority / max_priority;
  return ratio > 0.5 ? 3 : ratio > 0.2 ? 2 : ratio > 0.05 ? 1 : 0;
}

}  // namespace

const MarkerBuilder::ShapeGeometry& MarkerBuilder::geometry(const stc::World& world, stc::ShapeId id) {
  if (shapes_.size() <= id) shapes_.resize(id + 1);
  ShapeGeometry& g = shapes_[id];
  if (g.built) return g;
  const stc::ShapeInfo& info = world.shape(id);
  const stc::VoxelShape& v = info.voxels;
  const double s = v.voxelSize();
  for (int k = 0; k < v.nz(); ++k) {
    for (int j = 0; j < v.ny(); ++j) {
      for (int i = 0; i < v.nx(); ++i) {
        if (!v.isSurfaceVoxel(i, j, k)) continue;
        g.surface_voxels.push_back(toPointMsg(stc::Vec3(i + 0.5, j + 0.5, k + 0.5) * s - info.body_origin));
      }
    }
  }
  const stc::SphereTree& tree = info.tree;
  g.levels.resize(static_cast<std::size_t>(tree.levelCount()));
  std::vector<std::int32_t> nodes;
  for (int level = 0; level < tree.levelCount(); ++level) {
    nodes.clear();
    for (std::int32_t n = tree.levelBegin(level); n < tree.levelBegin(level + 1); ++n) nodes.push_back(n);
    std::sort(nodes.begin(), nodes.end(),
              [&](std::int32_t a, std::int32_t b) { return tree.node(a).radius < tree.node(b).radius; });
    auto& groups = g.levels[static_cast<std::size_t>(level)];
    double group_smallest = 0.0;
    for (std::int32_t n : nodes) {
      const stc::SphereNode& node = tree.node(n);
      if (groups.empty() || node.radius > group_smallest * kRadiusGroupRatio) {
        groups.emplace_back();
        group_smallest = node.radius;
      }
      groups.back().radius = std::max(groups.back().radius, node.radius);
      groups.back().centres.push_back(toPointMsg(node.centre));
    }
  }
  g.built = true;
  return g;
}

Marker& MarkerBuilder::next(visualization_msgs::MarkerArray& out, const std::string& ns, int type,
                            const ros::Time& stamp, const std::string& frame) {
  if (out.markers.size() <= used_) out.markers.resize(used_ + 1);
  Marker& m = out.markers[used_++];
  m.header.stamp = stamp;
  m.header.frame_id = frame;
  m.ns = ns;
  m.id = next_id_++;
  m.type = type;
  m.action = Marker::ADD;
  m.pose = geometry_msgs::Pose();
  m.pose.orientation.w = 1.0;
  m.scale = geometry_msgs::Vector3();
  m.color = std_msgs::ColorRGBA();
  m.lifetime = ros::Duration(0);
  m.frame_locked = false;
  m.points.clear();  // keeps capacity
  m.colors.clear();
  m.text.clear();
  return m;
}

void MarkerBuilder::build(const stc::World& world, const std::unordered_map<stc::EntityId, Rgba>& colors,
                          const MarkerOptions& options, const std::optional<stc::Vec3>& gaze_point,
                          const ros::Time& stamp, visualization_msgs::MarkerArray& out) {
  used_ = 0;
  next_id_ = 0;
  next(out, "", Marker::CUBE, stamp, options.frame).action = Marker::DELETEALL;

  const auto& ids = world.entityIds();
  const auto& bodies = world.bodies();
  const auto& shape_ids = world.bodyShapes();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const ShapeGeometry& g = geometry(world, shape_ids[i]);
    const double voxel = world.shape(shape_ids[i]).voxels.voxelSize();
    if (options.voxels) {
      Marker& m = next(out, "voxels", Marker::CUBE_LIST, stamp, options.frame);
      setPose(m, bodies[i].pose);
      m.scale.x = m.scale.y = m.scale.z = voxel * kVoxelFill;
      const auto c = colors.find(ids[i]);
      const Rgba color = c != colors.end() ? c->second : paletteColor(ids[i]);
      m.color = rgba(color[0], color[1], color[2], color[3]);
      m.points.assign(g.surface_voxels.begin(), g.surface_voxels.end());
    }
    for (int level : options.levels) {
      if (!options.static_trees && bodies[i].is_static) break;
      if (level < 0 || static_cast<std::size_t>(level) >= g.levels.size()) continue;
      if (level_ns_.size() <= static_cast<std::size_t>(level)) {
        for (int l = static_cast<int>(level_ns_.size()); l <= level; ++l) level_ns_.push_back("tree_level_" + std::to_string(l));
      }
      for (const RadiusGroup& group : g.levels[static_cast<std::size_t>(level)]) {
        Marker& m = next(out, level_ns_[static_cast<std::size_t>(level)], Marker::SPHERE_LIST, stamp, options.frame);
        setPose(m, bodies[i].pose);
        m.scale.x = m.scale.y = m.scale.z = 2.0 * group.radius;
        m.color = levelColor(level);
        m.points.assign(group.centres.begin(), group.centres.end());
      }
    }
  }
  addContacts(world, options, stamp, out);
  if (gaze_point) addGaze(*gaze_point, options, stamp, out);
  out.markers.resize(used_);
}

void MarkerBuilder::addContacts(const stc::World& world, const MarkerOptions& options, const ros::Time& stamp,
                                visualization_msgs::MarkerArray& out) {
  const auto& contacts = world.contacts();
  const std::size_t n = std::min(contacts.size(), options.max_contacts);
  if (n == 0) return;
  double max_priority = 0.0;
  for (std::size_t i = 0; i < n; ++i) max_priority = std::max(max_priority, contacts[i].priority);

  // Pointers into out.markers below: size it first so next() cannot reallocate.
  if (out.markers.size() < used_ + kContactClasses + 1) out.markers.resize(used_ + kContactClasses + 1);
  std::array<Marker*, kContactClasses> classes{};
  for (int k = 0; k < kContactClasses; ++k) {
    Marker& m = next(out, "contacts", Marker::SPHERE_LIST, stamp, options.frame);
    m.scale.x = m.scale.y = m.scale.z = options.contact_size * (1.0 + 0.7 * k);
    m.color = kResolvedColor;  // per-point colours below
    classes[static_cast<std::size_t>(k)] = &m;
  }
  Marker& normals = next(out, "contact_normals", Marker::LINE_LIST, stamp, options.frame);
  normals.scale.x = 0.25 * options.contact_size;
  normals.color = rgba(1.0f, 1.0f, 1.0f, 0.8f);
  const double normal_length = 3.0 * options.contact_size;
  for (std::size_t i = 0; i < n; ++i) {
    const stc::Contact& c = contacts[i];
    Marker& m = *classes[static_cast<std::size_t>(contactClass(c.priority, max_priority))];
    m.points.push_back(toPointMsg(c.point));
    m.colors.push_back(c.resolved ? kResolvedColor : kUnresolvedColor);
    normals.points.push_back(toPointMsg(c.point));
    normals.points.push_back(toPointMsg(c.point + normal_length * c.normal));
  }
  // rviz rejects empty lists: drop the classes nothing fell into.
  std::size_t write = used_ - kContactClasses - 1;
  for (std::size_t read = write; read < used_; ++read) {
    if (out.markers[read].points.empty()) continue;
    if (read != write) std::swap(out.markers[read], out.markers[write]);
    ++write;
  }
  used_ = write;
}

// Only the point: in a view matching the camera the ray from the eye would
// cover the screen.
void MarkerBuilder::addGaze(const stc::Vec3& gaze_point, const MarkerOptions& options, const ros::Time& stamp,
                            visualization_msgs::MarkerArray& out) {
  Marker& dot = next(out, "gaze", Marker::SPHERE, stamp, options.frame);
  dot.pose.position = toPointMsg(gaze_point);
  dot.scale.x = dot.scale.y = dot.scale.z = 3.0 * options.contact_size;
  dot.color = kGazeColor;
}

}  // namespace stc_ros
