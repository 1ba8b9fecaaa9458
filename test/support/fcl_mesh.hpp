// FCL ground truth for tests and benchmarks: a VoxelShape as the closed
// triangle mesh of its exposed voxel faces, and exact collide / distance on it.
// Test code only: the core never includes FCL.
#pragma once

#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/math/bv/OBBRSS.h>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace stc::truth {

using FclMesh = fcl::BVHModel<fcl::OBBRSS<double>>;

// Triangles of the exposed faces, vertices shared between faces (grid corners
// deduplicated), counter-clockwise seen from outside (normals point out).
struct SurfaceMesh {
  std::vector<Vec3> vertices;  // body frame: grid point - body_origin
  std::vector<std::array<std::int32_t, 3>> triangles;
};

// Voxel faces whose neighbour is empty or outside the grid.
std::int64_t exposedFaceCount(const VoxelShape& shape);

// Two triangles per exposed face, in the body frame (origin = body_origin in
// grid coordinates, normally the centre of mass).
SurfaceMesh buildSurfaceMesh(const VoxelShape& shape, const Vec3& body_origin);

std::shared_ptr<FclMesh> toFclMesh(const SurfaceMesh& mesh);
std::shared_ptr<FclMesh> makeFclMesh(const VoxelShape& shape, const Vec3& body_origin);

// Body-frame-to-world transform in FCL's type.
fcl::Transform3d toFcl(const Pose& pose);

// FCL mesh-mesh collide tests the surfaces: a body wholly inside another
// (no face crossing) is not colliding. The sphere-trees follow the same
// convention (they cover surface voxels only).
bool exactCollide(const FclMesh& a, const Pose& pose_a, const FclMesh& b, const Pose& pose_b);

// Distance between the surfaces; 0 when they collide.
double exactDistance(const FclMesh& a, const Pose& pose_a, const FclMesh& b, const Pose& pose_b);

// Whether a body-frame point lies inside an occupied voxel (points on a
// voxel face count as inside). With it a caller tells "separate" from
// "wholly inside the other body", which FCL's surface test cannot.
bool insideSolid(const VoxelShape& shape, const Vec3& body_origin, const Vec3& body_point);

}  // namespace stc::truth
