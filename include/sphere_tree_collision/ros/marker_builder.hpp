// MarkerBuilder: the World as rviz markers, all in the world frame so they need
// no tf. Namespaces (switch them in rviz's MarkerArray display):
//   voxels            one CUBE_LIST per entity (surface voxels only: the inside is hidden)
//   tree_level_<L>    sphere-tree level L, semi-transparent; SPHERE_LIST draws one
//                     radius per marker, so each level's spheres are grouped by radius
//   contacts          SPHERE_LIST per size class: green = resolved at the leaves,
//                     orange = accepted unresolved; larger = higher perceptual priority
//   contact_normals   LINE_LIST along each contact normal
//   gaze              the fixation: a sphere where the gaze ray first meets the scene
// The first marker is always DELETEALL, so removed entities vanish.
// Per-shape geometry is cached; the output's storage is reused between calls.
#pragma once

#include "sphere_tree_collision/ros/entity_request.hpp"
#include "sphere_tree_collision/world.hpp"

#include <ros/time.h>
#include <visualization_msgs/MarkerArray.h>

#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace stc_ros {

struct MarkerOptions {
  std::string frame = "world";
  std::vector<int> levels{1, 2};  // sphere-tree levels to draw
  bool voxels = true;
  bool static_trees = true;       // false: no tree levels for static entities (large walls hide the scene)
  std::size_t max_contacts = 2000;
  double contact_size = 0.04;     // metres: diameter of the lowest-priority contact sphere
};

class MarkerBuilder {
 public:
  void build(const stc::World& world, const std::unordered_map<stc::EntityId, Rgba>& colors,
             const MarkerOptions& options, const std::optional<stc::Vec3>& gaze_point, const ros::Time& stamp,
             visualization_msgs::MarkerArray& out);

  // Marker count of the last build (DELETEALL included).
  std::size_t lastMarkerCount() const { return used_; }

 private:
  struct RadiusGroup {
    double radius = 0.0;  // drawn radius: the group's largest, so nothing is drawn smaller
    std::vector<geometry_msgs::Point> centres;  // body frame
  };
  struct ShapeGeometry {
    bool built = false;
    std::vector<geometry_msgs::Point> surface_voxels;  // voxel centres, body frame
    std::vector<std::vector<RadiusGroup>> levels;      // [level][group]
  };
  const ShapeGeometry& geometry(const stc::World& world, stc::ShapeId id);
  visualization_msgs::Marker& next(visualization_msgs::MarkerArray& out, const std::string& ns,
                                   int type, const ros::Time& stamp, const std::string& frame);
  void addContacts(const stc::World& world, const MarkerOptions& options, const ros::Time& stamp,
                   visualization_msgs::MarkerArray& out);
  void addGaze(const stc::Vec3& gaze_point, const MarkerOptions& options, const ros::Time& stamp,
               visualization_msgs::MarkerArray& out);

  std::vector<ShapeGeometry> shapes_;  // by ShapeId
  std::vector<std::string> level_ns_;  // "tree_level_<L>", built once
  std::size_t used_ = 0;
  int next_id_ = 0;
};

}  // namespace stc_ros
