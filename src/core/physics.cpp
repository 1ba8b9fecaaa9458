// Physics: the World's integrate and response phases over its flat arrays.
#include "sphere_tree_collision/physics.hpp"

#include "sphere_tree_collision/dynamics.hpp"
#include "sphere_tree_collision/world.hpp"

#include <algorithm>

namespace stc {
namespace {

// Approach slower than this many ticks of free fall is resting, not a bounce.
constexpr double kRestingFallTicks = 4.0;

}  // namespace

const ShapeBounds& Physics::boundsOf(std::uint32_t shape, const ShapeOf& shape_of) {
  // Built once per shape; the World keeps shapes in a deque, so trees never move.
  if (shape >= bounds_.size()) bounds_.resize(shape + 1);
  ShapeBounds& bounds = bounds_[shape];
  if (bounds.tree == nullptr) {
    const ShapeInfo& info = shape_of(shape);
    bounds = makeShapeBounds(info.tree, &info.voxels, info.body_origin);
  }
  return bounds;
}

void Physics::integrate(std::vector<BodyState>& bodies, const std::vector<std::uint32_t>& body_shapes,
                        const ShapeOf& shape_of, const Vec3& gravity, const ResponseOptions& options,
                        double dt) {
  report_.sweep = SweepStats{};
  gravity_speed_ = gravity.norm() * dt;
  start_.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) start_[i] = bodies[i].pose;
  IntegrationOptions integration;
  integration.gravity = gravity;
  integration.gyroscopic = options.gyroscopic;
  integratePositions(bodies, integration, dt);
  integrateVelocities(bodies, integration, dt);
  sweep_scratch_.fast.assign(bodies.size(), 0);
  // Without a response nothing would turn a body put back at its hit: no sweep.
  if (!(options.continuous && options.enabled && dt > 0.0)) return;
  for (const std::uint32_t shape : body_shapes) boundsOf(shape, shape_of);  // no resize below
  body_bounds_.resize(bodies.size());
  for (std::size_t i = 0; i < bodies.size(); ++i) body_bounds_[i] = &bounds_[body_shapes[i]];
  report_.sweep.fast_bodies =
      markFastBodies(bodies, start_, body_bounds_, options.sweep_threshold, sweep_scratch_.fast);
}

void Physics::sweep(std::vector<BodyState>& bodies, const std::vector<std::array<std::uint32_t, 2>>& pair_bodies,
                    std::size_t count, const ResponseOptions& options) {
  sweep_scratch_.clamped.clear();
  if (report_.sweep.fast_bodies == 0 || !options.continuous || !options.enabled) return;
  report_.sweep = sweepFastBodies(bodies, start_, body_bounds_, pair_bodies, count, options.sweep_threshold,
                                  sweep_scratch_);
}

void Physics::respond(const std::vector<PairTest>& tests, std::size_t count,
                      const std::vector<std::array<std::uint32_t, 2>>& pair_bodies,
                      const std::vector<double>& priorities, bool accept_unresolved,
                      const std::vector<std::uint32_t>& body_shapes, const ShapeOf& shape_of,
                      std::vector<BodyState>& bodies, const ResponseOptions& options, double dt,
                      std::vector<Contact>& contacts, const SolveBudget& budget) {
  contacts.clear();
  ContactBuildOptions build;
  build.max_contacts_per_pair = options.max_contacts_per_pair;
  build.accept_unresolved = accept_unresolved;
  build.face_normals = options.face_normals;
  for (const std::uint32_t shape : body_shapes) boundsOf(shape, shape_of);  // no resize below
  sweep_hit_of_pair_.assign(count, -1);
  for (const std::uint32_t body : sweep_scratch_.clamped) {
    const SweepHit& hit = sweep_scratch_.hits[body];
    if (hit.pair < count) sweep_hit_of_pair_[hit.pair] = static_cast<std::int32_t>(body);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t ia = pair_bodies[i][0];
    const std::uint32_t ib = pair_bodies[i][1];
    const std::size_t before = contacts.size();
    builder_.append(tests[i], ia, ib, priorities[i], &bounds_[body_shapes[ia]], &bounds_[body_shapes[ib]],
                    build, contacts);
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
  report_.solve = solver_.solve(bodies, contacts, solve, dt, budget);
}

}  // namespace stc
