#include "fcl_mesh.hpp"

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>

namespace stc::truth {

namespace {

constexpr int kAxisStep[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

}  // namespace

std::int64_t exposedFaceCount(const VoxelShape& shape) {
  std::int64_t faces = 0;
  for (int k = 0; k < shape.nz(); ++k)
    for (int j = 0; j < shape.ny(); ++j)
      for (int i = 0; i < shape.nx(); ++i) {
        if (!shape.occupied(i, j, k)) continue;
        for (const auto& d : kAxisStep)
          if (!shape.occupied(i + d[0], j + d[1], k + d[2])) ++faces;
      }
  return faces;
}

SurfaceMesh buildSurfaceMesh(const VoxelShape& shape, const Vec3& body_origin) {
  const int cx = shape.nx() + 1, cy = shape.ny() + 1, cz = shape.nz() + 1;
  // Grid corner -> vertex index, so that neighbouring faces share vertices
  // (and therefore edges): the mesh is closed, not a soup of quads.
  std::vector<std::int32_t> corner_vertex(static_cast<std::size_t>(cx) * cy * cz, -1);
  SurfaceMesh mesh;
  const double s = shape.voxelSize();
  auto vertexAt = [&](int i, int j, int k) {
    const std::size_t key = static_cast<std::size_t>(i) +
                            static_cast<std::size_t>(cx) * (static_cast<std::size_t>(j) +
                                                            static_cast<std::size_t>(cy) * k);
    std::int32_t& v = corner_vertex[key];
    if (v < 0) {
      v = static_cast<std::int32_t>(mesh.vertices.size());
      mesh.vertices.push_back(Vec3(i, j, k) * s - body_origin);
    }
    return v;
  };

  for (int k = 0; k < shape.nz(); ++k)
    for (int j = 0; j < shape.ny(); ++j)
      for (int i = 0; i < shape.nx(); ++i) {
        if (!shape.occupied(i, j, k)) continue;
        for (int dir = 0; dir < 6; ++dir) {
          const int* d = kAxisStep[dir];
          if (shape.occupied(i + d[0], j + d[1], k + d[2])) continue;
          // Face normal along axis a; (u, v, a) is a right-handed cycle, so the
          // corner order (0,0) (1,0) (1,1) (0,1) in (u, v) faces +a.
          const int a = dir / 2, u = (a + 1) % 3, v = (a + 2) % 3;
          const bool positive = dir % 2 == 0;
          int quad[4];
          const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
          for (int c = 0; c < 4; ++c) {
            // Reverse the winding on the negative side.
            const int* o = uv[positive ? c : (4 - c) % 4];
            int p[3] = {i, j, k};
            p[a] += positive ? 1 : 0;
            p[u] += o[0];
            p[v] += o[1];
            quad[c] = vertexAt(p[0], p[1], p[2]);
          }
          mesh.triangles.push_back({quad[0], quad[1], quad[2]});
          mesh.triangles.push_back({quad[0], quad[2], quad[3]});
        }
      }
  return mesh;
}

std::shared_ptr<FclMesh> toFclMesh(const SurfaceMesh& mesh) {
  std::vector<fcl::Vector3d> points(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    triangles.emplace_back(static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1]),
                           static_cast<std::size_t>(t[2]));
  auto model = std::make_shared<FclMesh>();
  model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size()));
  model->addSubModel(points, triangles);
  model->endModel();
  model->computeLocalAABB();
  return model;
}

std::shared_ptr<FclMesh> makeFclMesh(const VoxelShape& shape, const Vec3& body_origin) {
  return toFclMesh(buildSurfaceMesh(shape, body_origin));
}

fcl::Transform3d toFcl(const Pose& pose) {
  fcl::Transform3d tf = fcl::Transform3d::Identity();
  tf.linear() = pose.orientation.normalized().toRotationMatrix();
  tf.translation() = pose.position;
  return tf;
}

bool exactCollide(const FclMesh& a, const Pose& pose_a, const FclMesh& b, const Pose& pose_b) {
  fcl::CollisionRequestd request;  // one contact is enough to answer yes/no
  fcl::CollisionResultd result;
  fcl::collide(&a, toFcl(pose_a), &b, toFcl(pose_b), request, result);
  return result.isCollision();
}

double exactDistance(const FclMesh& a, const Pose& pose_a, const FclMesh& b, const Pose& pose_b) {
  // Mesh-mesh distance runs the RSS traversal with exact triangle-triangle
  // distances (no GJK); overlapping triangles give 0 (and rel/abs error 0
  // asks for the exact minimum).
  fcl::DistanceRequestd request;
  fcl::DistanceResultd result;
  fcl::distance(&a, toFcl(pose_a), &b, toFcl(pose_b), request, result);
  return std::max(0.0, result.min_distance);
}

bool insideSolid(const VoxelShape& shape, const Vec3& body_origin, const Vec3& body_point) {
  const Vec3 g = (body_point + body_origin) / shape.voxelSize();
  const Vec3 lo = g.array().floor();
  // A point on a face or edge belongs to every voxel it touches.
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj)
      for (int di = 0; di < 2; ++di) {
        const int d[3] = {di, dj, dk};
        int idx[3];
        bool candidate = true;
        for (int a = 0; a < 3; ++a) {
          idx[a] = static_cast<int>(lo[a]) - d[a];
          if (d[a] == 1 && g[a] != lo[a]) candidate = false;  // not on that boundary
        }
        if (candidate && shape.occupied(idx[0], idx[1], idx[2])) return true;
      }
  return false;
}

}  // namespace stc::truth
