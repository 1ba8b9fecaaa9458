// Impulses (paper 3.5, 4): restitution, non-penetration and Coulomb friction
// iterated over all contacts of the tick before the state is committed
// (sequential impulses by default, the paper's simultaneous Jacobi scheme on
// request; docs/response.md has the measurements), shock propagation,
// split-impulse position correction. Works on flat std::vector<BodyState> /
// std::vector<Contact> arrays, without a World.
#pragma once

#include "contact_partition.hpp"
#include "solver_thread_plan.hpp"
#include "warm_start_cache.hpp"
#include "wide_batches.hpp"
#include "sphere_tree_collision/body.hpp"
#include "deadline.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/response_options.hpp"
#include "sphere_tree_collision/types.hpp"
#include "workers.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace stc {

// Two unit vectors completing unit n to a right-handed basis (t1, t2, n);
// the same n always gives the same pair (warm-started friction relies on it).
void tangentBasis(const Vec3& n, Vec3& t1, Vec3& t2);


struct SolveStats {
  std::size_t contacts = 0;
  std::size_t warm_started = 0;     // contacts that found last tick's impulse
  std::size_t warm_by_feature = 0;  // ... of those, by the same feature id (leaf sphere pair)
  std::size_t manifolds = 0;        // body pairs with contacts (rows of one pair are solved together)
  std::size_t bounced = 0;          // contacts that got a restitution impulse
  double max_penetration = 0.0;     // max(-separation) over the contacts, metres
  int velocity_passes = 0;          // velocity iterations run (>= 1 with contacts)
  int position_passes = 0;          // split-impulse iterations run (>= 1 with penetration)
  double refinement_seconds = 0.0;  // spent in the iterations a deadline may cut (set with one)
  std::uint32_t slabs = 1;          // slabs of the manifolds' blocks (contact_partition.hpp)
  std::size_t crossing_manifolds = 0;  // manifolds in the stages after the first (across slabs)
  std::size_t wide_batches = 0;        // batches of up to four manifolds the passes took (0: one at a time)
};

// What the tick lets the solver spend: the response is refineable (paper 3.5
// and 4: a lower level of response to fall back on). The warm start, the
// first velocity iteration and the first position iteration always run; more
// only up to max_iterations (and ResponseOptions::iterations), and, with a
// deadline, only while the solver's estimate of their cost (its first
// velocity pass, timed) fits before it.
struct SolveBudget {
  int max_iterations = std::numeric_limits<int>::max();
  Deadline deadline;
};

