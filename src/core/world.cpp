// World: composes shapes, entities, what follows them and fracture, and runs
// the phases of one tick.
#include "world_parts.hpp"

#include "carried_state.hpp"
#include "flat_hash_map.hpp"
#include "grow_capacity.hpp"
#include "tick_context.hpp"
#include "world_access.hpp"
#include "world_fracture.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace stc {
namespace {

// The reserve for what follows the narrow phase forgets a cost spike by this
// factor a tick: it follows rises at once and halves in about 14 ticks.
constexpr double kReserveDecay = 0.95;
// ... and is kept with this margin: that cost varies from tick to tick (how
// far the narrow phase got changes the contacts to build). On corner_drift
// 500 at 16.7 ms a margin of 1.1 took the ticks over 1.1 x budget from 2% to
// 0.5% for 2% less narrow-phase time; on the rockfall 1,000, whose mandatory
// part swings more (p50 9, p99 12-13 ms), 1.1 left 1.8-2.4% of its ticks over
// and a p99 of 1.14-1.17 x, 1.25 0.2-0.6% and 0.96-1.06 x (2026-12-04).
constexpr double kReserveMargin = 1.25;

// Whether the narrow phase has a limit this tick: its own time, the tick's
// deadline or a sphere-test count (then pairs may be left unresolved).
bool narrowPhaseLimited(const Budget& budget, const Deadline& tick_end) {
  return budget.seconds < std::numeric_limits<double>::infinity() || tick_end.isSet() ||
         budget.sphere_tests < std::numeric_limits<std::int64_t>::max();
}

}  // namespace

World::Parts::Parts(World& owner, const WorldConfig& config)
    : world_(&owner),
      config_(config),
      workers_(config.threads),
      narrow_chunks_(makeNarrowChunks(narrowChunkCount(static_cast<std::size_t>(workers_.threads()), false),
                                      config.scheduler)),
      narrow_chunks_used_(static_cast<std::size_t>(workers_.threads())),
      fracture_(std::make_unique<WorldFracture>()) {
  validateLimits(config_.limits);
  validateMeshLimits(config_.mesh_limits);
  validateGravity(config_.gravity, config_.limits);
  validateFractureOptions(config_.fracture);
  validateSleepOptions(config_.sleeping);
  validateResponseOptions(config_.response);
}
World::Parts::~Parts() = default;

// ---------------------------------------------------------------------------------
// World: its calls, each into its parts

World::World(const WorldConfig& config) : parts_(std::make_unique<Parts>(*this, config)) {}
World::~World() = default;
World::World(World&& other) noexcept : parts_(std::move(other.parts_)) {
  if (parts_) parts_->world_ = this;
}
World& World::operator=(World&& other) noexcept {
  parts_ = std::move(other.parts_);
  if (parts_) parts_->world_ = this;
  return *this;
}

ShapeId World::addShape(const std::string& key, VoxelShape shape) { return parts_->addShape(key, std::move(shape)); }
std::optional<ShapeId> World::findShape(const std::string& key) const { return parts_->shapes_.findShape(key); }
const ShapeInfo& World::shape(ShapeId id) const { return parts_->shapes_.shape(id); }
std::size_t World::shapeCount() const { return parts_->shapes_.shapeCount(); }
void World::setShapeRecipe(ShapeId id, const ShapeRecipe& recipe) { parts_->shapes_.setShapeRecipe(id, recipe); }

EntityId World::addEntity(const EntitySpec& spec) { return parts_->addEntity(spec); }
void World::validateEntity(const EntitySpec& spec) const { parts_->validateEntity(spec); }
bool World::removeEntity(EntityId id) { return parts_->removeEntity(id); }
std::optional<EntityId> World::findByName(const std::string& name) const { return parts_->rows_.findByName(name); }
void World::clear() { parts_->clear(); }
void World::releaseMemory() { parts_->releaseMemory(); }
std::vector<EntityId> World::breakEntity(EntityId id, const Vec3& point, const Vec3& normal) {
  return parts_->breakEntity(id, point, normal);
}

TickReport World::step(double dt, const Budget& budget) { return parts_->step(dt, budget); }
void World::setClock(SecondsClock clock) { parts_->setClock(std::move(clock)); }
const std::vector<QuarantinedEntity>& World::quarantined() const { return parts_->quarantined_; }

