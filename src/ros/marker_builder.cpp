#include "sphere_tree_collision/ros/marker_builder.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace stc_ros {
namespace {

using visualization_msgs::Marker;

// Spheres whose radii differ by less than this ratio share one SPHERE_LIST,
// drawn at the group's largest radius (never smaller than the true sphere).
constexpr double kRadiusGroupRatio = 1.03;
// Coarse levels fainter than fine ones, so two levels drawn together both read;
// a level drawn alone is nearly opaque, so its bodies read as solid (the
// demo's: level 1 alone, the cheapest for rviz that still shows each rock),
// and contacts inside still show through.
float levelAlpha(int level, bool alone) { return alone ? 0.8f : level <= 1 ? 0.3f : 0.5f; }
constexpr double kVoxelFill = 0.94;  // cubes a little smaller than the voxel: the grid shows
constexpr int kMaxGroups = 512;      // radius groups per level and entity (marker id = entity id * 512 + group)

// One hue per level, so neighbouring levels read apart.
std_msgs::ColorRGBA levelColor(int level, bool alone) {
  static const std::array<std::array<float, 3>, 8> kHues{{{1.0f, 1.0f, 1.0f},
                                                          {0.25f, 0.55f, 1.0f},
                                                          {0.1f, 1.0f, 0.75f},
                                                          {1.0f, 0.8f, 0.1f},
                                                          {1.0f, 0.3f, 0.3f},
                                                          {0.7f, 0.3f, 1.0f},
                                                          {0.2f, 0.9f, 0.9f},
                                                          {0.9f, 0.5f, 0.8f}}};
  const auto& h = kHues[static_cast<std::size_t>(level) % kHues.size()];
  return toColorMsg(h[0], h[1], h[2], levelAlpha(level, alone));
}

const std_msgs::ColorRGBA kResolvedColor = toColorMsg(0.2f, 0.9f, 0.2f, 1.0f);
const std_msgs::ColorRGBA kUnresolvedColor = toColorMsg(1.0f, 0.45f, 0.0f, 1.0f);
const std_msgs::ColorRGBA kGazeColor = toColorMsg(1.0f, 0.1f, 0.9f, 0.9f);

void setPose(Marker& m, const stc::Pose& pose) {
  m.pose.position = toPointMsg(pose.position);
  m.pose.orientation = toQuaternionMsg(pose.orientation);
}

int contactClass(double priority, double max_priority) {
  if (!(max_priority > 0.0)) return 0;
  const double ratio = priority / max_priority;
  return ratio > 0.5 ? 3 : ratio > 0.2 ? 2 : ratio > 0.05 ? 1 : 0;
}

int groupId(stc::EntityId id, std::size_t group) {
  return static_cast<int>((static_cast<std::uint64_t>(id) * kMaxGroups + group) & 0x7fffffffu);
}

const std::string kContactsNs = "contacts", kNormalsNs = "contact_normals", kGazeNs = "gaze", kVoxelsNs = "voxels",
                  kStaticBoxesNs = "static_boxes";

}  // namespace