// Velocity solve: non-penetration (speculative: a contact with a gap s > 0
// lets the bodies close at most s/dt this tick) and Coulomb friction
// (circular cone, friction = sqrt(mu_a mu_b)), iterated with rows ordered up
// the contact graph from the static bodies; then shock propagation (see
// ResponseOptions). Restitution (e = max(e_a, e_b)) comes first, as
// collisions: contacts approaching faster than the threshold that close their
// gap this tick are bounced in waves before the solve (collide(); a bounce
// across a speculative gap also closes the gap, so it starts at the surface).
// Position correction by split impulse: pseudo-velocities that move the
// bodies out of penetration beyond the slop and are then discarded, so no
// kinetic energy is added. Contacts' normal_impulse/friction_impulse are
// filled in. The contacts of one body pair (its manifold: consecutive in the
// array, as ContactBuilder emits them) are solved together, and the manifolds
// block by block (contact_partition.hpp: any threads, the same bits). Warm starting
// keeps each pair's manifold from tick to tick: a point takes the impulse of
// last tick's point with the same feature id (Contact::node_a/node_b, the
// leaf sphere pair it was built from), else of the nearest one in body A's
// frame within half the gap bound; each old point is used once (the swept
// test's hit, kSweepHitNode, neither takes nor lends one). Stopped early by the
// budget, the state is as consistent as after a full solve: normal impulses
// >= 0, friction clamped to the cone as each pass goes, and velocities what
// the impulses sum to (shock propagation aside: it holds supports still).
class ContactSolver {
 public:
  SolveStats solve(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                   const ResponseOptions& options, double dt, const SolveBudget& budget = SolveBudget{});
  // The soft step (SolverKind::Soft; contact_solver_soft.cpp). The contacts
  // were found at the bodies' poses now, which the integration predicted
  // from `start_poses` (the tick's start) with velocities `start_v`, `start_w`.
  // The bodies go back to the start and move again by `options.substeps`
  // substeps of h = dt / substeps, what the integration added to their
  // velocities (gravity) spread evenly over them, each turning torque-free
  // by h (rotateFreely); each substep: that share, the impulses so far (warm start), one pass with
  // soft contacts (a penetration beyond the slop pushed out as a damped
  // spring, at most max_push_speed; a gap closed at most to contact),
  // positions moved by h, one pass without the push (relax). Each contact's
  // separation is measured again each pass from its bodies' moves since its
  // poses (anchors fixed in the bodies). Restitution comes first, as the
  // default's waves. Stores the velocities and the poses; the contacts get
  // the tick's impulses; the warm start keeps the last substep's.
  // A body in `start.held` (the swept test put it back at its first hit)
  // goes no further along its path from the start than the hit in any
  // substep, and keeps no speed onward along it there: the substeps would
  // otherwise move it through what it hit, as the swept test's discrete step
  // was stopped from doing.
  // Refineable by `budget`: the first substep is timed and prices the rest;
  // those that do not fit before the deadline merge into fewer, longer ones
  // (softer contacts, the same tick), one alone once the deadline has passed;
  // budget.max_iterations caps the substeps.
  struct TickStart {
    const std::vector<Pose>* poses = nullptr;  // per body, the tick's start
    const std::vector<Vec3>* v = nullptr;
    const std::vector<Vec3>* w = nullptr;
    const std::vector<std::uint32_t>* held = nullptr;  // bodies the swept test put back (may be null)
  };
  SolveStats solveSoft(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                       const ResponseOptions& options, double dt, const TickStart& start,
                       const SolveBudget& budget = SolveBudget{});
  void forget() { warm_.clear(); }  // drop warm-start impulses
  // Threads of the velocity, shock and position iterations (nullptr: the
  // caller's alone); the result is the same whatever they are
  // (contact_partition.hpp: a body pair's manifold is one group). A stage
  // of fewer than `task_manifolds` manifolds is solved on the calling thread
  // (ResponseOptions::solver_task_manifolds).
  void setWorkers(const Workers* workers, std::size_t task_manifolds) {
    workers_ = workers;
    plan_.setWorkers(workers, task_manifolds);
  }

  // What the next solve warm-starts from (the sleeping pairs' manifolds kept
  // with WarmStartCache::keepWhileHeld; a saved world's through solved(),
  // held() and restore()).
  const WarmStartCache& warmStartCache() const { return warm_; }
  WarmStartCache& warmStartCache() { return warm_; }

