// Response (paper 3.5, 4): contacts from the deepest intersecting sphere pairs
// of each colliding PairTest; impulses with restitution and Coulomb friction,
// iterated over all contacts of the tick before the state is committed
// (sequential impulses by default, the paper's simultaneous Jacobi scheme on
// request; docs/response.md has the measurements), shock propagation,
// split-impulse position correction; and a swept test that stops fast bodies
// at their first contact.
//
// Everything here also works without a World: the free functions and classes
// take flat std::vector<BodyState> / std::vector<Contact> arrays.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/dynamics.hpp"
#include "sphere_tree_collision/pair_test.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace stc {

struct ShapeInfo;  // world.hpp

// How the impulses of one tick are iterated (docs/response.md has the measurements).
enum class SolverKind : std::uint8_t {
  Sequential,  // projected Gauss-Seidel (sequential impulses): each contact sees the last one's impulse
  Jacobi,      // the paper's simultaneous scheme: every iteration computes all impulses from
               // one state, then applies them together (mass splitting keeps it convergent)
};
// "sequential" | "jacobi"; throws InputError("solver") otherwise.
SolverKind parseSolverKind(const std::string& name);
const char* toString(SolverKind kind);

struct ResponseOptions {
  bool enabled = true;
  int iterations = 20;                  // velocity (and position) iterations per tick, >= 1
  // m/s: slower approach is treated as resting. The World raises it to at
  // least 4 |g| dt: a body resting under gravity falls that fast within a
  // speculative gap in one or two ticks, and bouncing on that would never settle.
  double restitution_threshold = 0.2;
  double position_correction = 0.2;     // fraction of penetration removed per tick, [0, 1]
  double allowed_penetration = 0.0;     // metres kept as slop (0: 2% of the contact's gap bound h_a + h_b)
  SolverKind solver = SolverKind::Sequential;
  bool warm_starting = true;            // start from last tick's impulses of matching contacts
  // After the iterations, one sweep up the contact graph from the static
  // bodies in which each supporting body counts as immovable for what rests
  // on it (shock propagation, Guendelman et al. 2003): stacks and heavy-on-light
  // hold; only approach towards the support is removed, never added.
  bool shock_propagation = true;
  int max_contacts_per_pair = 4;        // spread-out representatives of the sphere pairs, 1..16
  bool face_normals = true;             // voxel-box face axis when it separates more (ContactBuilder)
  bool continuous = true;               // sweep fast bodies back to their first contact
  // A body is fast when it moves (incl. rotation at its farthest sphere) more
  // than this fraction of its smallest leaf radius in one tick.
  double sweep_threshold = 0.5;
  bool gyroscopic = true;               // implicit-midpoint w x Iw (see dynamics.hpp)
};
// Throws InputError naming the field ("response.iterations", ...).
void validateResponseOptions(const ResponseOptions& options);

// Two unit vectors completing unit n to a right-handed basis (t1, t2, n);
// the same n always gives the same pair (warm-started friction relies on it).
void tangentBasis(const Vec3& n, Vec3& t1, Vec3& t2);

// ---------------------------------------------------------------------------
// Per-shape bounds, computed once per shape

// Where the shape is inside each node's sphere. A sphere only says the shape
// lies within r of its centre (up to h inside for a leaf); the voxels whose
// centres lie in the sphere also bound it by their axis-aligned box (body
// frame). The surface of the node towards a direction u is then taken at
// support(u) = min(r, box support): an outer bound of the node's part of the
// shape, exact for a single-voxel leaf (a cube) and for a box-shaped part
// face-on, where r alone leaves a gap of up to h.
struct ShapeBounds {
  const SphereTree* tree = nullptr;
  std::vector<Vec3> box_offset;  // per node: box centre minus sphere centre (body frame)
  std::vector<Vec3> box_half;    // per node: box half extents
  std::vector<double> reach;     // per node: max over its leaves of |c_leaf - c_node| + r_leaf
  double min_leaf_radius = 0.0;
  double bound_radius = 0.0;     // max over leaves of |c_leaf| + r_leaf (about the body origin)

  // Distance from node's centre to its surface towards `direction_body` (unit, body frame).
  double support(std::int32_t node, const Vec3& direction_body) const {
    const std::size_t i = static_cast<std::size_t>(node);
    const double box = box_offset[i].dot(direction_body) + box_half[i].dot(direction_body.cwiseAbs());
    return std::min(tree->node(node).radius, box);
  }
};
// voxels == nullptr: boxes are the spheres' cubes (support = r). body_origin:
// the grid-frame point the tree was built about (ShapeInfo::body_origin).
ShapeBounds makeShapeBounds(const SphereTree& tree, const VoxelShape* voxels = nullptr,
                            const Vec3& body_origin = Vec3::Zero());

