// The gap bound h of a sphere-tree node: max over points p of the node's sphere
// surface of f(p) = dist(p, K), K = the occupied voxels of the node's octree
// cell (the solid part of the shape the node stands for).
//
// Why it bounds the gap: if spheres a and b touch (or their surfaces cross),
// some point p lies on both surfaces, and since K_a and K_b are parts of the
// two shapes the true gap is at most dist(p, K_a) + dist(p, K_b) <= h_a + h_b.
// Measuring to the cell's solid rather than to its surface voxels only makes h
// smaller where the sphere dips into the body, where no gap can be.
//
// Why the result is a rigorous upper bound: f is 1-Lipschitz. The sphere is
// covered by the radial images of squares on the faces of the cube [-1,1]^3.
// Radial projection x -> x/|x| is the nearest-point map onto the unit ball for
// |x| >= 1 (all cube-surface points), and nearest-point maps onto convex sets
// are 1-Lipschitz; so every sphere point of a square of side w (cube units)
// lies within rho = radius * w / sqrt(2) of the image s of the square's centre,
// and f <= f(s) + rho on that patch. Branch and bound: keep a cover of the
// sphere by patches, split the patch with the largest f(s) + rho until that
// largest bound is within `tolerance` of the best f(s) seen. The answer, the
// largest f(s) + rho over a cover, is >= the true max and <= true max + tol.
#include "voxel_pyramid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <vector>

namespace stc::detail {
namespace {

struct Patch {
  int face;       // axis = face / 2, side = face % 2 ? +1 : -1
  double u, v;    // centre on the face, in [-1, 1]^2
  double width;   // side length, cube units
  double f;       // distance from the sample point to K (an upper bound, exact when found)
  double upper;   // f + rho: bound on f over the whole patch
  Vec3 sample;    // radial image of the centre on the sphere
};

Vec3 samplePoint(const Vec3& centre, double radius, int face, double u, double v) {
  const int axis = face / 2;
  Vec3 q;
  q[axis] = (face % 2) ? 1.0 : -1.0;
  q[(axis + 1) % 3] = u;
  q[(axis + 2) % 3] = v;
  return centre + radius * q.normalized();
}

}  // namespace

double sphereGapBound(const VoxelPyramid& pyramid, int level, const CellIndex& cell,
                      const Vec3& centre, double radius, double tolerance) {
  const auto rhoOf = [&](double width) { return radius * width / std::sqrt(2.0); };
  const auto less = [](const Patch& a, const Patch& b) { return a.upper < b.upper; };
  std::priority_queue<Patch, std::vector<Patch>, decltype(less)> open(less);
  const double inf = std::numeric_limits<double>::infinity();

  double best = 0.0;  // largest f(sample) seen: a lower bound on the true max
  for (int face = 0; face < 6; ++face)
    for (double u : {-0.5, 0.5})
      for (double v : {-0.5, 0.5}) {
        Patch p{face, u, v, 1.0, 0.0, 0.0, samplePoint(centre, radius, face, u, v)};
        p.f = pyramid.distanceToSet(p.sample, level, cell, inf);
        p.upper = p.f + rhoOf(p.width);
        best = std::max(best, p.f);
        open.push(p);
      }

  while (true) {
    const Patch top = open.top();
    if (top.upper <= best + tolerance) return top.upper;
    open.pop();
    const double w = top.width * 0.5;
    for (double du : {-0.5, 0.5})
      for (double dv : {-0.5, 0.5}) {
        Patch p{top.face, top.u + du * w, top.v + dv * w, w, 0.0, 0.0, Vec3::Zero()};
        p.sample = samplePoint(centre, radius, p.face, p.u, p.v);
        // Lipschitz seed from the parent prunes the nearest-voxel search; the
        // small slack keeps it an upper bound despite rounding.
        const double seed = top.f + (p.sample - top.sample).norm() + 1e-9 * (1.0 + radius);
        p.f = pyramid.distanceToSet(p.sample, level, cell, seed);
        p.upper = p.f + rhoOf(p.width);
        best = std::max(best, p.f);
        open.push(p);
      }
  }
}

}  // namespace stc::detail