const MarkerBuilder::ShapeGeometry& MarkerBuilder::geometry(const stc::World& world, stc::ShapeId id) {
  if (shapes_.size() <= id) shapes_.resize(id + 1);
  ShapeGeometry& g = shapes_[id];
  if (g.built) return g;
  const stc::ShapeInfo& info = world.shape(id);
  const stc::VoxelShape& v = info.voxels;
  const double s = v.voxelSize();
  stc::Vec3 lo = stc::Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int k = 0; k < v.nz(); ++k) {
    for (int j = 0; j < v.ny(); ++j) {
      for (int i = 0; i < v.nx(); ++i) {
        if (!v.isSurfaceVoxel(i, j, k)) continue;
        const stc::Vec3 centre = stc::Vec3(i + 0.5, j + 0.5, k + 0.5) * s - info.body_origin;
        g.surface_voxels.push_back(toPointMsg(centre));
        lo = lo.cwiseMin(centre);
        hi = hi.cwiseMax(centre);
      }
    }
  }
  if (!g.surface_voxels.empty()) {
    g.box_centre = 0.5 * (lo + hi);
    g.box_size = (hi - lo).array() + s;
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
      const bool room = groups.size() < static_cast<std::size_t>(kMaxGroups);  // else the last group widens
      if (groups.empty() || (room && node.radius > group_smallest * kRadiusGroupRatio)) {
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

const std::string& MarkerBuilder::levelNamespace(int level) {
  while (level_ns_.size() <= static_cast<std::size_t>(level)) {
    level_ns_.push_back("tree_level_" + std::to_string(level_ns_.size()));
  }
  return level_ns_[static_cast<std::size_t>(level)];
}

bool MarkerBuilder::drawsLevel(const ShapeGeometry& g, int level, bool is_static, const MarkerOptions& options) const {
  if (is_static && !options.static_trees) return false;
  return level >= 0 && static_cast<std::size_t>(level) < g.levels.size();
}

Marker& appendMarker(visualization_msgs::MarkerArray& out, std::size_t& used, const std::string& ns, int id, int type,
                     const ros::Time& stamp, const std::string& frame) {
  if (out.markers.size() <= used) out.markers.resize(used + 1);
  Marker& m = out.markers[used++];
  m.header.stamp = stamp;
  m.header.frame_id = frame;
  m.ns = ns;
  m.id = id;
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

Marker& MarkerBuilder::next(visualization_msgs::MarkerArray& out, const std::string& ns, int id, int type,
                            const ros::Time& stamp, const std::string& frame) {
  return appendMarker(out, used_, ns, id, type, stamp, frame);
}

void MarkerBuilder::begin(visualization_msgs::MarkerArray& out) {
  used_ = 0;
  (void)out;
}

void MarkerBuilder::end(visualization_msgs::MarkerArray& out) { out.markers.resize(used_); }

void MarkerBuilder::deleteAll(const MarkerOptions& options, visualization_msgs::MarkerArray& out) {
  next(out, "", 0, Marker::CUBE, ros::Time(0), options.frame).action = Marker::DELETEALL;
}

void MarkerBuilder::addEntity(const stc::World& world, std::size_t index, const Rgba& color,
                              const std::string& entity_frame, bool frame_locked, const MarkerOptions& options,
                              const ros::Time& stamp, visualization_msgs::MarkerArray& out) {
  const stc::EntityId id = world.entityIds()[index];
  const stc::BodyState& body = world.bodies()[index];
  const stc::ShapeId shape = world.bodyShapes()[index];
  const ShapeGeometry& g = geometry(world, shape);
  const std::string& frame = frame_locked ? entity_frame : options.frame;
  const ros::Time when = frame_locked ? ros::Time(0) : stamp;  // frame-locked: rviz uses the latest tf
  const auto place = [&](Marker& m) {
    m.frame_locked = frame_locked;
    if (!frame_locked) setPose(m, body.pose);
  };
  if (body.is_static && !options.static_voxels) {
    // One box instead of every voxel: a wall of thousands of voxels costs rviz
    // as much as one cube (the rockfall's ravine: ~24,000 cubes become ~370).
    // A static entity never moves: the box is placed in the world frame, not
    // frame-locked, so rviz does not look up hundreds of wall frames each frame.
    Marker& m = next(out, kStaticBoxesNs, static_cast<int>(id & 0x7fffffffu), Marker::CUBE, stamp, options.frame);
    setPose(m, stc::Pose{body.pose.apply(g.box_centre), body.pose.orientation});
    m.scale.x = g.box_size.x();
    m.scale.y = g.box_size.y();
    m.scale.z = g.box_size.z();
    m.color = toColorMsg(color[0], color[1], color[2], color[3]);
  } else if (options.voxels) {
    Marker& m = next(out, kVoxelsNs, static_cast<int>(id & 0x7fffffffu), Marker::CUBE_LIST, when, frame);
    place(m);
    m.scale.x = m.scale.y = m.scale.z = world.shape(shape).voxels.voxelSize() * kVoxelFill;
    m.color = toColorMsg(color[0], color[1], color[2], color[3]);
    m.points.assign(g.surface_voxels.begin(), g.surface_voxels.end());
  }
  for (int level : options.levels) {
    if (!drawsLevel(g, level, body.is_static, options)) continue;
    const auto& groups = g.levels[static_cast<std::size_t>(level)];
    for (std::size_t k = 0; k < groups.size(); ++k) {
      Marker& m = next(out, levelNamespace(level), groupId(id, k), Marker::SPHERE_LIST, when, frame);
      place(m);
      m.scale.x = m.scale.y = m.scale.z = 2.0 * groups[k].radius;
      m.color = levelColor(level, options.levels.size() == 1);
      m.points.assign(groups[k].centres.begin(), groups[k].centres.end());
    }
  }
}

void MarkerBuilder::deleteEntity(const stc::World& world, stc::EntityId id, stc::ShapeId shape, bool is_static,
                                 const MarkerOptions& options, visualization_msgs::MarkerArray& out) {
  const ShapeGeometry& g = geometry(world, shape);
  if (is_static && !options.static_voxels) {
    next(out, kStaticBoxesNs, static_cast<int>(id & 0x7fffffffu), Marker::CUBE, ros::Time(0), options.frame).action =
        Marker::DELETE;
  } else if (options.voxels) {
    next(out, kVoxelsNs, static_cast<int>(id & 0x7fffffffu), Marker::CUBE_LIST, ros::Time(0), options.frame).action =
        Marker::DELETE;
  }
  for (int level : options.levels) {
    if (!drawsLevel(g, level, is_static, options)) continue;
    for (std::size_t k = 0; k < g.levels[static_cast<std::size_t>(level)].size(); ++k) {
      next(out, levelNamespace(level), groupId(id, k), Marker::SPHERE_LIST, ros::Time(0), options.frame).action =
          Marker::DELETE;
    }
  }
}

void MarkerBuilder::addDynamic(const stc::World& world, const MarkerOptions& options,
                               const std::optional<stc::Vec3>& gaze_point, const ros::Time& stamp, bool track,
                               visualization_msgs::MarkerArray& out) {
  const auto& contacts = world.contacts();
  const std::size_t n = std::min(contacts.size(), options.max_contacts);
  double max_priority = 0.0;
  for (std::size_t i = 0; i < n; ++i) max_priority = std::max(max_priority, contacts[i].priority);
  std::array<std::size_t, kContactClasses> per_class{};
  for (std::size_t i = 0; i < n; ++i) ++per_class[static_cast<std::size_t>(contactClass(contacts[i].priority, max_priority))];

  // A slot with content is (re)added; an empty one that was drawn is deleted
  // (rviz rejects empty point lists, and a stale one would stay on screen).
  const auto slot = [&](int index, bool has_content, const std::string& ns, int id, int type) -> Marker* {
    bool& live = live_[static_cast<std::size_t>(index)];
    if (!has_content) {
      if (track && live) next(out, ns, id, type, stamp, options.frame).action = Marker::DELETE;
      if (track) live = false;
      return nullptr;
    }
    if (track) live = true;
    return &next(out, ns, id, type, stamp, options.frame);
  };
  // Pointers into out.markers: size it first so next() cannot reallocate under them.
  if (out.markers.size() < used_ + kSlots) out.markers.resize(used_ + kSlots);
  std::array<Marker*, kContactClasses> classes{};
  for (int k = 0; k < kContactClasses; ++k) {
    Marker* m = slot(k, per_class[static_cast<std::size_t>(k)] > 0, kContactsNs, k, Marker::SPHERE_LIST);
    if (m) {
      m->scale.x = m->scale.y = m->scale.z = options.contact_size * (1.0 + 0.7 * k);
      m->color = kResolvedColor;  // per-point colours below
    }
    classes[static_cast<std::size_t>(k)] = m;
  }
  Marker* normals = slot(kContactClasses, n > 0, kNormalsNs, 0, Marker::LINE_LIST);
  if (normals) {
    normals->scale.x = 0.25 * options.contact_size;
    normals->color = toColorMsg(1.0f, 1.0f, 1.0f, 0.8f);
  }
  const double normal_length = 3.0 * options.contact_size;
  for (std::size_t i = 0; i < n; ++i) {
    const stc::Contact& c = contacts[i];
    Marker& m = *classes[static_cast<std::size_t>(contactClass(c.priority, max_priority))];
    m.points.push_back(toPointMsg(c.point));
    m.colors.push_back(c.resolved ? kResolvedColor : kUnresolvedColor);
    normals->points.push_back(toPointMsg(c.point));
    normals->points.push_back(toPointMsg(c.point + normal_length * c.normal));
  }
  if (Marker* dot = slot(kContactClasses + 1, gaze_point.has_value(), kGazeNs, 0, Marker::SPHERE)) {
    dot->pose.position = toPointMsg(*gaze_point);
    dot->scale.x = dot->scale.y = dot->scale.z = 3.0 * options.contact_size;
    dot->color = kGazeColor;
  }
}

void MarkerBuilder::buildFull(const stc::World& world, const std::vector<Rgba>& colors_by_index,
                              const MarkerOptions& options, const std::optional<stc::Vec3>& gaze_point,
                              const ros::Time& stamp, visualization_msgs::MarkerArray& out) {
  begin(out);
  deleteAll(options, out);
  forgetDynamic();
  for (std::size_t i = 0; i < world.entityCount(); ++i) {
    addEntity(world, i, colors_by_index[i], options.frame, false, options, stamp, out);
  }
  addDynamic(world, options, gaze_point, stamp, true, out);
  end(out);
}

}  // namespace stc_ros
