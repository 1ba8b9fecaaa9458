// Impulse solver: non-penetration + Coulomb friction, restitution, split-impulse
// position correction; sequential (Gauss-Seidel) or simultaneous (Jacobi).
#include "contact_solver.hpp"

#include "dynamics.hpp"
#include "contact_rows.hpp"
#include "grow_capacity.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

namespace stc {

using namespace contact_rows;

void tangentBasis(const Vec3& n, Vec3& t1, Vec3& t2) {
  t1 = std::abs(n.x()) < 0.57735 ? Vec3(0.0, n.z(), -n.y()) : Vec3(n.y(), -n.x(), 0.0);
  t1.normalize();
  t2 = n.cross(t1);
}

namespace {

constexpr int kUnreached = std::numeric_limits<int>::max();
// How many rows ahead preparing them asks for their contacts and bodies.
constexpr std::size_t kRowsAhead = 8;
constexpr std::size_t kRowsPerTask = 256;       // rows prepared by one task, at least
constexpr std::size_t kManifoldsPerTask = 128;  // manifolds' rolling resistance or cache, at least
// A restitution wave's stage goes to the team from this many rows per
// manifold a solver stage needs (a bounce step is about a row's work).
constexpr std::size_t kWaveRowsPerManifold = 4;
// A pair's points kept for the warm start: one bit each in warmStart's `used`.
constexpr std::uint32_t kCachedPointsPerPair = WarmStartCache::kMaxPoints;
static_assert(kCachedPointsPerPair <= 32, "warmStart's `used` has 32 bits");

// Appends to `out`, ascending, the indices whose flag is set; eight flags
// at a time, as a wave's rows are few among many.
void appendFlagged(const std::vector<std::uint8_t>& flags, std::vector<std::uint32_t>& out) {
  const std::size_t n = flags.size();
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, flags.data() + i, sizeof word);
    if (word == 0) continue;
    for (std::size_t k = i; k < i + 8; ++k) {
      if (flags[k] != 0) out.push_back(static_cast<std::uint32_t>(k));
    }
  }
  for (; i < n; ++i) {
    if (flags[i] != 0) out.push_back(static_cast<std::uint32_t>(i));
  }
}

// One sequential-impulse step of a row (ContactSolver::relax).
STC_HOT_INLINE void relaxRow(ContactSolver::Row& row, ContactSolver::Motion& a, ContactSolver::Motion& b) {
  // Friction first, bounded by the normal impulse so far (Box2D order).
  const Eigen::Vector2d d = frictionStep(row, relativeVelocity(row, a.v, a.w, b.v, b.w), row.mass[1], row.mass[2]);
  applyFriction(row, d.x(), d.y(), a, b);
  // Measured again after the friction impulse (from precomputed couplings
  // it is the same in exact arithmetic, but its rounding put test_fracture's
  // settling pieces over their energy tolerance).
  const double vn = relativeVelocity(row, a.v, a.w, b.v, b.w).dot(row.n);
  const double normal = std::max(0.0, row.lambda[0] + row.mass[0] * (-row.speculative - vn));
  const double dn = normal - row.lambda[0];
  row.lambda[0] = normal;
  applyNormal(row, dn, a, b);
}

}  // namespace

void ContactSolver::relax(Row& row, Motion& a, Motion& b) { relaxRow(row, a, b); }

void ContactSolver::resistRolling(Rolling& roll, double normal, Motion& a, Motion& b) {
  rollingStep(roll, normal, a.w, b.w, a, b);
}

