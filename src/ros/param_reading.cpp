#include "sphere_tree_collision/ros/param_reading.hpp"

#include <cmath>
#include <vector>

namespace stc_ros {

double positiveParam(const ros::NodeHandle& nh, const std::string& name, double fallback) {
  const double value = paramOr(nh, name, fallback);
  if (!(value > 0.0) || !std::isfinite(value)) throw stc::InputError(name, "must be finite and > 0");
  return value;
}

double nonNegativeParam(const ros::NodeHandle& nh, const std::string& name, double fallback) {
  const double value = paramOr(nh, name, fallback);
  if (!(value >= 0.0) || !std::isfinite(value)) throw stc::InputError(name, "must be finite and >= 0");
  return value;
}

int intParamIn(const ros::NodeHandle& nh, const std::string& name, int fallback, int lo, int hi) {
  const int value = paramOr(nh, name, fallback);
  if (value < lo || value > hi) {
    throw stc::InputError(name, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

std::optional<stc::Vec3> vec3Param(const ros::NodeHandle& nh, const std::string& name) {
  std::vector<double> v;
  if (!readParam(nh, name, v)) return std::nullopt;
  if (v.size() != 3) throw stc::InputError(name, "expected a list of 3 numbers");
  const stc::Vec3 out(v[0], v[1], v[2]);
  if (!out.allFinite()) throw stc::InputError(name, "not finite");
  return out;
}

}  // namespace stc_ros
