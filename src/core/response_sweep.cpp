// Anti-tunnelling: fast bodies are swept from their start to their end pose
// and put back at their first contact (paper 3.5: backtracking to the instant
// of collision).
#include "sphere_tree_collision/response.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {
namespace {

// Earliest t in [0, t_max] with |d0 + t v| <= reach; -1 when there is none.
double firstTouch(const Vec3& d0, const Vec3& v, double reach, double t_max) {
  const double c = d0.squaredNorm() - reach * reach;
  if (c <= 0.0) return 0.0;
  const double b = d0.dot(v);
  if (b >= 0.0) return -1.0;  // not closing
  const double a = v.squaredNorm();
  const double disc = b * b - a * c;
  if (disc < 0.0) return -1.0;
  const double t = (-b - std::sqrt(disc)) / a;
  return t <= t_max ? t : -1.0;
}

// Distance from point p to the segment [s0, s1].
double segmentDistance(const Vec3& p, const Vec3& s0, const Vec3& s1) {
  const Vec3 d = s1 - s0;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
  return (s0 + t * d - p).norm();
}

struct Sweeper {
  const ShapeBounds& fast;
  const ShapeBounds& other;
  Mat3 r0, r1, ro;  // fast body at start and end, other body
  Vec3 x0, x1, xo;
  double best;      // earliest hit so far, fraction of the tick
  std::vector<std::pair<std::int32_t, std::int32_t>>& stack;

  // First instant the two leaves' voxel boxes overlap deeper than a quarter
  // of the thinner box's half extent on all six face axes (the slab test of
  // a box moving along a line, the fast box kept at its end orientation);
  // -1 when they do not, or when they already do at the start (a resting
  // contact: the solver's). Penetration tested on boxes, not spheres: a flat
  // leaf's sphere reaches far beyond its voxels, and a body sliding over a
  // floor would keep running into the spheres ahead.
  double leafEntry(std::int32_t nf, std::int32_t no) const {
    const std::size_t f = static_cast<std::size_t>(nf);
    const std::size_t o = static_cast<std::size_t>(no);
    const Vec3 local_f = fast.tree->node(nf).centre + fast.box_offset[f];
    const Vec3 pa0 = r0 * local_f + x0;
    const Vec3 pa1 = r1 * local_f + x1;
    const Vec3 pb = ro * (other.tree->node(no).centre + other.box_offset[o]) + xo;
    const Vec3& hf = fast.box_half[f];
    const Vec3& ho = other.box_half[o];
    const double tolerance = 0.25 * std::min(hf.minCoeff(), ho.minCoeff());
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 6; ++k) {
      const Vec3 u = k < 3 ? Vec3(r1.col(k)) : Vec3(ro.col(k - 3));
      const double reach = hf.dot((r1.transpose() * u).cwiseAbs()) +
                           ho.dot((ro.transpose() * u).cwiseAbs()) - tolerance;
      if (reach <= 0.0) return -1.0;
      const double x0u = (pb - pa0).dot(u);
      const double dx = (pb - pa1).dot(u) - x0u;
      if (dx == 0.0) {
        if (std::abs(x0u) >= reach) return -1.0;
        continue;
      }
      const double t1 = (-reach - x0u) / dx;
      const double t2 = (reach - x0u) / dx;
      lo = std::max(lo, std::min(t1, t2));
      hi = std::min(hi, std::max(t1, t2));
      if (lo >= hi) return -1.0;
    }
    if (lo <= 0.0) return -1.0;  // overlapping at the start, or never
    return lo <= best ? lo : -1.0;
  }

  bool run() {
    bool hit = false;
    stack.clear();
    stack.emplace_back(0, 0);
    while (!stack.empty()) {
      const auto [nf, no] = stack.back();
      stack.pop_back();
      const SphereNode& f = fast.tree->node(nf);
      const SphereNode& o = other.tree->node(no);
      const Vec3 a0 = r0 * f.centre + x0;
      const Vec3 a1 = r1 * f.centre + x1;
      const Vec3 b = ro * o.centre + xo;
      const bool f_leaf = f.child_count == 0;
      const bool o_leaf = o.child_count == 0;
      if (f_leaf && o_leaf) {
        const double t = leafEntry(nf, no);
        if (t >= 0.0 && t < best) {
          best = t;
          hit = true;
        }
        continue;
      }
      const double bound = fast.reach[static_cast<std::size_t>(nf)] + other.reach[static_cast<std::size_t>(no)];
      if (firstTouch(a0 - b, a1 - a0, bound, best) < 0.0) continue;
      // Open the node with the larger reach (a leaf cannot be opened).
      const bool open_fast = !f_leaf && (o_leaf || fast.reach[static_cast<std::size_t>(nf)] >=
                                                       other.reach[static_cast<std::size_t>(no)]);
      if (open_fast) {
        for (std::int32_t c = f.first_child; c < f.first_child + f.child_count; ++c) stack.emplace_back(c, no);
      } else {
        for (std::int32_t c = o.first_child; c < o.first_child + o.child_count; ++c) stack.emplace_back(nf, c);
      }
    }
    return hit;
  }
};

}  // namespace

SweepStats sweepFastBodies(std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes, double threshold,
                           SweepScratch* scratch) {
  SweepStats stats;
  SweepScratch local;
  std::vector<std::pair<std::int32_t, std::int32_t>>& stack = (scratch != nullptr ? *scratch : local).stack;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    BodyState& body = bodies[i];
    const ShapeBounds* fast = shapes[i];
    if (body.is_static || fast == nullptr || fast->tree == nullptr) continue;
    const Pose& p0 = start[i];
    const Pose p1 = body.pose;
    const double moved = (p1.position - p0.position).norm() +
                         p0.orientation.angularDistance(p1.orientation) * fast->bound_radius;
    if (!(moved > threshold * fast->min_leaf_radius)) continue;
    ++stats.fast_bodies;

    Sweeper sweeper{*fast, *fast, p0.orientation.toRotationMatrix(), p1.orientation.toRotationMatrix(),
                    Mat3::Identity(), p0.position, p1.position, Vec3::Zero(), 1.0, stack};
    bool hit = false;
    for (std::size_t j = 0; j < bodies.size(); ++j) {
      const ShapeBounds* other = shapes[j];
      if (j == i || other == nullptr || other->tree == nullptr) continue;
      const BodyState& o = bodies[j];
      // Cull: the other body's ball against the fast body's swept ball.
      if (segmentDistance(o.pose.position, p0.position, p1.position) >
          fast->bound_radius + other->bound_radius) {
        continue;
      }
      Sweeper s{*fast, *other, sweeper.r0, sweeper.r1, o.pose.orientation.toRotationMatrix(),
                p0.position, p1.position, o.pose.position, sweeper.best, stack};
      if (s.run()) {
        sweeper.best = s.best;
        hit = true;
      }
    }
    if (!hit) continue;
    const double t = sweeper.best;
    body.pose.position = p0.position + t * (p1.position - p0.position);
    body.pose.orientation = p0.orientation.slerp(t, p1.orientation).normalized();
    refreshWorldInertia(body);
    ++stats.clamped;
  }
  return stats;
}

}  // namespace stc
