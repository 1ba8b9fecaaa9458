// Impulse solver: non-penetration + Coulomb friction, restitution, split-impulse
// position correction; sequential (Gauss-Seidel) or simultaneous (Jacobi).
#include "sphere_tree_collision/contact_solver.hpp"

#include "sphere_tree_collision/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {

void tangentBasis(const Vec3& n, Vec3& t1, Vec3& t2) {
  t1 = std::abs(n.x()) < 0.57735 ? Vec3(0.0, n.z(), -n.y()) : Vec3(n.y(), -n.x(), 0.0);
  t1.normalize();
  t2 = n.cross(t1);
}

void ContactSolver::prepare(const std::vector<BodyState>& bodies,
                            const std::vector<Contact>& contacts, const ResponseOptions& options,
                            double dt, SolveStats& stats) {
  const std::size_t body_count = bodies.size();
  v_.resize(body_count);
  w_.resize(body_count);
  pv_.assign(body_count, Vec3::Zero());
  pw_.assign(body_count, Vec3::Zero());
  contact_count_.assign(body_count, 0);
  for (std::size_t i = 0; i < body_count; ++i) {
    v_[i] = bodies[i].linear_velocity;
    w_[i] = bodies[i].angular_velocity;
  }
  const bool jacobi = options.solver == SolverKind::Jacobi;
  if (jacobi) {
    dv_.assign(body_count, Vec3::Zero());
    dw_.assign(body_count, Vec3::Zero());
  }
  for (const Contact& c : contacts) {
    ++contact_count_[c.index_a];
    ++contact_count_[c.index_b];
  }

  rows_.clear();
  for (std::size_t ci = 0; ci < contacts.size(); ++ci) {
    const Contact& c = contacts[ci];
    const BodyState& ba = bodies[c.index_a];
    const BodyState& bb = bodies[c.index_b];
    Row row;
    row.contact = static_cast<std::uint32_t>(ci);
    row.a = c.index_a;
    row.b = c.index_b;
    row.inv_ma = ba.is_static ? 0.0 : ba.inv_mass;
    row.inv_mb = bb.is_static ? 0.0 : bb.inv_mass;
    row.static_a = ba.is_static;
    row.static_b = bb.is_static;
    if (row.inv_ma == 0.0 && row.inv_mb == 0.0) continue;  // two immovable bodies
    row.ra = c.point - ba.pose.position;
    row.rb = c.point - bb.pose.position;
    row.n = c.normal;
    tangentBasis(row.n, row.t1, row.t2);
    const Vec3 dirs[3] = {row.n, row.t1, row.t2};
    // Mass splitting (Jacobi): each body's inverse mass counts once per contact on it.
    const double split_a = jacobi ? std::max(1, contact_count_[row.a]) : 1.0;
    const double split_b = jacobi ? std::max(1, contact_count_[row.b]) : 1.0;
    for (int k = 0; k < 3; ++k) {
      const Vec3 rxd_a = row.ra.cross(dirs[k]);
      const Vec3 rxd_b = row.rb.cross(dirs[k]);
      row.ang_a[k] = ba.is_static ? Vec3::Zero() : Vec3(ba.inv_inertia_world * rxd_a);
      row.ang_b[k] = bb.is_static ? Vec3::Zero() : Vec3(bb.inv_inertia_world * rxd_b);
      const double ka = row.inv_ma + rxd_a.dot(row.ang_a[k]);
      const double kb = row.inv_mb + rxd_b.dot(row.ang_b[k]);
      row.k_a[k] = ka;
      row.k_b[k] = kb;
      const double k_total = split_a * ka + split_b * kb;
      row.mass[k] = k_total > 0.0 ? 1.0 / k_total : 0.0;
    }
    row.friction = std::sqrt(std::max(0.0, ba.material.friction * bb.material.friction));
    row.restitution = std::max(ba.material.restitution, bb.material.restitution);
    const Vec3 vrel = v_[row.b] + w_[row.b].cross(row.rb) - v_[row.a] - w_[row.a].cross(row.ra);
    row.approach = vrel.dot(row.n);
    const double s = c.separation;
    row.speculative = s > 0.0 ? s / dt : 0.0;
    const double slop = options.allowed_penetration > 0.0 ? options.allowed_penetration
                                                          : 0.02 * c.gap_bound;
    if (s < -slop) {
      row.push = options.position_correction * (-s - slop) / dt;
    } else {
      row.push = s > 0.0 ? -s / dt : 0.0;  // pseudo-velocities may close a gap, never open one
    }
    stats.max_penetration = std::max(stats.max_penetration, -s);
    rows_.push_back(row);
  }
  stats.contacts = rows_.size();
  orderFromTheGround(bodies);
  colourRows(body_count);
  stats.colours = colouring_.colourCount();
}

