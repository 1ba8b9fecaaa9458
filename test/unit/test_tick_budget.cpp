// One budget for the whole tick (issue 9, item 2): the solver always runs its
// warm start and one velocity and one position pass, refines only while the
// budget allows, and stops in a consistent state; the narrow phase gets what
// integrate, the broad phase and the reserve leave; budgets that are never
// reached change nothing. Deterministic: iteration counts and a fake clock.
#include "stepping_clock.hpp"

#include "contact_solver.hpp"
#include "deadline.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <utility>

namespace stc {
namespace {

constexpr double kDt = 1.0 / 60.0;

// corner_drift with 125 rocks, as built.
SceneWorld corner125() {
  SceneParams params;
  params.entities = 125;
  return makeSceneWorld(SceneKind::CornerDrift, params);
}

// corner_drift with 125 rocks after `ticks` full ticks: a pile in the corner.
World pile(int ticks) {
  World w = std::move(corner125().world);
  // The reserve the budgeted ticks start from is measured by these ticks: on
  // the real clock it would depend on the machine's load.
  w.setClock(steppingClock(1e-4));
  for (int i = 0; i < ticks; ++i) w.step(kDt, Budget::unlimited());
  return w;
}

// The pile after 1.5 s, built once for the solver tests (they only read it).
const World& pile90() {
  static const World w = pile(90);
  return w;
}

bool finite(const BodyState& b) {
  return allFinite(b.pose.position) && b.pose.orientation.coeffs().allFinite() &&
         allFinite(b.linear_velocity) && allFinite(b.angular_velocity);
}

// A solver stopped anywhere leaves every normal impulse >= 0 and every
// velocity equal to what the impulses on the body sum to, linear and angular
// (solves without shock propagation: it holds the supporting body still on
// purpose, so there the reaction is not applied).
void expectConsistent(const std::vector<BodyState>& before, const std::vector<BodyState>& after,
                      const std::vector<Contact>& contacts) {
  std::vector<Vec3> dv(before.size(), Vec3::Zero()), dw(before.size(), Vec3::Zero());
  for (const Contact& c : contacts) {
    EXPECT_GE(c.normal_impulse, 0.0);
    const Vec3 p = c.normal_impulse * c.normal + c.friction_impulse;  // on b, minus on a
    const BodyState& a = before[c.index_a];
    const BodyState& b = before[c.index_b];
    if (!a.is_static) {
      dv[c.index_a] -= a.inv_mass * p;
      dw[c.index_a] -= a.inv_inertia_world * (c.point - a.pose.position).cross(p);
    }
    if (!b.is_static) {
      dv[c.index_b] += b.inv_mass * p;
      dw[c.index_b] += b.inv_inertia_world * (c.point - b.pose.position).cross(p);
    }
  }
  for (std::size_t i = 0; i < before.size(); ++i) {
    ASSERT_TRUE(finite(after[i])) << i;
    const Vec3 v = before[i].linear_velocity + dv[i];
    const Vec3 w = before[i].angular_velocity + dw[i];
    EXPECT_LE((after[i].linear_velocity - v).norm(), 1e-9 * (1.0 + v.norm())) << i;
    EXPECT_LE((after[i].angular_velocity - w).norm(), 1e-9 * (1.0 + w.norm())) << i;
  }
}

struct Solved {
  SolveStats stats;
  std::vector<BodyState> bodies;
  std::vector<Contact> contacts;
};

ResponseOptions withoutShock() {
  ResponseOptions options;
  options.shock_propagation = false;
  return options;
}

// One solve of the pile's last contacts from its current state.
Solved solveOnce(const World& w, const SolveBudget& budget, const ResponseOptions& options = withoutShock()) {
  Solved s;
  s.bodies = w.bodies();
  s.contacts = w.contacts();
  ContactSolver solver;
  s.stats = solver.solve(s.bodies, s.contacts, options, kDt, budget);
  return s;
}

TEST(TickBudget, SolverAlwaysRunsOneVelocityAndOnePositionPass) {
  const World& w = pile90();
  ASSERT_GT(w.contacts().size(), 100u);
  const SecondsClock clock = steppingClock(1e-3);
  SolveBudget none_left;
  none_left.max_iterations = 0;
  SolveBudget passed;
  passed.deadline = Deadline(&clock, -1.0);  // already over when the solve starts
  for (const SolveBudget& budget : {none_left, passed}) {
    const Solved s = solveOnce(w, budget);
    EXPECT_EQ(s.stats.velocity_passes, 1);
    ASSERT_GT(s.stats.max_penetration, 0.0);  // the pile penetrates: positions are corrected
    EXPECT_EQ(s.stats.position_passes, 1);
    expectConsistent(w.bodies(), s.bodies, s.contacts);
  }
}

TEST(TickBudget, SolverStopsAtTheIterationBudget) {
  const World& w = pile90();
  ResponseOptions options = withoutShock();
  options.iterations = 20;
  for (const int cap : {2, 3, 7}) {
    SolveBudget budget;
    budget.max_iterations = cap;
    const Solved s = solveOnce(w, budget, options);
    EXPECT_EQ(s.stats.velocity_passes, cap);
    EXPECT_EQ(s.stats.position_passes, cap);
    expectConsistent(w.bodies(), s.bodies, s.contacts);
  }
  SolveBudget above;
  above.max_iterations = 50;  // the options' count still bounds it
  EXPECT_EQ(solveOnce(w, above, options).stats.velocity_passes, 20);
  EXPECT_EQ(solveOnce(w, SolveBudget{}, options).stats.velocity_passes, 20);
}

TEST(TickBudget, SolverRefinesOnlyWhileTheDeadlineAllows) {
  const World& w = pile90();
  const int configured = ResponseOptions{}.iterations;
  int previous = 1;
  for (const double seconds_left : {0.0, 0.004, 0.012, 0.030, 1000.0}) {
    // Every clock read costs 1 ms, so the first pass is priced at 1 ms.
    const SecondsClock clock = steppingClock(1e-3);
    SolveBudget budget;
    budget.deadline = Deadline(&clock, seconds_left);
    const Solved s = solveOnce(w, budget, ResponseOptions{});  // with shock propagation
    EXPECT_GE(s.stats.velocity_passes, previous) << seconds_left;  // more time never gives less
    EXPECT_GE(s.stats.position_passes, 1) << seconds_left;
    EXPECT_LE(s.stats.position_passes, s.stats.velocity_passes) << seconds_left;
    if (seconds_left < 0.03) EXPECT_LT(s.stats.velocity_passes, configured) << seconds_left;
    for (const BodyState& b : s.bodies) ASSERT_TRUE(finite(b));
    previous = s.stats.velocity_passes;
  }
  EXPECT_EQ(previous, configured);  // a far deadline: every configured iteration
}

TEST(TickBudget, BudgetsThatAreNeverReachedChangeNothing) {
  World unlimited = pile(0), roomy = pile(0);
  Budget far = Budget::ofTickSeconds(1e6);
  far.solver_iterations = ResponseOptions{}.iterations;
  bool contacts = false;
  for (int i = 0; i < 60; ++i) {
    const TickReport a = unlimited.step(kDt, Budget::unlimited());
    const TickReport b = roomy.step(kDt, far);
    if (a.response.contacts > 0) {
      contacts = true;
      EXPECT_EQ(a.response.velocity_passes, ResponseOptions{}.iterations);
      EXPECT_EQ(b.response.velocity_passes, a.response.velocity_passes);
      EXPECT_EQ(b.response.position_passes, a.response.position_passes);
    }
    EXPECT_FALSE(b.detection.interrupted);
  }
  ASSERT_TRUE(contacts);
  for (std::size_t i = 0; i < unlimited.bodies().size(); ++i) {  // bit for bit
    EXPECT_EQ(unlimited.bodies()[i].pose.position, roomy.bodies()[i].pose.position) << i;
    EXPECT_EQ(unlimited.bodies()[i].linear_velocity, roomy.bodies()[i].linear_velocity) << i;
    EXPECT_EQ(unlimited.bodies()[i].angular_velocity, roomy.bodies()[i].angular_velocity) << i;
  }
}

TEST(TickBudget, NarrowPhaseGetsWhatTheFixedPhasesAndTheReserveLeave) {
  World w = pile(60);
  w.setClock(steppingClock(1e-4));
  const double tick = 0.02;
  bool interrupted_with_time = false;
  for (int i = 0; i < 30; ++i) {
    const TickReport r = w.step(kDt, Budget::ofTickSeconds(tick));
    EXPECT_EQ(r.budget.tick_budget_s, tick);
    EXPECT_GE(r.budget.reserve_s, 0.0);
    EXPECT_NEAR(r.budget.narrow_budget_s,
                std::max(0.0, tick - r.phases.integrate_s - r.phases.broad_s - r.phases.sweep_s - r.budget.reserve_s),
                1e-12);
    EXPECT_NEAR(r.budget.response_budget_s,
                std::max(0.0, tick - r.phases.integrate_s - r.phases.broad_s - r.phases.sweep_s - r.phases.narrow_s),
                1e-12);
    if (i == 0) EXPECT_GT(r.budget.reserve_s, 0.0);  // measured by the unlimited ticks before
    if (r.detection.interrupted && r.budget.narrow_budget_s > 0.0) {
      interrupted_with_time = true;
      EXPECT_GT(r.detection.sphere_tests, 0);
    }
    EXPECT_GE(r.response.velocity_passes, 1);
  }
  EXPECT_TRUE(interrupted_with_time);

  // A narrow-phase limit of its own still applies when it is the smaller.
  Budget both = Budget::ofTickSeconds(tick);
  both.seconds = 1e-4;
  EXPECT_NEAR(w.step(kDt, both).budget.narrow_budget_s, 1e-4, 1e-15);
}

// A clock whose read costs real time (a thread CPU clock is a system call,
// about 20 times the steady clock) is read once per many sphere tests, and
// the narrow phase still ends at its deadline. The clock's values are fake
// (every read 1e-4 s later), so what is asserted does not depend on the
// machine; only its cost is real: each read spins 2 us on the steady clock.
TEST(TickBudget, ACostlyClockIsReadOncePerManySphereTests) {
  constexpr double kStep = 1e-4;
  auto reads = std::make_shared<std::int64_t>(0);
  const SecondsClock costly = [reads] {
    const double until = steadySeconds() + 2e-6;
    while (steadySeconds() < until) {
    }
    return kStep * static_cast<double>((*reads)++);
  };
  EXPECT_GE(checkEveryFor(costly), 10 * BudgetTracker::kDefaultCheckEvery);
  EXPECT_LE(checkEveryFor(costly), kMostCheckEvery);
  EXPECT_EQ(checkEveryFor(steppingClock(kStep)), BudgetTracker::kDefaultCheckEvery) << "a cheap clock: as before";

  World w = pile(60);
  w.setClock(costly);
  bool interrupted = false;
  for (int i = 0; i < 10; ++i) {
    const TickReport r = w.step(kDt, Budget::ofTickSeconds(0.003));
    // Every read is kStep of fake time: the narrow phase's reads, less its
    // stamps and the read that saw the deadline, came one per 320 sphere
    // tests or fewer (with a cheap clock, one per 32).
    const auto narrow_reads = static_cast<std::int64_t>(std::lround(r.phases.narrow_s / kStep));
    EXPECT_GE(r.detection.sphere_tests, 10 * BudgetTracker::kDefaultCheckEvery * (narrow_reads - 3)) << "tick " << i;
    // Ended by the first read past the deadline; two stamps follow it
    // (scheduling done, and the phase's end).
    EXPECT_LE(r.phases.narrow_s, r.budget.narrow_budget_s + 3 * kStep + 1e-12) << "tick " << i;
    interrupted = interrupted || r.detection.interrupted;
  }
  EXPECT_TRUE(interrupted) << "the deadline, not the pairs running out, ended the narrow phase";
}

// The response's time is its contacts' building and the solve: the report
// names the first (contacts_s), on the World's clock like every phase.
TEST(TickBudget, ResponseTimeIsBuildingTheContactsAndTheSolve) {
  World w = pile(60);
  for (int i = 0; i < 3; ++i) {
    const TickReport r = w.step(kDt, Budget::unlimited());
    ASSERT_GT(r.response.contacts, 0u);
    EXPECT_GT(r.phases.contacts_s, 0.0);
    EXPECT_LT(r.phases.contacts_s, r.phases.response_s) << "the solve after it is timed in response_s too";
  }
}

TEST(TickBudget, SpentTickStillRespondsAndStaysFiniteAndInTheBox) {
  // The tick is over before the narrow phase starts: every pair is accepted
  // unresolved and the solver runs its mandatory pass, tick after tick.
  auto [w, spec] = corner125();
  for (int i = 0; i < 240; ++i) {
    const TickReport r = w.step(kDt, Budget::ofTickSeconds(0.0));
    ASSERT_EQ(r.budget.narrow_budget_s, 0.0);
    ASSERT_EQ(r.detection.sphere_tests, 0);
    if (r.response.contacts > 0) ASSERT_EQ(r.response.velocity_passes, 1);
  }
  const Vec3 margin = Vec3::Constant(0.5 * SceneParams{}.entity_size);
  for (const EntityId id : spec.movers) {
    const BodyState& b = w.bodies()[*w.indexOf(id)];
    ASSERT_TRUE(finite(b));
    EXPECT_TRUE((b.pose.position.array() >= (spec.bounds.min - margin).array()).all()) << id;
    EXPECT_TRUE((b.pose.position.array() <= (spec.bounds.max + margin).array()).all()) << id;
    EXPECT_LT(b.linear_velocity.norm(), 10.0) << id;
  }
}

TEST(TickBudget, OnePassAWarmStartedTickHoldsABoxAtRest) {
  // Warm starting carries the impulses across ticks, so one pass a tick is
  // enough to hold a resting box (what the solver falls back to when starved).
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  World w(config);
  PresetParams p;
  p.resolution = 16;
  p.voxel_size = 0.125;
  const ShapeId plate = w.addShape("plate", makePreset("plate", p));
  EntitySpec floor;
  floor.shape = plate;
  floor.is_static = true;
  floor.pose.position = Vec3(0.0, 0.0, -0.5 * w.shape(plate).voxels.extent().z());
  w.addEntity(floor);
  p.resolution = 8;
  p.voxel_size = 0.05;
  EntitySpec box;
  box.shape = w.addShape("cube", makePreset("cube", p));
  box.pose.position = Vec3(0.0, 0.0, 0.2);
  w.addEntity(box);
  for (int i = 0; i < 120; ++i) w.step(kDt, Budget::ofSolverIterations(1));
  const BodyState& b = w.bodies()[1];
  EXPECT_LT(b.linear_velocity.norm(), 0.05);
  EXPECT_NEAR(b.pose.position.z(), 0.2, 0.01);
}

}  // namespace
}  // namespace stc