// ---------------------------------------------------------------------------
// Contacts

struct ContactBuildOptions {
  int max_contacts_per_pair = 4;
  bool accept_unresolved = true;  // policy accept: unresolved pairs give contacts too
  bool face_normals = true;       // see ContactBuilder; false: the paper's line of centres only
};

// Builds the contacts of PairTests. Candidates are the test's lastPairs()
// (leaf pairs when Colliding, the frontier when accepted Unresolved, the roots
// when no sphere was tested). Per candidate (paper Fig. 4): normal along the
// line of centres a -> b, point dividing the centres in proportion to the
// radii. With face_normals and ShapeBounds, a face axis of either node's voxel
// box replaces the line of centres when it separates the two nodes more (the
// separating-axis rule): face-on, the line of centres of two voxel spheres
// tilts by up to 45 degrees, making floors bumpy and balls sit in dimples;
// the point is then the middle of the two boxes' overlap on the face plane,
// halfway between the surfaces. Only candidates with at least half the
// deepest sphere overlap are refined so and can represent the pair.
// Up to max_contacts_per_pair representatives are picked spread out among the
// deep candidates (deepest corner first, then farthest, then largest
// triangle); every candidate joins its nearest representative; the cluster's
// normal is the mean over its deepest members (sphere overlap within 10% of
// its deepest: the pairs straight across the contact). separation is
// measured along that normal between the nodes' surfaces
// (ShapeBounds::support; the sphere itself without bounds). Coincident
// centres: the direction between the body centres, then +Z; never NaN.
class ContactBuilder {
 public:
  // Appends the contacts of one test (none when Separate, or Unresolved and not accepted).
  // bounds_a/bounds_b: of the test's trees, or nullptr (surface at the spheres).
  void append(const PairTest& test, std::uint32_t index_a, std::uint32_t index_b, double priority,
              const ShapeBounds* bounds_a, const ShapeBounds* bounds_b,
              const ContactBuildOptions& options, std::vector<Contact>& out);

 private:
  struct Candidate {
    Vec3 ca, cb, point, normal;
    double overlap = 0.0;                     // r_a + r_b - |c_b - c_a|
    double separation = 0.0;                  // gap between the surfaces along normal
    std::int32_t node_a = 0, node_b = 0;
    int cluster = 0;
    bool refined = false;                     // separation and face normal evaluated (deep enough)
  };
  std::vector<Candidate> candidates_;
  std::vector<int> reps_;
};

// ---------------------------------------------------------------------------
// Impulses

struct SolveStats {
  std::size_t contacts = 0;
  std::size_t warm_started = 0;     // contacts that found last tick's impulse
  std::size_t bounced = 0;          // contacts that got a restitution impulse
  double max_penetration = 0.0;     // max(-separation) over the contacts, metres
  int velocity_passes = 0;          // velocity iterations run (>= 1 with contacts)
  int position_passes = 0;          // split-impulse iterations run (>= 1 with penetration)
  double refinement_seconds = 0.0;  // spent in the iterations a deadline may cut (set with one)
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
// filled in. Warm starting matches contacts by entity pair and the contact
// point in body A's frame (within half the gap bound). Stopped early by the
// budget, the state is as consistent as after a full solve: normal impulses
// >= 0, friction clamped to the cone as each pass goes, and velocities what
// the impulses sum to (shock propagation aside: it holds supports still).
class ContactSolver {
 public:
  SolveStats solve(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                   const ResponseOptions& options, double dt, const SolveBudget& budget = SolveBudget{});
  void forget() { cache_.clear(); }  // drop warm-start impulses