// Gauss-Seidel converges fastest on a stack when the support is solved
// before what it supports: rows sorted by the contact-graph distance of their
// lower body from an immovable one (breadth-first from the static bodies).
// Jacobi is order-independent and skips this.
void ContactSolver::orderFromTheGround(const std::vector<BodyState>& bodies) {
  const std::size_t body_count = bodies.size();
  constexpr int kUnreached = std::numeric_limits<int>::max();
  depth_.assign(body_count, kUnreached);
  // Adjacency as CSR: rows touching each body.
  adjacency_start_.assign(body_count + 1, 0);
  for (const Row& row : rows_) {
    ++adjacency_start_[row.a + 1];
    ++adjacency_start_[row.b + 1];
  }
  for (std::size_t i = 0; i < body_count; ++i) adjacency_start_[i + 1] += adjacency_start_[i];
  adjacency_.resize(2 * rows_.size());
  fill_.assign(adjacency_start_.begin(), adjacency_start_.end() - 1);
  for (std::uint32_t r = 0; r < rows_.size(); ++r) {
    adjacency_[static_cast<std::size_t>(fill_[rows_[r].a]++)] = r;
    adjacency_[static_cast<std::size_t>(fill_[rows_[r].b]++)] = r;
  }
  queue_.clear();
  for (const Row& row : rows_) {
    for (const std::uint32_t i : {row.a, row.b}) {
      if (depth_[i] == kUnreached && (bodies[i].is_static || bodies[i].inv_mass == 0.0)) {
        depth_[i] = 0;
        queue_.push_back(i);
      }
    }
  }
  for (std::size_t q = 0; q < queue_.size(); ++q) {
    const std::uint32_t i = queue_[q];
    for (int k = adjacency_start_[i]; k < adjacency_start_[i + 1]; ++k) {
      const Row& row = rows_[adjacency_[static_cast<std::size_t>(k)]];
      const std::uint32_t other = row.a == i ? row.b : row.a;
      if (depth_[other] == kUnreached) {
        depth_[other] = depth_[i] + 1;
        queue_.push_back(other);
      }
    }
  }
  for (Row& row : rows_) {
    const int da = depth_[row.a];
    const int db = depth_[row.b];
    row.level = std::min(da, db);
    row.support = da < db ? 1 : (db < da ? 2 : 0);
  }
  // Stable counting sort by level through an index (rows are large; no
  // allocation once the scratch has grown). Unreached rows go last.
  int top = 0;
  for (const Row& row : rows_) {
    if (row.level != kUnreached) top = std::max(top, row.level);
  }
  const auto bucket = [&](const Row& row) {
    return static_cast<std::size_t>(row.level == kUnreached ? top + 1 : row.level);
  };
  level_start_.assign(static_cast<std::size_t>(top) + 3, 0);
  for (const Row& row : rows_) ++level_start_[bucket(row) + 1];
  for (std::size_t l = 1; l < level_start_.size(); ++l) level_start_[l] += level_start_[l - 1];
  order_.resize(rows_.size());
  for (std::uint32_t r = 0; r < rows_.size(); ++r) order_[level_start_[bucket(rows_[r])]++] = r;
  sorted_rows_.resize(rows_.size());
  for (std::size_t r = 0; r < rows_.size(); ++r) sorted_rows_[r] = rows_[order_[r]];
  rows_.swap(sorted_rows_);
}