Perception& World::perception() { return parts_->perception_; }
const Perception& World::perception() const { return parts_->perception_; }
const WorldConfig& World::config() const { return parts_->config_; }
void World::setScheduler(const SchedulerOptions& options) { parts_->setScheduler(options); }
void World::setUnresolvedPolicy(UnresolvedPolicy policy) { parts_->config_.unresolved_policy = policy; }
void World::setResponse(const ResponseOptions& options) { parts_->setResponse(options); }
void World::setGravity(const Vec3& gravity) { parts_->setGravity(gravity); }
bool World::wake(EntityId id) { return parts_->wake(id); }
bool World::isSleeping(EntityId id) const { return parts_->isSleeping(id); }
std::uint32_t World::sleepGroup(std::size_t index) const { return parts_->islands_.group(index); }
bool World::isRestless(EntityId id) const { return parts_->isRestless(id); }
ResponseLevel World::responseLevel(EntityId id) const { return parts_->responseLevel(id); }

void World::settleBroadPhase() { parts_->settleBroadPhase(); }

std::size_t World::entityCount() const { return parts_->rows_.entityCount(); }
const std::vector<EntityId>& World::entityIds() const { return parts_->rows_.entityIds(); }
const std::vector<BodyState>& World::bodies() const { return parts_->rows_.bodies(); }
std::vector<BodyState>& World::bodies() { return parts_->rows_.bodies(); }
const std::vector<ShapeId>& World::bodyShapes() const { return parts_->rows_.bodyShapes(); }
const std::vector<std::string>& World::bodyNames() const { return parts_->rows_.bodyNames(); }
const std::vector<double>& World::bodyDensities() const { return parts_->rows_.bodyDensities(); }
const std::vector<BoxMode>& World::bodyBoxModes() const { return parts_->rows_.bodyBoxModes(); }
std::uint8_t World::closedFaces(std::size_t index) const { return parts_->static_cover_.closedFaces(index); }
std::optional<std::size_t> World::indexOf(EntityId id) const { return parts_->rows_.indexOf(id); }

std::size_t World::pairCount() const { return parts_->pair_count_; }
std::size_t World::narrowChunks() const { return parts_->narrow_chunks_used_; }
int World::threads() const { return parts_->workers_.threads(); }
void World::timeTeamLoops(bool on) { parts_->workers_.timeLoops(on); }
const std::vector<Contact>& World::contacts() const { return parts_->contacts_; }

// Internal views (world_access.hpp).
const std::vector<PairTest>& pairTests(const World& world) { return WorldAccess::parts(world).pair_tests_; }
const SweepAndPrune& broadPhase(const World& world) { return WorldAccess::parts(world).broad_phase_; }
const PhysicsReport& physicsReport(const World& world) { return WorldAccess::parts(world).physics_.lastReport(); }
CarriedState carriedState(const World& world) { return WorldAccess::parts(world).carriedState(); }
void restoreCarried(World& world, const CarriedState& state) { WorldAccess::parts(world).restoreCarried(state); }

// ---------------------------------------------------------------------------------
// Shapes

ShapeId World::Parts::addShape(const std::string& key, VoxelShape voxels) {
  return shapes_.addShape(key, std::move(voxels), config_.voxel_limits, config_.tree);
}

// ---------------------------------------------------------------------------------
// Entities

void World::Parts::validateEntity(const EntitySpec& spec) const {
  validateBodyInput(spec.pose, spec.linear_velocity, spec.angular_velocity, spec.density,
                    spec.material, config_.limits);
  if (!spec.name.empty() && rows_.findByName(spec.name)) {
    throw InputError("name", "'" + spec.name + "' is already used");
  }
  if (spec.exact_orientation && !(std::abs(spec.pose.orientation.norm() - 1.0) <= kExactOrientationTolerance)) {
    throw InputError("pose.orientation", "an exact orientation must be a unit quaternion (within 1e-12)");
  }
  if (spec.sleep_group != 0 && (!spec.restored || spec.is_static || !spec.linear_velocity.isZero(0.0) ||
                                 !spec.angular_velocity.isZero(0.0))) {
    throw InputError("sleep", "only a restored movable body at rest (velocities 0) sleeps");
  }
  if (spec.closed_faces > kAllFaces || (spec.closed_faces != 0 && !spec.is_static)) {
    throw InputError("closed_faces", "static bodies only, a mask of faceBit values (at most " +
                                         std::to_string(kAllFaces) + ")");
  }
  if (spec.id != kInvalidEntity && rows_.indexOf(spec.id)) {
    throw InputError("id", std::to_string(spec.id) + " is already used");
  }
  if (rows_.entityCount() >= config_.max_entities || (spec.id == kInvalidEntity && !rows_.idsLeft())) {
    throw InputError("max_entities", "the world holds " + std::to_string(config_.max_entities) +
                                         " entities at most");
  }
}

