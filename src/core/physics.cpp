// Physics: the World's integrate, sweep and response phases over its flat
// arrays, as the step context names them.
#include "physics.hpp"

#include "dynamics.hpp"

#include "grow_capacity.hpp"

#include <algorithm>
#include <limits>

namespace stc {
namespace {

// Approach slower than this many ticks of free fall is resting, not a bounce.
constexpr double kRestingFallTicks = 4.0;
// Below this many pairs the contacts are built on the calling thread.
constexpr std::size_t kPairsPerTask = 64;
constexpr std::size_t kChunksPerThread = 4;  // contact building
// A contact whose normal is within about 25 degrees of the sweep's hit, near
// it, stops the approach the hit stopped (Physics::appendSweepHit).
constexpr double kHitCoveredCosine = 0.9;

// What a cache's placed contacts of the pair of `test` take from the pair now.
Contact placedBase(const PairTest& test, std::uint32_t ia, std::uint32_t ib, double priority) {
  Contact base;
  base.a = test.bodyA().id;
  base.b = test.bodyB().id;
  base.index_a = ia;
  base.index_b = ib;
  base.priority = priority;
  return base;
}

}  // namespace

void Physics::integrate(const StepContext& step) {
  std::vector<BodyState>& bodies = *step.bodies;
  const ResponseOptions& options = *step.options;
  report_.sweep = SweepStats{};
  gravity_speed_ = step.gravity.norm() * step.dt;
  start_.resize(bodies.size());
  // The soft step moves the bodies again from the tick's start, with the
  // velocities they started it with (ContactSolver::solveSoft).
  const bool soft = options.solver == SolverKind::Soft && options.enabled;
  if (soft) {
    start_v_.resize(bodies.size());
    start_w_.resize(bodies.size());
  }
  IntegrationOptions integration;
  integration.gravity = step.gravity;
  integration.gyroscopic = options.gyroscopic;
  // Without a response nothing would turn a body put back at its hit: no sweep.
  const bool sweeps = options.continuous && options.enabled && step.dt > 0.0;
  std::vector<std::uint8_t>& fast = sweep_scratch_.fast;
  fast.resize(bodies.size());
  if (sweeps) body_bounds_.resize(bodies.size());
  // Each body alone (moved, then marked fast or not): any split of the bodies
  // gives the same result.
  forEachIndex(step.workers, bodies.size(), kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (step.integrate_only != nullptr && (*step.integrate_only)[i] == 0) continue;
      start_[i] = bodies[i].pose;
      if (soft) {
        start_v_[i] = bodies[i].linear_velocity;
        start_w_[i] = bodies[i].angular_velocity;
      }
      integratePosition(bodies[i], integration, step.dt);
      integrateVelocity(bodies[i], integration, step.dt);
      fast[i] = 0;
      if (!sweeps) continue;
      body_bounds_[i] = &(*step.shape_bounds)[(*step.body_shapes)[i]];
      fast[i] = movesFast(bodies[i], start_[i], body_bounds_[i], options.sweep_threshold) ? 1 : 0;
    }
  });
  if (sweeps) report_.sweep.fast_bodies = static_cast<std::size_t>(std::count(fast.begin(), fast.end(), 1));
}

void Physics::sweep(const StepContext& step) {
  const ResponseOptions& options = *step.options;
  sweep_scratch_.clamped.clear();
  if (report_.sweep.fast_bodies == 0 || !options.continuous || !options.enabled) return;
  report_.sweep = sweepFastBodies(*step.bodies, start_, body_bounds_, *step.pair_bodies, *step.pair_count,
                                  options.sweep_threshold, sweep_scratch_, step.workers);
}

ReuseBody Physics::reuseBody(const StepContext& step, std::uint32_t index) const {
  const ShapeBounds& bounds = (*step.shape_bounds)[(*step.body_shapes)[index]];
  const BodyState& body = (*step.bodies)[index];
  // Its velocity as the last tick's response left it: without this tick's
  // gravity, which a body resting on another never gets to act on.
  const Vec3 v = body.is_static ? Vec3::Zero() : Vec3(body.linear_velocity - step.gravity * step.dt);
  return ReuseBody{(*step.ids)[index], &body.pose, v, body.angular_velocity, bounds.bound_radius};
}