// One sweep up the levels; within a level its rows are iterated, the
// supporting body of each row held still. Unreached rows (nothing static
// below them) are left as the iterations made them.
void ContactSolver::propagateShock(const ResponseOptions& options) {
  const int passes = std::max(2, options.iterations / 2);
  // Level by level; a level's rows colour by colour (forEachColourOfLevel).
  for (std::size_t level = 0; level < shockLevels(); ++level) {
    for (int pass = 0; pass < passes; ++pass) forEachColourOfLevel(level, [&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        Row& row = rows_[r];
        const bool move_a = row.support != 1 && !row.static_a;  // a is held when it supports b
        const bool move_b = row.support != 2 && !row.static_b;
        double mass[3];
        for (int k = 0; k < 3; ++k) {
          const double kk = (move_a ? row.k_a[k] : 0.0) + (move_b ? row.k_b[k] : 0.0);
          mass[k] = kk > 0.0 ? 1.0 / kk : 0.0;
        }
        const auto apply = [&](int k, double delta) {
          const Vec3& d = k == 0 ? row.n : (k == 1 ? row.t1 : row.t2);
          if (move_a) {
            v_[row.a] -= row.inv_ma * delta * d;
            w_[row.a] -= delta * row.ang_a[k];
          }
          if (move_b) {
            v_[row.b] += row.inv_mb * delta * d;
            w_[row.b] += delta * row.ang_b[k];
          }
        };
        const Eigen::Vector2d d = frictionStep(row, mass[1], mass[2]);
        apply(1, d.x());
        apply(2, d.y());
        const Vec3 vrel = v_[row.b] + w_[row.b].cross(row.rb) - v_[row.a] - w_[row.a].cross(row.ra);
        const double normal = std::max(0.0, row.lambda[0] + mass[0] * (-row.speculative - vrel.dot(row.n)));
        apply(0, normal - row.lambda[0]);
        row.lambda[0] = normal;
      }
    });
  }
}

void ContactSolver::warmStart(std::vector<Contact>& contacts, const std::vector<BodyState>& bodies,
                              SolveStats& stats) {
  if (cache_.empty()) return;
  const auto by_pair = [](const Cached& x, const Cached& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  };
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    const Contact& c = contacts[rows_[r].contact];
    Row& row = rows_[r];
    Cached key;
    key.a = c.a;
    key.b = c.b;
    const auto range = std::equal_range(cache_.begin(), cache_.end(), key, by_pair);
    if (range.first == range.second) continue;
    const BodyState& ba = bodies[row.a];
    const Vec3 local = ba.pose.orientation.conjugate() * (c.point - ba.pose.position);
    const double tolerance = std::max(0.5 * c.gap_bound, 1e-12);
    const Cached* best = nullptr;
    double best_d = tolerance * tolerance;
    for (auto it = range.first; it != range.second; ++it) {
      const double d = (it->local_a - local).squaredNorm();
      if (d <= best_d) {
        best_d = d;
        best = &*it;
      }
    }
    if (best == nullptr) continue;
    row.lambda[0] = best->normal;
    row.lambda[1] = best->friction.dot(row.t1);
    row.lambda[2] = best->friction.dot(row.t2);
    const Vec3 p = row.lambda[0] * row.n + row.lambda[1] * row.t1 + row.lambda[2] * row.t2;
    v_[row.a] -= row.inv_ma * p;
    v_[row.b] += row.inv_mb * p;
    for (int k = 0; k < 3; ++k) {
      w_[row.a] -= row.lambda[k] * row.ang_a[k];
      w_[row.b] += row.lambda[k] * row.ang_b[k];
    }
    ++stats.warm_started;
  }
}

// Jacobi: the impulses of one iteration, computed from one state, applied together.
void ContactSolver::commitJacobi(std::vector<Vec3>& v, std::vector<Vec3>& w) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    v[i] += dv_[i];
    w[i] += dw_[i];
    dv_[i].setZero();
    dw_[i].setZero();
  }
}

void ContactSolver::applyNormal(const Row& row, double impulse, std::vector<Vec3>& v,
                                std::vector<Vec3>& w) {
  // A static body's velocity is never written: colours do not hold it apart.
  if (!row.static_a) {
    v[row.a] -= row.inv_ma * impulse * row.n;
    w[row.a] -= impulse * row.ang_a[0];
  }
  if (!row.static_b) {
    v[row.b] += row.inv_mb * impulse * row.n;
    w[row.b] += impulse * row.ang_b[0];
  }
}

