// World: the shapes, the entities, what follows them, fracture and the
// phases (World::Parts, internal: src/core/world_parts.hpp); step() runs one
// tick:
//   1 integrate  2 broad phase  3 narrow phase + scheduler  4 response
// and returns a TickReport. Each phase reads what the previous one wrote.
#pragma once

#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/contact.hpp"
#include "sphere_tree_collision/limits.hpp"
#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/phase_options.hpp"
#include "sphere_tree_collision/response_options.hpp"
#include "sphere_tree_collision/shape_info.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/tick_report.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stc {

// BoxMode (body.hpp): "auto" | "fixed" | "dynamic"; throws InputError("box_mode").
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
  FractureOptions fracture;  // for bodies with a material strength (phase_options.hpp)
  SleepOptions sleeping;  // islands at rest sleep (phase_options.hpp); validated as "sleeping.*"
  // Threads of the tick (docs/parallel.md): 0 = every core, 1 = the calling thread
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
  // (faceBit, body.hpp), so no contact pushes a body out through them.
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

// The shapes (a ShapeLibrary), the entities' rows (an EntityTable), what
// follows each add and remove, fracture and the phases are World::Parts
// (src/core/world_parts.hpp), held by pointer: this header names none of
// them, and a World moves by moving the pointer (a moved-from World may only
// be assigned to or destroyed).
class World {
 public:
  explicit World(const WorldConfig& config = WorldConfig{});
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  // Shapes are shared: the same key returns the same id (the tree is built
  // once, under config().voxel_limits and config().tree; ShapeLibrary).
  ShapeId addShape(const std::string& key, VoxelShape shape);
  std::optional<ShapeId> findShape(const std::string& key) const;
  const ShapeInfo& shape(ShapeId id) const;  // throws InputError("shape") for an unknown id
  std::size_t shapeCount() const;
  // Records how shape `id` was made (ShapeInfo::recipe); the first recipe
  // of a shape stays (a shape found again by its key was made by it).
  void setShapeRecipe(ShapeId id, const ShapeRecipe& recipe);

  // Throws InputError naming the field ("shape", "pose.position",
  // "pose.orientation", "linear_velocity", "angular_velocity", "density",
  // "material.restitution", "material.friction", "name", "max_entities") and,
  // for a value beyond config().limits, the limit; on throw nothing changes.
  EntityId addEntity(const EntitySpec& spec);
  // What addEntity checks but the shape id, for a request whose shape is not
  // built yet: the same errors, in the same order.
  void validateEntity(const EntitySpec& spec) const;
  bool removeEntity(EntityId id);
  std::optional<EntityId> findByName(const std::string& name) const;
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
  const std::vector<QuarantinedEntity>& quarantined() const;
  // The bodies the last step (and breakEntity since) broke, with their pieces.
  const std::vector<BrokenEntity>& broken() const;

  Perception& perception();
  const Perception& perception() const;
  const WorldConfig& config() const;
  void setScheduler(const SchedulerOptions& options);
  void setUnresolvedPolicy(UnresolvedPolicy policy);
  // From the next step on; throws InputError (validateResponseOptions) and changes nothing.
  void setResponse(const ResponseOptions& options);
  // Throws InputError("gravity") as the constructor does; wakes every island.
  void setGravity(const Vec3& gravity);
  // Sleeping islands (islands.hpp). wake: the entity's island; false for an unknown id.
  bool wake(EntityId id);
  bool isSleeping(EntityId id) const;
  // The group the body at dense index `index` sleeps with (0: awake): what a
  // saved world writes (EntitySpec::sleep_group).
  std::uint32_t sleepGroup(std::size_t index) const;
  // Awake and failing the rest test at the last step (it moved out of its
  // rest balls, rest_test.hpp): what keeps its island awake. False when asleep.
  bool isRestless(EntityId id) const;
  // The response level the last step gave the entity's island
  // (island_levels.hpp): Full, Held (still, waiting for its turn), Asleep or
  // Static. Full for an unknown id.
  ResponseLevel responseLevel(EntityId id) const;

  // Brings the broad phase up to the entities added and removed since the
  // last step (before the first: all of them), as the next step's broad
  // phase would do first, so that a saved world holds its part: call it
  // before writeSceneYaml (the node's ~save does). Its pairs may then come in
  // another order than without it, so later ticks may differ in their last
  // bits, as after any spawn; what it finds is the same set of pairs.
  void settleBroadPhase();

  // Dense views, valid until the next add/remove/step. Adding or removing an
  // entity (or clear()) also empties the last step's pair tests and contacts().
  // A sleeping body's pose or velocity edited here wakes its island at the next step.
  std::size_t entityCount() const;
  const std::vector<EntityId>& entityIds() const;
  const std::vector<BodyState>& bodies() const;
  std::vector<BodyState>& bodies();
  const std::vector<ShapeId>& bodyShapes() const;
  const std::vector<std::string>& bodyNames() const;
  // The density each entity was added with (kg/m^3; a static body's too),
  // and its box mode as resolved (never Auto): what a saved world needs
  // that BodyState does not keep.
  const std::vector<double>& bodyDensities() const;
  const std::vector<BoxMode>& bodyBoxModes() const;
  // EntitySpec::closed_faces of the entity at dense index `index`.
  std::uint8_t closedFaces(std::size_t index) const;
  std::optional<std::size_t> indexOf(EntityId id) const;

  // Pairs the last step's narrow phase tested.
  std::size_t pairCount() const;
  // The last narrow phase's chunks (narrow_chunks.hpp; threads() before the
  // first): pairs chunkRange(pairCount(), k, narrowChunks()) were stepped by
  // chunk k's scheduler under chunkShare(budget, k, ...).
  std::size_t narrowChunks() const;
  // Threads the tick runs on (WorldConfig::threads resolved: 0 -> the cores).
  int threads() const;
  // Times the team's loops into TickReport::phases.team_* (Workers::timeLoops: three
  // clock reads a loop, about 200 loops a tick of 500 bodies); off by default.
  void timeTeamLoops(bool on);
  const std::vector<Contact>& contacts() const;

 private:
  struct Parts;  // src/core/world_parts.hpp
  std::unique_ptr<Parts> parts_;
  // The internal views tests, benches and the saved world's file read
  // (src/core/world_access.hpp).
  friend struct WorldAccess;
};

}  // namespace stc
