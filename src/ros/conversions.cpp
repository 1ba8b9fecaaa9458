#include "sphere_tree_collision/ros/conversions.hpp"

namespace stc_ros {

geometry_msgs::Point toPointMsg(const stc::Vec3& v) {
  geometry_msgs::Point p;
  p.x = v.x();
  p.y = v.y();
  p.z = v.z();
  return p;
}

geometry_msgs::Vector3 toVector3Msg(const stc::Vec3& v) {
  geometry_msgs::Vector3 m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}

geometry_msgs::Quaternion toQuaternionMsg(const stc::Quat& q) {
  geometry_msgs::Quaternion m;
  m.w = q.w();
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  return m;
}

geometry_msgs::Pose toPoseMsg(const stc::Pose& pose) {
  geometry_msgs::Pose m;
  m.position = toPointMsg(pose.position);
  m.orientation = toQuaternionMsg(pose.orientation);
  return m;
}

}  // namespace stc_ros