 private:
  // One contact's constraint rows: normal, two tangents.
  struct Row {
    std::uint32_t a = 0, b = 0;
    std::uint32_t contact = 0;  // index into the contacts array
    Vec3 ra, rb;  // contact point relative to the centres of mass
    Vec3 n, t1, t2;
    // Angular velocity change per unit impulse along n, t1, t2 (I^-1 (r x d)).
    Vec3 ang_a[3], ang_b[3];
    double inv_ma = 0.0, inv_mb = 0.0;
    double mass[3] = {0.0, 0.0, 0.0};  // 1 / effective mass along n, t1, t2
    double k_a[3] = {0.0, 0.0, 0.0};   // each body's part of the effective inverse mass
    double k_b[3] = {0.0, 0.0, 0.0};
    int level = 0;             // contact-graph distance of the lower body from a static one
    std::uint8_t support = 0;  // 1: a supports b (a is nearer the ground), 2: b supports a, 0: neither
    double friction = 0.0, restitution = 0.0;
    double approach = 0.0;     // normal relative velocity before the solve (< 0: closing)
    double speculative = 0.0;  // closing speed allowed by a gap: max(s, 0) / dt
    double push = 0.0;         // split impulse: target normal pseudo-velocity
    double lambda[3] = {0.0, 0.0, 0.0};
    double lambda_main = 0.0;  // normal impulse before restitution (what warm starts)
    double lambda_push = 0.0;
    double bounce_from = 0.0;  // normal velocity its bounce reverses (< 0), in its wave
    double lambda_wave = 0.0;  // impulse of the current restitution wave
    double bounce_impulse = 0.0;  // of all its restitution waves (before the solve)
    int wave = -1;             // restitution wave it bounced in (-1: none)
    bool bounced = false;      // took a restitution impulse this tick
  };
  struct Cached {
    EntityId a = kInvalidEntity, b = kInvalidEntity;
    Vec3 local_a = Vec3::Zero();  // contact point in body A's frame
    double normal = 0.0;
    Vec3 friction = Vec3::Zero();  // world frame
  };
  void prepare(const std::vector<BodyState>& bodies, const std::vector<Contact>& contacts,
               const ResponseOptions& options, double dt, SolveStats& stats);
  void orderFromTheGround(const std::vector<BodyState>& bodies);
  void warmStart(std::vector<Contact>& contacts, const std::vector<BodyState>& bodies,
                 SolveStats& stats);
  void commitJacobi(std::vector<Vec3>& v, std::vector<Vec3>& w);
  static void applyNormal(const Row& row, double impulse, std::vector<Vec3>& v, std::vector<Vec3>& w);
  void solveVelocities(const ResponseOptions& options, int passes);
  int affordableIterations(const ResponseOptions& options, int cap, double pass_seconds,
                           double seconds_left) const;
  void propagateShock(const ResponseOptions& options);
  void collide(const ResponseOptions& options, SolveStats& stats);
  int solvePositions(const ResponseOptions& options, const Deadline& deadline);
  void store(std::vector<BodyState>& bodies, std::vector<Contact>& contacts, double dt);

