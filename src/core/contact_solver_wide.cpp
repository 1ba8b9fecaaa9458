// The solver's sequential passes (velocity, shock propagation, position by
// translation, position shock) four manifolds at a time. A row step is a
// short run of scalar operations; four manifolds that share no movable body
// go through the same operations side by side, one lane each, in vector
// registers. The operations and their order are those of relaxRow and
// pushStep (contact_solver.cpp), with no fused multiply-add (CMakeLists.txt),
// so each lane computes the one-at-a-time result bit for bit.
#include "contact_solver.hpp"

#include "grow_capacity.hpp"

#include <cmath>
#include <cstring>

// The vector types below never cross a call that is not inlined, so the
// ABI note about passing them without AVX does not apply.
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

namespace stc {

namespace {

constexpr std::uint32_t kLanes = WideBatches::kLanes;
using WideRow = WideBatches::Row;
using WideShockMass = WideBatches::ShockMass;
using WidePush = WideBatches::Push;
using WideBatch = WideBatches::Batch;
using WideRolling = WideBatches::Rolling;
static_assert(kLanes == 4, "the lane types below are four doubles wide");

// Four doubles, and a lane mask of the same width (GCC/Clang vector types:
// SSE2 pairs by default, one AVX2 register in the avx2 clone below).
typedef double Wide __attribute__((vector_size(32)));
typedef long long WideMask __attribute__((vector_size(32)));

// Everything below is inlined into the batch loops, so it is compiled for their clones.
#define STC_WIDE inline __attribute__((always_inline))

struct Wide3 {
  Wide x, y, z;
};

STC_WIDE Wide load(const double* p) {
  Wide v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
STC_WIDE void store(double* p, const Wide& v) { std::memcpy(p, &v, sizeof v); }
STC_WIDE Wide3 load3(const double (&p)[3][kLanes]) { return {load(p[0]), load(p[1]), load(p[2])}; }

// The same expressions, and order, as Eigen's Vector3d cross and dot.
STC_WIDE Wide3 cross(const Wide3& u, const Wide3& v) {
  return {u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
}
STC_WIDE Wide dot(const Wide3& u, const Wide3& v) { return (u.x * v.x + u.y * v.y) + u.z * v.z; }

// Both bodies' velocities of every lane.
struct WideMotion {
  Wide3 va, wa, vb, wb;
};

// relativeVelocity (contact_solver.cpp): vb + wb x rb - va - wa x ra.
STC_WIDE Wide3 relativeVelocity(const WideMotion& m, const Wide3& ra, const Wide3& rb) {
  const Wide3 cb = cross(m.wb, rb);
  const Wide3 ca = cross(m.wa, ra);
  return {((m.vb.x + cb.x) - m.va.x) - ca.x, ((m.vb.y + cb.y) - m.va.y) - ca.y,
          ((m.vb.z + cb.z) - m.va.z) - ca.z};
}

STC_WIDE Wide select(const WideMask& on, const Wide& yes, const Wide& no) { return on ? yes : no; }
STC_WIDE Wide3 select(const WideMask& on, const Wide3& yes, const Wide3& no) {
  return {on ? yes.x : no.x, on ? yes.y : no.y, on ? yes.z : no.z};
}

// A batch's lanes: which have a row in a slot, and which bodies shock
// propagation moves (the others it holds).
struct LaneMasks {
  WideMask rows, move_a, move_b;
  STC_WIDE explicit LaneMasks(const WideBatch& batch) {
    for (std::uint32_t l = 0; l < kLanes; ++l) {
      rows[l] = batch.manifold_rows[l];
      move_a[l] = batch.move_a[l] ? -1 : 0;
      move_b[l] = batch.move_b[l] ? -1 : 0;
    }
  }
  STC_WIDE WideMask withRow(std::uint32_t slot) const {
    const WideMask at = {slot, slot, slot, slot};
    return rows > at;
  }
};

// What an impulse of squared length `squared` is scaled by to stay within
// `limit` (a cone's, friction's and rolling's): 1 inside, limit / length beyond.
STC_WIDE Wide coneScale(const Wide& squared, const Wide& limit) {
  const Wide zero = {0.0, 0.0, 0.0, 0.0};
  const Wide one = {1.0, 1.0, 1.0, 1.0};
  Wide length = squared;
  for (std::uint32_t l = 0; l < kLanes; ++l) length[l] = std::sqrt(squared[l]);
  return length > limit ? (length > zero ? limit / length : zero) : one;
}

// relaxRow for the lanes `on`, with the effective masses `mass`: friction,
// then non-penetration. Body A's velocities change only in the lanes on_a,
// B's in on_b (shock propagation holds a supporting body still).
STC_WIDE void relaxWide(WideRow& row, const double (&mass)[3][kLanes], const WideMask& on,
                        const WideMask& on_a, const WideMask& on_b, WideMotion& m) {
  const Wide zero = {0.0, 0.0, 0.0, 0.0};
  const Wide3 ra = load3(row.ra), rb = load3(row.rb);
  const Wide3 n = load3(row.n), t1 = load3(row.t1);
  const Wide3 t2 = cross(n, t1);  // as tangentBasis made it
  const Wide inv_ma = load(row.inv_ma), inv_mb = load(row.inv_mb);
  Wide lambda0 = load(row.lambda[0]), lambda1 = load(row.lambda[1]), lambda2 = load(row.lambda[2]);

  // frictionStep
  const Wide3 vrel = relativeVelocity(m, ra, rb);
  const Wide limit = load(row.friction) * (lambda0 + load(row.bounce_impulse));
  const Wide f1 = lambda1 - load(mass[1]) * dot(vrel, t1);
  const Wide f2 = lambda2 - load(mass[2]) * dot(vrel, t2);
  const Wide scale = coneScale(f1 * f1 + f2 * f2, limit);
  const Wide d1 = select(on, f1 * scale - lambda1, zero);
  const Wide d2 = select(on, f2 * scale - lambda2, zero);
  lambda1 = lambda1 + d1;
  lambda2 = lambda2 + d2;

  // applyFriction
  const Wide3 p = {d1 * t1.x + d2 * t2.x, d1 * t1.y + d2 * t2.y, d1 * t1.z + d2 * t2.z};
  const Wide3 a1 = load3(row.ang_a[1]), a2 = load3(row.ang_a[2]);
  const Wide3 b1 = load3(row.ang_b[1]), b2 = load3(row.ang_b[2]);
  const auto applyFriction = [&](Wide3& v, Wide3& w, const Wide& inv_m, const Wide3& k1, const Wide3& k2,
                                 bool minus, const WideMask& on) __attribute__((always_inline)) {
    const Wide3 dv = {inv_m * p.x, inv_m * p.y, inv_m * p.z};
    const Wide3 dw = {d1 * k1.x + d2 * k2.x, d1 * k1.y + d2 * k2.y, d1 * k1.z + d2 * k2.z};
    if (minus) {
      v = select(on, Wide3{v.x - dv.x, v.y - dv.y, v.z - dv.z}, v);
      w = select(on, Wide3{w.x - dw.x, w.y - dw.y, w.z - dw.z}, w);
    } else {
      v = select(on, Wide3{v.x + dv.x, v.y + dv.y, v.z + dv.z}, v);
      w = select(on, Wide3{w.x + dw.x, w.y + dw.y, w.z + dw.z}, w);
    }
  };
  applyFriction(m.va, m.wa, inv_ma, a1, a2, true, on_a);
  applyFriction(m.vb, m.wb, inv_mb, b1, b2, false, on_b);

  // Non-penetration, from the relative velocity after the friction impulse.
  const Wide vn = dot(relativeVelocity(m, ra, rb), n);
  const Wide target = lambda0 + load(mass[0]) * (-load(row.speculative) - vn);
  const Wide normal = zero < target ? target : zero;  // std::max(0.0, target)
  const Wide dn = select(on, normal - lambda0, zero);
  lambda0 = select(on, normal, lambda0);

  // applyNormal
  const Wide3 a0 = load3(row.ang_a[0]), b0 = load3(row.ang_b[0]);
  const Wide ka = inv_ma * dn, kb = inv_mb * dn;
  m.va = select(on_a, Wide3{m.va.x - ka * n.x, m.va.y - ka * n.y, m.va.z - ka * n.z}, m.va);
  m.vb = select(on_b, Wide3{m.vb.x + kb * n.x, m.vb.y + kb * n.y, m.vb.z + kb * n.z}, m.vb);
  m.wa = select(on_a, Wide3{m.wa.x - dn * a0.x, m.wa.y - dn * a0.y, m.wa.z - dn * a0.z}, m.wa);
  m.wb = select(on_b, Wide3{m.wb.x + dn * b0.x, m.wb.y + dn * b0.y, m.wb.z + dn * b0.z}, m.wb);

  store(row.lambda[0], lambda0);
  store(row.lambda[1], lambda1);
  store(row.lambda[2], lambda2);
}

// A lane's 3x3 matrix times a vector, in timesInOrder's order (contact_rows.hpp).
STC_WIDE Wide3 times(const double (&m)[3][3][kLanes], const Wide3& v) {
  const auto mul = [&](int i, int j, const Wide& x) __attribute__((always_inline)) { return load(m[i][j]) * x; };
  return {(mul(0, 0, v.x) + mul(0, 1, v.y)) + mul(0, 2, v.z), (mul(1, 0, v.x) + mul(1, 1, v.y)) + mul(1, 2, v.z),
          mul(2, 0, v.x) + (mul(2, 1, v.y) + mul(2, 2, v.z))};
}

// rollingStep (contact_rows.hpp) for the lanes `on`, the pair's normal
// impulse so far `normal`.
STC_WIDE void rollWide(WideRolling& roll, const Wide& normal, const WideMask& on, WideMotion& m) {
  const Wide limit = load(roll.per_normal) * normal;
  const Wide3 old = load3(roll.lambda);
  const Wide3 spin = times(roll.mass, Wide3{m.wb.x - m.wa.x, m.wb.y - m.wa.y, m.wb.z - m.wa.z});
  Wide3 lambda = {old.x - spin.x, old.y - spin.y, old.z - spin.z};
  const Wide scale = coneScale(dot(lambda, lambda), limit);
  lambda = {lambda.x * scale, lambda.y * scale, lambda.z * scale};
  const Wide3 delta = {lambda.x - old.x, lambda.y - old.y, lambda.z - old.z};
  const Wide3 da = times(roll.inv_ia, delta), db = times(roll.inv_ib, delta);
  m.wa = select(on, Wide3{m.wa.x - da.x, m.wa.y - da.y, m.wa.z - da.z}, m.wa);
  m.wb = select(on, Wide3{m.wb.x + db.x, m.wb.y + db.y, m.wb.z + db.z}, m.wb);
  store(roll.lambda[0], select(on, lambda.x, old.x));
  store(roll.lambda[1], select(on, lambda.y, old.y));
  store(roll.lambda[2], select(on, lambda.z, old.z));
}

// How many batches ahead a pass asks for the bodies it will read. A body's
// velocity is a line of its own that the other thread may have written last
// stage (cores far apart: a few hundred ns each) and, on a large pile, out of
// the cache; a pass that waits for them one batch at a time stalls on each.
constexpr std::size_t kBodiesAhead = 2;

// Asks for one body's line: for writing when the pass writes it, so it
// arrives owned; a static body's, which threads only read, for reading (the
// hint must be a constant, hence the branch).
STC_WIDE void prefetchMotion(const ContactSolver::Motion& body, bool for_writing) {
  if (for_writing) {
    __builtin_prefetch(&body, 1);
  } else {
    __builtin_prefetch(&body, 0);
  }
}

// Asks for the lines of a batch's bodies.
STC_WIDE void prefetchBodies(const WideBatch& ahead, const ContactSolver::Motion* motion) {
  for (std::uint32_t l = 0; l < ahead.lanes; ++l) {
    prefetchMotion(motion[ahead.body_a[l]], ahead.write_a[l]);
    prefetchMotion(motion[ahead.body_b[l]], ahead.write_b[l]);
  }
}

// One pass over batches: the velocity iterations' (kShock false) or shock
// propagation's, with the supporting bodies held (kShock).
template <bool kShock>
STC_WIDE void relaxBatchesOf(WideRow* wide_rows, const WideShockMass* shock_mass,
                             WideRolling* rolling, const WideBatch* batch,
                             std::size_t count, ContactSolver::Motion* motion) {
  for (std::size_t k = 0; k < count; ++k, ++batch) {
    if (k + kBodiesAhead < count) prefetchBodies(batch[kBodiesAhead], motion);
    WideMotion m{};
    for (std::uint32_t l = 0; l < batch->lanes; ++l) {
      const ContactSolver::Motion& a = motion[batch->body_a[l]];
      const ContactSolver::Motion& b = motion[batch->body_b[l]];
      m.va.x[l] = a.v.x(), m.va.y[l] = a.v.y(), m.va.z[l] = a.v.z();
      m.wa.x[l] = a.w.x(), m.wa.y[l] = a.w.y(), m.wa.z[l] = a.w.z();
      m.vb.x[l] = b.v.x(), m.vb.y[l] = b.v.y(), m.vb.z[l] = b.v.z();
      m.wb.x[l] = b.w.x(), m.wb.y[l] = b.w.y(), m.wb.z[l] = b.w.z();
    }
    const LaneMasks lanes(*batch);
    for (std::uint32_t s = 0; s < batch->rows; ++s) {
      const WideMask on = lanes.withRow(s);
      WideRow& row = wide_rows[batch->first_row + s];
      if (kShock) {
        relaxWide(row, shock_mass[batch->first_row + s].mass, on, on & lanes.move_a, on & lanes.move_b, m);
      } else {
        relaxWide(row, row.mass, on, on, on, m);
      }
    }
    // Each pair's rolling resistance after its rows, its normal impulse
    // summed over its rows as ContactSolver::normalImpulse sums it.
    if (rolling != nullptr) {
      const Wide zero = {0.0, 0.0, 0.0, 0.0};
      Wide normal = zero;
      for (std::uint32_t s = 0; s < batch->rows; ++s) {
        const WideRow& row = wide_rows[batch->first_row + s];
        normal = select(lanes.withRow(s), normal + (load(row.lambda[0]) + load(row.bounce_impulse)), normal);
      }
      WideRolling& roll = rolling[k];
      rollWide(roll, normal, load(roll.per_normal) != zero, m);
    }
    for (std::uint32_t l = 0; l < batch->lanes; ++l) {
      if (batch->write_a[l]) {
        ContactSolver::Motion& a = motion[batch->body_a[l]];
        a.v = Vec3(m.va.x[l], m.va.y[l], m.va.z[l]);
        a.w = Vec3(m.wa.x[l], m.wa.y[l], m.wa.z[l]);
      }
      if (batch->write_b[l]) {
        ContactSolver::Motion& b = motion[batch->body_b[l]];
        b.v = Vec3(m.vb.x[l], m.vb.y[l], m.vb.z[l]);
        b.w = Vec3(m.wb.x[l], m.wb.y[l], m.wb.z[l]);
      }
    }
  }
}

// pushStep by translation alone (contact_solver.cpp) for the lanes `on`,
// with the effective masses `mass`; A moves in the lanes on_a, B in on_b.
STC_WIDE void pushWide(WidePush& row, const double (&mass)[kLanes], const WideMask& on,
                       const WideMask& on_a, const WideMask& on_b, Wide3& va, Wide3& vb) {
  const Wide zero = {0.0, 0.0, 0.0, 0.0};
  const Wide3 n = load3(row.n);
  const Wide lambda = load(row.lambda);
  const Wide vn = dot(Wide3{vb.x - va.x, vb.y - va.y, vb.z - va.z}, n);
  const Wide unclamped = lambda + load(mass) * (load(row.push) - vn);
  WideMask pull;
  std::memcpy(&pull, row.pull, sizeof pull);
  const Wide normal = pull ? unclamped : (zero < unclamped ? unclamped : zero);
  const Wide delta = select(on, normal - lambda, zero);
  store(row.lambda, select(on, normal, lambda));
  const Wide ka = load(row.inv_ma) * delta, kb = load(row.inv_mb) * delta;
  va = select(on_a, Wide3{va.x - ka * n.x, va.y - ka * n.y, va.z - ka * n.z}, va);
  vb = select(on_b, Wide3{vb.x + kb * n.x, vb.y + kb * n.y, vb.z + kb * n.z}, vb);
}

// One split-impulse pass over batches (pseudo-velocities, translation
// alone): the position iterations' (kShock false) or the position shock
// sweep's, with the supporting bodies held (kShock).
template <bool kShock>
STC_WIDE void pushBatchesOf(WidePush* wide_rows, const WideBatch* batch,
                            std::size_t count, ContactSolver::Motion* pseudo) {
  for (std::size_t k = 0; k < count; ++k, ++batch) {
    if (k + kBodiesAhead < count) prefetchBodies(batch[kBodiesAhead], pseudo);
    Wide3 va{}, vb{};
    for (std::uint32_t l = 0; l < batch->lanes; ++l) {
      const Vec3& a = pseudo[batch->body_a[l]].v;
      const Vec3& b = pseudo[batch->body_b[l]].v;
      va.x[l] = a.x(), va.y[l] = a.y(), va.z[l] = a.z();
      vb.x[l] = b.x(), vb.y[l] = b.y(), vb.z[l] = b.z();
    }
    const LaneMasks lanes(*batch);
    for (std::uint32_t s = 0; s < batch->rows; ++s) {
      const WideMask on = lanes.withRow(s);
      WidePush& row = wide_rows[batch->first_row + s];
      if (kShock) {
        pushWide(row, row.shock_mass, on, on & lanes.move_a, on & lanes.move_b, va, vb);
      } else {
        pushWide(row, row.mass, on, on, on, va, vb);
      }
    }
    for (std::uint32_t l = 0; l < batch->lanes; ++l) {
      if (batch->write_a[l]) pseudo[batch->body_a[l]].v = Vec3(va.x[l], va.y[l], va.z[l]);
      if (batch->write_b[l]) pseudo[batch->body_b[l]].v = Vec3(vb.x[l], vb.y[l], vb.z[l]);
    }
  }
}

// Compiled for AVX2 too where the compiler can pick at load time (the same
// operations either way, no FMA: the same bits). Not under ThreadSanitizer:
// the loader runs the clones' resolver before the sanitizer is up, and it crashes.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__) && !defined(__SANITIZE_THREAD__)
#define STC_WIDE_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define STC_WIDE_CLONES
#endif

STC_WIDE_CLONES void relaxBatches(WideRow* wide_rows, WideRolling* rolling,
                                  const WideBatch* batch, std::size_t count,
                                  ContactSolver::Motion* motion) {
  relaxBatchesOf<false>(wide_rows, nullptr, rolling, batch, count, motion);
}

STC_WIDE_CLONES void shockBatches(WideRow* wide_rows, const WideShockMass* shock_mass,
                                  const WideBatch* batch, std::size_t count,
                                  ContactSolver::Motion* motion) {
  relaxBatchesOf<true>(wide_rows, shock_mass, nullptr, batch, count, motion);
}

STC_WIDE_CLONES void pushBatches(WidePush* wide_rows, const WideBatch* batch,
                                 std::size_t count, ContactSolver::Motion* pseudo) {
  pushBatchesOf<false>(wide_rows, batch, count, pseudo);
}

STC_WIDE_CLONES void shockPushBatches(WidePush* wide_rows, const WideBatch* batch,
                                      std::size_t count, ContactSolver::Motion* pseudo) {
  pushBatchesOf<true>(wide_rows, batch, count, pseudo);
}

}  // namespace

void ContactSolver::packWide(std::size_t first, std::size_t end) {
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::vector<WideBatch>& batches = wide_batches_.batches();
  std::vector<WideRow>& wide_rows = wide_batches_.rows();
  std::vector<WideShockMass>& shock_mass = wide_batches_.shockMass();
  for (std::size_t k = first; k < end; ++k) {
    const WideBatch& batch = batches[k];
    for (std::uint32_t s = 0; s < batch.rows; ++s) {
      WideRow& wide = wide_rows[batch.first_row + s];
      WideShockMass& shock = shock_mass[batch.first_row + s];
      std::memset(&wide, 0, sizeof wide);
      std::memset(&shock, 0, sizeof shock);
      for (std::uint32_t l = 0; l < batch.lanes; ++l) {
        if (s >= batch.manifold_rows[l]) continue;
        const Row& row = rows_[manifold_start[batch.manifold[l]] + s];
        const RowInfo& info = info_[manifold_start[batch.manifold[l]] + s];
        for (int i = 0; i < 3; ++i) {
          wide.ra[i][l] = row.ra[i];
          wide.rb[i][l] = row.rb[i];
          wide.n[i][l] = row.n[i];
          wide.t1[i][l] = row.t1[i];
          for (int d = 0; d < 3; ++d) {
            wide.ang_a[d][i][l] = row.ang_a[d][i];
            wide.ang_b[d][i][l] = row.ang_b[d][i];
          }
          wide.mass[i][l] = row.mass[i];
          shock.mass[i][l] = info.shock_mass[i];
          wide.lambda[i][l] = row.lambda[i];
        }
        wide.inv_ma[l] = row.inv_ma;
        wide.inv_mb[l] = row.inv_mb;
        wide.friction[l] = row.friction;
        wide.speculative[l] = row.speculative;
        wide.bounce_impulse[l] = row.bounce_impulse;
      }
    }
    if (!any_rolling_) continue;
    WideRolling& wide = wide_batches_.rolling()[k];
    std::memset(&wide, 0, sizeof wide);
    for (std::uint32_t l = 0; l < batch.lanes; ++l) {
      const Rolling& roll = rolling_[batch.manifold[l]];
      wide.per_normal[l] = roll.per_normal;
      for (int i = 0; i < 3; ++i) {
        wide.lambda[i][l] = roll.lambda[i];
        for (int j = 0; j < 3; ++j) {
          wide.mass[i][j][l] = roll.mass(i, j);
          wide.inv_ia[i][j][l] = roll.inv_ia(i, j);
          wide.inv_ib[i][j][l] = roll.inv_ib(i, j);
        }
      }
    }
  }
}

void ContactSolver::packWidePush(std::size_t first, std::size_t end) {
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::vector<WideBatch>& batches = wide_batches_.batches();
  std::vector<WidePush>& push = wide_batches_.push();
  for (std::size_t k = first; k < end; ++k) {
    const WideBatch& batch = batches[k];
    for (std::uint32_t s = 0; s < batch.rows; ++s) {
      WidePush& wide = push[batch.first_row + s];
      std::memset(&wide, 0, sizeof wide);
      for (std::uint32_t l = 0; l < batch.lanes; ++l) {
        if (s >= batch.manifold_rows[l]) continue;
        const std::uint32_t r = manifold_start[batch.manifold[l]] + s;
        const Row& row = rows_[r];
        const RowInfo& info = info_[r];
        for (int i = 0; i < 3; ++i) wide.n[i][l] = row.n[i];
        wide.inv_ma[l] = row.inv_ma;
        wide.inv_mb[l] = row.inv_mb;
        wide.push[l] = info.push;
        wide.mass[l] = info.push_mass;
        wide.shock_mass[l] = info.shock_push_mass;
        wide.lambda[l] = info.lambda_push;
        wide.pull[l] = info.bounced && info.push < 0.0 ? -1 : 0;
      }
    }
  }
}

void ContactSolver::unpackWide(std::size_t first, std::size_t end) {
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::vector<WideBatch>& batches = wide_batches_.batches();
  const std::vector<WideRow>& wide_rows = wide_batches_.rows();
  for (std::size_t k = first; k < end; ++k) {
    const WideBatch& batch = batches[k];
    for (std::uint32_t l = 0; l < batch.lanes; ++l) {
      for (std::uint32_t s = 0; s < batch.manifold_rows[l]; ++s) {
        const WideRow& wide = wide_rows[batch.first_row + s];
        Row& row = rows_[manifold_start[batch.manifold[l]] + s];
        for (int i = 0; i < 3; ++i) row.lambda[i] = wide.lambda[i][l];
      }
    }
    if (!any_rolling_) continue;
    const WideRolling& wide = wide_batches_.rolling()[k];
    for (std::uint32_t l = 0; l < batch.lanes; ++l) {
      Rolling& roll = rolling_[batch.manifold[l]];
      roll.lambda = Vec3(wide.lambda[0][l], wide.lambda[1][l], wide.lambda[2][l]);  // unchanged in a lane without it
    }
  }
}

void ContactSolver::propagateShockWide(int passes) {
  WideRow* rows = wide_batches_.rows().data();
  const WideShockMass* shock_mass = wide_batches_.shockMass().data();
  const WideBatch* batches = wide_batches_.batches().data();
  for (std::size_t level = 0; level < plan_.shockLevels(); ++level) {
    for (int pass = 0; pass < passes; ++pass) {
      plan_.forEachStageBatchesOfLevel(level, wide_batches_.starts(), [&](std::size_t first, std::size_t end) {
        shockBatches(rows, shock_mass, batches + first, end - first, motion_.data());
      });
    }
  }
}

void ContactSolver::solvePositionsWide() {
  WidePush* push = wide_batches_.push().data();
  const WideBatch* batches = wide_batches_.batches().data();
  plan_.forEachStageBatches(wide_batches_.starts(), [&](std::size_t first, std::size_t end) {
    pushBatches(push, batches + first, end - first, pseudo_.data());
  });
}

void ContactSolver::propagatePositionShockWide() {
  WidePush* push = wide_batches_.push().data();
  const WideBatch* batches = wide_batches_.batches().data();
  for (std::size_t level = 0; level < plan_.shockLevels(); ++level) {
    plan_.forEachStageBatchesOfLevel(level, wide_batches_.starts(), [&](std::size_t first, std::size_t end) {
      shockPushBatches(push, batches + first, end - first, pseudo_.data());
    });
  }
}

void ContactSolver::solveVelocitiesWide(int passes) {
  WideRow* rows = wide_batches_.rows().data();
  WideRolling* rolling = any_rolling_ ? wide_batches_.rolling().data() : nullptr;
  const WideBatch* batches = wide_batches_.batches().data();
  for (int it = 0; it < passes; ++it) {
    plan_.forEachStageBatches(wide_batches_.starts(), [&](std::size_t first, std::size_t end) {
      relaxBatches(rows, rolling != nullptr ? rolling + first : nullptr, batches + first, end - first, motion_.data());
    });
  }
}

}  // namespace stc