EntityId World::Parts::addEntity(const EntitySpec& spec) {
  // Validate everything first: on throw nothing has changed.
  const ShapeInfo& info = shapes_.shape(spec.shape);  // throws InputError("shape") for an unknown id
  validateEntity(spec);

  BodyState body;
  body.pose.position = spec.pose.position;
  body.pose.orientation = spec.exact_orientation ? spec.pose.orientation : spec.pose.orientation.normalized();
  body.material = spec.material;
  body.is_static = spec.is_static;
  if (!spec.is_static) {  // static bodies never move: zero velocities and inverse masses
    body.linear_velocity = spec.linear_velocity;
    body.angular_velocity = spec.angular_velocity;
    body.inv_mass = 1.0 / (spec.density * info.unit_mass.mass);
    body.inv_inertia_body = (spec.density * info.unit_mass.inertia).inverse();
    const Mat3 r = body.pose.orientation.toRotationMatrix();
    body.inv_inertia_world = r * body.inv_inertia_body * r.transpose();
  }
  BoxMode mode = spec.box_mode;
  if (mode == BoxMode::Auto) mode = info.elongated ? BoxMode::Dynamic : BoxMode::FixedCube;

  // The row, then what follows it.
  const EntityId id = rows_.addRow(body, spec.shape, mode, spec.density, spec.name, spec.id);
  const std::size_t index = rows_.entityCount() - 1;
  static_cover_.add(body, spec.closed_faces);
  broad_phase_.add(id, boxOf(index));  // static boxes are set here, once
  islands_.add(info.bounding_radius);
  if (spec.restored) {
    const bool sleeps = config_.sleeping.enabled && config_.response.enabled;
    islands_.restore(index, sleeps ? spec.sleep_group : 0, body.pose);
  }
  levels_.add();
  if (spec.is_static) physics_.forgetReuse();  // its neighbours' covered faces change
  invalidateLastTick();
  return id;
}

bool World::Parts::removeEntity(EntityId id) {
  const std::uint32_t found = rows_.indexMap().find(id);
  if (found == detail::FlatHashMap::kMissing) return false;
  const std::size_t index = found;
  const std::size_t last = rows_.entityCount() - 1;
  broad_phase_.partnersOf(id, &partners_);  // its own pairs, not all
  for (const EntityId partner : partners_) {  // what it touched loses it: wakes
    const std::uint32_t other = rows_.indexMap().find(partner);
    if (other != detail::FlatHashMap::kMissing) islands_.wake(other);  // missing: removed since the last update
  }
  if (rows_.bodies()[index].is_static) physics_.forgetReuse();  // its neighbours' covered faces change
  islands_.remove(index, last);
  levels_.remove(index, last);
  static_cover_.remove(index, last);
  broad_phase_.remove(id);
  rows_.removeRow(index);  // swap-remove, as the three above
  pairs_seen_.clear();  // a dense index moved
  invalidateLastTick();
  return true;
}

void World::Parts::clear() {
  rows_.clearRows();
  pairs_seen_.clear();
  broad_phase_ = SweepAndPrune();
  islands_.clear();
  levels_.clear();
  static_cover_.clear();
  physics_.forgetReuse();
  invalidateLastTick();
}

void World::Parts::releaseMemory() {
  rows_.releaseRowMemory();
  dropSpareCapacity(static_cover_);
  broad_phase_.releaseMemory();
  dropSpareCapacity(boxes_);
  dropSpareCapacity(pair_bodies_);
  dropSpareCapacity(pair_tested_);
  dropSpareCapacity(pairs_seen_);
  dropSpareCapacity(pair_priority_);
  dropSpareCapacity(pair_reused_);
  dropSpareCapacity(contacts_);
  physics_.releaseMemory();
  dropSpareCapacity(islands_);
  dropSpareCapacity(levels_);
  dropSpareCapacity(out_of_step_);
  dropSpareCapacity(held_through_tick_);
  fracture_->releaseMemory();
}