  std::vector<Row> rows_, sorted_rows_;
  std::vector<std::uint32_t> order_, level_start_;
  std::vector<Vec3> v_, w_;    // solver velocities, one per body
  std::vector<Vec3> dv_, dw_;  // Jacobi: impulses of one iteration, applied together
  std::vector<Vec3> pv_, pw_;  // split-impulse pseudo-velocities
  std::vector<int> contact_count_;
  std::vector<int> depth_, adjacency_start_, fill_;  // contact graph, for the row order
  std::vector<std::uint32_t> adjacency_, queue_;
  std::vector<Cached> cache_, next_cache_;
};

// One-shot solve without warm starting (tests, tools).
SolveStats solveContacts(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                         const ResponseOptions& options, double dt);

// ---------------------------------------------------------------------------
// Anti-tunnelling: swept test of fast bodies (paper: backtrack to the instant
// of collision), after the broad phase

struct SweepStats {
  std::size_t fast_bodies = 0;
  std::size_t clamped = 0;  // moved back to their first contact
  std::size_t pairs = 0;    // pairs swept (relative motion fast)
  std::size_t leaf_tests = 0;  // leaf box pairs tested
};

// A fast body's earliest hit of the tick.
struct SweepHit {
  double t = 1.0;              // fraction of the tick at the hit; 1: none
  std::uint32_t pair = 0;      // index into the candidate pairs
  Vec3 point = Vec3::Zero();   // halfway between the two leaf boxes' faces, below the held body's box centre
  Vec3 normal = Vec3::UnitZ(); // face axis the boxes met on, from pairs[pair][0] towards [1]
};

// Kept between ticks so a tick allocates nothing.
struct SweepScratch {
  std::vector<std::pair<std::int32_t, std::int32_t>> stack;  // node pairs of one sweep
  std::vector<std::uint8_t> fast;        // per body: moved far enough to be swept
  std::vector<SweepHit> hits;            // per body
  std::vector<std::uint32_t> clamped;    // bodies put back this tick
};

// Bodies moved from start[i] to bodies[i].pose this tick. A body is fast when
// it moved (rotation counted at its farthest leaf) more than `threshold` of
// its smallest leaf radius (ResponseOptions::sweep_threshold). Static bodies
// and shapes[i] == nullptr never are. Fills `fast`, returns the count.
std::size_t markFastBodies(const std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes, double threshold,
                           std::vector<std::uint8_t>& fast);

// Sweeps each fast body (scratch.fast, from markFastBodies) against its
// partners in pairs[0..pair_count) (dense body indices: the broad phase's
// pairs, found with swept boxes), never against all bodies, and only where
// the pair's relative motion is fast by the same threshold. Both bodies of a
// pair move along their chords from start to end pose; the leaves' voxel boxes
// are tested in that relative motion (hierarchy pruned by ShapeBounds::reach).
// A hit is the first instant a pair of leaf boxes overlaps deeper than a
// quarter of the thinner box, when at the end they would have passed through
// each other or sunk in deeper than the thinner box's half extent (a graze
// the discrete step resolves is left to it). The body is put back at its
// earliest hit (position lerp, orientation slerp). Its velocity is kept: the
// narrow phase of the same tick finds the contact there, and the response
// turns the approach (Physics::respond adds the hit as a contact when the
// narrow phase gave that pair none). scratch.hits and scratch.clamped say
// where. Pairs already overlapping at the start are resting contacts, left to
// the solver.
SweepStats sweepFastBodies(std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes,
                           const std::vector<std::array<std::uint32_t, 2>>& pairs, std::size_t pair_count,
                           double threshold, SweepScratch& scratch);

// ---------------------------------------------------------------------------
// The World's physics: integrate and respond, keeping what lasts between
// ticks (warm-start impulses by entity id, per-shape sweep data, scratch).

struct PhysicsReport {
  SweepStats sweep;
  SolveStats solve;
};

class Physics {
 public:
  // Voxels, tree and body origin of a shape id; called once per new shape.
  using ShapeOf = std::function<const ShapeInfo&(std::uint32_t shape)>;

  // Tick phase 1: positions, velocities (gravity), and which bodies are fast.
  void integrate(std::vector<BodyState>& bodies, const std::vector<std::uint32_t>& body_shapes,
                 const ShapeOf& shape_of, const Vec3& gravity, const ResponseOptions& options,
                 double dt);
  // After integrate: fast bodies need swept boxes in the broad phase, from
  // their start pose of the tick to their pose now.
  bool isFast(std::size_t body) const {
    return body < sweep_scratch_.fast.size() && sweep_scratch_.fast[body] != 0;
  }
  const Pose& startPose(std::size_t body) const { return start_[body]; }
  // Tick phase 2b, after the broad phase: sweep of the fast bodies against
  // their broad-phase partners pair_bodies[0..count) (sweepFastBodies).
  void sweep(std::vector<BodyState>& bodies, const std::vector<std::array<std::uint32_t, 2>>& pair_bodies,
             std::size_t count, const ResponseOptions& options);
  // Tick phase 4: contacts of tests[0..count) (pair_bodies: dense indices of
  // each test's bodies; the same pairs the sweep saw), plus the sweep's hit
  // for a pair whose test gave no contact, then impulses when options.enabled,
  // within `budget`.
  void respond(const std::vector<PairTest>& tests, std::size_t count,
               const std::vector<std::array<std::uint32_t, 2>>& pair_bodies,
               const std::vector<double>& priorities, bool accept_unresolved,
               const std::vector<std::uint32_t>& body_shapes, const ShapeOf& shape_of,
               std::vector<BodyState>& bodies, const ResponseOptions& options, double dt,
               std::vector<Contact>& contacts, const SolveBudget& budget = SolveBudget{});
  const PhysicsReport& lastReport() const { return report_; }
  void forget() { solver_.forget(); }

 private:
  const ShapeBounds& boundsOf(std::uint32_t shape, const ShapeOf& shape_of);

  ContactBuilder builder_;
  ContactSolver solver_;
  double gravity_speed_ = 0.0;  // |g| dt of the last integrate
  std::vector<ShapeBounds> bounds_;  // by shape id, built on first use
  std::vector<Pose> start_;
  std::vector<const ShapeBounds*> body_bounds_;
  SweepScratch sweep_scratch_;
  std::vector<std::int32_t> sweep_hit_of_pair_;  // body whose sweep hit that pair, or -1
  PhysicsReport report_;
};

}  // namespace stc
