// Reading private parameters strictly: a value of the wrong type or out of
// range throws stc::InputError naming the parameter, never falls back silently.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <ros/node_handle.h>

#include <optional>
#include <string>

namespace stc_ros {

// Reads `name` into `out` when it is set; false when it is not.
template <typename T>
bool readParam(const ros::NodeHandle& nh, const std::string& name, T& out) {
  if (!nh.hasParam(name)) return false;
  if (!nh.getParam(name, out)) throw stc::InputError(name, "has the wrong type");
  return true;
}

template <typename T>
T paramOr(const ros::NodeHandle& nh, const std::string& name, T fallback) {
  readParam(nh, name, fallback);
  return fallback;
}

// A value checked as the parameter `name` (start-up or live tuning): the value,
// or InputError(name). Finite and > 0; finite and >= 0; in [lo, hi].
double requirePositive(const std::string& name, double value);
double requireNonNegative(const std::string& name, double value);
int requireIn(const std::string& name, int value, int lo, int hi);

// Finite and > 0.
double positiveParam(const ros::NodeHandle& nh, const std::string& name, double fallback);
// Finite and >= 0.
double nonNegativeParam(const ros::NodeHandle& nh, const std::string& name, double fallback);
// In [lo, hi].
int intParamIn(const ros::NodeHandle& nh, const std::string& name, int fallback, int lo, int hi);
// A list of three finite numbers, when set.
std::optional<stc::Vec3> vec3Param(const ros::NodeHandle& nh, const std::string& name);

}  // namespace stc_ros
