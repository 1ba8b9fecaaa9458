// A saved world (issue 47 item 4): writeSceneYaml writes it, parseSceneYaml
// and addScene load it back into a new World with the same state bit for
// bit; numbers round-trip exactly; bad grids are refused by field.
#include "sphere_tree_collision/scene/scene_file.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include "../support/same_state.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <utility>

namespace {

using namespace stc;

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <typename M>
bool sameBits(const M& a, const M& b) {
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (!sameBits(a.data()[i], b.data()[i])) return false;
  }
  return true;
}

// Every pose and velocity of `a` and `b` (dense order), bit for bit; the
// index of the first body that differs, or -1.
long firstDifferentBody(const World& a, const World& b) {
  if (a.entityCount() != b.entityCount()) return 0;
  for (std::size_t i = 0; i < a.entityCount(); ++i) {
    const BodyState& x = a.bodies()[i];
    const BodyState& y = b.bodies()[i];
    if (!sameBits(x.pose.position, y.pose.position) || !sameBits(x.pose.orientation.coeffs(), y.pose.orientation.coeffs()) ||
        !sameBits(x.linear_velocity, y.linear_velocity) || !sameBits(x.angular_velocity, y.angular_velocity)) {
      return static_cast<long>(i);
    }
  }
  return -1;
}

// The whole state a scene file carries, bit for bit.
void expectSameWorld(const World& a, const World& b) {
  ASSERT_EQ(a.entityCount(), b.entityCount());
  EXPECT_TRUE(sameBits(a.config().gravity, b.config().gravity));
  EXPECT_EQ(firstDifferentBody(a, b), -1);
  for (std::size_t i = 0; i < a.entityCount(); ++i) {
    const BodyState& x = a.bodies()[i];
    const BodyState& y = b.bodies()[i];
    SCOPED_TRACE("body " + std::to_string(i));
    EXPECT_TRUE(sameBits(x.inv_mass, y.inv_mass));
    EXPECT_TRUE(sameBits(x.inv_inertia_body, y.inv_inertia_body));
    EXPECT_TRUE(sameBits(x.inv_inertia_world, y.inv_inertia_world));
    EXPECT_TRUE(sameBits(x.material.restitution, y.material.restitution));
    EXPECT_TRUE(sameBits(x.material.friction, y.material.friction));
    EXPECT_TRUE(sameBits(x.material.strength, y.material.strength));
    EXPECT_TRUE(sameBits(x.material.rolling_resistance, y.material.rolling_resistance));
    EXPECT_EQ(x.is_static, y.is_static);
    EXPECT_EQ(a.bodyNames()[i], b.bodyNames()[i]);
    EXPECT_TRUE(sameBits(a.bodyDensities()[i], b.bodyDensities()[i]));
    EXPECT_EQ(a.bodyBoxModes()[i], b.bodyBoxModes()[i]);
    EXPECT_EQ(a.closedFaces(i), b.closedFaces(i));
    const ShapeInfo& sa = a.shape(a.bodyShapes()[i]);
    const ShapeInfo& sb = b.shape(b.bodyShapes()[i]);
    EXPECT_EQ(sa.voxels.occupancy(), sb.voxels.occupancy());
    EXPECT_EQ(sa.voxels.nx(), sb.voxels.nx());
    EXPECT_TRUE(sameBits(sa.voxels.voxelSize(), sb.voxels.voxelSize()));
    EXPECT_TRUE(sameBits(sa.body_origin, sb.body_origin));
    EXPECT_EQ(sa.tree.nodes().size(), sb.tree.nodes().size());
  }
}

World loadSaved(const std::string& yaml, WorldConfig config) {
  const Scene scene = parseSceneYaml(yaml);
  config.gravity = scene.gravity;
  World world(config);
  addScene(world, scene);
  return world;
}

