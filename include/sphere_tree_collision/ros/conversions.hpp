// Conversions between ROS messages and core types. ROS side only.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Vector3.h>

namespace stc_ros {

inline stc::Vec3 toEigen(const geometry_msgs::Point& p) { return {p.x, p.y, p.z}; }
inline stc::Vec3 toEigen(const geometry_msgs::Vector3& v) { return {v.x, v.y, v.z}; }
// Not normalised: callers validate the norm first.
inline stc::Quat toEigen(const geometry_msgs::Quaternion& q) { return stc::Quat(q.w, q.x, q.y, q.z); }

geometry_msgs::Point toPointMsg(const stc::Vec3& v);
geometry_msgs::Vector3 toVector3Msg(const stc::Vec3& v);
geometry_msgs::Quaternion toQuaternionMsg(const stc::Quat& q);
geometry_msgs::Pose toPoseMsg(const stc::Pose& pose);

}  // namespace stc_ros
