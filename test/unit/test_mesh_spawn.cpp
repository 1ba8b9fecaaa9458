// Meshes spawned through the ROS glue (issue 14 item 1): a scene file entry
// and a SpawnEntity message naming a mesh_resource and a scale add an entity
// whose shape is the voxelised mesh, cached by resource, scale and resolution;
// bad resources are rejected naming the field.
#include "mesh_files.hpp"
#include "mesh_generators.hpp"
#include "temp_dir.hpp"

#include "sphere_tree_collision/ros/conversions.hpp"
#include "sphere_tree_collision/scene/entity_request.hpp"
#include "sphere_tree_collision/ros/mesh_resource.hpp"
#include "sphere_tree_collision/scene/scene_file.hpp"

#include <gtest/gtest.h>
#include <ros/package.h>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

namespace stc_ros {
namespace {

using namespace stc;  // the request path (scene/) is ROS-free

class MeshSpawn : public ::testing::Test {
 protected:
  void SetUp() override { stc::truth::writeStlBinary(stc::truth::cubeMesh(0.4), path_); }
  // file:// and plain paths are read only under ~mesh_roots: here the test's folder.
  stc::WorldConfig config() const {
    stc::WorldConfig c;
    c.mesh_roots = stc::canonicalMeshRoots({dir_.path()});
    return c;
  }
  stc::truth::TempDir dir_;
  std::string path_ = dir_.file("cube.stl");
};

TEST_F(MeshSpawn, SceneFileEntriesShareTheMeshShape) {
  const Scene scene = parseSceneYaml("entities:\n"
                                     "  - {name: a, mesh_resource: 'file://" + path_ +
                                     "', scale: [1, 1, 0.5], resolution: 8, position: [0, 0, 1]}\n"
                                     "  - {name: b, mesh_resource: 'file://" + path_ +
                                     "', scale: [1, 1, 0.5], resolution: 8, position: [2, 0, 1]}\n");
  stc::World world(config());
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
  const std::vector<stc::EntityId> ids = addScene(world, scene, {}, resolveMeshResource);
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
  // Judged where every request is (stc::validateRequest), when the scene is added.
  stc::World world(config());
  try {
    addScene(world, parseSceneYaml("entities:\n  - {preset: cube, mesh_resource: '" + path_ + "'}\n"));
    FAIL() << "accepted";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "entities[0].mesh_resource");
  }
  try {
    addScene(world, parseSceneYaml("entities:\n  - {preset: cube, scale: [1, 1, 1]}\n"));
    FAIL() << "accepted";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "entities[0].scale");
  }
  EXPECT_EQ(world.entityCount(), 0u);
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
  stc::World world(config());
  const stc::EntityId id = addRequest(world, toEntityRequest(msg));
  ASSERT_NE(id, stc::kInvalidEntity);
  const stc::VoxelShape& v = world.shape(world.bodyShapes()[0]).voxels;
  EXPECT_EQ(v.occupiedCount(), 4 * 4 * 4);  // 0.2 m cube at 0.05 m