std::uint32_t Physics::reusableEntry(const StepContext& step, std::uint32_t ia, std::uint32_t ib) const {
  return pair_cache_.find(reuseBody(step, ia), reuseBody(step, ib), step.dt);
}

// The contacts of pairs [first, last) appended to `out` in pair order.
void Physics::appendContacts(const StepContext& step, std::size_t first, std::size_t last,
                             ContactBuilder& builder, std::vector<Contact>& out, ChunkContacts& chunk) const {
  const ResponseOptions& options = *step.options;
  const std::vector<PairTest>& tests = *step.tests;
  const std::vector<std::array<std::uint32_t, 2>>& pair_bodies = *step.pair_bodies;
  const std::vector<double>& priorities = *step.priorities;
  const std::vector<std::uint32_t>& body_shapes = *step.body_shapes;
  const std::deque<ShapeBounds>& shape_bounds = *step.shape_bounds;
  ContactBuildOptions build;
  build.max_contacts_per_pair = options.max_contacts_per_pair;
  build.accept_unresolved = step.accept_unresolved;
  build.face_normals = options.face_normals;
  PairContactCache::Pending& reuse = chunk.reuse;
  PairContactCache::Pending& frontier = chunk.frontier;
  reuse.clear();
  frontier.clear();
  chunk.frontier_kept = 0;
  for (std::size_t i = first; i < last; ++i) {
    const std::uint32_t ia = pair_bodies[i][0];
    const std::uint32_t ib = pair_bodies[i][1];
    const std::size_t before = out.size();
    const std::uint32_t entry = step.reused != nullptr ? (*step.reused)[i] : PairContactCache::kNone;
    if (entry != PairContactCache::kNone) {  // its test resumed Colliding: last tick's contacts, placed anew
      pair_cache_.place(entry, placedBase(tests[i], ia, ib, priorities[i]), *tests[i].bodyA().pose,
                        *tests[i].bodyB().pose, out);
      pair_cache_.carry(entry, reuse);
      appendSweepHit(step, ia, ib, i, before, out);
      continue;
    }
    const PairStatus status = tests[i].status();
    if (step.steady_frontier && status == PairStatus::Unresolved && step.accept_unresolved) {
      const std::uint32_t kept = frontier_cache_.find(reuseBody(step, ia), reuseBody(step, ib), step.dt);
      if (kept != PairContactCache::kNone && frontier_cache_.entry(kept).level > tests[i].deepestLevel()) {
        frontier_cache_.place(kept, placedBase(tests[i], ia, ib, priorities[i]), *tests[i].bodyA().pose,
                              *tests[i].bodyB().pose, out);
        // Where the contacts act, their separations and sphere bounds are
        // the deeper frontier's (a leaf point's overlap was proven at a pose
        // within the tolerance, and pushes apart; a frontier point's does
        // not: place()). The level, the gap bound and the status are this
        // tick's, so that the contacts say what the tick's report sums
        // (World::narrowPhase) and where the narrow phase went.
        for (std::size_t k = before; k < out.size(); ++k) {
          out[k].level = std::max(0, tests[i].deepestLevel());
          out[k].gap_bound = tests[i].gapBound();
          out[k].resolved = false;
        }
        frontier_cache_.carry(kept, frontier);
        ++chunk.frontier_kept;
        holdOnStatic(step, ia, ib, before, out);
        appendSweepHit(step, ia, ib, i, before, out);
        continue;
      }
    }
    const StaticCover* cover = step.static_cover;
    const ShapeBounds& bounds_a = shape_bounds[body_shapes[ia]];
    const ShapeBounds& bounds_b = shape_bounds[body_shapes[ib]];
    const auto interior = [&](std::uint32_t body) {
      return step.interior_fields != nullptr ? &(*step.interior_fields)[body_shapes[body]] : nullptr;
    };
    builder.append(tests[i], ia, ib, priorities[i],
                   BodySurface{&bounds_a, cover != nullptr ? cover->of(ia) : nullptr, interior(ia)},
                   BodySurface{&bounds_b, cover != nullptr ? cover->of(ib) : nullptr, interior(ib)}, build, out);
    const double leaf_radius = std::min(bounds_a.min_leaf_radius, bounds_b.min_leaf_radius);
    if (step.reused != nullptr && status == PairStatus::Colliding && out.size() > before) {
      PairContactCache::record(tests[i], reuseBody(step, ia), reuseBody(step, ib),
                               options.reuse_tolerance * leaf_radius, out.data() + before, out.data() + out.size(), reuse);
    }
    if (step.steady_frontier && status != PairStatus::Separate && out.size() > before) {
      PairContactCache::record(tests[i], reuseBody(step, ia), reuseBody(step, ib), kFrontierTolerance * leaf_radius,
                               out.data() + before, out.data() + out.size(), frontier);
    }
    holdOnStatic(step, ia, ib, before, out);
    appendSweepHit(step, ia, ib, i, before, out);
  }
}

