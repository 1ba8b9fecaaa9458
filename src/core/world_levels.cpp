// World: the island levels of a limited response (island_levels.hpp) wired
// into the tick: what the allowance is, the joins after the broad phase, and
// what a unit of cost took.
#include "world_parts.hpp"

#include "tick_context.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {
namespace {

// Of what the tick budget leaves after the phases that must run (integrate,
// broad phase, swept test, fracture: their running mean, kCostUnitWeight), the
// share the full islands' mandatory response may take (contacts, one velocity
// and one position pass). The rest is the narrow phase's and the solver's
// further passes.
constexpr double kResponseShare = 0.5;
// The phases that must run and a unit of island cost: running means, this
// much of each tick's measure. A spike is not the next tick's cost: with each
// spike kept and forgotten by 0.95 a tick (as the narrow phase's reserve,
// world.cpp), the median tick of rockfall 5,000 used 2.8 of its 16.7 ms while
// 85 % of its bodies waited.
constexpr double kCostUnitWeight = 0.25;
// Metres added to the reach of two paths in the join test: rounding, and the
// contact builder's slop.
constexpr double kJoinMargin = 0.01;

// Radius of a ball about the centre of mass holding the shape and its
// tree's root sphere (which may reach past the shape: an unresolved pair
// accepted at the roots gives contacts there).
double reachOf(const ShapeInfo& shape) {
  const SphereNode& root = shape.tree.node(0);
  return std::max(shape.bounding_radius, root.centre.norm() + root.radius);
}

}  // namespace

bool World::Parts::responseLimited(const Budget& budget) {
  return budget.tick_seconds < std::numeric_limits<double>::infinity() ||
         budget.response_contacts < std::numeric_limits<std::int64_t>::max();
}

void World::Parts::chooseLevels(const Budget& budget, TickReport& report) {
  double allowance = std::numeric_limits<double>::infinity();
  if (budget.response_contacts < std::numeric_limits<std::int64_t>::max()) {
    allowance = static_cast<double>(std::max<std::int64_t>(budget.response_contacts, 0));
  }
  if (budget.tick_seconds < std::numeric_limits<double>::infinity() && cost_unit_s_ > 0.0) {
    const double left = std::max(budget.tick_seconds - must_run_s_, 0.0);
    allowance = std::min(allowance, kResponseShare * left / cost_unit_s_);
  }
  IslandLevels::Inputs in;
  in.bodies = &rows_.bodies();
  in.contacts = &contacts_;  // last tick's (emptied when entities came or went)
  in.perception = &perception_;
  in.allowance = allowance;
  levels_.choose(in, report.response.levels);
}

// After the broad phase's pairs are set up: a held island that a moving
// body's box reaches (directly, or through held bodies whose boxes overlap)
// runs this tick. Releasing it changes which pairs are tested and may wake a
// sleeper, which moves from now on too: until nothing more joins. Then the
// joined bodies are integrated, from where they were held; their boxes
// (IslandLevels::heldBox) already cover where that takes them.
void World::Parts::joinHeldIslands(TickContext& tick) {
  const double dt = tick.dt;
  const std::vector<BroadPair>& pairs = broad_phase_.pairs();
  const auto pair_at = [&](std::size_t k) { return pairs_seen_[k].indices; };
  // Each body's path this tick as a segment of its centre: a held body's
  // from where it is to where it would have gone, a moving one's from its
  // start pose to now. Two can touch (or meet at their root spheres, as an
  // unresolved pair accepted there does) only if balls about their centres
  // holding shape and root sphere (reachOf) come within reach along them: the
  // midpoints nearer than the radii plus the half paths.
  const std::vector<BodyState>& bodies = rows_.bodies();
  const auto reachOfBody = [&](std::uint32_t i) { return reachOf(shapes_.shapeAt(rows_.bodyShapes()[i])); };
  const auto near = [&](std::uint32_t a, std::uint32_t b) {
    const auto path = [&](std::uint32_t i, Vec3& mid, double& half) {
      const Vec3 end = bodies[i].pose.position;
      const Vec3 start = levels_.isHeld(i) ? Vec3(end + bodies[i].linear_velocity * dt)
                                          : physics_.startPose(i).position;
      mid = 0.5 * (start + end);
      half = 0.5 * (end - start).norm();
    };
    Vec3 ma, mb;
    double ha = 0.0, hb = 0.0;
    path(a, ma, ha);
    path(b, mb, hb);
    const double reach = reachOfBody(a) + reachOfBody(b) + ha + hb + kJoinMargin;
    return (ma - mb).squaredNorm() <= reach * reach;
  };
  bool joined = false;
  while (levels_.join(rows_.bodies(), pairs.size(), pair_at, near, tick.report.response.levels)) {
    joined = true;
    if (setUpPairTests()) setUpPairTests();
  }
  if (!joined) return;
  StepContext step = tick.physics;  // the tick's, for the joined bodies alone
  step.integrate_only = &levels_.joined();
  physics_.integrate(step);
}

void World::Parts::learnLevelCosts(double must_run_s, double response_mandatory_s, const TickReport& report) {
  must_run_s_ = must_run_s_ > 0.0 ? must_run_s_ + kCostUnitWeight * (must_run_s - must_run_s_) : must_run_s;
  const double units = static_cast<double>(contacts_.size() + report.response.levels.bodies_full);
  if (!(units > 0.0)) return;
  const double measured = response_mandatory_s / units;
  cost_unit_s_ = cost_unit_s_ > 0.0 ? cost_unit_s_ + kCostUnitWeight * (measured - cost_unit_s_) : measured;
}

const std::vector<std::uint8_t>& World::Parts::outOfStep() {
  const std::vector<std::uint8_t>& asleep = islands_.held();
  const std::size_t n = rows_.entityCount();
  out_of_step_.resize(n);
  for (std::size_t i = 0; i < n; ++i) out_of_step_[i] = (asleep[i] != 0 || levels_.isHeld(i)) ? 1 : 0;
  return out_of_step_;
}

ResponseLevel World::Parts::responseLevel(EntityId id) const {
  const auto index = rows_.indexOf(id);
  if (!index) return ResponseLevel::Full;
  if (rows_.bodies()[*index].is_static) return ResponseLevel::Static;
  if (islands_.isSleeping(*index)) return ResponseLevel::Asleep;
  return levels_.isHeld(*index) ? ResponseLevel::Held : ResponseLevel::Full;
}

}  // namespace stc