void ContactSolver::prepare(const std::vector<BodyState>& bodies,
                            const std::vector<Contact>& contacts, const ResponseOptions& options,
                            double dt, SolveStats& stats) {
  const std::size_t body_count = bodies.size();
  const bool jacobi = options.solver == SolverKind::Jacobi;
  motion_.resize(body_count);
  pseudo_.resize(body_count);
  out_of_solve_.resize(body_count);
  immovable_.resize(body_count);
  if (jacobi) delta_.resize(body_count);
  // Each body's solver velocities from its state alone: in pieces on the workers.
  forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      motion_[i].v = bodies[i].linear_velocity;
      motion_[i].w = bodies[i].angular_velocity;
      out_of_solve_[i] = bodies[i].is_static ? 1 : 0;
      immovable_[i] = (bodies[i].is_static || bodies[i].inv_mass == 0.0) ? 1 : 0;
      pseudo_[i] = Motion{};
      if (jacobi) delta_[i] = Motion{};
    }
  });
  if (jacobi) {  // mass splitting counts the contacts on each body
    contact_count_.assign(body_count, 0);
    for (const Contact& c : contacts) {
      ++contact_count_[c.index_a];
      ++contact_count_[c.index_b];
    }
  }
  const auto inverseMass = [&](std::uint32_t i) { return bodies[i].is_static ? 0.0 : bodies[i].inv_mass; };
  active_.clear();
  growCapacity(contact_bodies_, contacts.size());
  contact_bodies_.resize(contacts.size());
  for (std::uint32_t ci = 0; ci < contacts.size(); ++ci) {
    const Contact& c = contacts[ci];
    contact_bodies_[ci] = {c.index_a, c.index_b};
    if (immovable_[c.index_a] != 0 && immovable_[c.index_b] != 0) continue;  // two immovable bodies
    active_.push_back(ci);
  }
  orderFromTheGround();
  plan_.assign(order_, contact_bodies_, contact_level_, out_of_solve_, bodies);  // order_ now block by block
  stats.slabs = plan_.partition().slabs();
  stats.crossing_manifolds = plan_.partition().crossing();

  resizeRewritten(rows_, order_.size());
  resizeRewritten(info_, order_.size());
  // Everything sized by the rows grows with them, in the same tick (no
  // allocation in a later tick whose waves or manifolds happen to be larger;
  // both warm-start buffers, as they swap every tick).
  for (std::vector<std::uint32_t>* v : {&wave_rows_, &last_wave_rows_, &next_wave_rows_}) {
    growCapacityRewritten(*v, rows_.size());
  }
  growCapacityRewritten(wave_runs_, plan_.passRuns().size());
  resizeRewritten(row_bodies_, rows_.size());
  resizeRewritten(wave_flag_, rows_.size());
  warm_.reserve(rows_.size());
  // Each row from its contact alone: in pieces on the workers.
  const auto prepareRow = [&](std::size_t r) {
    const std::uint32_t ci = order_[r];
    const Contact& c = contacts[ci];
    const BodyState& ba = bodies[c.index_a];
    const BodyState& bb = bodies[c.index_b];
    Row& row = rows_[r];
    RowInfo& info = info_[r];
    info = RowInfo{};
    info.contact = ci;
    row.a = c.index_a;
    row.b = c.index_b;
    row.inv_ma = inverseMass(row.a);
    row.inv_mb = inverseMass(row.b);
    row.ra = c.point - ba.pose.position;
    row.rb = c.point - bb.pose.position;
    row.n = c.normal;
    tangentBasis(row.n, row.t1, row.t2);
    const Vec3 dirs[3] = {row.n, row.t1, row.t2};
    // Mass splitting (Jacobi): each body's inverse mass counts once per contact on it.
    const double split_a = jacobi ? std::max(1, contact_count_[row.a]) : 1.0;
    const double split_b = jacobi ? std::max(1, contact_count_[row.b]) : 1.0;
    const int da = depth_[row.a];
    const int db = depth_[row.b];
    info.level = contact_level_[ci];
    // Shock propagation holds the body nearer the ground for what rests on it.
    info.move_a = !(da < db);
    info.move_b = !(db < da);
    for (int k = 0; k < 3; ++k) {
      const Vec3 rxd_a = row.ra.cross(dirs[k]);
      const Vec3 rxd_b = row.rb.cross(dirs[k]);
      row.ang_a[k] = ba.is_static ? Vec3::Zero() : Vec3(ba.inv_inertia_world * rxd_a);
      row.ang_b[k] = bb.is_static ? Vec3::Zero() : Vec3(bb.inv_inertia_world * rxd_b);
      const double ka = row.inv_ma + rxd_a.dot(row.ang_a[k]);
      const double kb = row.inv_mb + rxd_b.dot(row.ang_b[k]);
      const double k_total = split_a * ka + split_b * kb;
      row.mass[k] = k_total > 0.0 ? 1.0 / k_total : 0.0;
      const double k_shock = (info.move_a ? ka : 0.0) + (info.move_b ? kb : 0.0);
      info.shock_mass[k] = k_shock > 0.0 ? 1.0 / k_shock : 0.0;
    }
    const double k_translation = split_a * row.inv_ma + split_b * row.inv_mb;
    info.push_mass = k_translation > 0.0 ? 1.0 / k_translation : 0.0;
    const double k_held = (info.move_a ? row.inv_ma : 0.0) + (info.move_b ? row.inv_mb : 0.0);
    info.shock_push_mass = k_held > 0.0 ? 1.0 / k_held : 0.0;
    row.lambda[0] = row.lambda[1] = row.lambda[2] = 0.0;
    row.bounce_impulse = 0.0;
    row.friction = std::sqrt(std::max(0.0, ba.material.friction * bb.material.friction));
    info.restitution = std::max(ba.material.restitution, bb.material.restitution);
    info.approach =
        relativeVelocity(row, motion_[row.a].v, motion_[row.a].w, motion_[row.b].v, motion_[row.b].w).dot(row.n);
    const double s = c.separation;
    row.speculative = s > 0.0 ? s / dt : 0.0;
    const double slop = options.allowed_penetration > 0.0 ? options.allowed_penetration
                                                          : 0.02 * c.sphere_bound;
    if (s < -slop) {
      info.push = options.position_correction * (-s - slop) / dt;
    } else {
      info.push = s > 0.0 ? -s / dt : 0.0;  // pseudo-velocities may close a gap, never open one
    }
    // Restitution's wave 0 (collide): closing faster than the threshold and than its gap.
    info.bounced = info.restitution > 0.0 && info.approach < -std::max(options.restitution_threshold, row.speculative);
    info.wave = info.bounced ? 0 : -1;
    info.bounce_from = info.approach;
    wave_flag_[r] = info.bounced ? 1 : 0;
    row_bodies_[r] = {row.a, row.b};
  };
  // A row reads its contact and both bodies at random places (the rows are in
  // block order): each contact is asked for 2 kRowsAhead rows before its row,
  // and its bodies kRowsAhead rows before, so the reads overlap.
  const auto prefetchBodies = [&](std::size_t r) {
    const Contact& c = contacts[order_[r]];
    for (const std::uint32_t i : {c.index_a, c.index_b}) {
      const BodyState& b = bodies[i];
      __builtin_prefetch(&b.pose);
      __builtin_prefetch(&b.inv_mass);
      __builtin_prefetch(&b.inv_inertia_world);
      __builtin_prefetch(&b.material);
      __builtin_prefetch(&motion_[i]);
    }
  };
  forEachIndex(workers_, order_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      if (r + 2 * kRowsAhead < end) __builtin_prefetch(&contacts[order_[r + 2 * kRowsAhead]]);
      if (r + kRowsAhead < end) prefetchBodies(r + kRowsAhead);
      prepareRow(r);
    }
  });
  for (const std::uint32_t ci : order_) stats.max_penetration = std::max(stats.max_penetration, -contacts[ci].separation);
  stats.contacts = rows_.size();
  stats.manifolds = plan_.manifoldStart().size() - 1;
  prepareRolling(bodies, jacobi);
  wide_ = options.wide_passes && !jacobi;
  if (wide_) {
    const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
    wide_batches_.assign(plan_, rows_.size(), motion_.size(), [&](std::uint32_t m) {
      const std::uint32_t r = manifold_start[m];
      return WideBatches::ManifoldFacts{info_[r].level, rows_[r].a, rows_[r].b, info_[r].move_a, info_[r].move_b};
    });
  }
  stats.wide_batches = wide_ ? wide_batches_.batches().size() : 0;
}

