// World: composes the shapes (ShapeLibrary), the entities' rows
// (EntityTable), what follows them, fracture (WorldFracture) and the phases;
// step() runs one tick:
//   1 integrate  2 broad phase  3 narrow phase + scheduler  4 response
// and returns a TickReport. Each phase reads what the previous one wrote.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/carried_state.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/entity_table.hpp"
#include "sphere_tree_collision/fracture.hpp"
#include "sphere_tree_collision/island_levels.hpp"
#include "sphere_tree_collision/islands.hpp"
#include "sphere_tree_collision/limits.hpp"
#include "sphere_tree_collision/narrow_chunks.hpp"
#include "sphere_tree_collision/pair_test.hpp"
#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/response.hpp"
#include "sphere_tree_collision/scheduler.hpp"
#include "sphere_tree_collision/shape_library.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/static_cover.hpp"
#include "sphere_tree_collision/sweep_and_prune.hpp"
#include "sphere_tree_collision/tick_report.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"
#include "sphere_tree_collision/workers.hpp"

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace stc {

// BoxMode (entity_table.hpp): "auto" | "fixed" | "dynamic"; throws InputError("box_mode").
BoxMode parseBoxMode(const std::string& name);
const char* toString(BoxMode mode);

struct WorldConfig {
  Vec3 gravity = Vec3::Zero();
  SchedulerOptions scheduler;
  UnresolvedPolicy unresolved_policy = UnresolvedPolicy::Accept;
  SphereTreeOptions tree;
  VoxelLimits voxel_limits;
  MeshLimits mesh_limits;  // what a mesh file may hold (limits.hpp); validated by name
  // Folders a mesh named by a file:// URI or a path may be read from
  // (canonical, as canonicalMeshRoots gives them; mesh_loader.hpp). Empty:
  // only package:// resources (resolved by the ROS layer) are read.
  std::vector<std::string> mesh_roots;
  std::size_t max_entities = 20000;
  ResponseOptions response;
  PhysicalLimits limits;  // inputs beyond them are rejected; bodies beyond them quarantined
  FractureOptions fracture;  // for bodies with a material strength (fracture.hpp)
  SleepOptions sleeping;  // islands at rest sleep (islands.hpp); validated as "sleeping.*"
  // Threads of the tick (workers.hpp): 0 = every core, 1 = the calling thread
  // alone (no task library), n = n. Results at an unlimited budget do not
  // depend on it (docs/parallel.md). Throws
  // InputError("threads") outside [0, kMaxThreads].
  int threads = 1;
};

// How far from 1 the norm of an EntitySpec::exact_orientation may be (a
// pose the integrator normalised is within a few ulp).
constexpr double kExactOrientationTolerance = 1e-12;

struct EntitySpec {
  std::string name;         // optional; unique when given
  ShapeId shape = 0;
  Pose pose;                // of the body frame (origin at the centre of mass)
  // The orientation as given, bit for bit, not normalised: a saved world's,
  // unit to round-off (within kExactOrientationTolerance, else
  // InputError("pose.orientation")). False: normalised.
  bool exact_orientation = false;
  Vec3 linear_velocity = Vec3::Zero();
  Vec3 angular_velocity = Vec3::Zero();
  double density = 1000.0;  // kg/m^3, > 0
  Material material;
  bool is_static = false;
  BoxMode box_mode = BoxMode::Auto;
  // Static bodies only: faces of the body frame that are not surfaces
  // (faceBit, static_cover.hpp), so no contact pushes a body out through them.
  // The back of a one-sided wall or floor (faceBit(2, false) when its inside
  // faces +z): a body pressed deeper than half the wall's thickness is still
  // pushed back in, not out through the back. 0: every face is a surface.
  std::uint8_t closed_faces = 0;
  // A saved world's body (scene_file.hpp), restored as it was at the end of
  // a tick: not new (a new body's box wakes the sleepers it touches), and
  // with sleep_group > 0 asleep with the other bodies of that group, which
  // wake together (its velocities must be 0; movable bodies only). Ignored
  // with sleeping or the response off. Throws InputError("sleep").
  bool restored = false;
  std::uint32_t sleep_group = 0;
  // The id it had in a saved world: kept, so that its pairs' bodies come in
  // the same order (the lower id first) and its frame keeps its name.
  // kInvalidEntity: the next id. One in use: InputError("id").
  EntityId id = kInvalidEntity;
};

// One entity removed at the end of a tick, and why.
struct QuarantinedEntity {
  EntityId id = kInvalidEntity;
  std::string name;
  ShapeId shape = 0;
  Quarantine reason = Quarantine::None;
};

// One body broken (by the last step, or breakEntity since): its pieces replace it.
struct BrokenEntity {
  EntityId id = kInvalidEntity;
  std::string name;
  ShapeId shape = 0;
  std::vector<EntityId> pieces;
};

class WorldFracture;  // src/core/world_fracture.hpp
struct TickContext;   // src/core/tick_context.hpp

// The shapes are a ShapeLibrary (shape_library.hpp) and the entities' rows
// an EntityTable (entity_table.hpp), private bases: what World adds to them
// is the validation, and the parts that follow each add and remove.
class World : private ShapeLibrary, private EntityTable {
 public:
  explicit World(const WorldConfig& config = WorldConfig{});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  // Shapes are shared: the same key returns the same id (the tree is built
  // once, under config().voxel_limits and config().tree; ShapeLibrary).
  ShapeId addShape(const std::string& key, VoxelShape shape);
  using ShapeLibrary::findShape;
  using ShapeLibrary::shape;
  using ShapeLibrary::shapeCount;
  using ShapeLibrary::setShapeRecipe;

  // Throws InputError naming the field ("shape", "pose.position",
  // "pose.orientation", "linear_velocity", "angular_velocity", "density",
  // "material.restitution", "material.friction", "name", "max_entities") and,
  // for a value beyond config().limits, the limit; on throw nothing changes.
  EntityId addEntity(const EntitySpec& spec);
  // What addEntity checks but the shape id, for a request whose shape is not
  // built yet: the same errors, in the same order.
  void validateEntity(const EntitySpec& spec) const;
  bool removeEntity(EntityId id);
  using EntityTable::findByName;
  void clear();  // removes every entity, keeps shapes
  // Hands back what the pooled arrays keep beyond today's entities and pairs
  // (after a large removal: a flood of 10,000 spawns and despawns left 13 MB
  // in them). Changes no state but the order of the broad phase's pairs (it
  // is rebuilt), so later ticks may differ in their last bits, as after any
  // removal; the next ticks allocate again what they need. Not for every
  // tick: it copies every per-entity array.
  void releaseMemory();

  // Breaks a body as an impact at `point` along `normal` (world frame) would
  // (fracture.hpp): its pieces replace it, each with the parent's velocity at
  // its centre of mass and the parent's spin, so momentum is kept. Returns
  // the pieces' ids, or nothing when the body stays whole (static, unknown,
  // nothing to split, or a piece the limits would reject).
  std::vector<EntityId> breakEntity(EntityId id, const Vec3& point, const Vec3& normal);

  // Throws InputError("dt") only. A body whose state leaves the limits during
  // the tick is removed at its end (see quarantined()); the rest goes on. A
  // state edited through bodies() is checked the same way before the tick.
  TickReport step(double dt, const Budget& budget);
  // Time source of step(): phase times and deadlines (default steadySeconds).
  // A fake clock makes time budgets deterministic in tests. Reads the clock
  // a few dozen times, to space the narrow phase's reads by what one costs
  // (checkEveryFor, budget.hpp).
  void setClock(SecondsClock clock);
  // The entities the last step removed, with the reason.
  const std::vector<QuarantinedEntity>& quarantined() const { return quarantined_; }
  // The bodies the last step (and breakEntity since) broke, with their pieces.
  const std::vector<BrokenEntity>& broken() const;

  Perception& perception() { return perception_; }
  const Perception& perception() const { return perception_; }
  const WorldConfig& config() const { return config_; }
  void setScheduler(const SchedulerOptions& options);
  void setUnresolvedPolicy(UnresolvedPolicy policy) { config_.unresolved_policy = policy; }
  // From the next step on; throws InputError (validateResponseOptions) and changes nothing.
  void setResponse(const ResponseOptions& options);
  // Throws InputError("gravity") as the constructor does; wakes every island.
  void setGravity(const Vec3& gravity);
  // Sleeping islands (islands.hpp). wake: the entity's island; false for an unknown id.
  bool wake(EntityId id);
  bool isSleeping(EntityId id) const;
  // The group the body at dense index `index` sleeps with (0: awake): what a
  // saved world writes (EntitySpec::sleep_group).
  std::uint32_t sleepGroup(std::size_t index) const { return islands_.group(index); }
  // Awake and failing the rest test at the last step (it moved out of its
  // rest balls, rest_test.hpp): what keeps its island awake. False when asleep.
  bool isRestless(EntityId id) const;
  // The response level the last step gave the entity's island
  // (island_levels.hpp): Full, Held (still, waiting for its turn), Asleep or
  // Static. Full for an unknown id.
  ResponseLevel responseLevel(EntityId id) const;

  // What the next tick carries over from the last besides the bodies' rows
  // (carried_state.hpp), by dense index: a saved world's contact_state.
  CarriedState carriedState() const;
  // The same put back into a World that holds the saved world's entities in
  // the same dense order with the same ids (EntitySpec::id), before its
  // first step: its next ticks at an unlimited budget are then the saved
  // world's, bit for bit (docs/ros_interface.md, Saved worlds). Throws
  // InputError naming the part and the field ("rest[2].body", "boxes",
  // "banding", "broad_pairs", "carried[0].leaf", "warm[3]", ...) and then
  // changes nothing.
  void restoreCarried(const CarriedState& state);
  // Brings the broad phase up to the entities added and removed since the
  // last step (before the first: all of them), as the next step's broad
  // phase would do first, so that carriedState() holds its part: call it
  // before saving (the node's ~save does). Its pairs may then come in
  // another order than without it, so later ticks may differ in their last
  // bits, as after any spawn; what it finds is the same set of pairs.
  void settleBroadPhase();

  // Dense views, valid until the next add/remove/step. Adding or removing an
  // entity (or clear()) also empties pairTests()/contacts() of the last step.
  // A sleeping body's pose or velocity edited here wakes its island at the next step.
  using EntityTable::entityCount;
  using EntityTable::entityIds;
  using EntityTable::bodies;
  using EntityTable::bodyShapes;
  using EntityTable::bodyNames;
  using EntityTable::bodyDensities;
  using EntityTable::bodyBoxModes;
  // EntitySpec::closed_faces of the entity at dense index `index`.
  std::uint8_t closedFaces(std::size_t index) const { return static_cover_.closedFaces(index); }
  using EntityTable::indexOf;

  // Narrow-phase results of the last step: pairTests()[0..pairCount()).
  const std::vector<PairTest>& pairTests() const { return pair_tests_; }
  std::size_t pairCount() const { return pair_count_; }
  // The last narrow phase's chunks (narrow_chunks.hpp; threads() before the
  // first): pairs chunkRange(pairCount(), k, narrowChunks()) were stepped by
  // chunk k's scheduler under chunkShare(budget, k, ...).
  std::size_t narrowChunks() const { return narrow_chunks_used_; }
  // Threads the tick runs on (WorldConfig::threads resolved: 0 -> the cores).
  int threads() const { return workers_.threads(); }
  // Times the team's loops into TickReport::phases.team_* (Workers::timeLoops: three
  // clock reads a loop, about 200 loops a tick of 500 bodies); off by default.
  void timeTeamLoops(bool on) { workers_.timeLoops(on); }
  const std::vector<Contact>& contacts() const { return contacts_; }
  // The broad phase: its pairs and boxes as of the last step (checks and tests).
  const SweepAndPrune& broadPhase() const { return broad_phase_; }
  // What the physics did in the last step: fast bodies swept back, solver stats.
  const PhysicsReport& physicsReport() const { return physics_.lastReport(); }

 private:
  // The tick's context, made once at its start (tick_context.hpp), then the
  // phases in tick order; each times itself into the report (PhaseTimer).
  TickContext beginTick(double dt, const Budget& budget, TickReport& report);
  void integrate(TickContext& tick);
  void broadPhase(TickContext& tick);  // also sets up the pair tests of its pairs
  void continuousCollision(TickContext& tick);
  void narrowPhase(TickContext& tick);  // notes when the scheduler stopped (what follows is not interruptible)
  void response(TickContext& tick);
  // First and last: removes bodies beyond the limits; bodies flagged in
  // `unchanged` (held through the tick) are not looked at again.
  void quarantine(TickReport& report, const std::vector<std::uint8_t>* unchanged = nullptr);
  // Fracture after the response, and the breaks that waited, at the tick's
  // start (WorldFracture::fracture / breakPending, world_fracture.cpp); their
  // time counts in TickFracture::fracture_s.
  void fracture(TickContext& tick);
  void breakPending(TickContext& tick);
  Aabb boxOf(std::size_t index) const;
  Aabb sweptBoxOf(std::size_t index) const;
  void invalidateLastTick();
  // Island levels (world_levels.cpp). Whether the response is limited this
  // tick; the islands ranked and the ones beyond the allowance held
  // (before integrate); held islands a moving body reaches joined to the tick
  // and integrated (after the broad phase's pairs); after the tick, what a
  // unit of cost took and what the phases that must run took, for the next.
  static bool responseLimited(const Budget& budget);
  void chooseLevels(const Budget& budget, TickReport& report);
  void joinHeldIslands(TickContext& tick);
  void learnLevelCosts(double must_run_s, double response_mandatory_s, const TickReport& report);
  // The solver's "held" bodies: asleep or held by their level (for its warm-start store).
  const std::vector<std::uint8_t>& outOfStep();
  bool setUpPairTests();  // bodies of the broad phase's pairs; true when a sleeping island woke

  WorldConfig config_;
  Workers workers_;  // before the phases that use it
  // The shapes: the ShapeLibrary base (shapes_, shape_bounds_, cover_shapes_).
  // The entities' rows: the EntityTable base (ids_, bodies_, body_shapes_,
  // box_modes_, densities_, names_, index_of_).
  StaticCover static_cover_;  // static bodies' faces other static bodies cover, by dense index

  SweepAndPrune broad_phase_;
  std::vector<Aabb> boxes_;  // this tick's box of each body, by dense index (pooled)
  std::vector<EntityId> partners_;  // removeEntity: the broad-phase partners of the removed body (pooled)
  // The narrow phase's chunks, as many as it ever cuts (narrow_chunks.hpp): a
  // scheduler each and the arena of its pair tests' hits; in a vector made
  // once, so the arenas keep their address when the World is moved (the pair
  // tests point at them).
  std::vector<NarrowChunk> narrow_chunks_;
  std::size_t narrow_chunks_used_ = 1;  // by the last narrow phase
  Perception perception_;
  std::vector<PairTest> pair_tests_;  // pooled: capacity kept between ticks
  std::size_t pair_count_ = 0;
  std::vector<std::array<std::uint32_t, 2>> pair_bodies_;  // dense indices of each pair test's bodies
  std::vector<std::uint8_t> pair_tested_;  // setUpPairTests: per broad-phase pair, not static-static
  // setUpPairTests: each broad-phase pair's ids and dense indices as last
  // looked up, by its place in the pair list (a pair mostly keeps its place
  // from tick to tick); emptied when a removal moves dense indices.
  struct SeenPair {
    BroadPair ids{0, 0};  // {0, 0} is no pair: a miss
    std::array<std::uint32_t, 2> indices{};
  };
  std::vector<SeenPair> pairs_seen_;
  std::vector<double> pair_priority_;  // perceptual priority of each pair test (0 without gaze)
  std::vector<std::uint32_t> pair_reused_;  // each pair's carried-over contacts (PairContactCache), or kNone
  std::vector<Contact> contacts_;
  Physics physics_;  // integration and response (response.hpp), warm-start state
  Islands islands_;  // which bodies sleep, indexed like bodies_
  IslandLevels levels_;  // which awake islands are held this tick, indexed like bodies_
  // Learnt from timed ticks (world_levels.cpp): seconds of the response's
  // mandatory part per unit of island cost, and of the phases that must run.
  double cost_unit_s_ = 0.0;
  double must_run_s_ = 0.0;
  std::vector<std::uint8_t> out_of_step_;  // outOfStep (pooled)
  SecondsClock clock_ = steadySeconds;
  std::int64_t clock_check_every_ = BudgetTracker::kDefaultCheckEvery;  // of clock_ (setClock)
  double reserve_s_ = 0.0;  // TickReport::budget.reserve_s of the next tick
  std::vector<QuarantinedEntity> quarantined_;  // by the last step
  std::vector<std::uint8_t> held_through_tick_;  // step: Islands::held() before endTick (pooled)
  std::unique_ptr<WorldFracture> fracture_;  // its queue, tree costs and what broke
};

}  // namespace stc
