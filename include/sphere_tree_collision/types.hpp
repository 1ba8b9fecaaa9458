// Basic value types shared by every part of the ROS-free core.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace stc {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

// Stable handle of an entity; never reused within one World.
using EntityId = std::uint32_t;
constexpr EntityId kInvalidEntity = std::numeric_limits<EntityId>::max();
// A shape of the World's ShapeLibrary (shape_library.hpp), shared by its entities.
using ShapeId = std::uint32_t;
// An ordered pair of entities as one key: a in the high half, b in the low.
inline std::uint64_t entityPairKey(EntityId a, EntityId b) { return (std::uint64_t{a} << 32) | std::uint64_t{b}; }

// Rigid transform from a body frame to the world frame.
struct Pose {
  Vec3 position = Vec3::Zero();
  Quat orientation = Quat::Identity();

  Vec3 apply(const Vec3& p) const { return orientation * p + position; }
};

struct Aabb {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();

  bool overlaps(const Aabb& o) const {
    return min.x() <= o.max.x() && o.min.x() <= max.x() && min.y() <= o.max.y() &&
           o.min.y() <= max.y() && min.z() <= o.max.z() && o.min.z() <= max.z();
  }
  // Inside or on the boundary (false for a NaN coordinate).
  bool contains(const Vec3& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

// Rejected input. `field()` names the offending field (e.g. "voxel_size",
// "occupancy", "preset") so callers can report it verbatim.
class InputError : public std::invalid_argument {
 public:
  InputError(std::string field, std::string reason)
      : std::invalid_argument(field + ": " + reason), field_(std::move(field)), reason_(std::move(reason)) {}
  const std::string& field() const { return field_; }
  // What is wrong with the field, without its name (to name it otherwise).
  const std::string& reason() const { return reason_; }

 private:
  std::string field_;
  std::string reason_;
};

inline bool allFinite(const Vec3& v) { return v.allFinite(); }

}  // namespace stc
