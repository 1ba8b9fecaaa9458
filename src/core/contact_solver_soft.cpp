// The soft step (SolverKind::Soft), after the idea of Box2D v3's solver:
// substeps inside the tick, soft contacts, positions moved in the solve.
// Reuses the default solver's rows, blocks, stages and restitution waves.
#include "contact_solver.hpp"

#include "dynamics.hpp"
#include "contact_rows.hpp"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>

namespace stc {

using namespace contact_rows;

namespace {

constexpr std::size_t kRowsPerTask = 256;
// A substep of at most this many sqrt(bound / |g|) (bound: a contact's
// sphere bound, about a voxel): see substepCount.
constexpr double kSubstepPerScale = 0.07;
constexpr int kMaxSubsteps = 64;
// The restitution waves before the substeps, and the passes of each: a count
// of the soft step's own, so that ResponseOptions::iterations (the default
// solver's) is not used by it (a ball's bounce then depends on the other
// solver's setting).
constexpr int kSoftCollisionPasses = 20;
constexpr double kPi = 3.14159265358979323846;

// A soft contact as a damped spring of `hertz` and `damping_ratio`, solved
// implicitly over a substep h: the push speed per metre of penetration, and
// how much of the rigid impulse and of the impulse so far a step applies
// (Catto, "Solver2D" notes: the soft step's coefficients).
struct Softness {
  double bias_rate = 0.0;
  double mass_scale = 1.0;
  double impulse_scale = 0.0;
};

Softness makeSoftness(double hertz, double damping_ratio, double h) {
  const double omega = 2.0 * kPi * hertz;
  const double a1 = 2.0 * damping_ratio + h * omega;
  const double a2 = h * omega * a1;
  const double a3 = 1.0 / (1.0 + a2);
  return Softness{omega / a1, a2 * a3, a3};
}

// What one pass of the substeps needs besides the rows.
struct SoftPass {
  Softness moving, immovable;  // contacts of two movable bodies, and against an immovable one
  double inv_h = 0.0;
  double max_push = 0.0;
  bool bias = true;  // false: the relaxing pass (a gap still closes at most to contact)
};

// One soft step of a row at separation `s` now: friction (bounded by the
// normal impulse so far, the default's order), then the normal impulse.
// (Normal first let the sliding cube of test_physics stop where it should,
// but launched rocks at 30 m/s in test_stability's zero-budget pile.)
STC_HOT_INLINE void softRow(ContactSolver::Row& row, double s, const SoftPass& pass, ContactSolver::Motion& a,
                            ContactSolver::Motion& b) {
  const Eigen::Vector2d d = frictionStep(row, relativeVelocity(row, a.v, a.w, b.v, b.w), row.mass[1], row.mass[2]);
  applyFriction(row, d.x(), d.y(), a, b);
  double bias = 0.0, mass_scale = 1.0, impulse_scale = 0.0;
  if (s > 0.0) {
    // Speculative: close the gap at most to contact this substep. The
    // relaxing pass comes after the move and leaves an open contact to the
    // next substep's biased pass: so the velocity a tick stores is the one
    // its last substep moved with.
    if (!pass.bias) return;
    bias = s * pass.inv_h;
  } else if (pass.bias && s + row.slop < 0.0) {
    // Beyond the slop: soft. Within it the row holds rigidly, as in the
    // relaxing pass: no push, and no give either (a soft row there let its
    // impulse leak each substep, so a resting body sank on towards the slop
    // while the relaxing pass stored it still: the sliding cube of
    // test_physics crept at 1e-4 m/s after it stopped).
    const Softness& soft = (row.inv_ma == 0.0 || row.inv_mb == 0.0) ? pass.immovable : pass.moving;
    bias = std::max(soft.bias_rate * (s + row.slop), -pass.max_push);
    mass_scale = soft.mass_scale;
    impulse_scale = soft.impulse_scale;
  }
  const double vn = relativeVelocity(row, a.v, a.w, b.v, b.w).dot(row.n);
  const double impulse = -row.mass[0] * mass_scale * (vn + bias) - impulse_scale * row.lambda[0];
  const double normal = std::max(0.0, row.lambda[0] + impulse);
  applyNormal(row, normal - row.lambda[0], a, b);
  row.lambda[0] = normal;
}

}  // namespace

double ContactSolver::closedSince(const Row& row) const {
  const SoftMove& ma = soft_move_[row.a];
  const SoftMove& mb = soft_move_[row.b];
  const Vec3 d = (mb.p - ma.p) + (mb.q * row.rb - row.rb) - (ma.q * row.ra - row.ra);
  return row.n.dot(d);
}

void ContactSolver::prepareSoft(const std::vector<Contact>& contacts, const ResponseOptions& options, double dt) {
  forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      Row& row = rows_[r];
      RowInfo& info = info_[r];
      const Contact& c = contacts[info.contact];
      row.separation = c.separation;
      row.slop = options.allowed_penetration > 0.0 ? options.allowed_penetration : 0.02 * c.sphere_bound;
      // A contact the narrow phase did not prove (a budget cut it at the
      // root spheres or a frontier: separation 0 or a gap bound, wherever the
      // bodies were predicted) says nothing of how near the bodies were at
      // the tick's start: its separation holds from there, as the default
      // solver holds it from the poses it is found at. Measured back from the
      // predicted poses instead, a rock sliding down a plate under a starved
      // budget was let close a "gap" of its own predicted move each tick and
      // sank 1.6 voxels into the plate.
      const double moved = closedSince(row);  // the bodies' moves since, along n (one measure for both uses)
      if (!c.resolved) row.separation -= (row.separation + moved) - row.separation;
      // Wave 0 of the restitution as prepare() classifies it, but from the
      // gap at the tick's start: a contact bounces when it closes that gap
      // this tick faster than the threshold.
      const double s = row.separation + moved;
      row.speculative = s > 0.0 ? s / dt : 0.0;
      info.bounced = info.restitution > 0.0 && info.approach < -std::max(options.restitution_threshold, row.speculative);
      info.wave = info.bounced ? 0 : -1;
      wave_flag_[r] = info.bounced ? 1 : 0;
    }
  });
}

