// The steps of one contact row that the solver's passes share (the default
// passes in contact_solver.cpp, the soft step in contact_solver_soft.cpp):
// relative velocity, friction clamped to its cone, the impulses along the
// normal, rolling resistance. Internal to src/core.
#pragma once

#include "contact_solver.hpp"

#include <cmath>

namespace stc {
namespace contact_rows {

#if defined(__GNUC__)
#define STC_HOT_INLINE inline __attribute__((always_inline))
#else
#define STC_HOT_INLINE inline
#endif

// Relative velocity of b's point to a's point.
STC_HOT_INLINE Vec3 relativeVelocity(const ContactSolver::Row& row, const Vec3& va, const Vec3& wa, const Vec3& vb,
                             const Vec3& wb) {
  return vb + wb.cross(row.rb) - va - wa.cross(row.ra);
}

// Friction of one row from the relative velocity now, clamped to the cone of
// its normal impulse so far (incl. the bounce); adds to its lambdas and
// returns the change along t1, t2.
STC_HOT_INLINE Eigen::Vector2d frictionStep(ContactSolver::Row& row, const Vec3& vrel, double mass_t1, double mass_t2) {
  const double limit = row.friction * (row.lambda[0] + row.bounce_impulse);
  const double t1 = row.lambda[1] - mass_t1 * vrel.dot(row.t1);
  const double t2 = row.lambda[2] - mass_t2 * vrel.dot(row.t2);
  const double tn = std::sqrt(t1 * t1 + t2 * t2);
  const double scale = tn > limit ? (tn > 0.0 ? limit / tn : 0.0) : 1.0;
  const Eigen::Vector2d delta(t1 * scale - row.lambda[1], t2 * scale - row.lambda[2]);
  row.lambda[1] += delta.x();
  row.lambda[2] += delta.y();
  return delta;
}

// Impulse `d1` along t1 plus `d2` along t2 (b gets +, a gets -).
STC_HOT_INLINE void applyFriction(const ContactSolver::Row& row, double d1, double d2, ContactSolver::Motion& a,
                          ContactSolver::Motion& b) {
  const Vec3 p = d1 * row.t1 + d2 * row.t2;
  a.v -= row.inv_ma * p;
  b.v += row.inv_mb * p;
  a.w -= d1 * row.ang_a[1] + d2 * row.ang_a[2];
  b.w += d1 * row.ang_b[1] + d2 * row.ang_b[2];
}

STC_HOT_INLINE void applyNormal(const ContactSolver::Row& row, double impulse, ContactSolver::Motion& a,
                        ContactSolver::Motion& b) {
  a.v -= row.inv_ma * impulse * row.n;
  b.v += row.inv_mb * impulse * row.n;
  a.w -= impulse * row.ang_a[0];
  b.w += impulse * row.ang_b[0];
}

// m v with its sums in a fixed order, the one Eigen's Matrix3d * Vector3d
// takes with SSE2 (rows 0 and 1 as a packet, column by column; row 2 as a
// reduction split in halves), written out so that the four-wide passes
// (contact_solver_wide.cpp, `times`) can follow it whatever Eigen does on
// another target.
STC_HOT_INLINE Vec3 timesInOrder(const Mat3& m, const Vec3& v) {
  return Vec3((m(0, 0) * v.x() + m(0, 1) * v.y()) + m(0, 2) * v.z(), (m(1, 0) * v.x() + m(1, 1) * v.y()) + m(1, 2) * v.z(),
              m(2, 0) * v.x() + (m(2, 1) * v.y() + m(2, 2) * v.z()));
}

// One step of a pair's rolling resistance: the angular impulse that stops
// the bodies' relative spin, its sum held within per_normal times the
// pair's normal impulse so far (a ball of the cone, as friction's).
STC_HOT_INLINE void rollingStep(ContactSolver::Rolling& roll, double normal, const Vec3& wa, const Vec3& wb,
                                ContactSolver::Motion& out_a, ContactSolver::Motion& out_b) {
  const double limit = roll.per_normal * normal;
  Vec3 lambda = roll.lambda - timesInOrder(roll.mass, wb - wa);
  const double norm = std::sqrt((lambda.x() * lambda.x() + lambda.y() * lambda.y()) + lambda.z() * lambda.z());
  if (norm > limit) lambda *= norm > 0.0 ? limit / norm : 0.0;
  const Vec3 delta = lambda - roll.lambda;
  roll.lambda = lambda;
  out_a.w -= timesInOrder(roll.inv_ia, delta);
  out_b.w += timesInOrder(roll.inv_ib, delta);
}

}  // namespace contact_rows

// The passes' walk over manifolds (contact_solver.hpp: overManifolds).
template <typename Step>
void ContactSolver::overManifolds(std::size_t first, std::size_t end, std::vector<Motion>& motion, Step&& step) {
  overManifolds(first, end, motion, step, [](std::size_t, Motion&, Motion&) {});
}

template <typename Step, typename After>
void ContactSolver::overManifolds(std::size_t first, std::size_t end, std::vector<Motion>& motion, Step&& step,
                                  After&& after) {
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::vector<SolverGroup>& manifolds = plan_.manifolds();
  for (std::size_t m = first; m < end; ++m) {
    const std::uint32_t begin = manifold_start[m];
    const std::uint32_t stop = manifold_start[m + 1];
    const std::uint32_t ia = rows_[begin].a;
    const std::uint32_t ib = rows_[begin].b;
    Motion a = motion[ia];
    Motion b = motion[ib];
    for (std::uint32_t r = begin; r < stop; ++r) step(r, a, b);
    after(m, a, b);
    if (manifolds[m].a != SolverGroup::kStatic) motion[ia] = a;
    if (manifolds[m].b != SolverGroup::kStatic) motion[ib] = b;
  }
}

}  // namespace stc