void World::Parts::setScheduler(const SchedulerOptions& options) {
  // All made before any is replaced (makeScheduler may throw: change nothing).
  // The chunks stay: their arenas hold the last tick's pairs.
  std::vector<NarrowChunk> made = makeNarrowChunks(narrow_chunks_.size(), options);
  for (std::size_t k = 0; k < made.size(); ++k) narrow_chunks_[k].scheduler = std::move(made[k].scheduler);
  config_.scheduler = options;
}

void World::Parts::setResponse(const ResponseOptions& options) {
  validateResponseOptions(options);
  if (options.solver != config_.response.solver) physics_.forget();  // impulses of another kind of step
  config_.response = options;
  physics_.forgetReuse();  // contacts built under the options before
  if (!options.enabled) islands_.wakeAll();  // detection alone: every pair is tested again
}

void World::Parts::setGravity(const Vec3& gravity) {
  validateGravity(gravity, config_.limits);
  config_.gravity = gravity;
  islands_.wakeAll();
}

bool World::Parts::wake(EntityId id) {
  const auto index = rows_.indexOf(id);
  if (index) islands_.wake(*index);
  return index.has_value();
}

bool World::Parts::isSleeping(EntityId id) const {
  const auto index = rows_.indexOf(id);
  return index && islands_.isSleeping(*index);
}

bool World::Parts::isRestless(EntityId id) const {
  const auto index = rows_.indexOf(id);
  return index && islands_.isRestless(*index);
}

// The last tick's pair tests point at bodies and its contacts name dense
// indices: both go stale when entities are added or removed.
void World::Parts::invalidateLastTick() {
  pair_count_ = 0;
  contacts_.clear();
}

// ---------------------------------------------------------------------------------
// The tick

void World::Parts::setClock(SecondsClock clock) {
  clock_check_every_ = checkEveryFor(clock);
  clock_ = std::move(clock);
}

TickReport World::Parts::step(double dt, const Budget& budget) {
  if (!(std::isfinite(dt) && dt >= 0.0)) throw InputError("dt", "must be finite and >= 0");
  TickReport report;
  report.bodies.entities = rows_.entityCount();
  quarantined_.clear();
  fracture_->newStep();
  quarantine(report);  // states edited through bodies() since the last step
  // Sleeping saves physics: without a response nothing sleeps, and every pair
  // is tested (and reports its contacts) every tick.
  SleepOptions sleeping = config_.sleeping;
  sleeping.enabled = sleeping.enabled && config_.response.enabled;
  islands_.beginTick(rows_.bodies(), sleeping);  // sleepers held as static until endTick
  TickContext tick = beginTick(dt, budget, report);
  // One team for the phases: the workers stay awake from loop to loop
  // (waking one costs more than many a loop here: docs/parallel.md).
  const LoopTimes loops_before = workers_.loopTimes();
  workers_.withTeam([&](Team&) {
    breakPending(tick);  // splits the last tick had no time for
    integrate(tick);
    broadPhase(tick);
    continuousCollision(tick);
    narrowPhase(tick);
    response(tick);
    tick.response_end = tick.time.now;  // from here on nothing is cut: fracture has its own limit
    fracture(tick);
  });
  const LoopTimes loops_after = workers_.loopTimes();
  report.phases.team_loops = loops_after.loops - loops_before.loops;
  report.phases.team_loop_s = loops_after.loop_s - loops_before.loop_s;
  report.phases.team_wait_s = loops_after.wait_s - loops_before.wait_s;
  report.phases.total_s = tick.time.now - tick.time.start;
  report.response.contacts = contacts_.size();
  report.bodies.entities = rows_.entityCount();
  // What followed the scheduler could not be cut: the next ticks keep it in reserve.
  const double mandatory_s = tick.response_end - tick.scheduled - report.response.response_refinement_s;
  reserve_s_ = std::max(mandatory_s, kReserveDecay * reserve_s_);
  // Held through the tick, a sleeper was neither moved nor solved: its state
  // passed the first check unchanged (endTick releases the holds).
  held_through_tick_ = islands_.held();
  islands_.endTick(rows_.bodies(), contacts_, dt, sleeping);  // held islands are not movable: no rest, no sleep
  if (tick.levelled) {
    levels_.release(rows_.bodies(), report.response.levels);
    const double must_run_s = (tick.narrow_start - tick.time.start) + (tick.time.now - tick.response_end);
    if (tick.timed) learnLevelCosts(must_run_s, mandatory_s, report);
  } else {
    levels_.unused();
  }
  quarantine(report, &held_through_tick_);
  report.bodies.sleeping = islands_.sleepingCount();
  return report;
}