// A pair resists rolling with the larger coefficient of its two materials,
// over a rolling radius: the mean over its points of the distance from the
// point to the nearer centre of mass of a movable body (a ball's radius; a
// rock's, where it touches). Box2D v3 takes the larger coefficient too.
void ContactSolver::prepareRolling(const std::vector<BodyState>& bodies, bool jacobi) {
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::size_t manifolds = manifold_start.size() - 1;
  // Sized by the rows (a manifold has at least one), as they grow: a later
  // tick with more manifolds and no more rows allocates nothing.
  growCapacity(rolling_, rows_.size());
  if (rolling_.size() < manifolds) rolling_.resize(manifolds);
  std::atomic<bool> any{false};
  const auto prepareManifold = [&](std::size_t m) {
    Rolling& roll = rolling_[m];
    roll.lambda.setZero();
    roll.per_normal = 0.0;
    const std::uint32_t begin = manifold_start[m], stop = manifold_start[m + 1];
    const BodyState& ba = bodies[rows_[begin].a];
    const BodyState& bb = bodies[rows_[begin].b];
    const double coefficient = std::max(ba.material.rolling_resistance, bb.material.rolling_resistance);
    if (!(coefficient > 0.0)) return;
    roll.inv_ia = ba.is_static ? Mat3::Zero() : ba.inv_inertia_world;
    roll.inv_ib = bb.is_static ? Mat3::Zero() : bb.inv_inertia_world;
    // Mass splitting (Jacobi), as the rows: each body counts once per contact on it.
    const double split_a = jacobi ? std::max(1, contact_count_[rows_[begin].a]) : 1.0;
    const double split_b = jacobi ? std::max(1, contact_count_[rows_[begin].b]) : 1.0;
    const Mat3 k = split_a * roll.inv_ia + split_b * roll.inv_ib;
    if (!(std::abs(k.determinant()) > 0.0)) return;
    roll.mass = k.inverse();
    double radius = 0.0;
    for (std::uint32_t r = begin; r < stop; ++r) {
      double nearer = std::numeric_limits<double>::infinity();
      if (!ba.is_static) nearer = std::min(nearer, rows_[r].ra.norm());
      if (!bb.is_static) nearer = std::min(nearer, rows_[r].rb.norm());
      radius += nearer;
    }
    roll.per_normal = coefficient * radius / (stop - begin);
    if (roll.per_normal > 0.0) any.store(true, std::memory_order_relaxed);
  };
  forEachIndex(workers_, manifolds, kManifoldsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t m = begin; m < end; ++m) prepareManifold(m);
  });
  any_rolling_ = any.load();
}

// Gauss-Seidel converges fastest on a stack when the support is solved
// before what it supports: rows sorted by the contact-graph distance of their
// lower body from an immovable one (breadth-first from the static bodies).
// Fills order_ with the active contacts, stably sorted by that level
// (unreached ones last), and depth_ per body.
void ContactSolver::orderFromTheGround() {
  const std::size_t body_count = immovable_.size();
  depth_.assign(body_count, kUnreached);
  // Adjacency as CSR: for each body, the other body of each active contact on it.
  adjacency_start_.assign(body_count + 1, 0);
  for (const std::uint32_t ci : active_) {
    ++adjacency_start_[contact_bodies_[ci][0] + 1];
    ++adjacency_start_[contact_bodies_[ci][1] + 1];
  }
  for (std::size_t i = 0; i < body_count; ++i) adjacency_start_[i + 1] += adjacency_start_[i];
  adjacency_.resize(2 * active_.size());
  fill_.assign(adjacency_start_.begin(), adjacency_start_.end() - 1);
  for (const std::uint32_t ci : active_) {
    const auto [a, b] = contact_bodies_[ci];
    adjacency_[static_cast<std::size_t>(fill_[a]++)] = b;
    adjacency_[static_cast<std::size_t>(fill_[b]++)] = a;
  }
  // Each body enters the queue once at most, and a level is at most the body
  // count: sized by the bodies, so the first immovable body in contact (a
  // sleeper held as static) allocates nothing.
  growCapacity(queue_, body_count);
  growCapacity(level_start_, body_count + 3);
  queue_.clear();
  for (const std::uint32_t ci : active_) {
    for (const std::uint32_t i : contact_bodies_[ci]) {
      if (depth_[i] == kUnreached && immovable_[i] != 0) {
        depth_[i] = 0;
        queue_.push_back(i);
      }
    }
  }
  for (std::size_t q = 0; q < queue_.size(); ++q) {
    const std::uint32_t i = queue_[q];
    for (int k = adjacency_start_[i]; k < adjacency_start_[i + 1]; ++k) {
      const std::uint32_t other = adjacency_[static_cast<std::size_t>(k)];
      if (depth_[other] == kUnreached) {
        depth_[other] = depth_[i] + 1;
        queue_.push_back(other);
      }
    }
  }
  // Stable counting sort by level. Unreached contacts go last.
  growCapacity(contact_level_, contact_bodies_.size());
  contact_level_.resize(contact_bodies_.size());
  int top = 0;
  for (const std::uint32_t ci : active_) {
    const int level = std::min(depth_[contact_bodies_[ci][0]], depth_[contact_bodies_[ci][1]]);
    contact_level_[ci] = level;
    if (level != kUnreached) top = std::max(top, level);
  }
  const auto bucket = [&](std::uint32_t ci) {
    const int level = contact_level_[ci];
    return static_cast<std::size_t>(level == kUnreached ? top + 1 : level);
  };
  level_start_.assign(static_cast<std::size_t>(top) + 3, 0);
  for (const std::uint32_t ci : active_) ++level_start_[bucket(ci) + 1];
  for (std::size_t l = 1; l < level_start_.size(); ++l) level_start_[l] += level_start_[l - 1];
  order_.resize(active_.size());
  for (const std::uint32_t ci : active_) order_[level_start_[bucket(ci)]++] = ci;
}


