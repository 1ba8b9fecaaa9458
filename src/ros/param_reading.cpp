#include "sphere_tree_collision/ros/param_reading.hpp"

#include <cmath>
#include <vector>

namespace stc_ros {

double requirePositive(const std::string& name, double value) {
  if (!(value > 0.0) || !std::isfinite(value)) throw stc::InputError(name, "must be finite and > 0");
  return value;
}

double requireNonNegative(const std::string& name, double value) {
  if (!(value >= 0.0) || !std::isfinite(value)) throw stc::InputError(name, "must be finite and >= 0");
  return value;
}

int requireIn(const std::string& name, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    throw stc::InputError(name, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return value;
}

double positiveParam(const ros::NodeHandle& nh, const std::string& name, double fallback) {
  return requirePositive(name, paramOr(nh, name, fallback));
}

double nonNegativeParam(const ros::NodeHandle& nh, const std::string& name, double fallback) {
  return requireNonNegative(name, paramOr(nh, name, fallback));
}

int intParamIn(const ros::NodeHandle& nh, const std::string& name, int fallback, int lo, int hi) {
  return requireIn(name, paramOr(nh, name, fallback), lo, hi);
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