// Read once, at the tick's start: the clock, the deadline and the physics
// phases' view of the World (its pointers hold for the tick; the pair count
// is read where it stands when each phase runs).
TickContext World::Parts::beginTick(double dt, const Budget& budget, TickReport& report) {
  const double start = clock_();
  const bool timed = budget.tick_seconds < std::numeric_limits<double>::infinity();  // NaN: none
  const Deadline tick_end = timed ? Deadline(&clock_, start + std::max(budget.tick_seconds, 0.0)) : Deadline();
  if (timed) report.budget.tick_budget_s = std::max(budget.tick_seconds, 0.0);
  TickContext tick(report);
  tick.dt = dt;
  tick.budget = budget;
  tick.tick_end = tick_end;
  tick.timed = timed;
  tick.levelled = responseLimited(budget);
  tick.time = TickTime{&clock_, start, start};
  StepContext& step = tick.physics;
  step.dt = dt;
  step.gravity = config_.gravity;
  step.options = &config_.response;
  step.bodies = &rows_.bodies();
  step.body_shapes = &rows_.bodyShapes();
  step.shape_bounds = &shapes_.shapeBounds();
  step.interior_fields = &shapes_.interiorFields();
  step.tests = &pair_tests_;
  step.pair_count = &pair_count_;
  step.pair_bodies = &pair_bodies_;
  step.priorities = &pair_priority_;
  step.reused = Physics::reusesContacts(config_.response) ? &pair_reused_ : nullptr;
  step.accept_unresolved = config_.unresolved_policy == UnresolvedPolicy::Accept;
  step.steady_frontier = narrowPhaseLimited(budget, tick_end);
  step.budget.max_iterations = budget.solver_iterations;
  step.budget.deadline = tick_end;
  step.contacts = &contacts_;
  step.workers = &workers_;
  step.ids = &rows_.entityIds();
  step.held_asleep = &islands_.held();
  step.static_cover = &static_cover_;
  return tick;
}

// The island levels first (held islands are static until released), then
// semi-implicit Euler; marks the fast bodies (physics.hpp).
void World::Parts::integrate(TickContext& tick) {
  PhaseTimer timer(tick.time, tick.report.phases.integrate_s);
  if (tick.levelled) chooseLevels(tick.budget, tick.report);
  physics_.integrate(tick.physics);
}

Aabb World::Parts::boxOf(std::size_t index) const {
  const BodyState& body = rows_.bodies()[index];
  const ShapeInfo& info = shapes_.shapeAt(rows_.bodyShapes()[index]);
  Aabb box;
  if (rows_.bodyBoxModes()[index] != BoxMode::Dynamic) {
    // Fixed cube: holds the shape in any orientation, only follows the centre of mass.
    const Vec3 half = Vec3::Constant(info.bounding_radius);
    box.min = body.pose.position - half;
    box.max = body.pose.position + half;
    return box;
  }
  // Dynamic: the level-1 spheres (the root alone for a one-level tree) cover
  // every surface voxel, so their rotated AABB holds the shape; few spheres,
  // and much tighter than the root sphere for long, thin shapes.
  const SphereTree& tree = info.tree;
  const int level = tree.levelCount() > 1 ? 1 : 0;
  const Mat3 r = body.pose.orientation.toRotationMatrix();
  box.min = Vec3::Constant(std::numeric_limits<double>::infinity());
  box.max = -box.min;
  for (std::int32_t n = tree.levelBegin(level); n < tree.levelBegin(level + 1); ++n) {
    const SphereNode& node = tree.node(n);
    const Vec3 c = r * node.centre + body.pose.position;
    box.min = box.min.cwiseMin(c - Vec3::Constant(node.radius));
    box.max = box.max.cwiseMax(c + Vec3::Constant(node.radius));
  }
  return box;
}