  // A body's velocities as the solver sees them: one cache line per body.
  // A cache line each: bodies next to each other in the array may belong to
  // blocks that two threads solve at once.
  struct alignas(64) Motion {
    Vec3 v = Vec3::Zero();
    Vec3 w = Vec3::Zero();
  };
  // What the iterations read and write of one contact point: its normal and
  // two tangent rows. Everything else about the contact is in RowInfo, so
  // each pass streams only this.
  struct Row {
    std::uint32_t a = 0, b = 0;
    Vec3 ra, rb;  // contact point relative to the centres of mass
    Vec3 n, t1, t2;
    // Angular velocity change per unit impulse along n, t1, t2 (I^-1 (r x d)).
    Vec3 ang_a[3], ang_b[3];
    double inv_ma = 0.0, inv_mb = 0.0;
    double mass[3] = {0.0, 0.0, 0.0};  // 1 / effective mass along n, t1, t2
    double friction = 0.0;
    double speculative = 0.0;          // closing speed allowed by a gap: max(s, 0) / dt
    double lambda[3] = {0.0, 0.0, 0.0};
    double bounce_impulse = 0.0;       // of all its restitution waves (before the solve)
    // The soft step only: the contact's separation at the poses it was
    // found at (measured again from the bodies' moves each substep), and
    // the penetration it keeps as slop.
    double separation = 0.0;
    double slop = 0.0;
  };
  // Rolling resistance of one body pair (Material::rolling_resistance): an
  // angular impulse on the two bodies' relative spin, held within
  // `per_normal` times the pair's normal impulse. Solved after the pair's
  // rows, in the velocity iterations.
  struct Rolling {
    Mat3 mass = Mat3::Zero();   // (I_a^-1 + I_b^-1)^-1, world frame
    Mat3 inv_ia = Mat3::Zero(), inv_ib = Mat3::Zero();  // zero for a static body
    double per_normal = 0.0;    // coefficient * rolling radius (m); 0: none
    Vec3 lambda = Vec3::Zero(); // angular impulse so far (b gets +, a gets -)
  };
  // One sequential-impulse step of a row (friction, then non-penetration)
  // on the velocities of its two bodies: the unit of work of a pass.
  static void relax(Row& row, Motion& a, Motion& b);
  // One step of a pair's rolling resistance, its rows' normal impulse so far
  // `normal`, on the pair's velocities a and b (after its rows, in a pass).
  static void resistRolling(Rolling& roll, double normal, Motion& a, Motion& b);

 private:
  // The rest of a row: the restitution waves, shock propagation and the
  // position pass read it; the velocity iterations do not.
  struct RowInfo {
    std::uint32_t contact = 0;  // index into the contacts array
    int level = 0;              // contact-graph distance of the lower body from a static one
    bool move_a = true, move_b = true;   // shock propagation holds the supporting body
    double shock_mass[3] = {0.0, 0.0, 0.0};  // 1 / effective mass with the support held
    double restitution = 0.0;
    double approach = 0.0;     // normal relative velocity before the solve (< 0: closing)
    double push = 0.0;         // split impulse: target normal pseudo-velocity
    double push_mass = 0.0;    // 1 / effective mass along n of the bodies' translation alone
    double shock_push_mass = 0.0;  // the same with the support held (position shock sweep)
    // What warm starts the next tick: the velocity iterations' impulses (normal
    // without the bounce; friction along t1, t2), which both bodies took.
    // Shock propagation's later ones the upper body took alone.
    double lambda_main = 0.0;
    double friction_main[2] = {0.0, 0.0};
    double lambda_push = 0.0;
    double bounce_from = 0.0;  // normal velocity its bounce reverses (< 0), in its wave
    double lambda_wave = 0.0;  // impulse of the current restitution wave
    int wave = -1;             // restitution wave it bounced in (-1: none)
    bool bounced = false;      // took a restitution impulse this tick
    // The soft step: the impulses of all its substeps (normal, t1, t2), and
    // its bounce, which bounds friction in the first substep only.
    double soft_total[3] = {0.0, 0.0, 0.0};
    double soft_bounce = 0.0;
    double soft_kept[3] = {0.0, 0.0, 0.0};  // its impulses before a substep's shock sweep
  };
  void prepare(const std::vector<BodyState>& bodies, const std::vector<Contact>& contacts,
               const ResponseOptions& options, double dt, SolveStats& stats);
  void orderFromTheGround();  // from active_, contact_bodies_ and immovable_
  using ManifoldRun = SolverThreadPlan::ManifoldRun;
  // step(r, a, b) over the rows r of manifolds [first, end), a and b the
  // pair's entries of `motion` copied in, then written back (a static body's
  // never is: blocks do not hold it apart).
  template <typename Step>
  void overManifolds(std::size_t first, std::size_t end, std::vector<Motion>& motion, Step&& step);
  // The same, then after(m, a, b) once a manifold m's rows are done.
  template <typename Step, typename After>
  void overManifolds(std::size_t first, std::size_t end, std::vector<Motion>& motion, Step&& step,
                     After&& after);
  // Fills rolling_ (after the rows); any_rolling_ when a pair resists.
  void prepareRolling(const std::vector<BodyState>& bodies, bool jacobi);
  double normalImpulse(std::size_t manifold) const;  // its rows' normal impulses so far, bounces included
  void warmStart(std::vector<Contact>& contacts, const std::vector<BodyState>& bodies,
                 SolveStats& stats);
  void commitJacobi(std::vector<Motion>& motion);
  // The refineable passes after the warm start: the velocity iterations
  // (the first timed, pricing the rest against the deadline), shock
  // propagation, the position passes and their shock sweep.
  void iterate(const ResponseOptions& options, const SolveBudget& budget, SolveStats& stats);
  void solveVelocities(const ResponseOptions& options, int passes);
  int affordableIterations(const ResponseOptions& options, int cap, double pass_seconds,
                           double seconds_left) const;
  void propagateShock(const ResponseOptions& options);
  void collide(const ResponseOptions& options, SolveStats& stats);
  void waveRuns();  // collide(): each pass run's rows of the wave, in wave_runs_
  int solvePositions(const ResponseOptions& options, const Deadline& deadline);
  // One split-impulse step of a row: its pseudo-impulse towards info.push,
  // the relative motion read from a and b, `mass` along n, applied to out_a
  // and out_b (by translation alone unless `turns`).
  static void pushStep(const Row& row, RowInfo& info, const Motion& a, const Motion& b, double mass, bool turns,
                       Motion& out_a, Motion& out_b);
  // After the position passes, one sweep up the levels with the supporting
  // body of each row held: what they left of a pile's overlap goes upward.
  void propagatePositionShock(const ResponseOptions& options);
  void store(std::vector<BodyState>& bodies, std::vector<Contact>& contacts, double dt);