TEST(SavedWorld, NumbersReadBackAsTheSameBits) {
  const double values[] = {-0.0,
                           0.1,
                           1.0 / 3.0,
                           std::numeric_limits<double>::denorm_min(),
                           -std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::max(),
                           -std::numeric_limits<double>::max(),
                           std::nextafter(1.0, 2.0),
                           std::nextafter(1.0, 0.0),
                           6.02214076e23,
                           -1.602176634e-19};
  for (double v : values) {
    World world;
    const ShapeId cube = world.addShape("cube", makePreset("cube", PresetParams{}));
    world.setShapeRecipe(cube, ShapeRecipe{"cube", PresetParams{}, "", Vec3::Ones(), 0.0, 0});
    EntitySpec spec;
    spec.shape = cube;
    world.addEntity(spec);
    world.bodies()[0].linear_velocity = Vec3(v, -v, 0.0);  // beyond the limits: parsed, not added
    const Scene scene = parseSceneYaml(writeSceneYaml(world));
    ASSERT_EQ(scene.entities.size(), 1u);
    const Vec3 read = scene.entities[0].request.spec.linear_velocity;
    EXPECT_TRUE(sameBits(read.x(), v)) << v;
    EXPECT_TRUE(sameBits(read.y(), -v)) << v;
  }
}

// The field a one-entity scene is refused by (parsed, then added to a new
// World, which then holds nothing), or "accepted".
std::string refusedField(const std::string& entity) {
  World world;
  try {
    addScene(world, parseSceneYaml("entities:\n  - {" + entity + "}\n"));
  } catch (const InputError& e) {
    EXPECT_EQ(world.entityCount(), 0u);
    return e.field();
  }
  return "accepted";
}

TEST(SavedWorld, BadGridsAreRefusedByField) {
  const auto refusedGrid = [](const std::string& grid) { return refusedField("grid: " + grid); };
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: 0.05, runs: [0, 3]}"), "entities[0].grid.runs");
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: 0.05, runs: [0, -1, 3]}"), "entities[0].grid.runs");
  EXPECT_EQ(refusedGrid("{size: [0, 1, 1], voxel_size: 0.05, runs: [0]}"), "entities[0].grid.size");
  EXPECT_EQ(refusedGrid("{size: [4096, 4096, 4096], voxel_size: 0.05, runs: [0]}"), "entities[0].grid.size");
  EXPECT_EQ(refusedGrid("{size: [2, 1], voxel_size: 0.05, runs: [0, 2]}"), "entities[0].grid.size");
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: x, runs: [0, 2]}"), "entities[0].grid.voxel_size");
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], runs: [0, 2]}"), "entities[0].grid");
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: 0.05, runs: [0, 2], holes: 1}"), "entities[0].grid.holes");
  EXPECT_EQ(refusedGrid("[1, 2]"), "entities[0].grid");
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: 0.05, runs: [0, 2]}"), "accepted");
  // Then validateRequest's and VoxelShape::create's: an empty grid, a bad voxel size.
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: 0.05, runs: [2]}"), "entities[0].occupancy");
  EXPECT_EQ(refusedGrid("{size: [2, 1, 1], voxel_size: -1, runs: [0, 2]}"), "entities[0].voxel_size");
  EXPECT_EQ(refusedField("grid: {size: [2, 1, 1], voxel_size: 0.05, runs: [0, 2]}, voxel_size: 0.1"),
            "entities[0].voxel_size");
}

TEST(SavedWorld, AnExactOrientationIsKeptAndMustBeUnit) {
  const Quat q = Quat(0.3, 0.5, -0.2, 0.7).normalized();
  const std::string quat = "[" + std::to_string(q.x()) + ", " + std::to_string(q.y()) + ", " +
                           std::to_string(q.z()) + ", " + std::to_string(q.w()) + "]";
  // Six digits: not unit within 1e-12, refused by field; normalised when given as quat.
  EXPECT_EQ(refusedField("preset: cube, orientation: {unit_quat: " + quat + "}"), "entities[0].orientation");
  EXPECT_EQ(refusedField("preset: cube, orientation: {quat: " + quat + "}"), "accepted");
}