// One sweep up the levels; within a level its rows are iterated, the
// supporting body of each row held still. Unreached rows (nothing static
// below them) are left as the iterations made them.
void ContactSolver::propagateShock(const ResponseOptions& options) {
  const int passes = std::max(2, options.iterations / 2);
  if (wide_) {
    propagateShockWide(passes);
    return;
  }
  const auto shockStep = [&](std::size_t r, Motion& pair_a, Motion& pair_b) {
    Row& row = rows_[r];
    const RowInfo& info = info_[r];
    // The held body takes no impulse: its part goes to a copy, dropped.
    Motion held_a = pair_a, held_b = pair_b;
    Motion& a = info.move_a ? pair_a : held_a;
    Motion& b = info.move_b ? pair_b : held_b;
    const Eigen::Vector2d d =
        frictionStep(row, relativeVelocity(row, a.v, a.w, b.v, b.w), info.shock_mass[1], info.shock_mass[2]);
    applyFriction(row, d.x(), d.y(), a, b);
    held_a = pair_a;
    held_b = pair_b;
    const double vn = relativeVelocity(row, a.v, a.w, b.v, b.w).dot(row.n);
    const double normal = std::max(0.0, row.lambda[0] + info.shock_mass[0] * (-row.speculative - vn));
    applyNormal(row, normal - row.lambda[0], a, b);
    row.lambda[0] = normal;
  };
  // Level by level; a level's manifolds stage by stage.
  for (std::size_t level = 0; level < plan_.shockLevels(); ++level) {
    for (int pass = 0; pass < passes; ++pass) {
      plan_.forEachStageOfLevel(level, [&](std::size_t first, std::size_t end) {
        overManifolds(first, end, motion_, shockStep);
      });
    }
  }
}

// Each manifold looks up last tick's manifold of its entity pair once; each
// point takes the impulse of the old point with its feature id, else of the
// nearest unused old point within half the gap bound (in A's frame).
void ContactSolver::warmStart(std::vector<Contact>& contacts, const std::vector<BodyState>& bodies,
                              SolveStats& stats) {
  if (warm_.empty()) return;
  std::atomic<std::size_t> by_feature{0}, started{0};
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::vector<SolverGroup>& manifolds = plan_.manifolds();
  // Stage by stage, as a pass: each body meets its manifolds in the same
  // order whatever the thread count, and a block's bodies stay on its thread.
  plan_.forEachStage([&](std::size_t first_manifold, std::size_t end_manifold) {
    std::size_t feature_hits = 0, warm = 0;
    for (std::size_t m = first_manifold; m < end_manifold; ++m) {
      const std::uint32_t first = manifold_start[m];
      const std::uint32_t last = manifold_start[m + 1];
      const Contact& c0 = contacts[info_[first].contact];
      const std::uint64_t key = entityPairKey(c0.a, c0.b);
      const WarmStartCache::Point* old = nullptr;
      const WarmStartCache::Manifold* found = warm_.find(key, old);
      if (found == nullptr) continue;
      Motion a = motion_[rows_[first].a];
      Motion b = motion_[rows_[first].b];
      if (any_rolling_ && rolling_[m].per_normal > 0.0) {
        Rolling& roll = rolling_[m];
        roll.lambda = found->rolling;
        a.w -= roll.inv_ia * roll.lambda;
        b.w += roll.inv_ib * roll.lambda;
      }
      const std::uint32_t old_count = found->count;
      std::uint32_t used = 0;  // bit j: old point j taken (at most kCachedPointsPerPair)
      const BodyState& ba = bodies[rows_[first].a];
      const Quat to_a = ba.pose.orientation.conjugate();
      for (std::uint32_t r = first; r < last; ++r) {
        const Contact& c = contacts[info_[r].contact];
        if (c.node_a == kSweepHitNode) continue;  // an impact: starts cold
        int best = -1;
        for (std::uint32_t j = 0; j < old_count && best < 0; ++j) {
          if (!(used >> j & 1u) && old[j].node_a == c.node_a && old[j].node_b == c.node_b) best = static_cast<int>(j);
        }
        if (best >= 0) {
          ++feature_hits;
        } else {
          const Vec3 local = to_a * (c.point - ba.pose.position);
          const double tolerance = std::max(0.5 * c.sphere_bound, 1e-12);
          double best_d = tolerance * tolerance;
          for (std::uint32_t j = 0; j < old_count; ++j) {
            if ((used >> j & 1u) || old[j].node_a == kSweepHitNode) continue;  // nor lends an impact's impulse
            const double d = (old[j].local_a - local).squaredNorm();
            if (d <= best_d) {
              best_d = d;
              best = static_cast<int>(j);
            }
          }
          if (best < 0) continue;
        }
        used |= 1u << best;
        Row& row = rows_[r];
        row.lambda[0] = old[best].normal;
        row.lambda[1] = old[best].friction.dot(row.t1);
        row.lambda[2] = old[best].friction.dot(row.t2);
        const Vec3 p = row.lambda[0] * row.n + row.lambda[1] * row.t1 + row.lambda[2] * row.t2;
        a.v -= row.inv_ma * p;
        b.v += row.inv_mb * p;
        for (int k = 0; k < 3; ++k) {
          a.w -= row.lambda[k] * row.ang_a[k];
          b.w += row.lambda[k] * row.ang_b[k];
        }
        ++warm;
      }
      // A static body's motion is never written: two blocks may share it.
      if (manifolds[m].a != SolverGroup::kStatic) motion_[rows_[first].a] = a;
      if (manifolds[m].b != SolverGroup::kStatic) motion_[rows_[first].b] = b;
    }
    by_feature.fetch_add(feature_hits, std::memory_order_relaxed);
    started.fetch_add(warm, std::memory_order_relaxed);
  });
  stats.warm_by_feature += by_feature.load();
  stats.warm_started += started.load();
}

