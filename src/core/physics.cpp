// Physics: the World's integrate, sweep and response phases over its flat
// arrays, as the step context names them.
#include "sphere_tree_collision/physics.hpp"

#include "sphere_tree_collision/dynamics.hpp"

#include <algorithm>

namespace stc {
namespace {

// Approach slower than this many ticks of free fall is resting, not a bounce.
constexpr double kRestingFallTicks = 4.0;

}  // namespace

void Physics::integrate(const StepContext& step) {
  std::vector<BodyState>& bodies = *step.bodies;
  const ResponseOptions& options = *step.options;
  report_.sweep = SweepStats{};
  gravity_speed_ = step.gravity.norm() * step.dt;
  start_.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) start_[i] = bodies[i].pose;
  IntegrationOptions integration;
  integration.gravity = step.gravity;
  integration.gyroscopic = options.gyroscopic;
  integratePositions(bodies, integration, step.dt);
  integrateVelocities(bodies, integration, step.dt);
  sweep_scratch_.fast.assign(bodies.size(), 0);
  // Without a response nothing would turn a body put back at its hit: no sweep.
  if (!(options.continuous && options.enabled && step.dt > 0.0)) return;
  body_bounds_.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    body_bounds_[i] = &(*step.shape_bounds)[(*step.body_shapes)[i]];
  }
  report_.sweep.fast_bodies =
      markFastBodies(bodies, start_, body_bounds_, options.sweep_threshold, sweep_scratch_.fast);
}

void Physics::sweep(const StepContext& step) {
  const ResponseOptions& options = *step.options;
  sweep_scratch_.clamped.clear();
  if (report_.sweep.fast_bodies == 0 || !options.continuous || !options.enabled) return;
  report_.sweep = sweepFastBodies(*step.bodies, start_, body_bounds_, *step.pair_bodies, step.pair_count,
                                  options.sweep_threshold, sweep_scratch_);
}

void Physics::respond(const StepContext& step) {
  const ResponseOptions& options = *step.options;
  const std::vector<PairTest>& tests = *step.tests;
  const std::vector<std::array<std::uint32_t, 2>>& pair_bodies = *step.pair_bodies;
  const std::vector<double>& priorities = *step.priorities;
  const std::vector<std::uint32_t>& body_shapes = *step.body_shapes;
  const std::deque<ShapeBounds>& shape_bounds = *step.shape_bounds;
  const std::size_t count = step.pair_count;
  std::vector<Contact>& contacts = *step.contacts;
  contacts.clear();
  ContactBuildOptions build;
  build.max_contacts_per_pair = options.max_contacts_per_pair;
  build.accept_unresolved = step.accept_unresolved;
  build.face_normals = options.face_normals;
  sweep_hit_of_pair_.assign(count, -1);
  for (const std::uint32_t body : sweep_scratch_.clamped) {
    const SweepHit& hit = sweep_scratch_.hits[body];
    if (hit.pair < count) sweep_hit_of_pair_[hit.pair] = static_cast<std::int32_t>(body);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t ia = pair_bodies[i][0];
    const std::uint32_t ib = pair_bodies[i][1];
    const std::size_t before = contacts.size();
    builder_.append(tests[i], ia, ib, priorities[i], &shape_bounds[body_shapes[ia]],
                    &shape_bounds[body_shapes[ib]], build, contacts);
    if (contacts.size() == before && sweep_hit_of_pair_[i] >= 0) {
      // The sweep held a body back at this pair's first touch but the test
      // (interrupted, or not accepted) gave no contact: the hit is the contact,
      // so the response turns the approach the sweep stopped.
      const SweepHit& hit = sweep_scratch_.hits[static_cast<std::size_t>(sweep_hit_of_pair_[i])];
      Contact c;
      c.a = tests[i].bodyA().id;
      c.b = tests[i].bodyB().id;
      c.index_a = ia;
      c.index_b = ib;
      c.point = hit.point;
      c.normal = hit.normal;
      c.resolved = true;
      c.priority = priorities[i];
      contacts.push_back(c);
    }
  }
  report_.solve = SolveStats{};
  if (!options.enabled) return;
  ResponseOptions solve = options;
  solve.restitution_threshold = std::max(options.restitution_threshold, kRestingFallTicks * gravity_speed_);
  report_.solve = solver_.solve(*step.bodies, contacts, solve, step.dt, step.budget);
}

}  // namespace stc