// A world of every kind of shape source: presets, an explicit grid, a mesh,
// static plates with closed faces, named and unnamed, coloured and not.
World mixedWorld(const WorldConfig& config) {
  World world(config);
  const std::string mesh = std::filesystem::absolute("meshes/bumpy_scan.stl").string();
  const std::string yaml = R"(
gravity: [0, 0, -9.81]
entities:
  - {name: floor, preset: plate, resolution: 40, voxel_size: 0.1, position: [0, 0, -0.05], static: true,
     closed_faces: [-z], friction: 0.7}
  - {name: rock, preset: rock, resolution: 9, voxel_size: 0.04, seed: 7, position: [0.1, 0.2, 0.6],
     orientation: {rpy: [0.3, 0.2, 0.1]}, velocity: [0.1, 0, 0], angular_velocity: [0, 1, 0], density: 2500}
  - {name: block, grid: {size: [3, 2, 2], voxel_size: 0.05, runs: [1, 5, 2, 4]}, position: [-0.4, 0, 0.4],
     color: [0.1, 0.2, 0.3, 0.4], restitution: 0.1, strength: 50, rolling_resistance: 0.05}
  - {mesh_resource: ")" + mesh + R"(", resolution: 12, scale: [0.5, 0.5, 0.5], position: [0.5, -0.3, 0.5],
     orientation: {rpy: [0, 0, 0.6]}}
  - {preset: sphere, resolution: 8, voxel_size: 0.03, position: [0.3, 0.5, 0.3], box_mode: dynamic,
     repeat: {count: [3, 1, 1], spacing: [0.3, 0, 0]}}
)";
  const Scene scene = parseSceneYaml(yaml);
  world.setGravity(scene.gravity);
  addScene(world, scene, RequestDefaults{}, meshPathWithinRoots);
  return world;
}

WorldConfig meshConfig(int threads) {
  WorldConfig config;
  config.mesh_roots = canonicalMeshRoots({std::filesystem::absolute("meshes").string()});
  config.threads = threads;
  return config;
}

TEST(SavedWorld, MixedShapesLoadBackAsTheSameState) {
  World world = mixedWorld(meshConfig(1));
  for (int t = 0; t < 20; ++t) world.step(1.0 / 60.0, Budget::unlimited());
  const std::string yaml = writeSceneYaml(world, [](EntityId id) -> std::optional<Rgba> {
    if (id == 2) return Rgba{0.1f, 0.2f, 0.3f, 0.4f};
    return std::nullopt;
  });
  EXPECT_NE(yaml.find("grid: {size: [3, 2, 2]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("mesh_resource: \""), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("closed_faces: [-z]"), std::string::npos) << yaml;
  const World loaded = loadSaved(yaml, meshConfig(1));
  expectSameWorld(world, loaded);
  // Written again, the same text: nothing was lost or rounded.
  const Scene again = parseSceneYaml(yaml);
  EXPECT_EQ(again.entities[2].request.color, (Rgba{0.1f, 0.2f, 0.3f, 0.4f}));
  EXPECT_FALSE(again.entities[1].request.color.has_value());
  EXPECT_EQ(writeSceneYaml(loaded, [](EntityId id) -> std::optional<Rgba> {
              if (id == 2) return Rgba{0.1f, 0.2f, 0.3f, 0.4f};
              return std::nullopt;
            }),
            yaml);
}

TEST(SavedWorld, RockfallLoadsBackAsTheSameState) {
  SceneParams params;
  params.entities = 300;
  WorldConfig config;
  SceneWorld made = makeSceneWorld(SceneKind::Rockfall, params, config);
  for (int t = 0; t < 120; ++t) made.world.step(made.spec.dt, Budget::unlimited());
  const World loaded = loadSaved(writeSceneYaml(made.world), config);
  expectSameWorld(made.world, loaded);
}


// The next ticks at an unlimited budget: the first where the two runs part (-1: none).
int firstDifferentTick(World& a, World& b, double dt, int ticks) {
  for (int t = 0; t < ticks; ++t) {
    a.step(dt, Budget::unlimited());
    b.step(dt, Budget::unlimited());
    if (firstDifferentBody(a, b) >= 0) return t;
  }
  return -1;
}

double maxPositionGap(const World& a, const World& b) {
  double gap = 0.0;
  for (std::size_t i = 0; i < a.entityCount(); ++i) {
    gap = std::max(gap, (a.bodies()[i].pose.position - b.bodies()[i].pose.position).norm());
  }
  return gap;
}

