#include "mesh_accuracy.hpp"

#include "mesh_generators.hpp"
#include "pose_sampling.hpp"
#include "sphere_union.hpp"

#include "pair_test.hpp"

#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>

namespace stc::truth {
namespace {

double pointToMesh(const FclMesh& mesh, const Vec3& p) {
  static const auto point = std::make_shared<fcl::Sphered>(1e-9);
  fcl::DistanceRequestd request;
  fcl::DistanceResultd result;
  fcl::Transform3d at = fcl::Transform3d::Identity();
  at.translation() = p;
  fcl::distance(&mesh, fcl::Transform3d::Identity(), point.get(), at, request, result);
  return std::max(0.0, result.min_distance);
}

// Inside the mesh's solid: empty voxels are outside (the flood reached them),
// else the winding number decides.
bool insideMesh(const MeshBody& body, const Vec3& p) {
  const VoxelShape& s = body.voxels.shape;
  const Vec3 g = ((p + body.origin) / s.voxelSize()).array().floor();
  if (!s.occupied(int(g.x()), int(g.y()), int(g.z()))) return false;
  return windingNumber(body.mesh, p) > 0.5;
}

std::vector<Ball> levelBalls(const SphereTree& tree, int level) {
  std::vector<Ball> balls;
  for (std::int32_t i = tree.levelBegin(level); i < tree.levelBegin(level + 1); ++i)
    balls.push_back({tree.node(i).centre, tree.node(i).radius});
  return balls;
}

}  // namespace

MeshBody makeMeshBody(const std::string& name, const TriangleMesh& mesh, int resolution, int levels) {
  MeshBody b;
  b.name = name;
  VoxeliseOptions options;
  options.resolution = resolution;
  options.source = name;
  b.voxels = voxeliseMesh(mesh, options);
  b.origin = computeMassProperties(b.voxels.shape, 1.0).centre_of_mass;
  SphereTreeOptions tree_options;
  tree_options.max_levels = levels;
  b.tree = SphereTree::build(b.voxels.shape, b.origin, tree_options);
  b.mesh = mesh;
  for (Vec3& v : b.mesh.vertices) {
    v -= b.voxels.grid_origin + b.origin;
    b.radius = std::max(b.radius, v.norm());
  }
  b.extent = (b.voxels.stats.max - b.voxels.stats.min).maxCoeff();
  SurfaceMesh surface;
  surface.vertices = b.mesh.vertices;
  surface.triangles = b.mesh.triangles;
  b.fcl = toFclMesh(surface);
  return b;
}

std::vector<Vec3> outerSurfacePoints(const MeshBody& body, double spacing) {
  std::vector<Vec3> points;
  for (const auto& t : body.mesh.triangles) {
    const Vec3 &a = body.mesh.vertices[t[0]], &b = body.mesh.vertices[t[1]], &c = body.mesh.vertices[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
    const Vec3 normal = (b - a).cross(c - a);
    if (normal.squaredNorm() == 0.0) continue;
    // Tested a hair outside, where the winding number is defined: about 0
    // beside the outer surface, about 1 inside another part.
    const Vec3 nudge = 1e-4 * spacing * normal.normalized();
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Vec3 p = a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n);
        if (windingNumber(body.mesh, p + nudge) < 0.5) points.push_back(p);
      }
  }
  return points;
}

double coverageExcess(const MeshBody& body, int level, const std::vector<Vec3>& points) {
  const std::vector<Ball> balls = levelBalls(body.tree, level);
  double excess = 0.0;
  for (const Vec3& p : points) {
    double outside = 1e30;
    for (const Ball& ball : balls) outside = std::min(outside, (p - ball.centre).norm() - ball.radius);
    excess = std::max(excess, outside);
  }
  return excess;
}

FitError fitError(const MeshBody& body, int level, double spacing) {
  FitError e;
  double sum = 0.0;
  forEachUnionBoundaryPoint(levelBalls(body.tree, level), spacing, [&](std::size_t, const Vec3& p) {
    if (insideMesh(body, p)) return;
    const double d = pointToMesh(*body.fcl, p);
    e.worst = std::max(e.worst, d);
    sum += d;
    ++e.samples;
  });
  e.mean = e.samples > 0 ? sum / static_cast<double>(e.samples) : 0.0;
  return e;
}

PairAccuracy measurePairs(const MeshBody& a, const MeshBody& b, int poses, std::uint64_t seed) {
  Rng rng(seed);
  PairAccuracy acc;
  PairTest test;
  for (int n = 0; n < poses; ++n) {
    Pose pa, pb;
    pa.orientation = randomRotation(rng);
    pb.orientation = randomRotation(rng);
    pb.position = randomDirection(rng) * randomUniform(rng, 0.0, 1.1 * (a.radius + b.radius));
    ++acc.poses;
    const bool truth = exactCollide(*a.fcl, pa, *b.fcl, pb);
    if (!truth) {
      // A vertex of one inside the other, and no face crossing: nested.
      const Vec3 b_in_a = pa.orientation.inverse() * (pb.apply(b.mesh.vertices[0]) - pa.position);
      const Vec3 a_in_b = pb.orientation.inverse() * (pa.apply(a.mesh.vertices[0]) - pb.position);
      if (windingNumber(a.mesh, b_in_a) > 0.5 || windingNumber(b.mesh, a_in_b) > 0.5) {
        ++acc.nested;
        continue;
      }
    }
    test.reset({0, &a.tree, &pa}, {1, &b.tree, &pb});
    while (!test.resolved()) test.step();
    const bool tree = test.status() == PairStatus::Colliding;
    acc.colliding += truth;
    if (truth && !tree) {
      ++acc.missed;
      // Closest leaf pair: how much both leaf levels must grow to touch.
      double gap = 1e30;
      for (std::int32_t i = 0; i < static_cast<std::int32_t>(a.tree.nodes().size()); ++i) {
        if (!a.tree.isLeaf(i)) continue;
        const Vec3 ca = pa.apply(a.tree.node(i).centre);
        for (std::int32_t j = 0; j < static_cast<std::int32_t>(b.tree.nodes().size()); ++j) {
          if (!b.tree.isLeaf(j)) continue;
          gap = std::min(gap, (pb.apply(b.tree.node(j).centre) - ca).norm() - a.tree.node(i).radius -
                                  b.tree.node(j).radius);
        }
      }
      acc.margin_needed = std::max(acc.margin_needed, 0.5 * gap);
    }
    if (tree) {
      acc.false_positive += !truth;
      const double distance = truth ? 0.0 : exactDistance(*a.fcl, pa, *b.fcl, pb);
      const double bound = test.gapBound();
      if (distance > bound + 1e-9) ++acc.bound_violations;
      const double margins = a.voxels.shape.surfaceMargin() + b.voxels.shape.surfaceMargin();
      if (distance > bound - margins + 1e-9) ++acc.voxel_bound_violations;
      if (bound > 0.0) acc.worst_bound_ratio = std::max(acc.worst_bound_ratio, distance / bound);
    }
  }
  return acc;
}

}  // namespace stc::truth