Eigen::Vector2d ContactSolver::frictionStep(Row& row, double mass_t1, double mass_t2) const {
  const Vec3 vrel = v_[row.b] + w_[row.b].cross(row.rb) - v_[row.a] - w_[row.a].cross(row.ra);
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

void ContactSolver::solveVelocities(const ResponseOptions& options, int passes) {
  const bool jacobi = options.solver == SolverKind::Jacobi;
  std::vector<Vec3>& out_v = jacobi ? dv_ : v_;
  std::vector<Vec3>& out_w = jacobi ? dw_ : w_;
  for (int it = 0; it < passes; ++it) {
    // Colour by colour; a colour's rows share no movable body (any split).
    forEachColour([&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        Row& row = rows_[r];
        // Friction first, bounded by the normal impulse so far (Box2D order).
        const Eigen::Vector2d d = frictionStep(row, row.mass[1], row.mass[2]);
        const double d1 = d.x(), d2 = d.y();
        const Vec3 pt = d1 * row.t1 + d2 * row.t2;
        if (!row.static_a) {
          out_v[row.a] -= row.inv_ma * pt;
          out_w[row.a] -= d1 * row.ang_a[1] + d2 * row.ang_a[2];
        }
        if (!row.static_b) {
          out_v[row.b] += row.inv_mb * pt;
          out_w[row.b] += d1 * row.ang_b[1] + d2 * row.ang_b[2];
        }

        // Non-penetration (Jacobi: v_ is untouched until the commit, so this is
        // the same state the friction above saw).
        const Vec3 vrel = v_[row.b] + w_[row.b].cross(row.rb) - v_[row.a] - w_[row.a].cross(row.ra);
        const double normal =
            std::max(0.0, row.lambda[0] + row.mass[0] * (-row.speculative - vrel.dot(row.n)));
        const double dn = normal - row.lambda[0];
        row.lambda[0] = normal;
        applyNormal(row, dn, out_v, out_w);
      }
    });
    if (jacobi) commitJacobi(v_, w_);
  }
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
  std::vector<Vec3>& out_v = jacobi ? dv_ : v_;
  std::vector<Vec3>& out_w = jacobi ? dw_ : w_;
  const auto normalVelocity = [&](const Row& row) {
    return (v_[row.b] + w_[row.b].cross(row.rb) - v_[row.a] - w_[row.a].cross(row.ra)).dot(row.n);
  };
  bool any = false;
  for (Row& row : rows_) {
    row.bounce_impulse = 0.0;
    row.bounced = row.restitution > 0.0 && row.approach < -std::max(options.restitution_threshold, row.speculative);
    row.wave = row.bounced ? 0 : -1;
    row.bounce_from = row.approach;
    any = any || row.bounced;
  }
  if (!any) return;
  for (int wave = 0; wave < options.iterations; ++wave) {
    for (Row& row : rows_) {
      if (row.wave == wave) {
        ++stats.bounced;
        row.lambda_wave = 0.0;
      }
    }
    for (int it = 0; it < options.iterations; ++it) {
      for (Row& row : rows_) {
        if (row.wave != wave) continue;
        const double target = -row.restitution * row.bounce_from;
        const double impulse = std::max(0.0, row.lambda_wave + row.mass[0] * (target - normalVelocity(row)));
        const double delta = impulse - row.lambda_wave;
        row.lambda_wave = impulse;
        row.bounce_impulse += delta;
        applyNormal(row, delta, out_v, out_w);
      }
      if (jacobi) commitJacobi(v_, w_);
    }
    bool next = false;
    for (Row& row : rows_) {
      if (row.wave == wave || row.restitution <= 0.0) continue;
      const double vn = normalVelocity(row);
      if (vn < -std::max(options.restitution_threshold, row.speculative)) {
        row.wave = wave + 1;
        row.bounce_from = vn;
        row.bounced = true;
        next = true;
      }
    }
    if (!next) break;
  }
}

// Returns the passes run: options.iterations, fewer when the deadline
// passes first (never fewer than one when anything needs correcting).
int ContactSolver::solvePositions(const ResponseOptions& options, const Deadline& deadline) {
  bool any = false;
  for (const Row& row : rows_) any = any || row.push > 0.0 || (row.bounced && row.push < 0.0);
  if (!any) return 0;
  const bool jacobi = options.solver == SolverKind::Jacobi;
  std::vector<Vec3>& out_v = jacobi ? dv_ : pv_;
  std::vector<Vec3>& out_w = jacobi ? dw_ : pw_;
  int passes = 0;
  for (int it = 0; it < options.iterations; ++it, ++passes) {
    if (it > 0 && deadline.passed()) break;
    forEachColour([&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        Row& row = rows_[r];
        const Vec3 vrel =
            pv_[row.b] + pw_[row.b].cross(row.rb) - pv_[row.a] - pw_[row.a].cross(row.ra);
        // A contact that bounced across a speculative gap also closes the gap
        // (may pull): the bounce starts at the surface, not where the gap
        // was seen, so the rebound height does not gain up to |v| dt.
        const double unclamped = row.lambda_push + row.mass[0] * (row.push - vrel.dot(row.n));
        const double normal = row.bounced && row.push < 0.0 ? unclamped : std::max(0.0, unclamped);
        const double delta = normal - row.lambda_push;
        row.lambda_push = normal;
        applyNormal(row, delta, out_v, out_w);
      }
    });
    if (jacobi) commitJacobi(pv_, pw_);
  }
  return passes;
}