namespace {

// A body's voxels deepest along `u` (world, unit) in each quadrant of the
// plane across `u` about its centre of mass: up to four far corners of leaf
// boxes (exact for the voxels), in `points`; returns how many.
int deepestPoints(const ShapeBounds& bounds, const Pose& pose, const Vec3& u, Vec3 (&points)[4]) {
  const Vec3 u_body = pose.orientation.conjugate() * u;
  Vec3 t1, t2;
  tangentBasis(u_body, t1, t2);
  const Vec3 sign(u_body.x() < 0.0 ? -1.0 : 1.0, u_body.y() < 0.0 ? -1.0 : 1.0, u_body.z() < 0.0 ? -1.0 : 1.0);
  const SphereTree& tree = *bounds.tree;
  double best[4];
  std::fill(best, best + 4, -std::numeric_limits<double>::infinity());
  Vec3 found[4];
  for (std::int32_t n = tree.levelBegin(0); n < tree.levelBegin(tree.levelCount()); ++n) {
    if (!tree.isLeaf(n)) continue;
    const std::size_t k = static_cast<std::size_t>(n);
    const Vec3 corner = tree.node(n).centre + bounds.box_offset[k] + bounds.box_half[k].cwiseProduct(sign);
    const int q = (corner.dot(t1) < 0.0 ? 1 : 0) + (corner.dot(t2) < 0.0 ? 2 : 0);
    const double along = corner.dot(u_body);
    if (along > best[q]) {
      best[q] = along;
      found[q] = corner;
    }
  }
  int count = 0;
  for (int q = 0; q < 4; ++q) {
    if (best[q] > -std::numeric_limits<double>::infinity()) points[count++] = pose.position + pose.orientation * found[q];
  }
  return count;
}

}  // namespace

// An unresolved pair's contact from the two root spheres, between a movable
// and a static body, whose boxes touch (separation 0: its overlap is not
// proven, so it pushes nothing apart) acts at one point, where the boxes
// overlap: a rock rolling on a plate under a tick budget turned its far
// corners into the plate a few mm a tick, below the sweep's threshold,
// until they were more than a voxel deep. It becomes the movable body's
// deepest voxels along the normal, one per quadrant around it: a manifold
// that holds the body up where it touches.
void Physics::holdOnStatic(const StepContext& step, std::uint32_t ia, std::uint32_t ib, std::size_t before,
                           std::vector<Contact>& out) const {
  const BodyState& a = (*step.bodies)[ia];
  const BodyState& b = (*step.bodies)[ib];
  if (a.is_static == b.is_static) return;
  const std::uint32_t mover = a.is_static ? ib : ia;
  const ShapeBounds& bounds = (*step.shape_bounds)[(*step.body_shapes)[mover]];
  const Pose& pose = (*step.bodies)[mover].pose;
  const std::size_t end = out.size();
  for (std::size_t k = before; k < end; ++k) {
    if (out[k].resolved || out[k].node_a != 0 || out[k].node_b != 0 || out[k].separation > 0.0) continue;
    Vec3 points[4];
    const int count = deepestPoints(bounds, pose, a.is_static ? Vec3(-out[k].normal) : out[k].normal, points);
    out[k].point = points[0];
    for (int p = 1; p < count; ++p) {
      Contact c = out[k];
      c.point = points[p];
      out.push_back(c);
    }
  }
}