  // The soft step (contact_solver_soft.cpp). A body's move since the poses
  // its contacts were found at: translation, and rotation (world frame).
  struct SoftMove {
    Vec3 p = Vec3::Zero();
    Quat q = Quat::Identity();
  };
  // A row's separation at the poses now (soft_move_): its separation where
  // found plus closedSince, the bodies' moves since along its normal.
  double closedSince(const Row& row) const;
  double separationNow(const Row& row) const { return row.separation + closedSince(row); }
  // Rows' separations at the tick's start, the restitution's wave 0 from them.
  void prepareSoft(const std::vector<Contact>& contacts, const ResponseOptions& options, double dt);
  // A substep's shock sweep (contact_solver_soft.cpp), substep length h.
  void holdSupports(const ResponseOptions& options, double h);
  // What the substeps run on besides the rows: `hold`: a shock sweep in
  // each (holdSupports); `count`: the substeps the tick asks for.
  struct SoftRun {
    bool hold = false;
    int count = 1;
    const SolveBudget* budget = nullptr;
  };
  // The substeps after the restitution and the warm start; returns how many ran.
  int substeps(std::vector<BodyState>& bodies, const ResponseOptions& options, double dt, const SoftRun& run);
  // One substep of length h, `share` of the tick's gain, the first or not.
  void substep(std::vector<BodyState>& bodies, const ResponseOptions& options, double h, double share, bool first,
               bool hold);
  // A held body back within its reach (solveSoft's `start.held`) after a
  // substep's move, its speed onward along its path dropped there.
  struct SoftReach;
  static void keepWithinReach(const SoftReach& reach, BodyState& body, Motion& motion);
  // The soft step sweeps shock propagation in each substep only when some
  // body rests on one at least this much lighter than itself (10:1 holds
  // without it; a pile of like bodies does not pay for it).
  static constexpr double kHeavyOnLight = 10.0;
  std::vector<SoftMove> soft_move_;
  std::vector<Pose> soft_found_;   // per body: the poses its contacts were found at
  std::vector<Motion> soft_gain_;  // per body: what the integration added to v and w this tick
  // Per body the swept test put back: its path's direction from the tick's
  // start and how far along it the hit is (length < 0: not held).
  struct SoftReach {
    Vec3 origin = Vec3::Zero();
    Vec3 direction = Vec3::Zero();
    double length = -1.0;
  };
  std::vector<SoftReach> soft_reach_;
  bool any_reach_ = false;

