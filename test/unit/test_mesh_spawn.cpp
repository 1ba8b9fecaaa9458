// Meshes spawned through the ROS glue (issue 14 item 1): a scene file entry
// and a SpawnEntity message naming a mesh_resource and a scale add an entity
// whose shape is the voxelised mesh, cached by resource, scale and resolution;
// bad resources are rejected naming the field.
#include "mesh_files.hpp"
#include "mesh_generators.hpp"
#include "temp_dir.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/ros/entity_request.hpp"
#include "sphere_tree_collision/ros/mesh_resource.hpp"
#include "sphere_tree_collision/ros/scene_file.hpp"

#include <gtest/gtest.h>
#include <ros/package.h>

#include <cstdlib>
#include <functional>
#include <string>

namespace stc_ros {
namespace {

class MeshSpawn : public ::testing::Test {
 protected:
  void SetUp() override { stc::truth::writeStlBinary(stc::truth::cubeMesh(0.4), path_); }
  stc::truth::TempDir dir_;
  std::string path_ = dir_.file("cube.stl");
};

TEST_F(MeshSpawn, SceneFileEntriesShareTheMeshShape) {
  const Scene scene = parseSceneYaml("entities:\n"
                                     "  - {name: a, mesh_resource: 'file://" + path_ +
                                     "', scale: [1, 1, 0.5], resolution: 8, position: [0, 0, 1]}\n"
                                     "  - {name: b, mesh_resource: 'file://" + path_ +
                                     "', scale: [1, 1, 0.5], resolution: 8, position: [2, 0, 1]}\n");
  stc::World world;
  const std::vector<stc::EntityId> ids = addScene(world, scene);
  ASSERT_EQ(ids.size(), 2u);
  const stc::ShapeId shape = world.bodyShapes()[0];
  EXPECT_EQ(world.bodyShapes()[1], shape);  // one shape, one tree
  const stc::VoxelShape& v = world.shape(shape).voxels;
  EXPECT_EQ(v.nx(), 8);
  EXPECT_EQ(v.nz(), 4);  // scaled to 0.2 m: 4 voxels of 0.05 m
  EXPECT_EQ(v.occupiedCount(), 8 * 8 * 4);
  EXPECT_EQ(world.shape(shape).key.rfind("mesh:", 0), 0u) << world.shape(shape).key;
}

TEST(ShippedMeshScene, LoadsByPackageResourceAndTheLinkComesToRestOnTheScan) {
  // config/meshes.yaml (README's picture): meshes named package://, resolved
  // from the source tree the tests run in when no ROS environment says where.
  if (ros::package::getPath("sphere_tree_collision").empty()) ::setenv("ROS_PACKAGE_PATH", ".", 1);
  const Scene scene = loadSceneYaml("config/meshes.yaml");
  stc::WorldConfig config;
  config.gravity = scene.gravity;
  stc::World world(config);
  const std::vector<stc::EntityId> ids = addScene(world, scene);
  ASSERT_EQ(ids.size(), 3u);
  const auto link = world.findByName("link"), scan = world.findByName("scan");
  ASSERT_TRUE(link && scan);
  for (const auto id : {*link, *scan}) {
    const stc::ShapeInfo& shape = world.shape(world.bodyShapes()[*world.indexOf(id)]);
    EXPECT_EQ(shape.key.rfind("mesh:", 0), 0u) << shape.key;
    EXPECT_GT(shape.voxels.occupiedCount(), 0);
  }
  for (int t = 0; t < 240; ++t) world.step(1.0 / 60.0, stc::Budget::unlimited());  // 4 s
  const stc::BodyState& l = world.bodies()[*world.indexOf(*link)];
  const stc::BodyState& c = world.bodies()[*world.indexOf(*scan)];
  EXPECT_GT(l.pose.position.z(), 0.0);            // on the floor or the scan, not through
  EXPECT_GT(c.pose.position.z(), 0.0);
  EXPECT_LT(l.linear_velocity.norm(), 0.05);      // at rest
  EXPECT_LT(c.linear_velocity.norm(), 0.05);
}

TEST_F(MeshSpawn, SceneFileRejectsAMeshWithAPresetOrAScaleWithoutAMesh) {
  try {
    parseSceneYaml("entities:\n  - {preset: cube, mesh_resource: '" + path_ + "'}\n");
    FAIL() << "accepted";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "entities[0].mesh_resource");
  }
  try {
    parseSceneYaml("entities:\n  - {preset: cube, scale: [1, 1, 1]}\n");
    FAIL() << "accepted";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "entities[0].scale");
  }
}