// A fast body's box covers its whole path of the tick (the cube that holds it
// in any orientation, at its start and at its end), so its sweep partners
// are among its broad-phase pairs.
Aabb World::Parts::sweptBoxOf(std::size_t index) const {
  const double radius = shapes_.shapeAt(rows_.bodyShapes()[index]).bounding_radius;
  const Vec3 start = physics_.startPose(index).position;
  const Vec3 end = rows_.bodies()[index].pose.position;
  Aabb box;
  box.min = start.cwiseMin(end) - Vec3::Constant(radius);
  box.max = start.cwiseMax(end) + Vec3::Constant(radius);
  return box;
}

void World::Parts::broadPhase(TickContext& tick) {
  PhaseTimer timer(tick.time, tick.report.phases.broad_s);
  const double dt = tick.dt;
  // The boxes in parallel (each body alone), then handed over in order. A
  // body held by its island's level gets the box of where it would go.
  const bool held = levels_.anyHeld();
  boxes_.resize(rows_.entityCount());
  workers_.forEach(rows_.entityCount(), kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!rows_.bodies()[i].is_static) {
        boxes_[i] = physics_.isFast(i) ? sweptBoxOf(i) : boxOf(i);
      } else if (held && levels_.isHeld(i)) {
        boxes_[i] = IslandLevels::heldBox(rows_.bodies()[i], shapes_.shapeAt(rows_.bodyShapes()[i]).bounding_radius, dt);
      }
    }
  });
  for (std::size_t i = 0; i < rows_.entityCount(); ++i) {
    if (!rows_.bodies()[i].is_static || (held && levels_.isHeld(i))) broad_phase_.setBox(rows_.entityIds()[i], boxes_[i]);
  }
  broad_phase_.update();
  tick.report.detection.broad_pairs = broad_phase_.pairs().size();

  const std::vector<BroadPair>& pairs = broad_phase_.pairs();
  if (pair_tests_.size() < pairs.size()) {  // pool grows only; last tick's tests are not read again
    resizeRewritten(pair_tests_, pairs.size());
    resizeRewritten(pair_bodies_, pairs.size());
    resizeRewritten(pair_priority_, pairs.size());
    resizeRewritten(pair_reused_, pairs.size());
  }
  // A moving body reached a sleeping island: it woke, its pairs are tested too.
  if (setUpPairTests()) setUpPairTests();
  if (held) joinHeldIslands(tick);
}

// The pairs' bodies; the tests themselves are reset by their chunk of the
// narrow phase, in parallel, each into its chunk's arena.
bool World::Parts::setUpPairTests() {
  pair_count_ = 0;
  if (islands_.quiet()) return false;  // all asleep: every pair is held-held or held-static
  // Each pair's dense indices and whether it is tested, in pieces on the
  // workers: each writes its own slots. The indices are last lookup's while
  // the pair at that place is the same (no removal since: pairs_seen_ emptied),
  // else a hash look-up each, at random.
  const std::vector<BroadPair>& pairs = broad_phase_.pairs();
  pair_tested_.resize(pairs.size());
  if (pairs_seen_.size() < pairs.size()) pairs_seen_.resize(pairs.size());
  workers_.forEach(pairs.size(), kBodiesPerTask, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const BroadPair pair = pairs[k];
      SeenPair& seen = pairs_seen_[k];
      if (!(seen.ids == pair)) {
        seen.ids = pair;
        seen.indices = {static_cast<std::uint32_t>(rows_.indexMap().find(pair.first)),
                        static_cast<std::uint32_t>(rows_.indexMap().find(pair.second))};
      }
      const std::array<std::uint32_t, 2>& indices = seen.indices;
      assert(indices[0] == rows_.indexMap().find(pair.first) && indices[1] == rows_.indexMap().find(pair.second));
      pair_bodies_[k] = indices;
      // Two static (or held) bodies: nothing can change.
      pair_tested_[k] = !(rows_.bodies()[indices[0]].is_static && rows_.bodies()[indices[1]].is_static);
    }
  });
  // In pair order: the wakes, and the tested pairs packed to the front
  // (pair_count_ never passes k, so the packing reads each slot before it is written).
  bool woke = false;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const std::array<std::uint32_t, 2> bodies = pair_bodies_[k];
    woke |= islands_.noteOverlap(bodies[0], bodies[1], rows_.bodies());
    if (pair_tested_[k] != 0) pair_bodies_[pair_count_++] = bodies;
  }
  if (woke) islands_.releaseWoken(rows_.bodies());
  return woke;
}

