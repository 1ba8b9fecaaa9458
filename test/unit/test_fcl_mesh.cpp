// The FCL ground truth itself: the voxel surface mesh is closed and outward,
// lives in the body frame, and FCL's answers on it match hand-computed poses.
#include "fcl_mesh.hpp"

#include "sphere_tree_collision/voxel_shape.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

namespace stc::truth {
namespace {

using Edge = std::pair<std::int32_t, std::int32_t>;

// Directed edge -> number of triangles using it in that direction.
std::map<Edge, int> directedEdges(const SurfaceMesh& mesh) {
  std::map<Edge, int> edges;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++edges[{t[e], t[(e + 1) % 3]}];
  return edges;
}

// Signed volume and its first moment by the divergence theorem: exact for a
// closed, outward-oriented mesh, wrong in sign or value otherwise.
std::pair<double, Vec3> volumeAndCentroid(const SurfaceMesh& mesh) {
  double volume = 0.0;
  Vec3 moment = Vec3::Zero();
  for (const auto& t : mesh.triangles) {
    const Vec3& p = mesh.vertices[t[0]];
    const Vec3& q = mesh.vertices[t[1]];
    const Vec3& r = mesh.vertices[t[2]];
    const double v = p.dot(q.cross(r)) / 6.0;  // tetrahedron with the origin
    volume += v;
    moment += v * (p + q + r) / 4.0;
  }
  return {volume, moment / volume};
}

Pose at(double x, double y, double z, const Quat& q = Quat::Identity()) {
  Pose p;
  p.position = Vec3(x, y, z);
  p.orientation = q;
  return p;
}

class PresetMesh : public ::testing::TestWithParam<std::string> {};

// Every edge used once in each direction: closed and consistently wound.
// Returns the number of undirected edges that break it.
std::size_t unbalancedEdges(const std::map<Edge, int>& edges) {
  std::size_t bad = 0;
  for (const auto& [edge, count] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    if (reverse == edges.end() || reverse->second != count) ++bad;
  }
  return bad;
}

void expectClosedOutwardBodyFrameMesh(const VoxelShape& shape, const std::string& what) {
  const MassProperties mp = computeMassProperties(shape, 1.0);
  const SurfaceMesh mesh = buildSurfaceMesh(shape, mp.centre_of_mass);

  const std::int64_t faces = exposedFaceCount(shape);
  ASSERT_GT(faces, 0) << what;
  EXPECT_EQ(static_cast<std::int64_t>(mesh.triangles.size()), 2 * faces) << what;

  // Manifold and closed: every undirected edge shared by exactly two
  // triangles, which traverse it in opposite directions.
  const auto edges = directedEdges(mesh);
  std::size_t not_two = 0;
  for (const auto& [edge, count] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    if (count != 1 || reverse == edges.end() || reverse->second != 1) ++not_two;
  }
  EXPECT_EQ(not_two, 0u) << what << ": edges not shared by exactly two triangles";

  // Euler characteristic of a closed surface: V - E + F = 2 - 2 * genus.
  const auto euler = static_cast<long>(mesh.vertices.size()) - static_cast<long>(edges.size() / 2) +
                     static_cast<long>(mesh.triangles.size());
  EXPECT_EQ(euler, what.rfind("ring", 0) == 0 ? 0 : 2) << what;

  // Outward orientation and body frame: enclosed volume = voxel volume, and
  // its centroid is the body origin (the centre of mass).
  const auto [volume, centroid] = volumeAndCentroid(mesh);
  const double voxel_volume = std::pow(shape.voxelSize(), 3);
  EXPECT_NEAR(volume, shape.occupiedCount() * voxel_volume, 1e-9 * volume) << what;
  EXPECT_LT(centroid.norm(), 1e-9 * shape.extent().norm()) << what;
}

TEST_P(PresetMesh, ClosedOutwardTwoTrianglesPerFaceInBodyFrame) {
  for (int resolution : {6, 10, 16}) {
    for (std::uint32_t seed : {1u, 2u, 3u}) {
      if (seed > 1 && GetParam() != "rock") break;
      PresetParams params;
      params.resolution = resolution;
      params.voxel_size = 0.05;
      params.seed = seed;
      expectClosedOutwardBodyFrameMesh(makePreset(GetParam(), params),
                                       GetParam() + " res " + std::to_string(resolution) +
                                           " seed " + std::to_string(seed));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Presets, PresetMesh,
                         ::testing::Values("cube", "sphere", "rock", "rod", "plate", "L", "ring"));

TEST(FclMesh, VoxelsMeetingOnlyAlongAnEdgeStayClosed) {
  // The presets are manifold from resolution 5 up; a 4-voxel ring is not:
  // its voxels meet diagonally, so those edges carry four triangles. The
  // mesh is still closed and outward (each directed edge has its reverse),
  // which is what FCL's surface tests need.
  PresetParams params;
  params.resolution = 4;
  params.voxel_size = 0.1;
  const VoxelShape ring = makePreset("ring", params);
  const SurfaceMesh mesh = buildSurfaceMesh(ring, Vec3::Zero());
  const auto edges = directedEdges(mesh);
  std::size_t four = 0;
  for (const auto& [edge, count] : edges) four += count == 2 ? 1 : 0;
  EXPECT_GT(four, 0u) << "expected diagonal voxel contacts";
  EXPECT_EQ(unbalancedEdges(edges), 0u);
  EXPECT_NEAR(volumeAndCentroid(mesh).first, ring.occupiedCount() * 1e-3, 1e-12);
}

TEST(FclMesh, SolidCubeHasOnlyItsHullAndVerticesAreShared) {
  PresetParams params;
  params.resolution = 4;
  params.voxel_size = 0.1;
  const VoxelShape cube = makePreset("cube", params);
  const SurfaceMesh mesh = buildSurfaceMesh(cube, Vec3::Zero());
  EXPECT_EQ(exposedFaceCount(cube), 6 * 16);
  EXPECT_EQ(mesh.triangles.size(), 2u * 6 * 16);
  // Grid corners on the hull: 5^3 - 3^3; none repeated, none from the inside.
  EXPECT_EQ(mesh.vertices.size(), 125u - 27u);
  for (const Vec3& v : mesh.vertices) {
    EXPECT_GE(v.minCoeff(), -1e-12);
    EXPECT_LE(v.maxCoeff(), 0.4 + 1e-12);
    EXPECT_TRUE(v.minCoeff() < 1e-12 || v.maxCoeff() > 0.4 - 1e-12) << "interior vertex";
  }
  // The body origin shifts every vertex.
  const SurfaceMesh shifted = buildSurfaceMesh(cube, Vec3(0.2, 0.2, 0.2));
  ASSERT_EQ(shifted.vertices.size(), mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    EXPECT_LT((shifted.vertices[i] - (mesh.vertices[i] - Vec3(0.2, 0.2, 0.2))).norm(), 1e-15);
}

// Two 0.4 m cubes (4 voxels of 0.1 m) centred on their centre of mass.
class TwoCubes : public ::testing::Test {
 protected:
  void SetUp() override {
    PresetParams params;
    params.resolution = 4;
    params.voxel_size = 0.1;
    const VoxelShape cube = makePreset("cube", params);
    mesh = makeFclMesh(cube, computeMassProperties(cube, 1.0).centre_of_mass);
  }
  std::shared_ptr<FclMesh> mesh;
};

TEST_F(TwoCubes, OverlappingCollideAndHaveZeroDistance) {
  EXPECT_TRUE(exactCollide(*mesh, at(0, 0, 0), *mesh, at(0.3, 0, 0)));
  EXPECT_EQ(exactDistance(*mesh, at(0, 0, 0), *mesh, at(0.3, 0, 0)), 0.0);
  // Rotated and shifted so no face is parallel: still overlapping.
  const Quat q(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  EXPECT_TRUE(exactCollide(*mesh, at(1, 2, 3), *mesh, at(1.25, 2.1, 3.05, q)));
  EXPECT_EQ(exactDistance(*mesh, at(1, 2, 3), *mesh, at(1.25, 2.1, 3.05, q)), 0.0);
}

TEST_F(TwoCubes, OneVoxelApartFaceToFace) {
  for (int axis = 0; axis < 3; ++axis) {
    Vec3 offset = Vec3::Zero();
    offset[axis] = 0.5;  // 0.4 (touching) + one voxel
    const Pose b = at(offset.x(), offset.y(), offset.z());
    EXPECT_FALSE(exactCollide(*mesh, at(0, 0, 0), *mesh, b));
    EXPECT_NEAR(exactDistance(*mesh, at(0, 0, 0), *mesh, b), 0.1, 1e-6) << "axis " << axis;
  }
}

TEST_F(TwoCubes, TouchingFaceToFaceIsZeroDistance) {
  // FCL's behaviour on exactly coincident faces: distance 0; collide reports
  // the coplanar contact as a collision.
  EXPECT_NEAR(exactDistance(*mesh, at(0, 0, 0), *mesh, at(0.4, 0, 0)), 0.0, 1e-12);
  EXPECT_TRUE(exactCollide(*mesh, at(0, 0, 0), *mesh, at(0.4, 0, 0)));
  // Just apart and just overlapping around the touching pose.
  EXPECT_FALSE(exactCollide(*mesh, at(0, 0, 0), *mesh, at(0.4 + 1e-7, 0, 0)));
  EXPECT_NEAR(exactDistance(*mesh, at(0, 0, 0), *mesh, at(0.4 + 1e-7, 0, 0)), 1e-7, 1e-9);
  EXPECT_TRUE(exactCollide(*mesh, at(0, 0, 0), *mesh, at(0.4 - 1e-7, 0, 0)));
}

TEST_F(TwoCubes, RotatedFortyFiveDegreesAboutZ) {
  // B's vertical edge points at A's +x face: it reaches 0.2 * sqrt(2) from B's centre.
  const Quat q(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()));
  const double reach = 0.2 + 0.2 * std::sqrt(2.0);
  for (double gap : {0.15, 0.02, 0.3}) {
    const Pose b = at(reach + gap, 0.05, 0.0, q);
    EXPECT_FALSE(exactCollide(*mesh, at(0, 0, 0), *mesh, b));
    EXPECT_NEAR(exactDistance(*mesh, at(0, 0, 0), *mesh, b), gap, 1e-6);
  }
  EXPECT_TRUE(exactCollide(*mesh, at(0, 0, 0), *mesh, at(reach - 0.01, 0.05, 0.0, q)));
  // The same pair with A moved and turned as a whole: distances are invariant.
  const Pose a = at(-1.0, 0.5, 2.0, Quat(Eigen::AngleAxisd(1.1, Vec3(0, 1, 1).normalized())));
  const Pose b_local = at(reach + 0.15, 0.05, 0.0, q);
  Pose b_world;
  b_world.position = a.apply(b_local.position);
  b_world.orientation = a.orientation * b_local.orientation;
  EXPECT_NEAR(exactDistance(*mesh, a, *mesh, b_world), 0.15, 1e-6);
}

TEST_F(TwoCubes, EdgeToEdgeAlongTheDiagonal) {
  // Unrotated cubes offset by (d, d, 0): the vertical edges face each other
  // across the diagonal, sqrt(2) * (d - 0.4) apart.
  for (double d : {0.45, 0.5, 0.7}) {
    EXPECT_NEAR(exactDistance(*mesh, at(0, 0, 0), *mesh, at(d, d, 0)), std::sqrt(2.0) * (d - 0.4),
                1e-6);
  }
}

TEST(FclMesh, BodyWhollyInsideAnotherIsNotCollidingForFcl) {
  // The convention the sphere-trees share: surfaces are tested, not volumes.
  PresetParams big_params;
  big_params.resolution = 8;
  big_params.voxel_size = 0.1;
  PresetParams small_params;
  small_params.resolution = 2;
  small_params.voxel_size = 0.1;
  const VoxelShape big = makePreset("cube", big_params);
  const VoxelShape small = makePreset("cube", small_params);
  const auto big_mesh = makeFclMesh(big, computeMassProperties(big, 1.0).centre_of_mass);
  const auto small_mesh = makeFclMesh(small, computeMassProperties(small, 1.0).centre_of_mass);
  EXPECT_FALSE(exactCollide(*big_mesh, at(0, 0, 0), *small_mesh, at(0.05, 0, 0)));
  // Distance is then between the surfaces: 0.4 - 0.05 - 0.1 to the nearest face.
  EXPECT_NEAR(exactDistance(*big_mesh, at(0, 0, 0), *small_mesh, at(0.05, 0, 0)), 0.25, 1e-6);
  // Crossing the surface is a collision again.
  EXPECT_TRUE(exactCollide(*big_mesh, at(0, 0, 0), *small_mesh, at(0.35, 0, 0)));
}

TEST(FclMesh, InsideSolidFollowsTheVoxels) {
  PresetParams params;
  params.resolution = 6;
  params.voxel_size = 0.1;
  const VoxelShape l_shape = makePreset("L", params);  // arms 2 voxels wide, 2 thick
  const Vec3 origin = computeMassProperties(l_shape, 1.0).centre_of_mass;
  auto grid = [&](double x, double y, double z) -> Vec3 { return Vec3(x, y, z) - origin; };
  EXPECT_TRUE(insideSolid(l_shape, origin, grid(0.05, 0.05, 0.05)));
  EXPECT_TRUE(insideSolid(l_shape, origin, grid(0.55, 0.15, 0.15)));  // end of the x arm
  EXPECT_FALSE(insideSolid(l_shape, origin, grid(0.4, 0.4, 0.1)));    // the notch of the L
  EXPECT_FALSE(insideSolid(l_shape, origin, grid(0.1, 0.1, 0.25)));   // above it
  EXPECT_FALSE(insideSolid(l_shape, origin, grid(-0.01, 0.1, 0.1)));  // outside the grid
  EXPECT_TRUE(insideSolid(l_shape, origin, grid(0.2, 0.4, 0.1)));     // on the notch's face
  EXPECT_TRUE(insideSolid(l_shape, origin, grid(0.6, 0.1, 0.1)));     // on the outer face
  EXPECT_FALSE(insideSolid(l_shape, origin, grid(0.6 + 1e-9, 0.1, 0.1)));
}

}  // namespace
}  // namespace stc::truth