// No contact carried between ticks (the default scene: six presets spinning
// apart, no gravity): the next 300 ticks of the saved world and of the
// loaded one are the same bits, at 1 and 2 threads. Orientations, inertia
// and the gyroscopic integration carry over exactly.
TEST(SavedWorld, AWorldWithoutContactsGoesOnTheSame) {
  for (int threads : {1, 2}) {
    WorldConfig config;
    config.threads = threads;
    World world = loadSaved(defaultSceneYaml(), config);
    for (int t = 0; t < 30; ++t) world.step(1.0 / 60.0, Budget::unlimited());
    World loaded = loadSaved(writeSceneYaml(world), config);
    expectSameWorld(world, loaded);
    EXPECT_EQ(firstDifferentTick(world, loaded, 1.0 / 60.0, 300), -1) << threads << " threads";
    EXPECT_GE(firstDifferentBody(world, loadSaved(defaultSceneYaml(), config)), 0);  // it did turn
  }
}

// Sleep is carried (`sleep: <group>`): a world whose movable bodies all
// sleep loads asleep, in the same groups, not as new bodies (whose boxes
// would wake the sleepers they touch), and its next 300 ticks are the
// saved world's, bit for bit, at 1 and 2 threads.
TEST(SavedWorld, ASleepingWorldLoadsAsleepAndStaysTheSame) {
  for (int threads : {1, 2}) {
    World world = mixedWorld(meshConfig(threads));
    std::size_t movable = 0;
    for (const BodyState& body : world.bodies()) movable += body.is_static ? 0 : 1;
    for (int t = 0; t < 1800; ++t) {
      const TickReport r = world.step(1.0 / 60.0, Budget::unlimited());
      if (r.bodies.sleeping == movable) break;
    }
    ASSERT_EQ(world.step(1.0 / 60.0, Budget::unlimited()).bodies.sleeping, movable) << "the pile never slept";
    const std::string yaml = writeSceneYaml(world);
    EXPECT_NE(yaml.find("sleep: 1"), std::string::npos);
    World loaded = loadSaved(yaml, meshConfig(threads));
    expectSameWorld(world, loaded);
    for (std::size_t i = 0; i < world.entityCount(); ++i) {
      EXPECT_EQ(loaded.sleepGroup(i), world.sleepGroup(i)) << i;
      EXPECT_EQ(loaded.isSleeping(loaded.entityIds()[i]), world.isSleeping(world.entityIds()[i])) << i;
    }
    EXPECT_EQ(firstDifferentTick(world, loaded, 1.0 / 60.0, 300), -1) << threads << " threads";
    EXPECT_EQ(loaded.step(1.0 / 60.0, Budget::unlimited()).bodies.sleeping, movable);
    // A group wakes whole, as it would have: wake one of its bodies.
    const std::uint32_t group = loaded.sleepGroup(1);
    ASSERT_NE(group, 0u);
    loaded.wake(loaded.entityIds()[1]);
    for (std::size_t i = 0; i < loaded.entityCount(); ++i) {
      if (world.sleepGroup(i) == group) EXPECT_FALSE(loaded.isSleeping(loaded.entityIds()[i])) << i;
    }
  }
}

TEST(SavedWorld, OnlyARestoredMovableBodyAtRestSleeps) {
  const auto refused = [](const std::string& entity) { return refusedField("preset: cube, " + entity); };
  EXPECT_EQ(refused("sleep: 2, velocity: [0, 0, 1]"), "entities[0].sleep");
  EXPECT_EQ(refused("sleep: 2, angular_velocity: [0, 1e-300, 0]"), "entities[0].sleep");
  EXPECT_EQ(refused("sleep: 2, static: true"), "entities[0].sleep");
  EXPECT_EQ(refused("sleep: -1"), "entities[0].sleep");
  EXPECT_EQ(refused("sleep: x"), "entities[0].sleep");
  EXPECT_EQ(refused("sleep: 1, repeat: {count: [2, 1, 1], spacing: [1, 0, 0]}"), "entities[0].sleep");
  EXPECT_EQ(refused("sleep: 2"), "accepted");
  EXPECT_EQ(refused("id: 5, repeat: {count: [2, 1, 1], spacing: [1, 0, 0]}"), "entities[0].id");
  EXPECT_EQ(refused("id: -1"), "entities[0].id");
  EXPECT_EQ(refused("id: 4294967295"), "entities[0].id");  // kInvalidEntity
  EXPECT_EQ(refused("id: 4294967294"), "accepted");
  EXPECT_EQ(refused("sleep: 0, velocity: [0, 0, 1]"), "accepted");
}


