// Rigid-body state of one entity, stored in the World's flat array.
#pragma once

#include "sphere_tree_collision/types.hpp"

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

}  // namespace stc
