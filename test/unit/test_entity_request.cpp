// The one request path of the spawn topic, ~spawn and scene files
// (entity_request.hpp): fields left at 0 where 0 means nothing take their
// documented defaults (issue 50), and every request is validated whole before
// any shape cache is asked (issue 47): a cached shape lets no bad field
// through, and control bytes in strings are refused by field.
#include "mesh_files.hpp"
#include "mesh_generators.hpp"
#include "temp_dir.hpp"
#include "thrown_field.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/scene/entity_request.hpp"
#include "sphere_tree_collision/scene/scene_file.hpp"
#include "sphere_tree_collision/ros/tick_clock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace stc_ros {
namespace {

using namespace stc;  // the request path (scene/) is ROS-free

using sphere_tree_collision::SpawnEntity;
using stc::thrownField;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// The README's shortest spawn: {name: 'r1', preset: 'rock', pose: {position: {z: 2}}}.
SpawnEntity shortestRock() {
  SpawnEntity m;
  m.name = "r1";
  m.preset = "rock";
  m.pose.position.z = 2.0;
  return m;
}

// The same rock, named `name`, with every field given.
SpawnEntity givenRock(const std::string& name, std::uint32_t resolution, double voxel_size, double density) {
  SpawnEntity m = shortestRock();
  m.name = name;
  m.resolution = resolution;
  m.voxel_size = voxel_size;
  m.density = density;
  m.pose.orientation.w = 1.0;
  return m;
}

const stc::BodyState& bodyOf(const stc::World& world, stc::EntityId id) { return world.bodies()[*world.indexOf(id)]; }
const std::string& shapeKeyOf(const stc::World& world, stc::EntityId id) {
  return world.shape(world.bodyShapes()[*world.indexOf(id)]).key;
}

TEST(RequestDefaults, TheShortestSpawnTakesEachDefault) {
  stc::World world;
  const stc::EntityId id = addRequest(world, toEntityRequest(shortestRock()));
  const stc::BodyState& body = bodyOf(world, id);
  EXPECT_EQ(shapeKeyOf(world, id), "rock/r8/v0.05/s0");  // resolution 8, voxel_size 0.05
  EXPECT_TRUE(body.pose.orientation.coeffs().isApprox(stc::Quat::Identity().coeffs()));
  EXPECT_EQ(body.pose.position, stc::Vec3(0, 0, 2));
  // restitution and friction 0 are real values, not defaults.
  EXPECT_EQ(body.material.restitution, 0.0);
  EXPECT_EQ(body.material.friction, 0.0);

  // The same rock with every field given: the same shape, the same mass (density 1000).
  const stc::EntityId full_id = addRequest(world, toEntityRequest(givenRock("r1_full", 8, 0.05, 1000.0)));
  EXPECT_EQ(world.bodyShapes()[*world.indexOf(full_id)], world.bodyShapes()[*world.indexOf(id)]);
  EXPECT_EQ(bodyOf(world, full_id).inv_mass, bodyOf(world, id).inv_mass);
}

// Not the package's defaults: a node started with other ~default_* parameters.
const RequestDefaults kOtherDefaults{6, 500.0, 0.1};

TEST(RequestDefaults, TheNodesDefaultsAreTheOnesTaken) {
  const RequestDefaults& defaults = kOtherDefaults;
  stc::World world;
  const stc::EntityId id = addRequest(world, toEntityRequest(shortestRock()), defaults);
  EXPECT_EQ(shapeKeyOf(world, id), "rock/r6/v0.1/s0");
  const stc::EntityId full_id = addRequest(world, toEntityRequest(givenRock("r1_full", 6, 0.1, 500.0)));
  EXPECT_EQ(bodyOf(world, full_id).inv_mass, bodyOf(world, id).inv_mass);
}

TEST(RequestDefaults, ASceneFileLeavingFieldsOutOrAtZeroAgreesWithTheTopic) {
  const RequestDefaults& defaults = kOtherDefaults;
  const Scene scene = parseSceneYaml(
      "entities:\n"
      "  - {name: left_out, preset: rock, position: [0, 0, 2]}\n"
      "  - {name: zeros, preset: rock, position: [1, 0, 2], resolution: 0, voxel_size: 0, density: 0,\n"
      "     orientation: {quat: [0, 0, 0, 0]}}\n");
  stc::World world;
  const std::vector<stc::EntityId> ids = addScene(world, scene, defaults);
  const stc::EntityId topic = addRequest(world, toEntityRequest(shortestRock()), defaults);
  for (const stc::EntityId id : ids) {
    EXPECT_EQ(shapeKeyOf(world, id), "rock/r6/v0.1/s1");  // a scene's seed defaults to 1
    EXPECT_EQ(bodyOf(world, id).inv_mass, bodyOf(world, ids[0]).inv_mass);
    EXPECT_TRUE(bodyOf(world, id).pose.orientation.coeffs().isApprox(stc::Quat::Identity().coeffs()));
  }
  EXPECT_EQ(shapeKeyOf(world, topic), "rock/r6/v0.1/s0");
}

TEST(RequestDefaults, NegativeAndNotFiniteValuesAreStillRefusedByField) {
  stc::World world;
  const auto field_of = [&world](const std::function<void(SpawnEntity&)>& edit) {
    SpawnEntity m = shortestRock();
    edit(m);
    return thrownField([&] { addRequest(world, toEntityRequest(m)); });
  };
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.density = -1.0; }), "density");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.density = kNaN; }), "density");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.density = kInf; }), "density");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.voxel_size = -0.05; }), "voxel_size");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.voxel_size = kNaN; }), "voxel_size");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.voxel_size = -kInf; }), "voxel_size");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.resolution = 100000; }), "resolution");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.pose.orientation.x = 0.5; }), "pose.orientation");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.pose.orientation.w = kNaN; }), "pose.orientation");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.restitution = -0.1; }), "material.restitution");
  EXPECT_EQ(field_of([](SpawnEntity& m) { m.friction = -0.5; }), "material.friction");
  // An explicit grid has no default size: 0 is refused.
  EXPECT_EQ(field_of([](SpawnEntity& m) {
              m.preset.clear();
              m.dims = {1, 1, 1};
              m.occupancy = {1};
            }),
            "voxel_size");
  EXPECT_EQ(world.entityCount(), 0u);
  // Scene files say the same.
  const auto scene_field = [&world](const std::string& entry) {
    return thrownField([&] { addScene(world, parseSceneYaml("entities:\n  - " + entry + "\n")); });
  };
  EXPECT_EQ(scene_field("{preset: rock, density: -1}"), "entities[0].density");
  EXPECT_EQ(scene_field("{preset: rock, voxel_size: -0.05}"), "entities[0].voxel_size");
  EXPECT_EQ(scene_field("{preset: rock, voxel_size: .nan}"), "entities[0].voxel_size");
  EXPECT_EQ(scene_field("{preset: rock, orientation: {quat: [0, 0, 0, 0.5]}}"), "entities[0].orientation");
  EXPECT_EQ(world.entityCount(), 0u);
}

