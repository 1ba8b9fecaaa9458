// Conversions between ROS messages and core types. ROS side only.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/scene/entity_request.hpp"
#include "sphere_tree_collision/types.hpp"

#include <sphere_tree_collision/SpawnEntity.h>

#include <geometry_msgs/Inertia.h>
#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/Vector3.h>
#include <std_msgs/ColorRGBA.h>

#include <string>

namespace stc_ros {

// Through tf2_eigen (tf2::fromMsg / tf2::toMsg), under names that say the direction.
stc::Vec3 toEigen(const geometry_msgs::Point& p);
stc::Vec3 toEigen(const geometry_msgs::Vector3& v);
// Not normalised: callers validate the norm first.
stc::Quat toEigen(const geometry_msgs::Quaternion& q);
// A tf transform as a pose; the rotation normalised (tf's is unit up to rounding).
stc::Pose toPose(const geometry_msgs::Transform& t);

geometry_msgs::Point toPointMsg(const stc::Vec3& v);
geometry_msgs::Vector3 toVector3Msg(const stc::Vec3& v);
geometry_msgs::Quaternion toQuaternionMsg(const stc::Quat& q);
geometry_msgs::Pose toPoseMsg(const stc::Pose& pose);
std_msgs::ColorRGBA toColorMsg(float r, float g, float b, float a);
// Mass and inertia tensor in the body frame (origin at the centre of mass,
// so com is 0); all 0 for a static body.
geometry_msgs::Inertia toInertiaMsg(const stc::BodyState& body);

// A SpawnEntity message as an EntityRequest, field for field. Throws
// InputError only for what the request type cannot hold (dims beyond int, an
// unknown up_axis); everything else is checked by stc::addRequest, which also
// gives fields left at 0 their defaults. An all-zero colour or scale means "none".
stc::EntityRequest toEntityRequest(const sphere_tree_collision::SpawnEntity& msg);

// addRequest names fields after the core (EntitySpec, VoxelShape); this gives
// the SpawnEntity field a user wrote (e.g. "linear_velocity" -> "twist.linear").
std::string spawnFieldOf(const std::string& core_field, bool is_preset);

}  // namespace stc_ros