void ContactSolver::keepWithinReach(const SoftReach& reach, BodyState& body, Motion& motion) {
  const double along = (body.pose.position - reach.origin).dot(reach.direction);
  if (along <= reach.length) return;
  body.pose.position -= (along - reach.length) * reach.direction;
  const double onward = motion.v.dot(reach.direction);
  if (onward > 0.0) motion.v -= onward * reach.direction;
}

void ContactSolver::substep(std::vector<BodyState>& bodies, const ResponseOptions& options, double h, double share,
                            bool first, bool hold) {
  SoftPass pass;
  // A quarter of the substep rate (the stiffest a soft contact stays stable
  // at, Box2D v3's bound), or contact_hertz below it: the stiffness follows
  // the substep, so a resting body's give (|g| / omega^2) shrinks with h.
  const double quarter_rate = 0.25 / h;
  const double hertz = options.contact_hertz > 0.0 ? std::min(options.contact_hertz, quarter_rate) : quarter_rate;
  pass.moving = makeSoftness(hertz, options.contact_damping_ratio, h);
  pass.immovable = makeSoftness(2.0 * hertz, options.contact_damping_ratio, h);
  pass.inv_h = 1.0 / h;
  pass.max_push = options.max_push_speed;
  const std::size_t body_count = bodies.size();
  const auto softStep = [&](std::size_t r, Motion& a, Motion& b) { softRow(rows_[r], separationNow(rows_[r]), pass, a, b); };
  const auto relaxStep = [&](std::size_t r, Motion& a, Motion& b) {
    Row& row = rows_[r];
    softRow(row, separationNow(row), pass, a, b);
    RowInfo& info = info_[r];  // this substep's impulses are final
    for (int k = 0; k < 3; ++k) info.soft_total[k] += row.lambda[k];
  };
  const auto roll = [&](std::size_t m, Motion& a, Motion& b) {
    if (rolling_[m].per_normal != 0.0) resistRolling(rolling_[m], normalImpulse(m), a, b);
  };
  // The impulses so far again, as each substep's warm start.
  const auto warmStep = [&](std::size_t r, Motion& a, Motion& b) {
    const Row& row = rows_[r];
    applyNormal(row, row.lambda[0], a, b);
    applyFriction(row, row.lambda[1], row.lambda[2], a, b);
  };
  const auto warmRoll = [&](std::size_t m, Motion& a, Motion& b) {
    const Rolling& rl = rolling_[m];
    if (rl.per_normal == 0.0) return;
    a.w -= rl.inv_ia * rl.lambda;
    b.w += rl.inv_ib * rl.lambda;
  };
  const auto pass_over = [&](auto& step) {
    plan_.forEachStage([&](std::size_t first_m, std::size_t end) {
      if (any_rolling_) {
        overManifolds(first_m, end, motion_, step, roll);
      } else {
        overManifolds(first_m, end, motion_, step);
      }
    });
  };
  // Each body alone: its share of the integration's gain, then (after the
  // biased pass) its move by h.
  forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (bodies[i].is_static) continue;
      motion_[i].v += share * soft_gain_[i].v;
      motion_[i].w += share * soft_gain_[i].w;
    }
  });
  if (!first && !rows_.empty()) {
    plan_.forEachStage([&](std::size_t first_m, std::size_t end) {
      if (any_rolling_) {
        overManifolds(first_m, end, motion_, warmStep, warmRoll);
      } else {
        overManifolds(first_m, end, motion_, warmStep);
      }
    });
  }
  pass.bias = true;
  if (!rows_.empty()) pass_over(softStep);
  if (hold) holdSupports(options, h);
  forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      BodyState& body = bodies[i];
      if (body.is_static) continue;
      body.pose.position += motion_[i].v * h;
      if (!motion_[i].w.isZero(0.0)) {  // the torque-free turn of h (the gyroscopic term's, energy kept)
        body.angular_velocity = motion_[i].w;
        const FreeRotation turned = rotateFreely(body, h, options.gyroscopic);
        body.pose.orientation = turned.orientation;
        motion_[i].w = turned.angular_velocity;
      }
      if (any_reach_ && soft_reach_[i].length >= 0.0) keepWithinReach(soft_reach_[i], body, motion_[i]);
      soft_move_[i].p = body.pose.position - soft_found_[i].position;
      soft_move_[i].q = body.pose.orientation * soft_found_[i].orientation.conjugate();
    }
  });
  pass.bias = false;
  if (!rows_.empty()) pass_over(relaxStep);
  if (first && !rows_.empty()) {
    // The bounce bounds friction in the first substep only: it acted once.
    forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
      for (std::size_t r = begin; r < end; ++r) {
        info_[r].soft_bounce = rows_[r].bounce_impulse;
        rows_[r].bounce_impulse = 0.0;
      }
    });
  }
}

