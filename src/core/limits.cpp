// Physical limits: validation of inputs and the per-tick quarantine test.
#include "sphere_tree_collision/limits.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <sstream>

namespace stc {
namespace {

// A unit quaternion may be off by this much before normalisation; more means
// the caller passed something that is not a rotation.
constexpr double kOrientationNormTolerance = 1e-3;

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

void requirePositive(double value, const char* name) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw InputError(name, "must be finite and > 0, got " + number(value));
  }
}

// Beyond the limit, named: "|v| = 1e+308 m/s exceeds max_speed = 1000 m/s".
void requireNormAtMost(const Vec3& v, double limit, const char* field, const char* limit_name,
                       const char* unit) {
  if (!v.allFinite()) throw InputError(field, "must be finite");
  const double norm = v.norm();
  if (!(norm <= limit)) {
    throw InputError(field, "|v| = " + number(norm) + " " + unit + " exceeds " + limit_name + " = " +
                                number(limit) + " " + unit);
  }
}

bool insideWorld(const Vec3& p, double extent) { return p.cwiseAbs().maxCoeff() <= extent; }

}  // namespace

void validateLimits(const PhysicalLimits& limits) {
  requirePositive(limits.max_speed, "max_speed");
  requirePositive(limits.max_spin, "max_spin");
  requirePositive(limits.world_extent, "world_extent");
  requirePositive(limits.min_density, "min_density");
  requirePositive(limits.max_density, "max_density");
  requirePositive(limits.max_friction, "max_friction");
  requirePositive(limits.max_gravity, "max_gravity");
  if (limits.min_density > limits.max_density) {
    throw InputError("min_density", number(limits.min_density) + " is above max_density " +
                                        number(limits.max_density));
  }
}

void validateMeshLimits(const MeshLimits& limits) {
  const std::pair<std::int64_t, const char*> fields[] = {{limits.max_mesh_bytes, "max_mesh_bytes"},
                                                         {limits.max_mesh_vertices, "max_mesh_vertices"},
                                                         {limits.max_mesh_triangles, "max_mesh_triangles"}};
  for (const auto& [value, name] : fields) {
    if (value < 1 || value > 2147483647) {
      throw InputError(name, "must be in [1, 2147483647], got " + std::to_string(value));
    }
  }
}

void validateGravity(const Vec3& gravity, const PhysicalLimits& limits) {
  requireNormAtMost(gravity, limits.max_gravity, "gravity", "max_gravity", "m/s^2");
}

void validateBodyInput(const Pose& pose, const Vec3& linear_velocity, const Vec3& angular_velocity,
                       double density, const Material& material, const PhysicalLimits& limits) {
  const double q_norm = pose.orientation.coeffs().norm();
  if (!pose.orientation.coeffs().allFinite() || !(std::abs(q_norm - 1.0) <= kOrientationNormTolerance)) {
    throw InputError("pose.orientation", "must be a unit quaternion (|q| = " + number(q_norm) + ", tolerance 1e-3)");
  }
  const Vec3& position = pose.position;
  if (!position.allFinite()) throw InputError("pose.position", "must be finite");
  if (!insideWorld(position, limits.world_extent)) {
    throw InputError("pose.position", "a coordinate is beyond world_extent = " + number(limits.world_extent) +
                                          " m (|x|, |y|, |z| <= extent)");
  }
  requireNormAtMost(linear_velocity, limits.max_speed, "linear_velocity", "max_speed", "m/s");
  requireNormAtMost(angular_velocity, limits.max_spin, "angular_velocity", "max_spin", "rad/s");
  if (!(density >= limits.min_density && density <= limits.max_density)) {
    throw InputError("density", number(density) + " kg/m^3 is outside [min_density, max_density] = [" +
                                    number(limits.min_density) + ", " + number(limits.max_density) + "]");
  }
  if (!(material.restitution >= 0.0 && material.restitution <= 1.0)) {
    throw InputError("material.restitution", "must be in [0, 1], got " + number(material.restitution));
  }
  if (!(material.friction >= 0.0 && material.friction <= limits.max_friction)) {
    throw InputError("material.friction", number(material.friction) + " is outside [0, max_friction = " +
                                              number(limits.max_friction) + "]");
  }
  if (!(material.rolling_resistance >= 0.0 && material.rolling_resistance <= 1.0)) {
    throw InputError("material.rolling_resistance", "must be in [0, 1], got " + number(material.rolling_resistance));
  }
  if (!(std::isfinite(material.strength) && material.strength >= 0.0)) {
    throw InputError("material.strength", "must be finite and >= 0 N s (0: unbreakable), got " +
                                              number(material.strength));
  }
}

const char* toString(Quarantine reason) {
  switch (reason) {
    case Quarantine::None: return "none";
    case Quarantine::NonFinite: return "non-finite state";
    case Quarantine::TooFast: return "speed above max_speed";
    case Quarantine::TooSpun: return "spin above max_spin";
    case Quarantine::LeftWorld: return "left the world";
  }
  return "unknown";
}

Quarantine quarantineReason(const BodyState& body, const PhysicalLimits& limits) {
  if (!body.pose.position.allFinite() || !body.pose.orientation.coeffs().allFinite() ||
      !body.linear_velocity.allFinite() || !body.angular_velocity.allFinite()) {
    return Quarantine::NonFinite;
  }
  if (!(body.linear_velocity.norm() <= limits.max_speed)) return Quarantine::TooFast;
  if (!(body.angular_velocity.norm() <= limits.max_spin)) return Quarantine::TooSpun;
  if (!insideWorld(body.pose.position, limits.world_extent)) return Quarantine::LeftWorld;
  return Quarantine::None;
}

}  // namespace stc