// Not a mesh feature, but a scene file's: a one-sided static floor
// (static_cover.hpp), its closed faces named in the body frame.
TEST(SceneFileClosedFaces, AStaticEntryClosesTheNamedFacesAndBadOnesAreRejectedByName) {
  const Scene scene = parseSceneYaml(
      "entities:\n  - {preset: plate, static: true, closed_faces: [-z, +x], position: [0, 0, -0.1]}\n");
  stc::World world;
  ASSERT_EQ(addScene(world, scene).size(), 1u);
  EXPECT_EQ(scene.entities[0].request.spec.closed_faces, stc::faceBit(2, false) | stc::faceBit(0, true));
  const auto field_of = [](const std::string& yaml) -> std::string {
    try {
      stc::World w;
      addScene(w, parseSceneYaml(yaml));
    } catch (const stc::InputError& e) {
      return e.field();
    }
    return "accepted";
  };
  EXPECT_EQ(field_of("entities:\n  - {preset: plate, static: true, closed_faces: [down]}\n"),
            "entities[0].closed_faces");
  EXPECT_EQ(field_of("entities:\n  - {preset: plate, static: true, closed_faces: -z}\n"),
            "entities[0].closed_faces");
  EXPECT_EQ(field_of("entities:\n  - {preset: cube, closed_faces: [-z]}\n"), "entities[0].closed_faces")
      << "a movable body's faces move apart: only static bodies close faces";
}

TEST(SpawnClosedFaces, AStaticSpawnClosesTheNamedFacesAndBadOnesAreRejectedByName) {
  sphere_tree_collision::SpawnEntity msg;
  msg.preset = "plate";
  msg.voxel_size = 0.05;
  msg.density = 1000.0;
  msg.pose.orientation.w = 1.0;
  msg.is_static = true;
  msg.closed_faces = {"-z"};
  stc::World world;
  EXPECT_EQ(toEntityRequest(msg).spec.closed_faces, stc::faceBit(2, false));
  ASSERT_NE(addRequest(world, toEntityRequest(msg)), stc::kInvalidEntity);
  const auto field_of = [&world](const sphere_tree_collision::SpawnEntity& m) -> std::string {
    try {
      addRequest(world, toEntityRequest(m));
    } catch (const stc::InputError& e) {
      return e.field();
    }
    return "accepted";
  };
  sphere_tree_collision::SpawnEntity bad = msg;
  bad.closed_faces = {"-z", "bottom"};
  EXPECT_EQ(field_of(bad), "closed_faces");
  bad = msg;
  bad.is_static = false;
  EXPECT_EQ(field_of(bad), "closed_faces") << "only static bodies close faces";
  EXPECT_EQ(world.entityCount(), 1u) << "a rejected spawn adds nothing";
}

TEST_F(MeshSpawn, SpawnMessageWithAMeshAddsItScaled) {
  sphere_tree_collision::SpawnEntity msg;
  msg.mesh_resource = path_;
  msg.scale.x = 0.5;
  msg.scale.y = 0.5;
  msg.scale.z = 0.5;
  msg.voxel_size = 0.05;
  msg.density = 1000.0;
  msg.pose.orientation.w = 1.0;
  stc::World world;
  const stc::EntityId id = addRequest(world, toEntityRequest(msg));
  ASSERT_NE(id, stc::kInvalidEntity);
  const stc::VoxelShape& v = world.shape(world.bodyShapes()[0]).voxels;
  EXPECT_EQ(v.occupiedCount(), 4 * 4 * 4);  // 0.2 m cube at 0.05 m

  msg.preset = "cube";
  try {
    toEntityRequest(msg);
    FAIL() << "accepted a mesh and a preset";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "mesh_resource");
  }
}