class CachedMesh : public ::testing::Test {
 protected:
  void SetUp() override { stc::truth::writeStlBinary(stc::truth::cubeMesh(0.4), path_); }
  SpawnEntity mesh(double voxel_size) const {
    SpawnEntity m;
    m.mesh_resource = path_;
    m.resolution = 10;
    m.voxel_size = voxel_size;
    return m;
  }
  // Plain paths are read only under ~mesh_roots: here the test's folder.
  stc::WorldConfig config() const {
    stc::WorldConfig c;
    c.mesh_roots = stc::canonicalMeshRoots({dir_.path()});
    return c;
  }
  stc::truth::TempDir dir_;
  std::string path_ = dir_.file("cube.stl");
};

// Issue 47 item 1: a mesh's shape key ignores a voxel_size that is not > 0, so
// the cache answered before anything validated. Refused by field, whether the
// shape is cached (after a valid spawn) or not (sent first).
TEST_F(CachedMesh, ABadVoxelSizeIsRefusedWhetherTheShapeIsCachedOrNot) {
  for (const bool cached : {false, true}) {
    SCOPED_TRACE(cached ? "cached" : "not cached");
    stc::World world(config());
    if (cached) ASSERT_NE(addRequest(world, toEntityRequest(mesh(0.0))), stc::kInvalidEntity);
    const std::size_t before = world.entityCount();
    for (const double bad : {-0.05, kNaN, -kInf, kInf}) {
      EXPECT_EQ(thrownField([&] { addRequest(world, toEntityRequest(mesh(bad))); }), "voxel_size") << bad;
    }
    EXPECT_EQ(world.entityCount(), before);
  }
}

// Issue 47 item 2: a NUL (or another control byte) would cut the path; refused by field,
// cached or not; the same in a scene file.
TEST_F(CachedMesh, ControlBytesInStringsAreRefusedByField) {
  for (const bool cached : {false, true}) {
    SCOPED_TRACE(cached ? "cached" : "not cached");
    stc::World world(config());
    if (cached) ASSERT_NE(addRequest(world, toEntityRequest(mesh(0.0))), stc::kInvalidEntity);
    const std::size_t before = world.entityCount();
    for (const std::string tail : {std::string(1, '\0') + ".obj", std::string("\n"), std::string("\x7f")}) {
      SpawnEntity m = mesh(0.0);
      m.mesh_resource = path_ + tail;
      EXPECT_EQ(thrownField([&] { addRequest(world, toEntityRequest(m)); }), "mesh_resource");
    }
    SpawnEntity preset = shortestRock();
    preset.preset = std::string("rock") + '\0';
    EXPECT_EQ(thrownField([&] { addRequest(world, toEntityRequest(preset)); }), "preset");
    EXPECT_EQ(world.entityCount(), before);
  }
  stc::World world;
  EXPECT_EQ(thrownField([&] {
              addScene(world, parseSceneYaml("entities:\n  - {mesh_resource: \"" + path_ + "\\0.obj\"}\n"));
            }),
            "entities[0].mesh_resource");
  EXPECT_EQ(thrownField([&] { loadSceneYaml(path_ + '\0' + ".yaml"); }), "scene");
}

// Issue 47 item 3: the guard of gaze stamps and ~spawn's tf stamp, in doubles.
TEST(StampAge, TheEndOfTimeIsRefusedAsHeaderStampNotAsADurationOverflow) {
  const ros::Time now(1765000000, 0);
  const ros::Time end(4294967295u, 999999999u);
  EXPECT_EQ(thrownField([&] { checkedStampAge(end, now, 10.0, 5.0, "limit"); }), "header.stamp");
  EXPECT_EQ(thrownField([&] { checkedStampAge(ros::Time(1, 0), now, 10.0, 5.0, "limit"); }), "header.stamp");
  EXPECT_EQ(checkedStampAge(ros::Time(0, 0), now, 10.0, 5.0, "limit"), 0.0);  // zero: now
  EXPECT_DOUBLE_EQ(checkedStampAge(ros::Time(1764999998, 0), now, 10.0, 5.0, "limit"), 2.0);
  EXPECT_DOUBLE_EQ(checkedStampAge(ros::Time(1765000004, 0), now, 10.0, 5.0, "limit"), -4.0);
}

}  // namespace
}  // namespace stc_ros
