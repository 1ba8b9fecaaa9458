// Dynamics: semi-implicit Euler with unit quaternions and an energy-safe
// gyroscopic term.
#include "dynamics.hpp"

#include <cmath>

namespace stc {
namespace {

Mat3 skew(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// A multiple of the identity (sphere, cube): w x I w = 0, no gyroscopic work.
bool isIsotropic(const Mat3& m) {
  const double d = m(0, 0);
  const double tol = 1e-12 * std::abs(d);
  return std::abs(m(1, 1) - d) <= tol && std::abs(m(2, 2) - d) <= tol &&
         std::abs(m(0, 1)) <= tol && std::abs(m(0, 2)) <= tol && std::abs(m(1, 2)) <= tol;
}

constexpr int kNewtonIterations = 12;

}  // namespace

void refreshWorldInertia(BodyState& body) {
  if (body.is_static) {
    body.inv_inertia_world.setZero();
    return;
  }
  const Mat3 r = body.pose.orientation.toRotationMatrix();
  body.inv_inertia_world = r * body.inv_inertia_body * r.transpose();
}

Quat integrateOrientation(const Quat& q, const Vec3& w, double dt) {
  const double angle = w.norm() * dt;
  if (!(angle > 0.0)) return q;
  const Quat turn(Eigen::AngleAxisd(angle, w / w.norm()));
  return (turn * q).normalized();
}

FreeRotation rotateFreely(const BodyState& body, double dt, bool gyroscopic) {
  const Vec3& w = body.angular_velocity;
  FreeRotation out{body.pose.orientation, w};
  if (body.is_static || !(dt > 0.0) || w.isZero(0.0)) return out;
  out.orientation = integrateOrientation(body.pose.orientation, w, dt);  // w constant: exact
  if (!gyroscopic || isIsotropic(body.inv_inertia_body)) return out;
  const Mat3 inertia = body.inv_inertia_body.inverse();
  if (!inertia.allFinite()) return out;
  const Mat3 r = body.pose.orientation.toRotationMatrix();
  const Vec3 w0 = r.transpose() * w;  // body frame

  // Implicit midpoint: I (x - w0) + dt m x (I m) = 0, m = (w0 + x) / 2.
  Vec3 x = w0;
  bool converged = false;
  for (int it = 0; it < kNewtonIterations; ++it) {
    const Vec3 m = 0.5 * (w0 + x);
    const Vec3 im = inertia * m;
    const Vec3 f = inertia * (x - w0) + dt * m.cross(im);
    const Mat3 jacobian = inertia + 0.5 * dt * (skew(m) * inertia - skew(im));
    const Vec3 step = jacobian.partialPivLu().solve(f);
    if (!step.allFinite()) break;
    x -= step;
    if (step.norm() <= 1e-13 * w0.norm()) {
      converged = true;
      break;
    }
  }
  // A step too large for Newton: keep w turning about itself (energy exact)
  // rather than accept an unconverged guess.
  if (!converged || !x.allFinite()) return out;
  const double e0 = w0.dot(inertia * w0);
  const double e1 = x.dot(inertia * x);
  if (e1 > e0 && e1 > 0.0) x *= std::sqrt(e0 / e1);  // round-off never adds energy

  // The midpoint rule is L1 = cay(-dt m) L0 in the body frame; turning the
  // body by cay(dt m) (quaternion (1, dt m / 2)) keeps R L, the world
  // angular momentum, exactly.
  const Vec3 half = 0.5 * dt * (0.5 * (w0 + x));
  const Quat turn(1.0, half.x(), half.y(), half.z());
  out.orientation = (body.pose.orientation * turn.normalized()).normalized();
  out.angular_velocity = out.orientation * x;
  return out;
}

void integratePosition(BodyState& body, const IntegrationOptions& options, double dt) {
  if (body.is_static) return;
  body.pose.position += body.linear_velocity * dt;
  if (!body.angular_velocity.isZero(0.0)) {
    const FreeRotation turned = rotateFreely(body, dt, options.gyroscopic);
    body.pose.orientation = turned.orientation;
    body.angular_velocity = turned.angular_velocity;
    refreshWorldInertia(body);
  }
}

void integratePositions(std::vector<BodyState>& bodies, const IntegrationOptions& options, double dt) {
  for (BodyState& body : bodies) integratePosition(body, options, dt);
}

void integrateVelocity(BodyState& body, const IntegrationOptions& options, double dt) {
  if (options.gravity.isZero(0.0)) return;
  if (!body.is_static && body.inv_mass > 0.0) body.linear_velocity += options.gravity * dt;
}

void integrateVelocities(std::vector<BodyState>& bodies, const IntegrationOptions& options,
                         double dt) {
  for (BodyState& body : bodies) integrateVelocity(body, options, dt);
}

double kineticEnergy(const BodyState& body) {
  if (body.is_static || body.inv_mass <= 0.0) return 0.0;
  const Vec3& w = body.angular_velocity;
  const double rotational = w.isZero(0.0) ? 0.0 : w.dot(worldInertia(body) * w);
  return 0.5 * (body.linear_velocity.squaredNorm() / body.inv_mass + rotational);
}

double potentialEnergy(const BodyState& body, const Vec3& gravity) {
  if (body.is_static || body.inv_mass <= 0.0) return 0.0;
  return -gravity.dot(body.pose.position) / body.inv_mass;
}

double totalEnergy(const std::vector<BodyState>& bodies, const Vec3& gravity, double dt) {
  double e = 0.0;
  for (const BodyState& body : bodies) {
    e += kineticEnergy(body) + potentialEnergy(body, gravity);
    if (dt != 0.0 && !body.is_static && body.inv_mass > 0.0) {
      e -= gravity.dot(body.linear_velocity) * 0.5 * dt / body.inv_mass;
    }
  }
  return e;
}

Vec3 linearMomentum(const std::vector<BodyState>& bodies) {
  Vec3 p = Vec3::Zero();
  for (const BodyState& body : bodies) {
    if (!body.is_static && body.inv_mass > 0.0) p += body.linear_velocity / body.inv_mass;
  }
  return p;
}

Vec3 angularMomentum(const std::vector<BodyState>& bodies) {
  Vec3 l = Vec3::Zero();
  for (const BodyState& body : bodies) {
    if (body.is_static || body.inv_mass <= 0.0) continue;
    l += body.pose.position.cross(body.linear_velocity / body.inv_mass) +
         worldInertia(body) * body.angular_velocity;
  }
  return l;
}

Mat3 worldInertia(const BodyState& body) {
  if (body.is_static || body.inv_mass <= 0.0) return Mat3::Zero();
  const Mat3 r = body.pose.orientation.toRotationMatrix();
  return r * body.inv_inertia_body.inverse() * r.transpose();
}

bool isFinite(const BodyState& body) {
  return body.pose.position.allFinite() && body.pose.orientation.coeffs().allFinite() &&
         body.linear_velocity.allFinite() && body.angular_velocity.allFinite() &&
         body.inv_inertia_world.allFinite();
}

}  // namespace stc