TEST_F(MeshSpawn, ADaeUpAxisIsAsWrittenUnlessZUpIsAsked) {
  // A Y_UP box 0.2 x 0.4 x 0.6 m: as written (rviz) its long side is z; with
  // up_axis z_up the file's y becomes z, so the long side lies along y.
  const std::string dae = dir_.file("box_y_up.dae");
  stc::truth::writeDae(stc::truth::boxMesh(stc::Vec3::Zero(), stc::Vec3(0.2, 0.4, 0.6)), dae, "Y_UP");
  sphere_tree_collision::SpawnEntity msg;
  msg.mesh_resource = "file://" + dae;
  msg.voxel_size = 0.05;
  msg.density = 1000.0;
  msg.pose.orientation.w = 1.0;
  stc::World world;
  addRequest(world, toEntityRequest(msg));
  msg.up_axis = "z_up";
  msg.pose.position.x = 2.0;
  addRequest(world, toEntityRequest(msg));
  const stc::VoxelShape& as_written = world.shape(world.bodyShapes()[0]).voxels;
  const stc::VoxelShape& turned = world.shape(world.bodyShapes()[1]).voxels;
  EXPECT_EQ(as_written.nz(), 12);
  EXPECT_EQ(turned.ny(), 12);
  EXPECT_EQ(turned.nz(), 8);
  EXPECT_EQ(as_written.occupiedCount(), turned.occupiedCount());

  // The scene file says the same; bad values are refused by name.
  const Scene scene = parseSceneYaml("entities:\n  - {mesh_resource: '" + dae +
                                     "', voxel_size: 0.05, up_axis: z_up}\n");
  ASSERT_EQ(scene.entities.size(), 1u);
  EXPECT_EQ(scene.entities[0].request.mesh_up_axis, stc::ColladaUpAxis::ToZUp);
  const auto field_of = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const stc::InputError& e) {
      return e.field();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(field_of([&] { parseSceneYaml("entities:\n  - {mesh_resource: '" + dae + "', up_axis: sideways}\n"); }),
            "entities[0].up_axis");
  EXPECT_EQ(field_of([&] { parseSceneYaml("entities:\n  - {preset: cube, up_axis: z_up}\n"); }),
            "entities[0].up_axis");
  msg.up_axis = "sideways";
  EXPECT_EQ(field_of([&] { toEntityRequest(msg); }), "up_axis");
  msg.mesh_resource.clear();
  msg.preset = "cube";
  msg.up_axis = "z_up";
  EXPECT_EQ(field_of([&] { toEntityRequest(msg); }), "up_axis");
}

TEST_F(MeshSpawn, PackageResourcesOfUnknownPackagesAreRejected) {
  EXPECT_EQ(resolveMeshResource(path_), path_);
  EXPECT_EQ(resolveMeshResource("file://" + path_), "file://" + path_);
  for (const std::string bad : {"package://no_such_package_xyz/meshes/a.stl", "package://only_a_name"}) {
    try {
      resolveMeshResource(bad);
      FAIL() << bad;
    } catch (const stc::InputError& e) {
      EXPECT_EQ(e.field(), "mesh_resource");
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST_F(MeshSpawn, AnOpenMeshIsRejectedAndNothingIsAdded) {
  stc::TriangleMesh sheet;
  sheet.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0.1}};
  sheet.triangles = {{0, 1, 2}};
  const std::string sheet_path = dir_.file("sheet.obj");
  stc::truth::writeObj(sheet, sheet_path);
  EntityRequest r;
  r.mesh_resource = sheet_path;
  r.spec.density = 1000.0;
  stc::World world;
  try {
    addRequest(world, r);
    FAIL() << "accepted an open sheet";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "mesh");
    EXPECT_NE(std::string(e.what()).find(sheet_path), std::string::npos) << e.what();
  }
  EXPECT_EQ(world.entityCount(), 0u);
}

}  // namespace
}  // namespace stc_ros