// Fast bodies put back at their first contact with a broad-phase partner
// (continuous.hpp, sweepFastBodies); the pair tests read the poses when they run.
void World::Parts::continuousCollision(TickContext& tick) {
  PhaseTimer timer(tick.time, tick.report.phases.sweep_s);
  physics_.sweep(tick.physics);
}

void World::Parts::narrowPhase(TickContext& tick) {
  PhaseTimer timer(tick.time, tick.report.phases.narrow_s);
  tick.narrow_start = timer.start();
  const double start = timer.start();
  const Budget& budget = tick.budget;
  const Deadline& tick_end = tick.tick_end;
  TickReport& report = tick.report;
  // Its own limit, or what the tick leaves after the reserve for what follows.
  double end = std::numeric_limits<double>::infinity();
  if (budget.seconds < end) end = start + budget.seconds;
  if (tick_end.isSet()) {
    report.budget.reserve_s = kReserveMargin * reserve_s_;
    end = std::min(end, tick_end.at() - report.budget.reserve_s);
  }
  if (end < std::numeric_limits<double>::infinity()) report.budget.narrow_budget_s = std::max(end - start, 0.0);
  const bool gaze = perception_.hasFixation();
  // Each chunk: reset its tests into its arena, then its scheduler over them
  // under its share of the sphere tests; every chunk watches the deadline.
  // The static bodies' covered faces, measured again only when a static body
  // came, went or moved (for the contacts; here, before any pair's contacts
  // are carried over, since those were built with the faces before).
  if (static_cover_.update(rows_.bodies(), rows_.bodyShapes(), shapes_.coverShapes())) physics_.forgetReuse();
  // A pair whose contacts last tick left valid resumes Colliding: no sphere
  // test, its contacts carried over (pair_contact_cache.hpp).
  const StepContext& step = tick.physics;
  const bool limited = narrowPhaseLimited(budget, tick_end);
  const std::size_t chunks = narrowChunkCount(static_cast<std::size_t>(workers_.threads()), limited);
  assert(chunks <= narrow_chunks_.size());
  narrow_chunks_used_ = chunks;
  workers_.forChunks(chunks, [&](std::size_t k, std::size_t) {
    NarrowChunk& chunk = narrow_chunks_[k];
    const auto [first, last] = chunkRange(pair_count_, k, chunks);
    chunk.arena.clear();
    for (std::size_t i = first; i < last; ++i) {
      const std::uint32_t ia = pair_bodies_[i][0], ib = pair_bodies_[i][1];
      const PairBody a{rows_.entityIds()[ia], &shapes_.shapeAt(rows_.bodyShapes()[ia]).tree, &rows_.bodies()[ia].pose};
      const PairBody b{rows_.entityIds()[ib], &shapes_.shapeAt(rows_.bodyShapes()[ib]).tree, &rows_.bodies()[ib].pose};
      const std::uint32_t entry =
          step.reused != nullptr ? physics_.reusableEntry(step, ia, ib) : PairContactCache::kNone;
      pair_reused_[i] = entry;
      if (entry == PairContactCache::kNone) {
        pair_tests_[i].reset(a, b, &chunk.arena);
      } else {
        const PairContactCache::Entry& e = physics_.pairCache().entry(entry);
        pair_tests_[i].resumeColliding(a, b, &chunk.arena, e.leaf, e.level);
      }
    }
    BudgetTracker tracker(chunkShare(budget.sphere_tests, k, chunks), Deadline(&clock_, end), clock_check_every_);
    chunk.stats = chunk.scheduler->run(pair_tests_.data() + first, last - first,
                                       PairBodies{pair_bodies_.data() + first, rows_.bodies().size()},
                                       gaze ? &perception_ : nullptr, tracker);
  }, limited ? Team::Claim::OwnShareWhole : Team::Claim::Balanced);
  const ScheduleStats stats = mergedStats(narrow_chunks_, chunks);
  tick.scheduled = clock_();
  report.detection.sphere_tests = stats.sphere_tests;
  report.detection.interrupted = stats.interrupted;
  report.detection.scheduling_overhead_s = stats.overhead_seconds;
  report.accuracy.perception_used = stats.used_perception;

  const bool accept = config_.unresolved_policy == UnresolvedPolicy::Accept;
  for (std::size_t i = 0; i < pair_count_; ++i) {
    const PairTest& test = pair_tests_[i];
    pair_priority_[i] = 0.0;
    switch (test.status()) {
      case PairStatus::Colliding:
        ++report.detection.colliding;
        if (pair_reused_[i] != PairContactCache::kNone) ++report.detection.reused;
        break;
      case PairStatus::Separate: ++report.detection.separate; break;
      case PairStatus::Unresolved: ++report.detection.unresolved; break;
    }
    const bool accepted_unresolved = accept && test.status() == PairStatus::Unresolved;
    if (accepted_unresolved) {
      ++report.detection.unresolved_accepted;
      report.accuracy.geometric_inaccuracy += test.gapEstimate();
      report.accuracy.geometric_bound += test.gapBound();
    }
    // Perceptual priority of every pair that becomes a contact; P sums the
    // accepted unresolved ones only (the artefacts a viewer could notice).
    if (gaze && (accepted_unresolved || test.status() == PairStatus::Colliding)) {
      pair_priority_[i] = perception_.measure(test).priority;
      report.accuracy.perception_used = true;
      if (accepted_unresolved) report.accuracy.perceived_inaccuracy += pair_priority_[i];
    }
  }
}

