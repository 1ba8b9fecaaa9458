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

struct Sweeper {
  const ShapeBounds& fast;
  const ShapeBounds& other;
  Mat3 r0, r1, ro0, ro1;  // fast body at start and end, other body at start and end
  Vec3 x0, x1, xo0, xo1;
  double best;            // earliest hit so far, fraction of the tick
  std::vector<std::pair<std::int32_t, std::int32_t>>& stack;
  Vec3 normal = Vec3::UnitZ();  // of the earliest hit, from the fast body towards the other
  Vec3 point = Vec3::Zero();

  // First instant the two leaves' voxel boxes overlap deeper than a quarter
  // of the thinner box's half extent on all six face axes, in their relative
  // motion (slab test of two boxes moving along lines, each kept at its end
  // orientation); -1 when they do not, or when they already do at the start
  // (a resting contact: the solver's). Penetration tested on boxes, not
  // spheres: a flat leaf's sphere reaches far beyond its voxels, and a body
  // sliding over a floor would keep running into the spheres ahead.
  // A hit that the discrete step handles is not one: while the boxes overlap
  // this tick they never get deeper than the thinner box's half extent (its
  // centre does not cross the other's face). A body grazing a wall or sliding
  // over a tiled floor keeps its motion; only one that would pass through or
  // sink in is held back. The depth (shallowest axis) is concave in t: taken
  // at the middle and the end of the overlap.
  double leafEntry(std::int32_t nf, std::int32_t no, int& axis, double& side) const {
    const std::size_t f = static_cast<std::size_t>(nf);
    const std::size_t o = static_cast<std::size_t>(no);
    const Vec3 local_f = fast.tree->node(nf).centre + fast.box_offset[f];
    const Vec3 local_o = other.tree->node(no).centre + other.box_offset[o];
    const Vec3 d0 = ro0 * local_o + xo0 - (r0 * local_f + x0);  // other's box centre from the fast one's
    const Vec3 d1 = ro1 * local_o + xo1 - (r1 * local_f + x1);
    const Vec3& hf = fast.box_half[f];
    const Vec3& ho = other.box_half[o];
    const double thinner = std::min(hf.minCoeff(), ho.minCoeff());
    const double tolerance = 0.25 * thinner;
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    double full[6], x0[6], dx[6];  // per axis: overlap extent, centre offset at start, its change
    int entry_axis = 0;
    for (int k = 0; k < 6; ++k) {
      const Vec3 u = k < 3 ? Vec3(r1.col(k)) : Vec3(ro1.col(k - 3));
      full[k] = hf.dot((r1.transpose() * u).cwiseAbs()) + ho.dot((ro1.transpose() * u).cwiseAbs());
      const double reach = full[k] - tolerance;
      if (reach <= 0.0) return -1.0;
      x0[k] = d0.dot(u);
      dx[k] = d1.dot(u) - x0[k];
      const double x0u = x0[k];
      if (dx[k] == 0.0) {
        if (std::abs(x0u) >= reach) return -1.0;
        continue;
      }
      const double t1 = (-reach - x0u) / dx[k];
      const double t2 = (reach - x0u) / dx[k];
      const double enter = std::min(t1, t2);
      if (enter > lo) {
        lo = enter;
        entry_axis = k;
      }
      hi = std::min(hi, std::max(t1, t2));
      if (lo >= hi) return -1.0;
    }
    if (lo <= 0.0 || lo > best) return -1.0;  // overlapping at the start, never, or later
    const auto depth = [&](double t) {
      double d = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 6; ++k) d = std::min(d, full[k] - std::abs(x0[k] + t * dx[k]));
      return d;
    };
    const double last = std::min(hi, 1.0);
    if (std::max(depth(0.5 * (lo + last)), depth(last)) <= thinner) return -1.0;  // a graze
    axis = entry_axis;
    const Vec3 u = axis < 3 ? Vec3(r1.col(axis)) : Vec3(ro1.col(axis - 3));
    side = (d0 + lo * (d1 - d0)).dot(u) >= 0.0 ? 1.0 : -1.0;
    return lo;
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
      const Vec3 b0 = ro0 * o.centre + xo0;
      const Vec3 b1 = ro1 * o.centre + xo1;
      const bool f_leaf = f.child_count == 0;
      const bool o_leaf = o.child_count == 0;
      if (f_leaf && o_leaf) {
        int axis = 0;
        double side = 1.0;
        const double t = leafEntry(nf, no, axis, side);
        if (t >= 0.0 && t < best) {
          best = t;
          hit = true;
          normal = side * (axis < 3 ? Vec3(r1.col(axis)) : Vec3(ro1.col(axis - 3)));
          point = 0.5 * (a0 + t * (a1 - a0) + b0 + t * (b1 - b0));
        }
        continue;
      }
      const double bound = fast.reach[static_cast<std::size_t>(nf)] + other.reach[static_cast<std::size_t>(no)];
      if (firstTouch(a0 - b0, (a1 - b1) - (a0 - b0), bound, best) < 0.0) continue;
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

bool sweepable(const BodyState& body, const ShapeBounds* shape) {
  return shape != nullptr && shape->tree != nullptr && !body.is_static;
}

}  // namespace