// Jacobi: the impulses of one iteration, computed from one state, applied together.
void ContactSolver::commitJacobi(std::vector<Motion>& motion) {
  for (std::size_t i = 0; i < motion.size(); ++i) {
    motion[i].v += delta_[i].v;
    motion[i].w += delta_[i].w;
    delta_[i] = Motion{};
  }
}

// Stage by stage; a stage's blocks share no movable body (any threads).
void ContactSolver::solveVelocities(const ResponseOptions& options, int passes) {
  if (options.solver == SolverKind::Jacobi) {
    // Friction and non-penetration from the same state (motion_ is untouched
    // until the commit), impulses into delta_.
    const auto jacobiStep = [&](std::size_t r, Motion& delta_a, Motion& delta_b) {
      Row& row = rows_[r];
      const Motion& a = motion_[row.a];
      const Motion& b = motion_[row.b];
      const Vec3 vrel = relativeVelocity(row, a.v, a.w, b.v, b.w);
      const Eigen::Vector2d d = frictionStep(row, vrel, row.mass[1], row.mass[2]);
      applyFriction(row, d.x(), d.y(), delta_a, delta_b);
      const double normal = std::max(0.0, row.lambda[0] + row.mass[0] * (-row.speculative - vrel.dot(row.n)));
      applyNormal(row, normal - row.lambda[0], delta_a, delta_b);
      row.lambda[0] = normal;
    };
    const auto jacobiRolling = [&](std::size_t m, Motion& delta_a, Motion& delta_b) {
      Rolling& roll = rolling_[m];
      if (roll.per_normal == 0.0) return;
      const std::uint32_t begin = plan_.manifoldStart()[m];
      rollingStep(roll, normalImpulse(m), motion_[rows_[begin].a].w, motion_[rows_[begin].b].w, delta_a, delta_b);
    };
    for (int it = 0; it < passes; ++it) {
      plan_.forEachStage([&](std::size_t first, std::size_t end) {
        if (any_rolling_) {
          overManifolds(first, end, delta_, jacobiStep, jacobiRolling);
        } else {
          overManifolds(first, end, delta_, jacobiStep);
        }
      });
      commitJacobi(motion_);
    }
    return;
  }
  if (wide_) {
    solveVelocitiesWide(passes);
    return;
  }
  // Sequential: the rows of one body pair in a row, on local copies of the
  // two bodies' velocities, then the pair's rolling resistance.
  const auto relaxStep = [&](std::size_t r, Motion& a, Motion& b) { relaxRow(rows_[r], a, b); };
  const auto relaxRolling = [&](std::size_t m, Motion& a, Motion& b) {
    Rolling& roll = rolling_[m];
    if (roll.per_normal != 0.0) resistRolling(roll, normalImpulse(m), a, b);
  };
  for (int it = 0; it < passes; ++it) {
    plan_.forEachStage([&](std::size_t first, std::size_t end) {
      if (any_rolling_) {
        overManifolds(first, end, motion_, relaxStep, relaxRolling);
      } else {
        overManifolds(first, end, motion_, relaxStep);
      }
    });
  }
}

double ContactSolver::normalImpulse(std::size_t m) const {
  double sum = 0.0;
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  for (std::uint32_t r = manifold_start[m]; r < manifold_start[m + 1]; ++r) {
    sum += rows_[r].lambda[0] + rows_[r].bounce_impulse;
  }
  return sum;
}

