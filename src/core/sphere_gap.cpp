// The gap bound h of a sphere-tree node: max over points p of the node's BALL
// of f(p) = dist(p, K), K = the occupied voxels of the node's octree cell (the
// solid part of the shape the node stands for).
//
// Why it bounds the gap: if balls a and b intersect, touch, or one holds the
// other, some point p lies in both, and since K_a and K_b are parts of the two
// shapes the true gap is at most dist(p, K_a) + dist(p, K_b) <= h_a + h_b. The
// ball (not just its surface) makes this hold for nested spheres too, and for
// the centre. Measuring to the cell's solid rather than to its surface voxels
// makes h smaller where the sphere dips into the body, where no gap can be.
//
// Why the result is a rigorous upper bound: f is 1-Lipschitz. The ball is cut
// into regions {centre + t r d : d in a patch of directions, t in [t0, t1]},
// where a patch is the radial image of a square (side w, cube units) on a face
// of the cube [-1,1]^3. Radial projection x -> x/|x| is the nearest-point map
// onto the unit ball for |x| >= 1 (all cube-surface points), and nearest-point
// maps onto convex sets are 1-Lipschitz, so directions of a patch lie within
// w/sqrt(2) of the image d of its centre. Hence every point of the region is
// within rho = r (t1 w / sqrt(2) + (t1 - t0) / 2) of the sample c + tm r d
// (tm the middle of [t0, t1]), and f <= f(sample) + rho there. Inside the
// solid f is 0 and the signed distance s = f - depth (depth = distance to the
// nearest point outside K) is 1-Lipschitz too, so f = max(s, 0) <=
// max(0, s(sample) + rho): deep samples clear big regions at once. And with
// q the nearest point of K to the sample, f(y) <= |y - q| for every y of the
// region; its max over the region is taken in closed form over the cap of
// directions (angle theta with chord w / sqrt(2)) and the radii t0, t1. This
// second order bound is what keeps the count of regions low near the maxima,
// where the sphere runs parallel to the shape. Branch and
// bound: keep a cover of the ball by regions, split the region with the
// largest f(sample) + rho (across directions or radius, whichever dominates
// rho) until that largest bound is within `tolerance` of the best f(sample)
// seen. The answer, the largest f(sample) + rho over a cover, is >= the true
// max and <= true max + tolerance.
#include "voxel_pyramid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <vector>

namespace stc::detail {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Region {
  int face;       // axis = face / 2, side = face % 2 ? +1 : -1
  double u, v;    // patch centre on the face, in [-1, 1]^2
  double width;   // patch side length, cube units
  double t0, t1;  // radial interval, fractions of the radius
  double f;       // distance from the sample to K (an upper bound, exact when found)
  double upper;   // f + rho: bound on f over the whole region
  Vec3 sample;
};

Vec3 direction(int face, double u, double v) {
  const int axis = face / 2;
  Vec3 q;
  q[axis] = (face % 2) ? 1.0 : -1.0;
  q[(axis + 1) % 3] = u;
  q[(axis + 2) % 3] = v;
  return q.normalized();
}

}  // namespace

double sphereGapBound(const VoxelPyramid& solid, const VoxelPyramid& empty, int level,
                      const CellIndex& cell, const Vec3& centre, double radius, double tolerance,
                      double give_up_above) {
  Vec3 cell_lo, cell_hi;
  solid.cellBox(level, cell, cell_lo, cell_hi);
  const auto angularRho = [&](const Region& g) { return radius * g.t1 * g.width / std::sqrt(2.0); };
  const auto radialRho = [&](const Region& g) { return radius * 0.5 * (g.t1 - g.t0); };
  const auto less = [](const Region& a, const Region& b) { return a.upper < b.upper; };
  std::priority_queue<Region, std::vector<Region>, decltype(less)> open(less);
  double best = 0.0;  // largest f(sample) seen: a lower bound on the true max

  // Fills sample, f and upper; `seed` must bound f(sample) from above.
  // Max of |y - q| over the region: |y - q|^2 = t^2 r^2 + |v|^2 - 2 t r (d'.v)
  // with v = q - centre; d'.v is least at the cap's edge (angle phi + theta
  // from v), and the quadratic in t is largest at t0 or t1.
  const auto farthestFrom = [&](const Vec3& q, const Region& g, const Vec3& d) {
    const Vec3 v = q - centre;
    const double vn = v.norm();
    const double chord = std::min(2.0, g.width / std::sqrt(2.0));
    const double theta = 2.0 * std::asin(0.5 * chord);
    const double phi = vn > 0.0 ? std::acos(std::clamp(d.dot(v) / vn, -1.0, 1.0)) : 0.0;
    const double least = vn * std::cos(std::min(M_PI, phi + theta));
    double far2 = 0.0;
    for (double t : {g.t0, g.t1}) far2 = std::max(far2, t * t * radius * radius + vn * vn - 2.0 * t * radius * least);
    return std::sqrt(far2) * (1.0 + 1e-12) + 1e-12 * (1.0 + radius);  // rounding slack, outward
  };
  const auto evaluate = [&](Region& g, double seed) {
    const Vec3 d = direction(g.face, g.u, g.v);
    g.sample = centre + radius * 0.5 * (g.t0 + g.t1) * d;
    Vec3 q;
    g.f = solid.distanceToSet(g.sample, level, cell, seed, &q);
    double depth = 0.0;  // distance to the nearest point outside K (0 outside K)
    if (g.f == 0.0) {
      // Outside the (clipped) cell is outside K; so are the cell's empty voxels.
      depth = std::min((g.sample - cell_lo).minCoeff(), (cell_hi - g.sample).minCoeff());
      if (depth > 0.0) depth = empty.distanceToSet(g.sample, level, cell, depth);
    }
    g.upper = std::max(0.0, g.f - depth + angularRho(g) + radialRho(g));
    if (q.allFinite()) g.upper = std::min(g.upper, farthestFrom(q, g, d));
    best = std::max(best, g.f);
    open.push(g);
    return best <= give_up_above;
  };
  for (int face = 0; face < 6; ++face)
    for (double u : {-0.5, 0.5})
      for (double v : {-0.5, 0.5}) {
        Region g{face, u, v, 1.0, 0.0, 1.0, 0.0, 0.0, Vec3::Zero()};
        if (!evaluate(g, kInfinity)) return kInfinity;
      }

  while (true) {
    const Region top = open.top();
    if (top.upper <= best + tolerance) return top.upper;
    open.pop();
    // Lipschitz seed from the parent prunes the nearest-voxel search; the
    // small slack keeps it an upper bound despite rounding.
    const auto seedFor = [&](const Region& g) {
      const Vec3 s = centre + radius * 0.5 * (g.t0 + g.t1) * direction(g.face, g.u, g.v);
      return top.f + (s - top.sample).norm() + 1e-9 * (1.0 + radius);
    };
    if (angularRho(top) >= radialRho(top)) {
      const double w = top.width * 0.5;
      for (double du : {-0.5, 0.5})
        for (double dv : {-0.5, 0.5}) {
          Region g = top;
          g.u += du * w;
          g.v += dv * w;
          g.width = w;
          if (!evaluate(g, seedFor(g))) return kInfinity;
        }
    } else {
      const double mid = 0.5 * (top.t0 + top.t1);
      Region inner = top, outer = top;
      inner.t1 = mid;
      outer.t0 = mid;
      if (!evaluate(inner, seedFor(inner)) || !evaluate(outer, seedFor(outer))) return kInfinity;
    }
  }
}

}  // namespace stc::detail