// Awake bodies in contact (a rockfall of 300 rocks after 120 ticks): the
// contacts carried between ticks, the warm start, the rest timers and the
// broad phase's pairs are in the file (contact_state), so the next 300 ticks
// are the saved world's, bit for bit, contacts included, at 1 and 2 threads.
// A rock despawned on the way puts the last entity in its place, and one
// spawned then takes its broad-phase slot: the ids are kept (`id`), so each
// pair's bodies still come in the same order, and the boxes go back in the
// order of their slots (slot_order), in which boxes entering a band are swept.
// `yaml` with the block of contact_state's `key` (its line and the rows
// under it) replaced by `block` (lines, each ending in a newline; "" drops it).
std::string withCarried(const std::string& yaml, const std::string& key, const std::string& block) {
  const std::size_t at = yaml.find("\n  " + key + ":", yaml.find("contact_state:"));
  EXPECT_NE(at, std::string::npos) << key;
  std::size_t end = yaml.find('\n', at + 1);
  while (end != std::string::npos && yaml.compare(end + 1, 4, "    ") == 0) end = yaml.find('\n', end + 1);
  return yaml.substr(0, at + 1) + block + (end == std::string::npos ? "" : yaml.substr(end + 1));
}

// The field a saved world is refused by, parsed and added to a new World
// (which then holds nothing), or "accepted".
std::string refusedWorldField(const std::string& yaml) {
  World world(meshConfig(1));
  try {
    addScene(world, parseSceneYaml(yaml));
  } catch (const InputError& e) {
    EXPECT_EQ(world.entityCount(), 0u) << e.what();
    return e.field();
  }
  return "accepted";
}

// `made` and `loaded` stepped side by side for 300 ticks at an unlimited
// budget: the same state bit for bit after each, and the same file after.
void expectGoesOnTheSame(World& made, World& loaded, double dt, const std::string& what) {
  int first_different = -1;
  for (int t = 0; t < 300; ++t) {
    made.step(dt, Budget::unlimited());
    loaded.step(dt, Budget::unlimited());
    if (first_different < 0 && !sameState(made, loaded)) first_different = t;
  }
  EXPECT_EQ(first_different, -1) << what << ": " << sameState(made, loaded).message() << "; 300 ticks later up to "
                                 << maxPositionGap(made, loaded) << " m apart";
  // What both carry on to the next tick is the same too.
  EXPECT_TRUE(writeSceneYaml(made) == writeSceneYaml(loaded)) << what;
}

// A rockfall of 300 rocks on `threads` threads.
SceneWorld rockfall300(int threads) {
  SceneParams params;
  params.entities = 300;
  WorldConfig config;
  config.threads = threads;
  return makeSceneWorld(SceneKind::Rockfall, params, config);
}

// Rock 400 (dense order) despawned and a twin of rock 500 spawned `above` it.
void despawnAndSpawn(World& world, double above) {
  ASSERT_TRUE(world.removeEntity(world.entityIds()[400]));
  EntitySpec rock;
  rock.shape = world.bodyShapes()[500];
  rock.pose.position = world.bodies()[500].pose.position + Vec3(0.0, 0.0, above);
  world.addEntity(rock);
}

TEST(SavedWorld, ATouchingWorldGoesOnTheSame) {
  for (int threads : {1, 2}) {
    SceneWorld made = rockfall300(threads);
    for (int t = 0; t < 120; ++t) {
      if (t == 60) despawnAndSpawn(made.world, 3.0);
      made.world.step(made.spec.dt, Budget::unlimited());
    }
    ASSERT_GT(made.world.contacts().size(), 100u);
    ASSERT_GT(made.world.entityIds()[400], made.world.entityIds()[401]);  // ids out of dense order
    World loaded = loadSaved(writeSceneYaml(made.world), made.world.config());
    expectGoesOnTheSame(made.world, loaded, made.spec.dt, std::to_string(threads) + " threads");
  }
}

