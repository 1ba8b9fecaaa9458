#include "sphere_tree_collision/ros/conversions.hpp"

#include <tf2_eigen/tf2_eigen.h>

#include <Eigen/LU>

#include <algorithm>
#include <climits>
#include <map>

namespace stc_ros {

namespace {

template <typename EigenType, typename Msg>
EigenType fromMsgAs(const Msg& msg) {
  EigenType out;
  tf2::fromMsg(msg, out);
  return out;
}

}  // namespace

stc::Vec3 toEigen(const geometry_msgs::Point& p) { return fromMsgAs<stc::Vec3>(p); }
stc::Vec3 toEigen(const geometry_msgs::Vector3& v) { return fromMsgAs<stc::Vec3>(v); }
stc::Quat toEigen(const geometry_msgs::Quaternion& q) { return fromMsgAs<stc::Quat>(q); }

stc::Pose toPose(const geometry_msgs::Transform& t) {
  stc::Pose pose;
  pose.position = toEigen(t.translation);
  pose.orientation = toEigen(t.rotation).normalized();
  return pose;
}

geometry_msgs::Point toPointMsg(const stc::Vec3& v) { return tf2::toMsg(v); }

geometry_msgs::Vector3 toVector3Msg(const stc::Vec3& v) {
  geometry_msgs::Vector3 m;
  return tf2::toMsg(v, m);
}

geometry_msgs::Quaternion toQuaternionMsg(const stc::Quat& q) { return tf2::toMsg(q); }

geometry_msgs::Pose toPoseMsg(const stc::Pose& pose) {
  geometry_msgs::Pose m;
  m.position = toPointMsg(pose.position);
  m.orientation = toQuaternionMsg(pose.orientation);
  return m;
}

geometry_msgs::Inertia toInertiaMsg(const stc::BodyState& body) {
  geometry_msgs::Inertia m;
  if (body.is_static || !(body.inv_mass > 0.0)) return m;
  m.m = 1.0 / body.inv_mass;
  const stc::Mat3 inertia = body.inv_inertia_body.inverse();
  m.ixx = inertia(0, 0);
  m.ixy = inertia(0, 1);
  m.ixz = inertia(0, 2);
  m.iyy = inertia(1, 1);
  m.iyz = inertia(1, 2);
  m.izz = inertia(2, 2);
  return m;
}

std_msgs::ColorRGBA toColorMsg(float r, float g, float b, float a) {
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

stc::EntityRequest toEntityRequest(const sphere_tree_collision::SpawnEntity& msg) {
  // Field for field; which shape source, and what belongs to it, is
  // stc::validateRequest's to judge, as for a scene file.
  stc::EntityRequest r;
  r.spec.name = msg.name;
  r.preset = msg.preset;
  r.mesh_resource = msg.mesh_resource;
  const stc::Vec3 scale = toEigen(msg.scale);
  if (!scale.isZero(0.0)) r.mesh_scale = scale;
  if (!msg.up_axis.empty()) r.mesh_up_axis = stc::parseColladaUpAxis(msg.up_axis);
  // Beyond int, any resolution is refused as the largest one would be.
  r.preset_params.resolution = static_cast<int>(std::min<std::uint32_t>(msg.resolution, INT_MAX));
  r.preset_params.seed = msg.seed;
  (msg.mesh_resource.empty() ? r.preset_params.voxel_size : r.mesh_voxel_size) = msg.voxel_size;
  if (msg.dims[0] != 0 || msg.dims[1] != 0 || msg.dims[2] != 0 || !msg.occupancy.empty()) {
    for (std::uint32_t d : msg.dims) {
      if (d == 0 || d > static_cast<std::uint32_t>(INT_MAX)) {
        throw stc::InputError("dims", "each of nx, ny, nz must be in [1, " + std::to_string(INT_MAX) + "]");
      }
    }
    stc::ExplicitGrid grid;
    grid.nx = static_cast<int>(msg.dims[0]);
    grid.ny = static_cast<int>(msg.dims[1]);
    grid.nz = static_cast<int>(msg.dims[2]);
    grid.voxel_size = msg.voxel_size;
    grid.occupancy = msg.occupancy;
    r.grid = std::move(grid);
  }
  r.spec.pose.position = toEigen(msg.pose.position);
  r.spec.pose.orientation = toEigen(msg.pose.orientation);
  r.spec.linear_velocity = toEigen(msg.twist.linear);
  r.spec.angular_velocity = toEigen(msg.twist.angular);
  r.spec.density = msg.density;
  r.spec.material.restitution = msg.restitution;
  r.spec.material.friction = msg.friction;
  r.spec.material.strength = msg.strength;
  r.spec.is_static = msg.is_static;
  if (!msg.closed_faces.empty()) r.spec.closed_faces = stc::parseFaces(msg.closed_faces);
  const auto& c = msg.color;
  if (c.r != 0.0f || c.g != 0.0f || c.b != 0.0f || c.a != 0.0f) r.color = stc::Rgba{c.r, c.g, c.b, c.a};
  return r;
}

std::string spawnFieldOf(const std::string& core_field, bool is_preset) {
  static const std::map<std::string, std::string> kFields{
      {"linear_velocity", "twist.linear"}, {"angular_velocity", "twist.angular"},
      {"material.restitution", "restitution"}, {"material.friction", "friction"},
      {"material.strength", "strength"},
      {"max_voxels", "dims"}, {"mesh", "mesh_resource"}, {"vertices", "mesh_resource"},
      {"triangles", "mesh_resource"}};
  if (is_preset && (core_field == "dims" || core_field == "max_voxels")) return "resolution";
  const auto it = kFields.find(core_field);
  return it == kFields.end() ? core_field : it->second;
}

}  // namespace stc_ros
