// MarkerBuilder: the World as rviz markers. Namespaces (switch them in rviz's
// MarkerArray display):
//   voxels            one CUBE_LIST per entity (surface voxels only: the inside is hidden)
//   tree_level_<L>    sphere-tree level L, semi-transparent; SPHERE_LIST draws one
//                     radius per marker, so each level's spheres are grouped by radius
//   contacts          SPHERE_LIST per size class: green = resolved at the leaves,
//                     orange = accepted unresolved; larger = higher perceptual priority
//   contact_normals   LINE_LIST along each contact normal
//   gaze              the fixation: a sphere where the gaze ray first meets the scene
// Entity geometry is either frame-locked in the entity's tf frame (sent once:
// rviz moves it with tf) or posed in the world frame (sent every time). Ids are
// stable: voxels id = entity id, tree groups id = entity id * 512 + group,
// contacts / normals / gaze fixed slots, so arrays can add and delete piecewise.
// Per-shape geometry is cached; the output's storage is reused between arrays.
#pragma once

#include "sphere_tree_collision/ros/entity_display.hpp"
#include "sphere_tree_collision/world.hpp"

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace stc_ros {

struct MarkerOptions {
  std::string frame = "world";
  std::vector<int> levels{1, 2};  // sphere-tree levels to draw
  bool voxels = true;
  bool static_trees = true;       // false: no tree levels for static entities (large walls hide the scene)
  bool static_voxels = true;      // false: a static entity drawn as one box around its voxels (ns static_boxes), cheap to render
  std::size_t max_contacts = 2000;
  double contact_size = 0.04;     // metres: diameter of the lowest-priority contact sphere
};

// out.markers[used] (the array grows when needed) made an ADD of a fresh
// marker, keeping the storage of its vectors; used is advanced. An array built
// piecewise is resized to `used` at the end.
visualization_msgs::Marker& appendMarker(visualization_msgs::MarkerArray& out, std::size_t& used,
                                         const std::string& ns, int id, int type, const ros::Time& stamp,
                                         const std::string& frame);

class MarkerBuilder {
 public:
  // An array is begin(), any of the add/delete calls, end().
  void begin(visualization_msgs::MarkerArray& out);
  void end(visualization_msgs::MarkerArray& out);

  void deleteAll(const MarkerOptions& options, visualization_msgs::MarkerArray& out);
  // Entity `index` of the world. frame_locked: in `entity_frame` at identity,
  // moved by rviz with tf; else in options.frame at the body pose, stamped.
  void addEntity(const stc::World& world, std::size_t index, const Rgba& color, const std::string& entity_frame,
                 bool frame_locked, const MarkerOptions& options, const ros::Time& stamp,
                 visualization_msgs::MarkerArray& out);
  // The markers addEntity made for an entity of `shape` (it may be gone from the world).
  void deleteEntity(const stc::World& world, stc::EntityId id, stc::ShapeId shape, bool is_static,
                    const MarkerOptions& options, visualization_msgs::MarkerArray& out);
  // Contacts and gaze. track: this array goes to every subscriber, so slots
  // drawn by the previous tracked array and empty now are deleted; untracked
  // (a snapshot after DELETEALL for one new subscriber) leaves that state alone.
  void addDynamic(const stc::World& world, const MarkerOptions& options, const std::optional<stc::Vec3>& gaze_point,
                  const ros::Time& stamp, bool track, visualization_msgs::MarkerArray& out);
  // After a tracked DELETEALL: nothing dynamic is drawn any more.
  void forgetDynamic() { live_.fill(false); }

  // Everything in the world frame, DELETEALL first (the "full" marker mode).
  void buildFull(const stc::World& world, const std::vector<Rgba>& colors_by_index, const MarkerOptions& options,
                 const std::optional<stc::Vec3>& gaze_point, const ros::Time& stamp,
                 visualization_msgs::MarkerArray& out);

 private:
  struct RadiusGroup {
    double radius = 0.0;  // drawn radius: the group's largest, so nothing is drawn smaller
    std::vector<geometry_msgs::Point> centres;  // body frame
  };
  struct ShapeGeometry {
    bool built = false;
    std::vector<geometry_msgs::Point> surface_voxels;  // voxel centres, body frame
    stc::Vec3 box_centre = stc::Vec3::Zero(), box_size = stc::Vec3::Zero();  // around the voxels, body frame
    std::vector<std::vector<RadiusGroup>> levels;      // [level][group], at most kMaxGroups per level
  };
  const ShapeGeometry& geometry(const stc::World& world, stc::ShapeId id);
  const std::string& levelNamespace(int level);
  bool drawsLevel(const ShapeGeometry& g, int level, bool is_static, const MarkerOptions& options) const;
  visualization_msgs::Marker& next(visualization_msgs::MarkerArray& out, const std::string& ns, int id,
                                   int type, const ros::Time& stamp, const std::string& frame);

  // Dynamic slots: contact size classes 0..3, normals, gaze.
  static constexpr int kContactClasses = 4;
  static constexpr int kSlots = kContactClasses + 2;
  std::array<bool, kSlots> live_{};

  std::vector<ShapeGeometry> shapes_;  // by ShapeId
  std::vector<std::string> level_ns_;  // "tree_level_<L>", built once
  std::size_t used_ = 0;
};

}  // namespace stc_ros