int ContactSolver::substeps(std::vector<BodyState>& bodies, const ResponseOptions& options, double dt,
                            const SoftRun& run) {
  const SolveBudget unlimited;
  const SolveBudget& budget = run.budget != nullptr ? *run.budget : unlimited;
  const Deadline& deadline = budget.deadline;
  // A spent tick moves its bodies the whole tick in one substep: the
  // cheapest level of the response (two passes), never a standstill.
  int count = std::max(1, std::min(run.count, budget.max_iterations));
  if (deadline.passed()) count = 1;
  const double first_share = 1.0 / count;
  const double t_first = deadline.isSet() ? deadline.now() : 0.0;
  substep(bodies, options, dt * first_share, first_share, true, run.hold);
  if (count == 1) return 1;
  int more = count - 1;
  double share = first_share;
  if (deadline.isSet()) {
    // The first substep prices the others; what does not fit merges into
    // fewer, longer substeps over the rest of the tick (at least one). As
    // doubles: a far deadline over a cheap substep is past any int.
    const double t_more = deadline.now();
    const double each = t_more - t_first;
    const double left = deadline.at() - t_more;
    if (each > 0.0 && left < each * static_cast<double>(more)) {
      more = static_cast<int>(std::max(1.0, std::floor(left / each)));
      share = (1.0 - first_share) / more;
    }
  }
  for (int sub = 0; sub < more; ++sub) substep(bodies, options, dt * share, share, false, run.hold);
  return 1 + more;
}

