// Two bodies in the same state bit for bit: pose, orientation and velocities
// compared with ==, none within a tolerance (tests and benchmarks alike).
#pragma once

#include "sphere_tree_collision/body.hpp"

namespace stc {

inline bool sameBits(const BodyState& a, const BodyState& b) {
  return a.pose.position == b.pose.position && a.pose.orientation.coeffs() == b.pose.orientation.coeffs() &&
         a.linear_velocity == b.linear_velocity && a.angular_velocity == b.angular_velocity;
}

}  // namespace stc