// Restitution before the solve, as collisions (Guendelman et al. 2003): wave
// 0 bounces the contacts that approach faster than the threshold and close
// their gap this tick, to separate at e times that approach; each further
// wave bounces the contacts its predecessor left approaching so, from that
// approach (a Newton's cradle passes the struck ball's speed down the row to
// the last ball). Each wave only pushes (impulses >= 0), so none gains
// energy. The solve then holds every contact and resolves what is left
// inelastically; friction is bounded by the bounce's impulse too.
void ContactSolver::collide(const ResponseOptions& options, SolveStats& stats) {
  const bool jacobi = options.solver == SolverKind::Jacobi;
  std::vector<Motion>& out = jacobi ? delta_ : motion_;
  const auto normalVelocity = [&](const Row& row) {
    const Motion& a = motion_[row.a];
    const Motion& b = motion_[row.b];
    return relativeVelocity(row, a.v, a.w, b.v, b.w).dot(row.n);
  };
  // Wave 0 was classified with the rows (prepare).
  wave_rows_.clear();
  appendFlagged(wave_flag_, wave_rows_);
  if (wave_rows_.empty()) return;
  // A row whose bodies did not move since it was last looked at still
  // separates: after each wave only the rows of the bodies it and the wave
  // before moved are looked at, found in a compact copy of the rows' bodies.
  last_wave_rows_.clear();
  moved_.assign(motion_.size(), 0);
  const auto movable = [](double inv_mass, const Vec3& angular) { return inv_mass != 0.0 || !angular.isZero(0.0); };
  // One bounce step of a row. An immovable body is left alone: blocks of a
  // stage may share one, and adding nothing to it changes nothing.
  const auto bounce = [&](std::uint32_t r) {
    RowInfo& info = info_[r];
    Row& row = rows_[r];
    const double target = -info.restitution * info.bounce_from;
    const double impulse = std::max(0.0, info.lambda_wave + row.mass[0] * (target - normalVelocity(row)));
    const double delta = impulse - info.lambda_wave;
    info.lambda_wave = impulse;
    row.bounce_impulse += delta;
    Motion unused;  // an immovable body's share goes here
    applyNormal(row, delta, movable(row.inv_ma, row.ang_a[0]) ? out[row.a] : unused,
                movable(row.inv_mb, row.ang_b[0]) ? out[row.b] : unused);
  };
  const auto bounceRows = [&](std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; ++i) bounce(wave_rows_[i]);
  };
  for (int wave = 0; wave < options.iterations && !wave_rows_.empty(); ++wave) {
    for (const std::uint32_t r : wave_rows_) {
      ++stats.bounced;
      info_[r].lambda_wave = 0.0;
    }
    // The wave's rows block by block (wave_rows_ ascends, as the rows do):
    // the blocks of a stage share no movable body, so a stage's blocks run
    // side by side and every body meets its rows in the one-thread order.
    if (!jacobi) waveRuns();
    for (int it = 0; it < options.iterations; ++it) {
      if (jacobi) {
        bounceRows(0, wave_rows_.size());
        commitJacobi(motion_);
        continue;
      }
      plan_.forEachStageOfRuns(wave_runs_, bounceRows, kWaveRowsPerManifold);
    }
    // The last wave's rows too: its own rows were not looked at after it.
    for (const auto* list : {&wave_rows_, &last_wave_rows_}) {
      for (const std::uint32_t r : *list) {
        const Row& row = rows_[r];
        if (movable(row.inv_ma, row.ang_a[0])) moved_[row.a] = 1;
        if (movable(row.inv_mb, row.ang_b[0])) moved_[row.b] = 1;
      }
    }
    // The next wave's rows, looked for in pieces on the workers (each row
    // writes only itself; the motion is not changed meanwhile).
    forEachIndex(workers_, row_bodies_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        wave_flag_[r] = 0;
        if (!moved_[row_bodies_[r][0]] && !moved_[row_bodies_[r][1]]) continue;
        RowInfo& info = info_[r];
        if (info.wave == wave || info.restitution <= 0.0) continue;
        const Row& row = rows_[r];
        const double vn = normalVelocity(row);
        if (vn < -std::max(options.restitution_threshold, row.speculative)) {
          info.wave = wave + 1;
          info.bounce_from = vn;
          info.bounced = true;
          wave_flag_[r] = 1;
        }
      }
    });
    next_wave_rows_.clear();
    appendFlagged(wave_flag_, next_wave_rows_);
    for (const auto* list : {&wave_rows_, &last_wave_rows_}) {
      for (const std::uint32_t r : *list) moved_[rows_[r].a] = moved_[rows_[r].b] = 0;
    }
    last_wave_rows_.swap(wave_rows_);
    wave_rows_.swap(next_wave_rows_);
  }
}

// For each run of a pass (a non-empty block), its rows in wave_rows_:
// wave_runs_[k] is [first, end) of wave_rows_ (both ascend).
void ContactSolver::waveRuns() {
  const std::vector<SolverThreadPlan::ManifoldRun>& pass_runs = plan_.passRuns();
  wave_runs_.resize(pass_runs.size());
  std::size_t i = 0;
  for (std::size_t k = 0; k < pass_runs.size(); ++k) {
    const std::uint32_t row_end = plan_.manifoldStart()[pass_runs[k].end];
    const std::size_t first = i;
    while (i < wave_rows_.size() && wave_rows_[i] < row_end) ++i;
    wave_runs_[k] = ManifoldRun{static_cast<std::uint32_t>(first), static_cast<std::uint32_t>(i)};
  }
  assert(i == wave_rows_.size());
}