std::size_t markFastBodies(const std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes, double threshold,
                           std::vector<std::uint8_t>& fast) {
  fast.assign(bodies.size(), 0);
  std::size_t count = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const ShapeBounds* shape = shapes[i];
    if (!sweepable(bodies[i], shape)) continue;
    const Pose& p0 = start[i];
    const Pose& p1 = bodies[i].pose;
    const double moved = (p1.position - p0.position).norm() +
                         p0.orientation.angularDistance(p1.orientation) * shape->bound_radius;
    if (moved > threshold * shape->min_leaf_radius) {
      fast[i] = 1;
      ++count;
    }
  }
  return count;
}

SweepStats sweepFastBodies(std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes,
                           const std::vector<std::array<std::uint32_t, 2>>& pairs, std::size_t pair_count,
                           SweepScratch& scratch) {
  SweepStats stats;
  scratch.hits.assign(bodies.size(), SweepHit{});
  scratch.clamped.clear();
  if (scratch.fast.size() != bodies.size()) return stats;  // markFastBodies not run on these bodies
  for (const std::uint8_t f : scratch.fast) stats.fast_bodies += f;
  if (stats.fast_bodies == 0) return stats;
  // Every pair sees the end poses of this integration: the result does not
  // depend on the pair order.
  for (std::size_t k = 0; k < pair_count; ++k) {
    for (int side = 0; side < 2; ++side) {
      const std::uint32_t i = pairs[k][static_cast<std::size_t>(side)];
      const std::uint32_t j = pairs[k][static_cast<std::size_t>(1 - side)];
      if (!scratch.fast[i] || shapes[j] == nullptr || shapes[j]->tree == nullptr) continue;
      SweepHit& hit = scratch.hits[i];
      const Pose& p0 = start[i];
      const Pose& p1 = bodies[i].pose;
      const Pose& q0 = start[j];
      const Pose& q1 = bodies[j].pose;
      Sweeper s{*shapes[i], *shapes[j], p0.orientation.toRotationMatrix(), p1.orientation.toRotationMatrix(),
                q0.orientation.toRotationMatrix(), q1.orientation.toRotationMatrix(),
                p0.position, p1.position, q0.position, q1.position, hit.t, scratch.stack};
      if (!s.run()) continue;
      hit.t = s.best;
      hit.pair = static_cast<std::uint32_t>(k);
      hit.point = s.point;
      hit.normal = side == 0 ? s.normal : Vec3(-s.normal);  // from pairs[k][0] towards pairs[k][1]
    }
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const double t = scratch.hits[i].t;
    if (!(t < 1.0)) continue;
    BodyState& body = bodies[i];
    const Pose& p0 = start[i];
    const Pose p1 = body.pose;
    body.pose.position = p0.position + t * (p1.position - p0.position);
    body.pose.orientation = p0.orientation.slerp(t, p1.orientation).normalized();
    refreshWorldInertia(body);
    scratch.clamped.push_back(static_cast<std::uint32_t>(i));
    ++stats.clamped;
  }
  return stats;
}

}  // namespace stc