  msg.preset = "cube";
  try {
    addRequest(world, toEntityRequest(msg));
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
  stc::World world(config());
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
  const std::size_t entities = world.entityCount();
  EXPECT_EQ(field_of([&] { addScene(world, parseSceneYaml("entities:\n  - {preset: cube, up_axis: z_up}\n")); }),
            "entities[0].up_axis");
  msg.up_axis = "sideways";
  EXPECT_EQ(field_of([&] { toEntityRequest(msg); }), "up_axis");
  msg.mesh_resource.clear();
  msg.preset = "cube";
  msg.up_axis = "z_up";
  EXPECT_EQ(field_of([&] { addRequest(world, toEntityRequest(msg)); }), "up_axis");
  EXPECT_EQ(world.entityCount(), entities);
}

TEST_F(MeshSpawn, PackageResourcesOfUnknownPackagesAreRejected) {
  const std::vector<std::string> roots = config().mesh_roots;
  const std::string real = std::filesystem::canonical(path_).string();
  EXPECT_EQ(resolveMeshResource(path_, roots), real);
  EXPECT_EQ(resolveMeshResource("file://" + path_, roots), real);
  for (const std::string bad : {"package://no_such_package_xyz/meshes/a.stl", "package://only_a_name"}) {
    try {
      resolveMeshResource(bad, roots);
      FAIL() << bad;
    } catch (const stc::InputError& e) {
      EXPECT_EQ(e.field(), "mesh_resource");
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

// Issue 47 item 2: a file:// URI or a path is read only under ~mesh_roots
// (`..` and symlinks resolved first); package:// always resolves, within its
// package. A refused path gets the same words whether its file exists or not.
TEST_F(MeshSpawn, FilePathsAreReadOnlyUnderTheMeshRoots) {
  if (ros::package::getPath("sphere_tree_collision").empty()) ::setenv("ROS_PACKAGE_PATH", ".", 1);
  const std::vector<std::string> roots = config().mesh_roots;
  stc::truth::TempDir outside;
  const std::string secret = outside.file("secret.stl");
  stc::truth::writeStlBinary(stc::truth::cubeMesh(0.4), secret);
  const std::string link = dir_.file("link.stl");  // inside the roots, leading out
  std::filesystem::create_symlink(secret, link);
  const std::string sub = dir_.file("sub");
  std::filesystem::create_directory(sub);
  // The reason of a refusal, the resource named in it replaced by "R".
  const auto refusal = [](const std::string& resource, const std::vector<std::string>& r) -> std::string {
    try {
      resolveMeshResource(resource, r);
    } catch (const stc::InputError& e) {
      EXPECT_EQ(e.field(), "mesh_resource") << e.what();
      std::string what = e.what();
      const std::size_t at = what.find(resource);
      EXPECT_NE(at, std::string::npos) << what << " names the resource as given";
      return at == std::string::npos ? what : what.replace(at, resource.size(), "R");
    }
    return "accepted";
  };
  const std::string words = refusal(secret, roots);
  EXPECT_NE(words, "accepted");
  EXPECT_EQ(words.find(outside.path()), std::string::npos) << words;
  for (const std::string& bad :
       {outside.path() + "/missing.stl", "file://" + secret, link, "file://" + link, dir_.path() + "/../" +
        std::filesystem::path(outside.path()).filename().string() + "/secret.stl",
        sub + "/../../" + std::filesystem::path(outside.path()).filename().string() + "/secret.stl",
        dir_.path() + "/missing.stl", sub + "/missing/../../cube.stl"}) {
    EXPECT_EQ(refusal(bad, roots), words) << bad;
  }
  EXPECT_EQ(refusal(path_, {}), refusal(outside.path() + "/missing.stl", {})) << "no roots: no file is read";
  EXPECT_NE(refusal(path_, {}).find("only package://"), std::string::npos) << refusal(path_, {});
  EXPECT_EQ(resolveMeshResource(sub + "/../cube.stl", roots), std::filesystem::canonical(path_).string());
  // package:// with no roots; a `..` that leads out of the package is refused.
  EXPECT_NO_THROW(resolveMeshResource("package://sphere_tree_collision/meshes/bumpy_scan.stl", {}));
  EXPECT_NO_THROW(resolveMeshResource("package://sphere_tree_collision/meshes/../meshes/bumpy_scan.stl", {}));
  for (const std::string bad : {"package://sphere_tree_collision/../x/meshes/a.stl",
                                "package://sphere_tree_collision/meshes/../../../etc/hostname.stl",
                                "package://sphere_tree_collision//etc/hostname.stl"}) {
    EXPECT_NE(refusal(bad, {}), "accepted") << bad;
  }
  // Through a spawn: refused by field, nothing added.
  stc::World world(config());
  sphere_tree_collision::SpawnEntity msg;
  msg.mesh_resource = "file://" + link;
  msg.voxel_size = 0.05;
  msg.pose.orientation.w = 1.0;
  EXPECT_EQ(refusal(msg.mesh_resource, world.config().mesh_roots), words);
  try {
    addRequest(world, toEntityRequest(msg));
    ADD_FAILURE() << "read a file outside the roots";
  } catch (const stc::InputError& e) {
    EXPECT_EQ(e.field(), "mesh_resource");
  }
  EXPECT_EQ(world.entityCount(), 0u);
  msg.mesh_resource = "file://" + path_;
  EXPECT_NE(addRequest(world, toEntityRequest(msg)), stc::kInvalidEntity);
}

TEST(MeshRoots, EachMustBeAnAbsolutePathToAFolderAndIsNamedByIndex) {
  stc::truth::TempDir dir;
  const std::string file = dir.file("a.stl");
  stc::truth::writeStlBinary(stc::truth::cubeMesh(0.4), file);
  const auto field_of = [](const std::vector<std::string>& roots) -> std::string {
    try {
      stc::canonicalMeshRoots(roots);
    } catch (const stc::InputError& e) {
      return e.field();
    }
    return "accepted";
  };
  EXPECT_EQ(field_of({dir.path()}), "accepted");
  EXPECT_EQ(field_of({dir.path(), "meshes"}), "mesh_roots[1]");  // relative
  EXPECT_EQ(field_of({dir.path() + "/missing"}), "mesh_roots[0]");
  EXPECT_EQ(field_of({file}), "mesh_roots[0]");  // a file, not a folder
  EXPECT_EQ(field_of({""}), "mesh_roots[0]");
  EXPECT_EQ(stc::canonicalMeshRoots({dir.path() + "/./"}), std::vector<std::string>{
                                                               std::filesystem::canonical(dir.path()).string()});
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
  stc::World world(config());
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
