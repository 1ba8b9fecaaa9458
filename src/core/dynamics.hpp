// Dynamics: semi-implicit Euler integration of rigid bodies (unit quaternions,
// world inertia from the body inertia and orientation), plus the energy and
// momentum measures the tests and the stability bench use.
//
// Order inside a tick (World::integrate): positions first with the velocities
// the last response produced (with the torque-free rotation, which changes w
// too), then gravity. The
// response then corrects those velocities at the new poses, and the next tick
// moves with them: v(n+1) = v(n) + g dt + impulses, x(n+1) = x(n) + v(n+1) dt,
// i.e. symplectic Euler with the tick boundary between solve and move.
#pragma once

#include "sphere_tree_collision/body.hpp"

#include <vector>

namespace stc {

struct IntegrationOptions {
  Vec3 gravity = Vec3::Zero();  // zero: no gravity work at all
  // Gyroscopic term (see rotateFreely). Off: the world angular velocity stays
  // constant between contacts (energy exact; angular momentum of an
  // asymmetric body not conserved, no tumbling).
  bool gyroscopic = true;
};

// R * inv_inertia_body * R^T from the current orientation (zero for static bodies).
void refreshWorldInertia(BodyState& body);

// Exact exponential map: rotate q by |w| dt about w (world frame), normalised.
// Exact for a constant w, where q += 0.5 (0,w) q dt loses 2 atan(|w|dt/2) vs
// |w| dt of the angle per tick (0.2 rad at 100 rad/s and 60 Hz).
Quat integrateOrientation(const Quat& q, const Vec3& w, double dt);

// Torque-free rotation over dt (Euler's equations I dw/dt + w x I w = 0 in
// the body frame). Isotropic bodies (cube, sphere) or gyroscopic = false: w is
// constant and the orientation turns by the exact exponential map. Otherwise
// the implicit midpoint rule, solved by Newton's method, gives the new body
// angular velocity, and the orientation turns by the Cayley map of the
// midpoint angular velocity: that pair conserves the kinetic energy and the
// world angular momentum exactly (a final clamp keeps round-off from adding
// energy). An explicit w x Iw term gains energy; the price here is a phase
// lag at large |w| dt (angle 2 atan(|w| dt / 2) instead of |w| dt per tick).
struct FreeRotation {
  Quat orientation;
  Vec3 angular_velocity;  // world frame
};
FreeRotation rotateFreely(const BodyState& body, double dt, bool gyroscopic = true);

// x += v dt; orientation and angular velocity by rotateFreely; world inertia
// refreshed. Static bodies untouched.
void integratePosition(BodyState& body, const IntegrationOptions& options, double dt);
void integratePositions(std::vector<BodyState>& bodies, const IntegrationOptions& options, double dt);
// v += g dt for movable bodies; nothing at all when gravity is zero.
void integrateVelocity(BodyState& body, const IntegrationOptions& options, double dt);
void integrateVelocities(std::vector<BodyState>& bodies, const IntegrationOptions& options,
                         double dt);

// Measures (static bodies count as infinite mass at rest: zero energy/momentum).
double kineticEnergy(const BodyState& body);
// -m g.x: zero when gravity is zero.
double potentialEnergy(const BodyState& body, const Vec3& gravity);
// Kinetic + potential. After World::step the poses were moved with the
// previous velocities and the velocities then updated, so positions lag
// the velocities by half a tick: pass the tick's dt to take the potential at
// x + v dt/2, which free fall conserves exactly (dt = 0: plain x).
double totalEnergy(const std::vector<BodyState>& bodies, const Vec3& gravity, double dt = 0.0);
Vec3 linearMomentum(const std::vector<BodyState>& bodies);
// About the world origin: sum of x cross m v + I w.
Vec3 angularMomentum(const std::vector<BodyState>& bodies);
// Body inertia (inverse of inv_inertia_body) in world axes; zero for static bodies.
Mat3 worldInertia(const BodyState& body);
// True when pose, velocities and world inertia are all finite.
bool isFinite(const BodyState& body);

}  // namespace stc