  // The sequential passes (velocity, shock, position, position shock),
  // kLanes manifolds side by side (contact_solver_wide.cpp) on the batches
  // of wide_batches_ (wide_batches.hpp), laid out after the rows are prepared.
  // Batches [first, end): rows_ copied in, or their impulses copied back.
  void packWide(std::size_t first, std::size_t end);
  void unpackWide(std::size_t first, std::size_t end);
  // `passes` sequential velocity passes on the batches (each pair's rolling
  // resistance after its rows), and shock propagation's (propagateShock).
  void solveVelocitiesWide(int passes);
  void propagateShockWide(int passes);
  // The position passes by translation alone on the batches: one pass, and
  // the position shock sweep (after packWidePush).
  void packWidePush(std::size_t first, std::size_t end);
  void solvePositionsWide();
  void propagatePositionShockWide();

  bool wide_ = false;  // this solve's sequential passes run on the batches
  WideBatches wide_batches_;

  std::vector<Row> rows_;
  std::vector<RowInfo> info_;
  std::vector<Rolling> rolling_;  // by manifold (filled only when any_rolling_)
  bool any_rolling_ = false;
  std::vector<std::uint32_t> order_, active_, level_start_;
  std::vector<std::uint32_t> wave_rows_, last_wave_rows_, next_wave_rows_;  // collide(): by wave
  std::vector<std::array<std::uint32_t, 2>> row_bodies_;  // collide(): each row's bodies, compact
  std::vector<std::uint8_t> wave_flag_;                   // collide(): per row, in the next wave
  std::vector<ManifoldRun> wave_runs_;                    // collide(): per pass run, its wave rows
  std::vector<std::uint8_t> moved_;                       // collide(): bodies the last two waves moved
  std::vector<Motion> motion_;  // solver velocities, one per body
  std::vector<Motion> delta_;   // Jacobi: impulses of one iteration, applied together
  std::vector<Motion> pseudo_;  // split-impulse pseudo-velocities
  std::vector<std::uint8_t> out_of_solve_;  // per body: static (or held) in this solve, compact
  std::vector<std::uint8_t> immovable_;     // per body: static or of infinite mass, compact
  // Per contact: its two dense body indices, compact, for the serial loops of
  // the set-up (the order from the ground, the groups), which would otherwise
  // read a whole Contact for two indices.
  std::vector<std::array<std::uint32_t, 2>> contact_bodies_;
  std::vector<int> contact_count_;
  std::vector<int> depth_, adjacency_start_, fill_;  // contact graph, for the row order
  std::vector<int> contact_level_;  // orderFromTheGround: per active contact, the lower body's depth
  std::vector<std::uint32_t> adjacency_, queue_;  // adjacency_: the other body of each contact at a body
  WarmStartCache warm_;  // last solve's manifolds and the sleeping pairs'
  const Workers* workers_ = nullptr;
  // Which manifolds run together, on which worker (solver_thread_plan.hpp):
  // the manifolds in block order (order_ is regrouped by it) and the loops
  // that run a pass's ranges of them stage by stage.
  SolverThreadPlan plan_;
};

// One-shot solve without warm starting (tests, tools).
SolveStats solveContacts(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                         const ResponseOptions& options, double dt);

}  // namespace stc