STC_HOT_INLINE void ContactSolver::pushStep(const Row& row, RowInfo& info, const Motion& a, const Motion& b,
                                           double mass, bool turns, Motion& out_a, Motion& out_b) {
  // Translation alone (the default): the pass never turns a body, so it
  // cannot set a resting one rocking (docs/sleeping.md).
  const double vn = turns ? relativeVelocity(row, a.v, a.w, b.v, b.w).dot(row.n) : (b.v - a.v).dot(row.n);
  // A contact that bounced across a speculative gap also closes the gap
  // (may pull): the bounce starts at the surface, not where the gap
  // was seen, so the rebound height does not gain up to |v| dt.
  const double unclamped = info.lambda_push + mass * (info.push - vn);
  const double normal = info.bounced && info.push < 0.0 ? unclamped : std::max(0.0, unclamped);
  const double delta = normal - info.lambda_push;
  info.lambda_push = normal;
  if (turns) {
    applyNormal(row, delta, out_a, out_b);
  } else {
    out_a.v -= row.inv_ma * delta * row.n;
    out_b.v += row.inv_mb * delta * row.n;
  }
}

// Returns the passes run: options.iterations, fewer when the deadline
// passes first (never fewer than one when anything needs correcting).
int ContactSolver::solvePositions(const ResponseOptions& options, const Deadline& deadline) {
  bool any = false;
  for (const RowInfo& info : info_) any = any || info.push > 0.0 || (info.bounced && info.push < 0.0);
  if (!any) return 0;
  const bool jacobi = options.solver == SolverKind::Jacobi;
  std::vector<Motion>& out = jacobi ? delta_ : pseudo_;
  const bool turns = options.position_turns;
  const auto positionStep = [&](std::size_t r, Motion& out_a, Motion& out_b) {
    const Row& row = rows_[r];
    RowInfo& info = info_[r];
    const Motion& a = jacobi ? pseudo_[row.a] : out_a;  // Jacobi: pseudo_ untouched until the commit
    const Motion& b = jacobi ? pseudo_[row.b] : out_b;
    pushStep(row, info, a, b, turns ? row.mass[0] : info.push_mass, turns, out_a, out_b);
  };
  int passes = 0;
  if (wide_ && !turns) {
    plan_.forEachStageBatches(wide_batches_.starts(),
                              [&](std::size_t first, std::size_t end) { packWidePush(first, end); });
    for (int it = 0; it < options.iterations; ++it, ++passes) {
      if (it > 0 && deadline.passed()) break;
      solvePositionsWide();
    }
    return passes;
  }
  for (int it = 0; it < options.iterations; ++it, ++passes) {
    if (it > 0 && deadline.passed()) break;
    // Stage by stage, as the velocity passes.
    plan_.forEachStage([&](std::size_t first, std::size_t end) { overManifolds(first, end, out, positionStep); });
    if (jacobi) commitJacobi(pseudo_);
  }
  return passes;
}

// Shock propagation at the position level (Guendelman et al. process contacts
// from the ground up): with few position passes (a tick budget leaves one) a
// rock at the bottom of a pile took the pile's push down as much as the
// floor's push up, and sank through the floor over a few seconds
// (corner_drift under a 16.7 ms budget). Held from below, it cannot be pushed
// into what supports it; what rests on it moves instead.
void ContactSolver::propagatePositionShock(const ResponseOptions& options) {
  const bool turns = options.position_turns;
  if (wide_ && !turns) {
    propagatePositionShockWide();
    return;
  }
  const auto shockPush = [&](std::size_t r, Motion& pair_a, Motion& pair_b) {
    const Row& row = rows_[r];
    RowInfo& info = info_[r];
    Motion held_a = pair_a, held_b = pair_b;  // the held body's part goes to a copy, dropped
    Motion& a = info.move_a ? pair_a : held_a;
    Motion& b = info.move_b ? pair_b : held_b;
    pushStep(row, info, a, b, turns ? info.shock_mass[0] : info.shock_push_mass, turns, a, b);
  };
  for (std::size_t level = 0; level < plan_.shockLevels(); ++level) {
    plan_.forEachStageOfLevel(level, [&](std::size_t first, std::size_t end) {
      overManifolds(first, end, pseudo_, shockPush);
    });
  }
}

// The most iterations (<= cap) that fit in seconds_left with everything that
// follows them, costed in passes over the rows at the price of the first
// velocity pass: per iteration beyond the first one velocity pass and one
// position pass (when any contact needs correcting); then shock propagation's
// max(2, n / 2) passes (and its one position sweep), and one more for
// restitution and storing the result.
int ContactSolver::affordableIterations(const ResponseOptions& options, int cap, double pass_seconds,
                                        double seconds_left) const {
  if (!(pass_seconds > 0.0)) return cap;
  bool corrects = false;
  for (const RowInfo& info : info_) corrects = corrects || info.push != 0.0;
  const auto passes_after_the_first = [&](int n) {
    const int shock = options.shock_propagation ? std::max(2, n / 2) + (corrects ? 1 : 0) : 0;
    return (n - 1) + (corrects ? n : 0) + shock + 1;
  };
  int n = 1;
  while (n < cap && passes_after_the_first(n + 1) * pass_seconds <= seconds_left) ++n;
  return n;
}

