// Physical limits: what the world accepts as input, and what a body may reach
// during a tick before it is quarantined (removed at the end of the tick).
// Finite is not enough: 1e308 m/s is finite and turns a pose into NaN a few
// ticks later, a subnormal density makes 1/mass overflow on first contact.
#pragma once

#include "sphere_tree_collision/body.hpp"

#include <cstdint>

namespace stc {

struct PhysicalLimits {
  double max_speed = 1000.0;      // m/s, |linear velocity|
  double max_spin = 1000.0;       // rad/s, |angular velocity|
  double world_extent = 10000.0;  // m: each coordinate of a centre of mass within [-extent, extent]
  double min_density = 1e-3;      // kg/m^3 (aerogel is ~1; no subnormals, no 1/mass overflow)
  double max_density = 1e6;       // kg/m^3 (osmium is 22,600)
  double max_friction = 10.0;     // Coulomb coefficient
  double max_gravity = 1000.0;    // m/s^2, |gravity|
};

// Throws InputError naming the limit ("max_speed", ...) when one is not
// finite and > 0, or min_density > max_density.
void validateLimits(const PhysicalLimits& limits);

// What a mesh file (STL, OBJ, DAE: untrusted bytes, parsed by assimp) may
// hold; named as the node's parameters (~max_mesh_bytes ...). The file's size
// is checked before it is read, its vertices and triangles (every instance a
// scene's nodes draw) before they are copied; its grid is limited by
// VoxelLimits::max_voxels. assimp's memory while it parses is up to about 30
// times the file's size (an OBJ of 8 MiB of bare faces: 260 MB): the size
// bounds it. Defaults: a binary STL of 330,000 triangles passes.
struct MeshLimits {
  std::int64_t max_mesh_bytes = 16ll << 20;      // 16 MiB
  std::int64_t max_mesh_vertices = 3'000'000;   // over all the file's meshes
  std::int64_t max_mesh_triangles = 1'000'000;
};

// Throws InputError naming the limit ("max_mesh_bytes", ...) unless each is
// in [1, 2^31 - 1] (a vertex index is 32-bit).
void validateMeshLimits(const MeshLimits& limits);

// Throws InputError("gravity") when not finite or above max_gravity.
void validateGravity(const Vec3& gravity, const PhysicalLimits& limits);

// Throws InputError naming the field and the limit: "pose.orientation" (not
// a unit quaternion within 1e-3), "pose.position" (not finite or beyond world_extent), "linear_velocity" (max_speed), "angular_velocity"
// (max_spin), "density" (min_density..max_density), "material.restitution"
// ([0, 1]), "material.friction" ([0, max_friction]),
// "material.rolling_resistance" ([0, 1]).
void validateBodyInput(const Pose& pose, const Vec3& linear_velocity, const Vec3& angular_velocity,
                       double density, const Material& material, const PhysicalLimits& limits);

// Why a body leaving a tick must be removed; None when it is fine.
enum class Quarantine : std::uint8_t {
  None,
  NonFinite,  // position, orientation or a velocity is NaN or infinite
  TooFast,    // |linear velocity| > max_speed
  TooSpun,    // |angular velocity| > max_spin
  LeftWorld,  // centre of mass beyond world_extent (falling forever: not an error)
};
const char* toString(Quarantine reason);  // "non-finite state", ..., "left the world"
Quarantine quarantineReason(const BodyState& body, const PhysicalLimits& limits);

}  // namespace stc