// The sweep held a body back at pair i's first touch: the response must turn
// that approach, or the body is held back again next tick while its velocity
// keeps gravity's gain (stored m/s, real mm/s). A contact of the pair turns
// it when it is proven at the leaves (resolved), faces the way the hit does
// and lies within a leaf diameter of it. Otherwise the hit (point between the
// two boxes, normal along the face they met on, separation minus their overlap
// there, as a leaf contact's says) becomes a contact: under a
// budget the test may give none proven (interrupted: none, or its frontier's,
// whose separations are at least 0 and whose normals run along the line of
// centres of spheres that may be the roots); and unbudgeted the leaves'
// contacts may lie elsewhere, where the bodies already touch and separate (a
// spinning cube on its neighbour, whose far corner the sweep saw coming down
// on it). A leaf contact beside the hit already stops it: the hit added as
// well was a fifth point of a rock pair. A full manifold gives up its
// shallowest point for the hit, the one doing least. The hit's contact is
// warm-started from nothing and warm-starts nothing (kSweepHitNode).
void Physics::appendSweepHit(const StepContext& step, std::uint32_t ia, std::uint32_t ib, std::size_t i,
                             std::size_t before, std::vector<Contact>& out) const {
  if (sweep_hit_of_pair_[i] < 0) return;
  const SweepHit& hit = sweep_scratch_.hits[static_cast<std::size_t>(sweep_hit_of_pair_[i])];
  const std::deque<ShapeBounds>& shape_bounds = *step.shape_bounds;
  const std::vector<std::uint32_t>& body_shapes = *step.body_shapes;
  const double leaf_diameter = 2.0 * std::min(shape_bounds[body_shapes[ia]].min_leaf_radius,
                                              shape_bounds[body_shapes[ib]].min_leaf_radius);
  std::size_t shallowest = before;
  for (std::size_t k = before; k < out.size(); ++k) {
    const Contact& c = out[k];
    if (c.resolved && c.normal.dot(hit.normal) >= kHitCoveredCosine &&
        (c.point - hit.point).squaredNorm() <= leaf_diameter * leaf_diameter) {
      return;
    }
    if (c.separation > out[shallowest].separation) shallowest = k;
  }
  const PairTest& test = (*step.tests)[i];
  Contact c;
  c.a = test.bodyA().id;
  c.b = test.bodyB().id;
  c.index_a = ia;
  c.index_b = ib;
  c.point = hit.point;
  c.normal = hit.normal;
  c.separation = hit.separation;
  c.resolved = true;
  c.priority = (*step.priorities)[i];
  c.node_a = kSweepHitNode;
  c.node_b = kSweepHitNode;
  const std::size_t most = static_cast<std::size_t>(std::max(1, step.options->max_contacts_per_pair));
  if (out.size() - before >= most) {
    out[shallowest] = c;
  } else {
    out.push_back(c);
  }
}