// The most iterations (<= cap) that fit in seconds_left with everything that
// follows them, costed in passes over the rows at the price of the first
// velocity pass: per iteration beyond the first one velocity pass and one
// position pass (when any contact needs correcting); then shock propagation's
// max(2, n / 2) passes, and one more for restitution and storing the result.
int ContactSolver::affordableIterations(const ResponseOptions& options, int cap, double pass_seconds,
                                        double seconds_left) const {
  if (!(pass_seconds > 0.0)) return cap;
  bool corrects = false;
  for (const Row& row : rows_) corrects = corrects || row.push != 0.0;
  const auto passes_after_the_first = [&](int n) {
    const int shock = options.shock_propagation ? std::max(2, n / 2) : 0;
    return (n - 1) + (corrects ? n : 0) + shock + 1;
  };
  int n = 1;
  while (n < cap && passes_after_the_first(n + 1) * pass_seconds <= seconds_left) ++n;
  return n;
}

void ContactSolver::store(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                          double dt) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    BodyState& body = bodies[i];
    if (body.is_static) continue;
    body.linear_velocity = v_[i];
    body.angular_velocity = w_[i];
    if (!pv_[i].isZero(0.0) || !pw_[i].isZero(0.0)) {
      body.pose.position += pv_[i] * dt;
      if (!pw_[i].isZero(0.0)) {
        body.pose.orientation = integrateOrientation(body.pose.orientation, pw_[i], dt);
        refreshWorldInertia(body);
      }
    }
  }

  // Report impulses on the contacts and keep them for next tick's warm start.
  next_cache_.clear();
  for (const Row& row : rows_) {
    Contact& c = contacts[row.contact];
    c.normal_impulse = row.lambda[0] + row.bounce_impulse;
    c.friction_impulse = row.lambda[1] * row.t1 + row.lambda[2] * row.t2;
    Cached cached;
    cached.a = c.a;
    cached.b = c.b;
    const BodyState& ba = bodies[row.a];
    cached.local_a = ba.pose.orientation.conjugate() * (c.point - ba.pose.position);
    cached.normal = row.lambda_main;
    cached.friction = c.friction_impulse;
    next_cache_.push_back(cached);
  }
  std::sort(next_cache_.begin(), next_cache_.end(), [](const Cached& x, const Cached& y) {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  });
  cache_.swap(next_cache_);
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
    cache_.clear();
    return stats;
  }
  collide(options, stats);
  if (options.warm_starting) warmStart(contacts, bodies, stats);
  // Refineable: the first velocity pass always runs; timed, it prices the
  // further iterations against the deadline. `run` carries the iterations
  // afforded to every later stage.
  const Deadline& deadline = budget.deadline;
  ResponseOptions run = options;
  run.iterations = std::max(1, std::min(options.iterations, budget.max_iterations));
  const double t_first = deadline.isSet() ? deadline.now() : 0.0;
  solveVelocities(run, 1);
  const double t_more = deadline.isSet() ? deadline.now() : 0.0;
  if (deadline.isSet()) {
    run.iterations = affordableIterations(run, run.iterations, t_more - t_first, deadline.at() - t_more);
  }
  solveVelocities(run, run.iterations - 1);
  stats.velocity_passes = run.iterations;
  const double t_rest = deadline.isSet() ? deadline.now() : 0.0;
  const bool jacobi = options.solver == SolverKind::Jacobi;
  if (jacobi) for (Row& row : rows_) row.lambda_main = row.lambda[0];
  if (options.shock_propagation) propagateShock(run);
  if (!jacobi) for (Row& row : rows_) row.lambda_main = row.lambda[0];
  const double t_positions = deadline.isSet() ? deadline.now() : 0.0;
  stats.position_passes = solvePositions(run, deadline);
  if (deadline.isSet()) {
    const double positions = deadline.now() - t_positions;
    const int extra = std::max(0, stats.position_passes - 1);
    stats.refinement_seconds = (t_rest - t_more) + positions * extra / std::max(1, stats.position_passes);
  }
  store(bodies, contacts, dt);
  if (!options.warm_starting) cache_.clear();
  return stats;
}

SolveStats solveContacts(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                         const ResponseOptions& options, double dt) {
  ContactSolver solver;
  return solver.solve(bodies, contacts, options, dt);
}

}  // namespace stc