// Shock propagation inside the substep, before the move: one sweep up the
// levels from the ground with each row's supporting body held, so that no
// body moves into what supports it however heavy its load. Its impulses move
// the upper bodies only and are not kept: the impulses so far (the next
// substep's warm start) stay the passes', which reach both bodies, so a
// support still learns its load.
void ContactSolver::holdSupports(const ResponseOptions& options, double h) {
  forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      Row& row = rows_[r];
      RowInfo& info = info_[r];
      const double s = separationNow(row);
      row.speculative = s > 0.0 ? s / h : 0.0;  // shock propagation's gap: this substep's
      for (int k = 0; k < 3; ++k) info.soft_kept[k] = row.lambda[k];
    }
  });
  ResponseOptions once = options;
  once.iterations = 2;  // max(2, iterations / 2) passes a level: two
  propagateShock(once);
  forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      for (int k = 0; k < 3; ++k) rows_[r].lambda[k] = info_[r].soft_kept[k];
    }
  });
}

SolveStats ContactSolver::solveSoft(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                                    const ResponseOptions& options, double dt, const TickStart& start,
                                    const SolveBudget& budget) {
  SolveStats stats;
  if (!(dt > 0.0) || bodies.empty()) return stats;
  assert(start.poses != nullptr && start.v != nullptr && start.w != nullptr);
  const std::vector<Pose>& start_poses = *start.poses;
  const std::vector<Vec3>& start_v = *start.v;
  const std::vector<Vec3>& start_w = *start.w;
  assert(start_poses.size() >= bodies.size() && start_v.size() >= bodies.size() && start_w.size() >= bodies.size());
  for (Contact& c : contacts) {
    c.normal_impulse = 0.0;
    c.friction_impulse.setZero();
  }
  const std::size_t body_count = bodies.size();
  soft_gain_.resize(body_count);
  soft_move_.resize(body_count);
  soft_found_.resize(body_count);
  // Each held body's reach: from its start to where the swept test put it
  // (its pose now), along that path (or, put back at the start itself,
  // along the velocity it was to move with).
  any_reach_ = start.held != nullptr && !start.held->empty();
  if (any_reach_) {
    soft_reach_.assign(body_count, SoftReach{});
    for (const std::uint32_t i : *start.held) {
      assert(i < body_count);
      const BodyState& body = bodies[i];
      if (body.is_static) continue;
      SoftReach& reach = soft_reach_[i];
      const Vec3 path = body.pose.position - start_poses[i].position;
      const double length = path.norm();
      const double speed = body.linear_velocity.norm();
      if (length > 0.0) {
        reach.direction = path / length;
      } else if (speed > 0.0) {
        reach.direction = body.linear_velocity / speed;
      } else {
        continue;  // nowhere to go: nothing to keep it from
      }
      reach.origin = start_poses[i].position;
      reach.length = length;
    }
  }
  // Velocities back to the tick's start (the rows' approach is measured from
  // them); the poses stay where the contacts were found until prepared.
  forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      BodyState& body = bodies[i];
      soft_move_[i] = SoftMove{};
      soft_found_[i] = body.pose;
      if (body.is_static) continue;
      soft_gain_[i].v = body.linear_velocity - start_v[i];
      soft_gain_[i].w = Vec3::Zero();  // the gyroscopic turn comes substep by substep (substeps())
      body.linear_velocity = start_v[i];
      body.angular_velocity = start_w[i];
    }
  });
  ResponseOptions sequential = options;
  sequential.wide_passes = false;  // the soft passes take one manifold at a time
  sequential.iterations = kSoftCollisionPasses;
  prepare(bodies, contacts, sequential, dt, stats);
  // The poses back to the tick's start: the moves since the contacts' poses.
  forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      BodyState& body = bodies[i];
      if (body.is_static) continue;
      body.pose = start_poses[i];
      soft_move_[i].p = body.pose.position - soft_found_[i].position;
      soft_move_[i].q = body.pose.orientation * soft_found_[i].orientation.conjugate();
    }
  });
  if (!rows_.empty()) prepareSoft(contacts, options, dt);
  // A heavy body on a much lighter support (the support nearer the ground).
  std::atomic<bool> heavy_on_light{false};
  if (options.shock_propagation && !rows_.empty() && plan_.shockLevels() > 0) {
    forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
      bool found = false;
      for (std::size_t r = begin; r < end && !found; ++r) {
        const Row& row = rows_[r];
        const RowInfo& info = info_[r];
        found = (!info.move_a && row.inv_mb > 0.0 && row.inv_ma >= kHeavyOnLight * row.inv_mb) ||
                (!info.move_b && row.inv_ma > 0.0 && row.inv_mb >= kHeavyOnLight * row.inv_ma);
      }
      if (found) heavy_on_light.store(true, std::memory_order_relaxed);
    });
  }
  const bool hold = heavy_on_light.load();
  // Substeps: a soft contact is at most a quarter of the substep rate stiff
  // (omega <= pi / 2h), so a body resting on it under gravity g gives
  // |g| / omega^2 >= 0.4 |g| h^2, and a stack of n such bodies about n^2 / 2
  // times that at its foot. Against the contact's size (its sphere bound,
  // about a voxel) that is (h / sqrt(bound / |g|))^2: small bodies or long
  // ticks need shorter substeps, or the give outgrows the voxel and cubes
  // sink into each other (a stack of 1 mm voxels at 60 Hz, or of 5 cm
  // voxels at dt = 0.1 s, fell through itself with 4). So the substeps are
  // at least options.substeps and as many as keep h <= kSubstepPerScale
  // sqrt(bound / |g|) for every contact (|g|: what integrate added to a
  // movable body's v, per second). Serial: the same count at any threads.
  ResponseOptions stepped = options;
  {
    double worst = 0.0;  // max over rows of |g| / bound (1 / s^2)
    for (std::size_t r = 0; r < rows_.size(); ++r) {
      const Row& row = rows_[r];
      const double bound = contacts[info_[r].contact].sphere_bound;
      if (!(bound > 0.0)) continue;
      double gain = 0.0;
      if (!bodies[row.a].is_static) gain = soft_gain_[row.a].v.squaredNorm();
      if (!bodies[row.b].is_static) gain = std::max(gain, soft_gain_[row.b].v.squaredNorm());
      worst = std::max(worst, std::sqrt(gain) / (dt * bound));
    }
    if (worst > 0.0) {
      const double needed = std::ceil(dt * std::sqrt(worst) / kSubstepPerScale - 1e-9);
      stepped.substeps = static_cast<int>(std::min<double>(kMaxSubsteps, std::max<double>(options.substeps, needed)));
    }
  }
  SoftRun run;
  run.hold = hold;
  run.count = stepped.substeps;
  run.budget = &budget;
  int ran = 0;
  plan_.onTeam([&] {
    if (!rows_.empty()) {
      collide(sequential, stats);
      if (options.warm_starting) warmStart(contacts, bodies, stats);
    }
    ran = substeps(bodies, stepped, dt, run);
  });
  stats.velocity_passes = rows_.empty() ? 0 : 2 * ran;
  // The warm start keeps the last substep's impulses; the contacts report the tick's.
  forEachIndex(workers_, rows_.size(), kRowsPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      Row& row = rows_[r];
      RowInfo& info = info_[r];
      info.lambda_main = row.lambda[0];
      info.friction_main[0] = row.lambda[1];
      info.friction_main[1] = row.lambda[2];
      for (int k = 0; k < 3; ++k) row.lambda[k] = info.soft_total[k];
      row.bounce_impulse = info.soft_bounce;
    }
  });
  forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!bodies[i].is_static) refreshWorldInertia(bodies[i]);
    }
  });
  if (rows_.empty()) {
    forEachIndex(workers_, body_count, kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        if (bodies[i].is_static) continue;
        bodies[i].linear_velocity = motion_[i].v;
        bodies[i].angular_velocity = motion_[i].w;
      }
    });
    warm_.commitNone(out_of_solve_);  // only the sleepers' manifolds stay
    return stats;
  }
  store(bodies, contacts, dt);  // pseudo-velocities are zero: velocities and the cache alone
  if (!options.warm_starting) forget();
  return stats;
}

}  // namespace stc