void ContactSolver::store(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                          double dt) {
  forEachIndex(workers_, bodies.size(), kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      BodyState& body = bodies[i];
      if (body.is_static) continue;
      body.linear_velocity = motion_[i].v;
      body.angular_velocity = motion_[i].w;
      const Motion& p = pseudo_[i];
      if (!p.v.isZero(0.0) || !p.w.isZero(0.0)) {
        body.pose.position += p.v * dt;
        if (!p.w.isZero(0.0)) {
          body.pose.orientation = integrateOrientation(body.pose.orientation, p.w, dt);
          refreshWorldInertia(body);
        }
      }
    }
  });

  // Report impulses on the contacts and keep each pair's manifold for next
  // tick's warm start. A manifold's points go where its rows are (at most
  // kCachedPointsPerPair of them), so manifolds fill in parallel.
  const std::vector<std::uint32_t>& manifold_start = plan_.manifoldStart();
  const std::size_t manifolds = manifold_start.size() - 1;
  warm_.beginNext(rows_.size(), manifolds);
  forEachIndex(workers_, manifolds, kManifoldsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t m = begin; m < end; ++m) {
      WarmStartCache::Manifold manifold;
      manifold.first = manifold_start[m];
      const std::uint32_t last = manifold_start[m + 1];
      const std::uint32_t stop = std::min(last, manifold.first + kCachedPointsPerPair);
      for (std::uint32_t r = manifold.first; r < last; ++r) {
        const Row& row = rows_[r];
        Contact& c = contacts[info_[r].contact];
        c.normal_impulse = row.lambda[0] + row.bounce_impulse;
        c.friction_impulse = row.lambda[1] * row.t1 + row.lambda[2] * row.t2;
        if (r == manifold.first) {
          manifold.pair = entityPairKey(c.a, c.b);
          manifold.index_a = row.a;
          manifold.index_b = row.b;
        }
        if (r >= stop) continue;
        const RowInfo& info = info_[r];
        warm_.keepPoint(r, c, bodies[row.a].pose, info.lambda_main,
                        info.friction_main[0] * row.t1 + info.friction_main[1] * row.t2);
      }
      manifold.count = stop - manifold.first;
      if (any_rolling_) manifold.rolling = rolling_[m].lambda;
      warm_.keepManifold(m, manifold);
    }
  });
  warm_.commitNext(out_of_solve_);
}

SolveStats ContactSolver::solve(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                                const ResponseOptions& options, double dt, const SolveBudget& budget) {
  SolveStats stats;
  if (!(dt > 0.0) || bodies.empty()) return stats;
  for (Contact& c : contacts) {
    c.normal_impulse = 0.0;
    c.friction_impulse.setZero();
  }
  prepare(bodies, contacts, options, dt, stats);
  if (rows_.empty()) {
    warm_.commitNone(out_of_solve_);
    return stats;
  }
  // Refineable: the first velocity pass always runs; timed, it prices the
  // further iterations against the deadline. `run` carries the iterations
  // afforded to every later stage.
  // The restitution waves, the warm start and the passes run on a team: the
  // workers stay awake from stage to stage.
  plan_.onTeam([&] {
    collide(options, stats);
    if (options.warm_starting) warmStart(contacts, bodies, stats);
    iterate(options, budget, stats);
  });
  store(bodies, contacts, dt);
  if (!options.warm_starting) forget();
  return stats;
}

void ContactSolver::iterate(const ResponseOptions& options, const SolveBudget& budget, SolveStats& stats) {
  const Deadline& deadline = budget.deadline;
  ResponseOptions run = options;
  run.iterations = std::max(1, std::min(options.iterations, budget.max_iterations));
  if (wide_) {
    plan_.forEachStageBatches(wide_batches_.starts(), [&](std::size_t first, std::size_t end) { packWide(first, end); });
  }
  const double t_first = deadline.isSet() ? deadline.now() : 0.0;
  solveVelocities(run, 1);
  const double t_more = deadline.isSet() ? deadline.now() : 0.0;
  if (deadline.isSet()) {
    run.iterations = affordableIterations(run, run.iterations, t_more - t_first, deadline.at() - t_more);
  }
  solveVelocities(run, run.iterations - 1);
  stats.velocity_passes = run.iterations;
  const double t_rest = deadline.isSet() ? deadline.now() : 0.0;
  const auto unpack = [&] {
    if (!wide_) return;
    plan_.forEachStageBatches(wide_batches_.starts(), [&](std::size_t first, std::size_t end) { unpackWide(first, end); });
  };
  // Warm-started, shock propagation's impulses would reach the support it
  // held as well: a heavy cube's weight, once a tick, on a light cube under
  // it. With 1 cm between four light cubes under a 1000:1 cube the scene
  // blew up from the second tick at 20 iterations (test_stability).
  unpack();
  forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      RowInfo& info = info_[r];
      info.lambda_main = rows_[r].lambda[0];
      info.friction_main[0] = rows_[r].lambda[1];
      info.friction_main[1] = rows_[r].lambda[2];
    }
  });
  if (options.shock_propagation) {
    propagateShock(run);
    unpack();  // the impulses the contacts report include the sweep's
  }
  const double t_positions = deadline.isSet() ? deadline.now() : 0.0;
  stats.position_passes = solvePositions(run, deadline);
  if (options.shock_propagation && stats.position_passes > 0) propagatePositionShock(run);
  if (deadline.isSet()) {
    const double positions = deadline.now() - t_positions;
    const int extra = std::max(0, stats.position_passes - 1);
    stats.refinement_seconds = (t_rest - t_more) + positions * extra / std::max(1, stats.position_passes);
  }
}


SolveStats solveContacts(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                         const ResponseOptions& options, double dt) {
  ContactSolver solver;
  return solver.solve(bodies, contacts, options, dt);
}

}  // namespace stc