// Saved between a despawn and a spawn and the next tick, as the node's ~save
// may fall: settleBroadPhase first (the node's save does it), and the loaded
// world goes on as the saved one.
TEST(SavedWorld, AWorldSavedBetweenASpawnAndTheNextTickGoesOnTheSame) {
  for (int threads : {1, 2}) {
    SceneWorld made = rockfall300(threads);
    for (int t = 0; t < 120; ++t) made.world.step(made.spec.dt, Budget::unlimited());
    despawnAndSpawn(made.world, 0.1);  // onto its twin: a pair at once
    EXPECT_EQ(writeSceneYaml(made.world).find("\n  boxes:"), std::string::npos) << "not settled: no broad phase";
    made.world.settleBroadPhase();
    const std::string yaml = writeSceneYaml(made.world);
    ASSERT_NE(yaml.find("\n  boxes:"), std::string::npos);
    World loaded = loadSaved(yaml, made.world.config());
    expectGoesOnTheSame(made.world, loaded, made.spec.dt, std::to_string(threads) + " threads");
  }
}

// A fracture that waits for its pieces' trees (the tick budget ran out) is
// carried and made at the loaded world's next tick, as at the saved one's.
TEST(SavedWorld, AFractureWaitingForItsTreesIsMadeAfterTheLoad) {
  const std::string yaml0 = R"(
gravity: [0, 0, -9.81]
entities:
  - {name: floor, preset: plate, resolution: 40, voxel_size: 0.1, position: [0, 0, -0.05], static: true}
  - {name: rock, preset: rock, resolution: 8, voxel_size: 0.05, seed: 3, position: [0, 0, 0.5],
     velocity: [1, 0, -12], angular_velocity: [0, 3, 0], density: 2600, strength: 1}
)";
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  World world(config);
  addScene(world, parseSceneYaml(yaml0));
  double now = 0.0;
  world.setClock([&now] { return now += 1e-3; });  // every read a millisecond later
  int deferred = -1;
  for (int t = 0; t < 120 && deferred < 0; ++t) {
    // A budget the fixed phases alone overrun: the break waits for its trees.
    if (world.step(1.0 / 60.0, Budget::ofTickSeconds(1e-4)).fracture.fractures_deferred > 0) deferred = t;
  }
  ASSERT_GE(deferred, 0) << "nothing broke";
  ASSERT_TRUE(world.findByName("rock").has_value());
  const std::string yaml = writeSceneYaml(world);
  ASSERT_NE(yaml.find("\n  breaks:\n    - [1, "), std::string::npos) << yaml.substr(yaml.find("contact_state:"));
  World loaded = loadSaved(yaml, world.config());
  const TickReport saved_next = world.step(1.0 / 60.0, Budget::unlimited());
  const TickReport loaded_next = loaded.step(1.0 / 60.0, Budget::unlimited());
  EXPECT_EQ(saved_next.fracture.fractures, 1u);
  EXPECT_EQ(loaded_next.fracture.fractures, 1u);
  EXPECT_FALSE(loaded.findByName("rock").has_value());
  EXPECT_TRUE(loaded.findByName("rock/piece0").has_value());
  EXPECT_TRUE(sameState(world, loaded)) << sameState(world, loaded).message();
  expectGoesOnTheSame(world, loaded, 1.0 / 60.0, "after the break");

  // Refused by field: a static body (the floor), a plane that is not one, a
  // body queued twice, a body the world does not hold.
  const std::pair<const char*, const char*> refusals[] = {
      {"    - [0, 0, 0, 0, 1, 0, 0]\n", "contact_state.breaks[0].body"},
      {"    - [1, 0, 0, 0, 0, 0, 0]\n", "contact_state.breaks[0]"},
      {"    - [1, 0, 0, 0, 1, 0, 0]\n    - [1, 0, 0, 0, 0, 1, 0]\n", "contact_state.breaks[1].body"},
      {"    - [2, 0, 0, 0, 1, 0, 0]\n", "contact_state.breaks[0].body"},
  };
  for (const auto& [rows, field] : refusals) {
    EXPECT_EQ(refusedWorldField(withCarried(yaml, "breaks", std::string("  breaks:\n") + rows)), field) << rows;
  }
}