// Contacts from the deepest sphere pairs of each colliding or accepted pair,
// then impulses and position correction (contact_builder.hpp,
// contact_solver.hpp), refined until the tick's deadline or the iteration budget.
void World::Parts::response(TickContext& tick) {
  PhaseTimer timer(tick.time, tick.report.phases.response_s);
  TickReport& report = tick.report;
  if (tick.timed) report.budget.response_budget_s = std::max(tick.tick_end.at() - timer.start(), 0.0);
  if (levels_.anyHeld()) tick.physics.held_asleep = &outOfStep();  // held pairs keep their warm start as sleepers'
  {
    PhaseTimer building(tick.time, report.phases.contacts_s);
    physics_.buildContacts(tick.physics);
  }
  report.response.frontier_kept = physics_.lastReport().frontier_kept;
  report.response.interior_contacts = physics_.lastReport().interior_contacts;
  physics_.solve(tick.physics);
  const SolveStats& stats = physics_.lastReport().solve;
  report.response.velocity_passes = stats.velocity_passes;
  report.response.position_passes = stats.position_passes;
  report.response.response_refinement_s = stats.refinement_seconds;
}

// A body the tick left non-finite or beyond the limits (an explosion, a
// solver blow-up, a fall forever) is removed here, before anything reads its
// state, and named in quarantined(). Removing invalidates this tick's
// contacts (they name dense indices); the rest of the world is untouched.
void World::Parts::quarantine(TickReport& report, const std::vector<std::uint8_t>* unchanged) {
  const std::size_t first = quarantined_.size();
  for (std::size_t i = 0; i < rows_.bodies().size(); ++i) {
    if (unchanged != nullptr && (*unchanged)[i] != 0) continue;
    if (rows_.bodies()[i].is_static) continue;  // never moves: checked at input
    const Quarantine reason = quarantineReason(rows_.bodies()[i], config_.limits);
    if (reason == Quarantine::None) continue;
    quarantined_.push_back({rows_.entityIds()[i], rows_.bodyNames()[i], rows_.bodyShapes()[i], reason});
    ++(reason == Quarantine::LeftWorld ? report.bodies.left_world : report.bodies.quarantined);
  }
  if (quarantined_.size() == first) return;
  for (std::size_t q = first; q < quarantined_.size(); ++q) removeEntity(quarantined_[q].id);
  report.bodies.entities = rows_.entityCount();
  report.response.contacts = contacts_.size();
}

}  // namespace stc
