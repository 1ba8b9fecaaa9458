// Accuracy of sphere-trees of voxelised meshes against the ORIGINAL mesh
// (issue 14 item 2), shared by test_mesh_accuracy and bench_mesh_accuracy:
// FCL collide / distance on the mesh's own triangles, the mesh's coverage by
// each tree level, and the levels' one-sided Hausdorff fit error.
#pragma once

#include "fcl_mesh.hpp"

#include "sphere_tree_collision/mesh_voxeliser.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"

#include <memory>
#include <string>
#include <vector>

namespace stc::truth {

struct MeshBody {
  std::string name;
  TriangleMesh mesh;           // body frame
  VoxelisedMesh voxels;
  Vec3 origin = Vec3::Zero();  // body origin (voxels' centre of mass), grid frame
  SphereTree tree;
  std::shared_ptr<FclMesh> fcl;  // the original triangles, body frame
  double radius = 0.0;           // max |vertex|, body frame
  double extent = 0.0;           // the mesh's longest side
};

// Voxelised at `resolution` voxels along the longest side, tree of `levels`
// levels (tight fit), mesh moved into the body frame.
MeshBody makeMeshBody(const std::string& name, const TriangleMesh& mesh, int resolution, int levels);

// Points of the mesh's outer surface: the triangles sampled about `spacing`
// apart (vertices included), without the points inside another part of the
// mesh (a union's inner triangles: winding number just outside above 1/2).
// Outward triangles assumed.
std::vector<Vec3> outerSurfacePoints(const MeshBody& body, double spacing);

// How far the mesh pokes out of one level's union of spheres: the max over
// `points` of the distance outside the nearest sphere; 0 when the level covers them.
double coverageExcess(const MeshBody& body, int level, const std::vector<Vec3>& points);

// One-sided Hausdorff error of a level against the mesh: distance to the
// mesh of the union's boundary points that are outside the mesh's solid.
struct FitError {
  double worst = 0.0;  // metres
  double mean = 0.0;
  long samples = 0;
};
FitError fitError(const MeshBody& body, int level, double spacing);

struct PairAccuracy {
  long poses = 0;
  long nested = 0;           // one mesh wholly inside the other: excluded
  long colliding = 0;        // FCL on the original meshes
  long missed = 0;           // FCL colliding, the full-depth tree test separate
  long false_positive = 0;   // FCL separate, the tree test colliding
  long bound_violations = 0; // tree colliding but mesh distance > gapBound() (h_a + h_b)
  long voxel_bound_violations = 0;  // the same against h without the surface margins (voxels only)
  double worst_bound_ratio = 0.0;  // max mesh distance / gapBound() over tree-colliding poses
  double margin_needed = 0.0;      // sphere growth (each side) that would catch every missed pose
};

// `poses` random poses of b around a (random rotations, b's origin at up to
// 1.1 times the sum of the radii), run to full depth.
PairAccuracy measurePairs(const MeshBody& a, const MeshBody& b, int poses, std::uint64_t seed);

}  // namespace stc::truth
