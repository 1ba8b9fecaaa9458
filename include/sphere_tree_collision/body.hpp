// What one entity is besides its shape: its rigid-body state (stored in the
// World's flat array), material, broad-phase box mode and closed faces.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace stc {

struct Material {
  double restitution = 0.3;  // [0, 1]
  double friction = 0.5;     // Coulomb coefficient, >= 0
  // Contact impulse (N s, summed over a tick's contacts) the body takes
  // before it breaks (fracture.hpp); 0: unbreakable. Finite, >= 0.
  double strength = 0.0;
  // Rolling (and spinning) resistance, dimensionless: a touching pair's
  // angular impulse against the relative spin of its two bodies is held
  // within this coefficient times the rolling radius times the pair's
  // normal impulse (torque c_rr * r * N, as Box2D v3's rollingResistance);
  // of a pair the larger coefficient counts (ContactSolver). 0: none (a
  // ball rolls on for ever). In [0, 1].
  double rolling_resistance = 0.0;
};

// Pose is of the body frame, whose origin is the centre of mass.
struct BodyState {
  Pose pose;
  Vec3 linear_velocity = Vec3::Zero();   // world frame
  Vec3 angular_velocity = Vec3::Zero();  // world frame
  double inv_mass = 0.0;                 // 0 for static bodies
  Mat3 inv_inertia_body = Mat3::Zero();  // body frame, about the centre of mass
  Mat3 inv_inertia_world = Mat3::Zero(); // R * inv_inertia_body * R^T, refreshed by integration
  Material material;
  bool is_static = false;
};

// How an entity's broad-phase box is made (paper 3.2).
enum class BoxMode : std::uint8_t {
  Auto,     // chosen from the shape: Dynamic when elongated, else FixedCube
  FixedCube,  // cube big enough for any orientation; only moves with the centre
  Dynamic,    // tight AABB of the rotated root-level spheres, recomputed each tick
};

// EntitySpec::closed_faces (world.hpp); the static cover (src/core) keeps
// them. Bit of a node box's face in a per-node mask: body-frame axis 0..2, outward
// along +axis (positive) or -axis.
inline std::uint8_t faceBit(int axis, bool positive) {
  return static_cast<std::uint8_t>(1u << (2 * axis + (positive ? 0 : 1)));
}
constexpr std::uint8_t kAllFaces = 63;
// "+x", "-x", "+y", "-y", "+z", "-z" (body frame) -> their faceBits OR'ed;
// throws InputError("closed_faces") naming an unknown face.
std::uint8_t parseFaces(const std::vector<std::string>& names);
// The names of a mask's faces, in faceBit order (parseFaces' inverse).
std::vector<std::string> faceNames(std::uint8_t mask);

}  // namespace stc
