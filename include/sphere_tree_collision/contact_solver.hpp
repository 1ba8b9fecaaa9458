// Impulses (paper 3.5, 4): restitution, non-penetration and Coulomb friction
// iterated over all contacts of the tick before the state is committed
// (sequential impulses by default, the paper's simultaneous Jacobi scheme on
// request; docs/response.md has the measurements), shock propagation,
// split-impulse position correction. Works on flat std::vector<BodyState> /
// std::vector<Contact> arrays, without a World.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/contact_colouring.hpp"
#include "sphere_tree_collision/response_options.hpp"
#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/workers.hpp"

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
  std::size_t bounced = 0;          // contacts that got a restitution impulse
  double max_penetration = 0.0;     // max(-separation) over the contacts, metres
  int velocity_passes = 0;          // velocity iterations run (>= 1 with contacts)
  int position_passes = 0;          // split-impulse iterations run (>= 1 with penetration)
  double refinement_seconds = 0.0;  // spent in the iterations a deadline may cut (set with one)
  std::uint32_t colours = 0;        // colours of the contacts (contact_colouring.hpp): passes' sync points
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
  // Threads of the velocity and position iterations (nullptr: the caller's
  // alone); the result is the same whatever they are (contact_colouring.hpp).
  void setWorkers(const Workers* workers) { workers_ = workers; }

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
    bool static_a = false, static_b = false;  // never moves: its velocity is not written
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
  // Friction of one row from the velocities now, clamped to the cone of its
  // normal impulse so far (incl. the bounce); adds to its lambdas and returns
  // the change along t1, t2.
  Eigen::Vector2d frictionStep(Row& row, double mass_t1, double mass_t2) const;
  void solveVelocities(const ResponseOptions& options, int passes);
  int affordableIterations(const ResponseOptions& options, int cap, double pass_seconds,
                           double seconds_left) const;
  void propagateShock(const ResponseOptions& options);
  void collide(const ResponseOptions& options, SolveStats& stats);
  int solvePositions(const ResponseOptions& options, const Deadline& deadline);
  void store(std::vector<BodyState>& bodies, std::vector<Contact>& contacts, double dt);
  // After orderFromTheGround: rows_ reordered by colour (contact_solver_colours.cpp).
  void colourRows(std::size_t body_count);
  // rows(begin, end) over every colour's rows in turn, a colour's body-pair
  // groups split over the workers; each range holds whole groups.
  void forEachColour(RangeFn rows);
  // Shock propagation's order: the levels from the ground (unreached rows
  // aside), and a level's rows colour by colour, as forEachColour.
  std::size_t shockLevels() const { return level_segment_start_.empty() ? 0 : level_segment_start_.size() - 1; }
  void forEachColourOfLevel(std::size_t level, RangeFn rows);
  void forEachGroupRun(std::uint32_t first, std::uint32_t end, RangeFn rows) const;  // groups [first, end)

  std::vector<Row> rows_, sorted_rows_;
  std::vector<std::uint32_t> order_, level_start_;
  std::vector<Vec3> v_, w_;    // solver velocities, one per body
  std::vector<Vec3> dv_, dw_;  // Jacobi: impulses of one iteration, applied together
  std::vector<Vec3> pv_, pw_;  // split-impulse pseudo-velocities
  std::vector<int> contact_count_;
  std::vector<int> depth_, adjacency_start_, fill_;  // contact graph, for the row order
  std::vector<std::uint32_t> adjacency_, queue_;
  std::vector<Cached> cache_, next_cache_;
  // Colouring (contact_solver_colours.cpp): the body-pair groups of the rows,
  // their colours, and in colour order where each colour's groups and each
  // group's rows start.
  const Workers* workers_ = nullptr;
  ContactColouring colouring_;
  std::vector<ColourGroup> groups_;
  std::vector<std::uint32_t> group_of_row_, colour_group_start_, group_row_start_, group_order_;
  // Per level from the ground: its runs of groups, one per colour
  // (positions in colour order); the levels' first runs.
  struct GroupRun {
    std::uint32_t first = 0, end = 0;
  };
  std::vector<GroupRun> level_runs_;
  std::vector<std::uint32_t> level_segment_start_, cursor_;
  std::vector<int> levels_;
};

// One-shot solve without warm starting (tests, tools).
SolveStats solveContacts(std::vector<BodyState>& bodies, std::vector<Contact>& contacts,
                         const ResponseOptions& options, double dt);

}  // namespace stc