// A malformed contact_state is refused by the field, and the entities its
// file added are removed again.
TEST(SavedWorld, ABadContactStateIsRefusedByField) {
  World world = mixedWorld(meshConfig(1));
  for (int t = 0; t < 20; ++t) world.step(1.0 / 60.0, Budget::unlimited());
  ASSERT_FALSE(world.contacts().empty());
  const std::string yaml = writeSceneYaml(world);
  ASSERT_NE(yaml.find("\n  warm:\n"), std::string::npos);
  EXPECT_EQ(refusedWorldField(yaml), "accepted");
  const std::string row16 = "[9, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]";
  const std::string floor_row = "[0" + row16.substr(2);
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "next_group", "  next_group: 0\n")), "contact_state.next_group");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "rest", "  rest:\n    - [1, 0, 0]\n")), "contact_state.rest[0]");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "rest", "  rest:\n    - " + row16 + "\n")),
            "contact_state.rest[0].body");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "rest", "  rest:\n    - " + floor_row + "\n")),
            "contact_state.rest[0].body");  // the floor: static
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "banding", "  banding: [0, 0, 0, 1, 1, 1, 0.5, 0, 0, 7]\n")),
            "contact_state.banding");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "band_order", "  band_order: [[[]], [[]], [[]]]\n")),
            "contact_state.banding");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "band_order", "  band_order: [[], []]\n")),
            "contact_state.band_order");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "boxes", "  boxes: []\n")), "contact_state.boxes");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "broad_pairs", "  broad_pairs: [0]\n")), "contact_state.broad_pairs");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "broad_pairs", "  broad_pairs: []\n")), "contact_state.broad_pairs");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "carried_points", "  carried_points: []\n")),
            yaml.find("\n  carried: []") == std::string::npos ? "contact_state.carried" : "accepted");
  // A carried entry's leaf pair names nodes of the two bodies' trees.
  EXPECT_EQ(refusedWorldField(withCarried(withCarried(yaml, "carried_points", "  carried_points: []\n"), "carried",
                                          "  carried:\n    - [0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 100000, 0, 0, 0]\n")),
            "contact_state.carried[0].leaf");
  EXPECT_EQ(refusedWorldField(withCarried(withCarried(yaml, "carried_points", "  carried_points: []\n"), "carried",
                                          "  carried:\n    - [0, 1, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0]\n")),
            "accepted");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "warm_points", "  warm_points: []\n")), "contact_state.warm");
  EXPECT_EQ(refusedWorldField(withCarried(withCarried(yaml, "warm_points", "  warm_points: []\n"), "warm",
                                          "  warm:\n    - [1, 1, 0, 0, 0, 0, 0]\n")),
            "contact_state.warm[0]");  // a body with itself
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "warm", "  warm:\n    - [0, 1, 0, 0, 0, 0, 33]\n")),
            "contact_state.warm[0].points");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "next_group", "  next_group: 1\n  extra: 1\n")),
            "contact_state.extra");
  // Saved before the first tick, or between a spawn and the next tick, without
  // settleBroadPhase: the broad phase starts afresh (no boxes written), the
  // rest is carried.
  World fresh = mixedWorld(meshConfig(1));
  const std::string unstepped = writeSceneYaml(fresh);
  EXPECT_EQ(unstepped.find("\n  boxes:"), std::string::npos);
  EXPECT_EQ(refusedWorldField(unstepped), "accepted");
  EntitySpec spawn;
  spawn.shape = world.bodyShapes()[1];
  spawn.pose.position = Vec3(2.0, 2.0, 1.0);
  world.addEntity(spawn);
  const std::string spawned = writeSceneYaml(world);
  EXPECT_EQ(spawned.find("\n  boxes:"), std::string::npos);
  EXPECT_NE(spawned.find("\n  warm:\n"), std::string::npos);
  EXPECT_EQ(refusedWorldField(spawned), "accepted");
  EXPECT_EQ(refusedWorldField(withCarried(unstepped, "next_group", "  next_group: 1\n  broad_pairs: []\n")),
            "contact_state.broad_pairs");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "band_order", "")), "contact_state.band_order");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "slot_order", "  slot_order: [0, 0, 1, 2, 3, 4, 5]\n")),
            "contact_state.banding");
  EXPECT_EQ(refusedWorldField(withCarried(yaml, "slot_order", "  slot_order: [6, 5, 4, 3, 2, 1, 0]\n")),
            "accepted");  // any order of the boxes
  // A saved world's state goes into a world that holds nothing yet.
  World busy = mixedWorld(meshConfig(1));
  try {
    addScene(busy, parseSceneYaml(yaml));
    ADD_FAILURE() << "loaded into a world with entities";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "contact_state");
  }
}

}  // namespace