void Physics::buildContacts(const StepContext& step) {
  const std::size_t count = *step.pair_count;
  std::vector<Contact>& contacts = *step.contacts;
  // Room for last tick's count and an eighth more, made while the vector is
  // empty: a pile's contacts grow a little most ticks, and growing as they
  // are appended copied the tick's contacts so far each time.
  const std::size_t last_count = contacts.size();
  contacts.clear();
  growCapacity(contacts, last_count + last_count / 8);
  growCapacity(sweep_hit_of_pair_, count);  // assign alone would reallocate to the exact count
  sweep_hit_of_pair_.assign(count, -1);
  for (const std::uint32_t body : sweep_scratch_.clamped) {
    const SweepHit& hit = sweep_scratch_.hits[body];
    if (hit.pair < count) sweep_hit_of_pair_[hit.pair] = static_cast<std::int32_t>(body);
  }
  // Each pair's contacts depend on that pair alone: chunks of the pairs in
  // parallel, each with its own builder, joined in pair order (the same
  // contacts, in the same order, whatever the thread count).
  // A few chunks a thread: a pile's colliding pairs bunch in the pair list.
  const std::size_t threads = step.workers != nullptr ? static_cast<std::size_t>(step.workers->threads()) : 1;
  const std::size_t chunks = threads > 1 && count >= kPairsPerTask ? kChunksPerThread * threads : 1;
  if (builders_.size() < chunks) builders_.resize(chunks);
  if (chunk_contacts_.size() < chunks) chunk_contacts_.resize(chunks);
  // The caches sized by the pairs: each pair keeps its deepest contacts (or
  // its carried ones), so the count creeps up as the gaze passes over a pile
  // (or as a pile's pairs go from built to carried and back); a tick with no
  // more pairs than any before then allocates nothing, and a forming pile's
  // buffers grow in the same few ticks.
  if (step.steady_frontier || step.reused != nullptr) {
    const std::size_t points_per_pair = static_cast<std::size_t>(std::max(1, step.options->max_contacts_per_pair));
    for (std::size_t k = 0; k < chunks; ++k) {
      const auto [first, last] = chunkRange(count, k, chunks);
      if (step.steady_frontier) chunk_contacts_[k].frontier.reserve(last - first, (last - first) * points_per_pair);
      if (step.reused != nullptr) chunk_contacts_[k].reuse.reserve(last - first, (last - first) * points_per_pair);
      if (chunks > 1) growCapacity(chunk_contacts_[k].contacts, (last - first) * points_per_pair);
    }
    if (step.steady_frontier) frontier_cache_.reserve(count, count * points_per_pair);
    if (step.reused != nullptr) pair_cache_.reserve(count, count * points_per_pair);
    growCapacity(contacts, count * points_per_pair);
  }
  if (chunks == 1) {
    appendContacts(step, 0, count, builders_[0], contacts, chunk_contacts_[0]);
  } else {
    // The builders take turns at the chunks, so each one's scratch grows to
    // what any part of the pair list needs and then allocates no more.
    ++builder_turn_;
    step.workers->forChunks(chunks, [&](std::size_t k, std::size_t) {
      std::vector<Contact>& chunk = chunk_contacts_[k].contacts;
      chunk.clear();
      const auto [first, last] = chunkRange(count, k, chunks);
      appendContacts(step, first, last, builders_[(k + builder_turn_) % chunks], chunk, chunk_contacts_[k]);
    }, Team::Claim::Balanced);
    for (std::size_t k = 0; k < chunks; ++k) {
      const std::vector<Contact>& chunk = chunk_contacts_[k].contacts;
      contacts.insert(contacts.end(), chunk.begin(), chunk.end());
    }
  }
  // The next tick's cache: this tick's entries, in pair order.
  if (step.reused != nullptr) {
    reuse_pending_.clear();
    for (std::size_t k = 0; k < chunks; ++k) reuse_pending_.push_back(&chunk_contacts_[k].reuse);
    pair_cache_.commit(reuse_pending_.data(), chunks);
  } else {
    pair_cache_.clear();
  }
  // Unlimited ticks keep the frontier entries as they are: they stay valid
  // while their bodies stay put, and a limited tick finds them again.
  report_.frontier_kept = 0;
  // Built or carried over, every contact measured against a solid.
  report_.interior_contacts = static_cast<std::size_t>(std::count_if(
      contacts.begin(), contacts.end(),
      [](const Contact& c) { return c.node_a == kInteriorNode || c.node_b == kInteriorNode; }));
  if (step.steady_frontier) {
    reuse_pending_.clear();
    for (std::size_t k = 0; k < chunks; ++k) {
      reuse_pending_.push_back(&chunk_contacts_[k].frontier);
      report_.frontier_kept += chunk_contacts_[k].frontier_kept;
    }
    frontier_cache_.commit(reuse_pending_.data(), chunks);
  }
}

void Physics::solve(const StepContext& step) {
  const ResponseOptions& options = *step.options;
  std::vector<Contact>& contacts = *step.contacts;
  report_.solve = SolveStats{};
  if (!options.enabled) return;
  ResponseOptions run = options;
  run.restitution_threshold = std::max(options.restitution_threshold, kRestingFallTicks * gravity_speed_);
  solver_.setWorkers(step.workers, static_cast<std::size_t>(options.solver_task_manifolds));
  solver_.warmStartCache().keepWhileHeld(step.ids, step.held_asleep);
  if (options.solver == SolverKind::Soft) {
    ContactSolver::TickStart start{&start_, &start_v_, &start_w_, &sweep_scratch_.clamped};
    report_.solve = solver_.solveSoft(*step.bodies, contacts, run, step.dt, start, step.budget);
  } else {
    report_.solve = solver_.solve(*step.bodies, contacts, run, step.dt, step.budget);
  }
}

void Physics::releaseMemory() {
  for (ChunkContacts& chunk : chunk_contacts_) dropSpareCapacity(chunk.contacts);
  dropSpareCapacity(solver_);
  dropSpareCapacity(start_);
  dropSpareCapacity(body_bounds_);
  dropSpareCapacity(sweep_hit_of_pair_);
}

}  // namespace stc
