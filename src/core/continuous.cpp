// Anti-tunnelling: fast bodies are swept from their start to their end pose
// and put back at their first contact (paper 3.5: backtracking to the instant
// of collision).
#include "continuous.hpp"

#include "dynamics.hpp"

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

// A node pair whose leaves close on each other by less than this share of the
// thinnest box half extent below them holds no hit (Sweeper::run). Below the
// exact 3/4, so rounding never drops a hit leafEntry would take.
constexpr double kNoHitShare = 0.74;

// A hit is the first instant two leaf boxes overlap deeper than this share of
// the thinner box's least half extent on every face axis (leafEntry): along
// the axis they meet on, that is their overlap there.
constexpr double kHitOverlapShare = 0.25;

struct Sweeper {
  const ShapeBounds& first;   // the pair's bodies
  const ShapeBounds& second;
  Mat3 r0, r1, ro0, ro1;  // first body at start and end, second body at start and end
  Vec3 x0, x1, xo0, xo1;
  double best;            // earliest hit so far, fraction of the tick
  std::vector<std::pair<std::int32_t, std::int32_t>>& stack;
  bool anchor_first = true;  // the contact point is taken below the first body's leaf (else the second's)
  double turn_first = 0.0;   // angle each body turns through this tick (rad)
  double turn_second = 0.0;
  bool prune_by_boxes = true;  // SweepScratch::prune_by_boxes
  Mat3 relative_abs = (ro1.transpose() * r1).cwiseAbs();  // |cosines| between the end axes
  Vec3 normal = Vec3::UnitZ();  // of the earliest hit, from the first body towards the second
  Vec3 point = Vec3::Zero();
  double overlap = 0.0;  // of the earliest hit's boxes along the normal, at the hit
  std::size_t leaf_tests = 0;

  // Two boxes (body-frame centres and half extents, the first's on the first
  // body), their centres moving along lines through the tick, each kept at
  // its end orientation: along each of the six face axes the overlap extent,
  // the centres' offset at the start and its change, and the times (lo, hi)
  // in which they overlap deeper than `tolerance` on every axis at once.
  struct BoxMotion {
    Vec3 d0, d1;  // second's box centre from the first's, at start and end
    double full[6], offset[6], change[6];  // axes 0-2: the first box's faces, 3-5: the second's
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    int entry_axis = 0;  // the axis whose overlap begins last (at lo)
  };
  // False when no such time exists.
  bool overlapInterval(const Vec3& local_f, const Vec3& hf, const Vec3& local_o, const Vec3& ho, double tolerance,
                       BoxMotion& m) const {
    m.d0 = ro0 * local_o + xo0 - (r0 * local_f + x0);
    m.d1 = ro1 * local_o + xo1 - (r1 * local_f + x1);
    const Vec3 d0_f = r1.transpose() * m.d0, d1_f = r1.transpose() * m.d1;
    const Vec3 d0_o = ro1.transpose() * m.d0, d1_o = ro1.transpose() * m.d1;
    for (int k = 0; k < 6; ++k) {
      if (k < 3) {
        m.full[k] = hf[k] + ho.dot(relative_abs.col(k));
        m.offset[k] = d0_f[k];
        m.change[k] = d1_f[k] - d0_f[k];
      } else {
        m.full[k] = hf.dot(relative_abs.row(k - 3)) + ho[k - 3];
        m.offset[k] = d0_o[k - 3];
        m.change[k] = d1_o[k - 3] - d0_o[k - 3];
      }
      const double reach = m.full[k] - tolerance;
      if (reach <= 0.0) return false;
      if (m.change[k] == 0.0) {
        if (std::abs(m.offset[k]) >= reach) return false;
        continue;
      }
      const double t1 = (-reach - m.offset[k]) / m.change[k];
      const double t2 = (reach - m.offset[k]) / m.change[k];
      const double enter = std::min(t1, t2);
      if (enter > m.lo) {
        m.lo = enter;
        m.entry_axis = k;
      }
      m.hi = std::min(m.hi, std::max(t1, t2));
      if (m.lo >= m.hi) return false;
    }
    return true;
  }

  // Whether any leaf pair below nodes nf, no can be a hit (leafEntry): one
  // needs a time in the tick at which its boxes overlap deeper than the
  // thinner box's half extent on all six axes. Leaf boxes lie within their
  // nodes' leaves boxes (same body frame), so along every axis they overlap
  // no deeper than those do: without such a time for the nodes' boxes, at
  // the least half extent below them, there is none below. Boxes keep their
  // end orientation while their centres move on lines from the start pose:
  // a leaf box's centre strays from its place in the node's box by at most
  // turn x its distance, so the node's box is grown by that.
  bool mayHitBelow(std::int32_t nf, std::int32_t no) const {
    const std::size_t f = static_cast<std::size_t>(nf);
    const std::size_t o = static_cast<std::size_t>(no);
    const double thinnest = 0.999 * std::min(first.thinnest[f], second.thinnest[o]);  // rounding: keep more
    const Vec3& half_f = first.leaves_half[f];
    const Vec3& half_o = second.leaves_half[o];
    BoxMotion m;
    return overlapInterval(first.leaves_centre[f], half_f + Vec3::Constant(turn_first * half_f.norm()),
                           second.leaves_centre[o], half_o + Vec3::Constant(turn_second * half_o.norm()), thinnest,
                           m) &&
           m.hi > 0.0 && m.lo < 1.0;
  }

  // First instant the two leaves' voxel boxes overlap deeper than a quarter
  // of the thinner box's half extent on all six face axes, in their relative
  // motion (overlapInterval); -1 when they do not, or when they already do
  // at the start (a resting contact: the solver's). Penetration tested on
  // boxes, not spheres: a flat leaf's sphere reaches far beyond its voxels,
  // and a body sliding over a floor would keep running into the spheres ahead.
  // A hit that the discrete step handles is not one: while the boxes overlap
  // this tick they never get deeper than the thinner box's half extent (its
  // centre does not cross the other box's face). A body grazing a wall or
  // sliding over a tiled floor keeps its motion; only one that would pass
  // through or sink in is held back. The depth (shallowest axis) is concave in t: taken
  // at the middle and the end of the overlap.
  //
  // On a hit, `n` is the face axis the boxes met on (from the first towards
  // the second) and `p` the contact point: on the plane halfway between the
  // two faces; across it, the box centre of the body to be held back (the
  // first when anchor_first), kept within the boxes' overlap: a ball landing
  // flat on a plate is pushed through its centre, not spun.
  double leafEntry(std::int32_t nf, std::int32_t no, Vec3& n, Vec3& p) const {
    const std::size_t f = static_cast<std::size_t>(nf);
    const std::size_t o = static_cast<std::size_t>(no);
    const Vec3& local_f = first.leaves_centre[f];  // a leaf's leaves box is its own voxel box
    const Vec3& local_o = second.leaves_centre[o];
    const Vec3& hf = first.leaves_half[f];
    const Vec3& ho = second.leaves_half[o];
    const double thinner = std::min(hf.minCoeff(), ho.minCoeff());
    BoxMotion m;
    if (!overlapInterval(local_f, hf, local_o, ho, kHitOverlapShare * thinner, m)) return -1.0;
    const double lo = m.lo;
    if (lo <= 0.0 || lo > best) return -1.0;  // overlapping at the start, never, or later
    const auto depth = [&](double t) {
      double d = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 6; ++k) d = std::min(d, m.full[k] - std::abs(m.offset[k] + t * m.change[k]));
      return d;
    };
    const double last = std::min(m.hi, 1.0);
    if (std::max(depth(0.5 * (lo + last)), depth(last)) <= thinner) return -1.0;  // a graze
    const Mat3& frame = m.entry_axis < 3 ? r1 : ro1;  // the box whose face it is
    const int k = m.entry_axis % 3;
    n = m.offset[m.entry_axis] + lo * m.change[m.entry_axis] >= 0.0 ? Vec3(frame.col(k)) : Vec3(-frame.col(k));
    const Vec3 ca = r0 * local_f + x0 + lo * (r1 * local_f + x1 - (r0 * local_f + x0));  // box centres at the hit
    const Vec3 cb = ca + m.d0 + lo * (m.d1 - m.d0);
    const auto extent = [&](const Vec3& u, const Vec3& h, const Mat3& r) { return h.dot((r.transpose() * u).cwiseAbs()); };
    p = 0.5 * (ca.dot(n) + extent(n, hf, r1) + cb.dot(n) - extent(n, ho, ro1)) * n;
    const Vec3& anchor = anchor_first ? ca : cb;
    for (const int j : {(k + 1) % 3, (k + 2) % 3}) {  // across the face: below the held body's box centre
      const Vec3 u = frame.col(j);
      const double lo_u = std::max(ca.dot(u) - extent(u, hf, r1), cb.dot(u) - extent(u, ho, ro1));
      const double hi_u = std::min(ca.dot(u) + extent(u, hf, r1), cb.dot(u) + extent(u, ho, ro1));
      p += std::clamp(anchor.dot(u), std::min(lo_u, hi_u), std::max(lo_u, hi_u)) * u;
    }
    return lo;
  }

  bool run() {
    bool hit = false;
    stack.clear();
    stack.emplace_back(0, 0);
    while (!stack.empty()) {
      const auto [nf, no] = stack.back();
      stack.pop_back();
      const SphereNode& f = first.tree->node(nf);
      const SphereNode& o = second.tree->node(no);
      const Vec3 a0 = r0 * f.centre + x0;
      const Vec3 a1 = r1 * f.centre + x1;
      const Vec3 b0 = ro0 * o.centre + xo0;
      const Vec3 b1 = ro1 * o.centre + xo1;
      const std::size_t fi = static_cast<std::size_t>(nf), oi = static_cast<std::size_t>(no);
      // No leaf pair below moves far enough against the other to be a hit:
      // leafEntry refuses a pair less than a quarter of the thinner box deep
      // at the start, and takes one only deeper than the thinner box's half
      // extent, so its box centres must close by more than 3/4 of it. A box
      // centre moves at most its node's centre's motion plus turn x reach.
      // (A pile's resting neighbours: their node pairs overlap from the
      // start and would otherwise be opened down to every touching leaf.)
      const double closing = ((a1 - a0) - (b1 - b0)).norm() + turn_first * first.reach[fi] +
                             turn_second * second.reach[oi];
      if (closing < kNoHitShare * std::min(first.thinnest[fi], second.thinnest[oi])) continue;
      const bool f_leaf = f.child_count == 0;
      const bool o_leaf = o.child_count == 0;
      if (f_leaf && o_leaf) {
        Vec3 n, p;
        ++leaf_tests;
        const double t = leafEntry(nf, no, n, p);
        if (t >= 0.0 && t < best) {
          best = t;
          hit = true;
          normal = n;
          point = p;
          overlap = kHitOverlapShare * std::min(first.leaves_half[static_cast<std::size_t>(nf)].minCoeff(),
                                                second.leaves_half[static_cast<std::size_t>(no)].minCoeff());
        }
        continue;
      }
      const double bound = first.reach[fi] + second.reach[oi];
      if (firstTouch(a0 - b0, (a1 - b1) - (a0 - b0), bound, best) < 0.0) continue;
      if (prune_by_boxes && !mayHitBelow(nf, no)) continue;
      // Open the node with the larger reach (a leaf cannot be opened).
      const bool open_first = !f_leaf && (o_leaf || first.reach[fi] >= second.reach[oi]);
      if (open_first) {
        for (std::int32_t c = f.first_child; c < f.first_child + f.child_count; ++c) stack.emplace_back(c, no);
      } else {
        for (std::int32_t c = o.first_child; c < o.first_child + o.child_count; ++c) stack.emplace_back(nf, c);
      }
    }
    return hit;
  }
};

bool sweepable(const ShapeBounds* shape) { return shape != nullptr && shape->tree != nullptr; }

bool sweepable(const BodyState& body, const ShapeBounds* shape) { return sweepable(shape) && !body.is_static; }

}  // namespace

bool movesFast(const BodyState& body, const Pose& start, const ShapeBounds* shape, double threshold) {
  if (!sweepable(body, shape)) return false;
  const double moved = (body.pose.position - start.position).norm() +
                       start.orientation.angularDistance(body.pose.orientation) * shape->bound_radius;
  return moved > threshold * shape->min_leaf_radius;
}

std::size_t markFastBodies(const std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes, double threshold,
                           std::vector<std::uint8_t>& fast) {
  fast.assign(bodies.size(), 0);
  std::size_t count = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    fast[i] = movesFast(bodies[i], start[i], shapes[i], threshold) ? 1 : 0;
    count += fast[i];
  }
  return count;
}

namespace {

// What every lane of one sweep reads.
struct SweepInput {
  const std::vector<BodyState>& bodies;
  const std::vector<Pose>& start;
  const std::vector<const ShapeBounds*>& shapes;
  const std::vector<std::array<std::uint32_t, 2>>& pairs;
  const std::vector<std::uint8_t>& fast;
  double threshold;
  bool prune_by_boxes;
  const std::uint8_t* moved = nullptr;  // after the first round: only pairs with a body put back in the last
  const SweepHit* held = nullptr;       // after the first round: per body, the instant it stopped (1: not put back)
};

// A hit of pair k at fraction t of `body`'s path holds it back, when it is
// the earliest of the lane's for that body so far.
void recordHit(SweepLane& lane, std::uint32_t body, std::size_t k, double t, const Vec3& point, const Vec3& normal,
               double overlap) {
  SweepHit& hit = lane.hits[body];
  if (!(t < hit.t)) return;
  if (!(hit.t < 1.0)) lane.touched.push_back(body);
  hit.t = t;
  hit.pair = static_cast<std::uint32_t>(k);
  hit.point = point;
  hit.normal = normal;
  hit.separation = -overlap;
}

// One pair's sweep, counted in the lane's stats; whether it hit.
bool sweepOnce(Sweeper& s, const SweepInput& in, SweepLane& lane) {
  s.prune_by_boxes = in.prune_by_boxes;
  ++lane.stats.pairs;
  const bool found = s.run();
  lane.stats.leaf_tests += s.leaf_tests;
  return found;
}

// The first round: pair k in the relative motion of its two bodies; a hit
// holds back whichever of them is fast, both at the same instant.
void sweepBoth(const SweepInput& in, std::size_t k, SweepLane& lane) {
  const std::vector<std::uint8_t>& fast = in.fast;
  const std::uint32_t a = in.pairs[k][0];
  const std::uint32_t b = in.pairs[k][1];
  const ShapeBounds* sa = in.shapes[a];
  const ShapeBounds* sb = in.shapes[b];
  if (!sweepable(sa) || !sweepable(sb)) return;
  const Pose& p0 = in.start[a];
  const Pose& p1 = in.bodies[a].pose;
  const Pose& q0 = in.start[b];
  const Pose& q1 = in.bodies[b].pose;
  // Bodies falling side by side are fast but not towards each other: the
  // pair is swept only when its relative motion is fast.
  const double turn_a = p0.orientation.angularDistance(p1.orientation);
  const double turn_b = q0.orientation.angularDistance(q1.orientation);
  const double relative = ((p1.position - p0.position) - (q1.position - q0.position)).norm() +
                          turn_a * sa->bound_radius + turn_b * sb->bound_radius;
  const double finest = std::min(fast[a] ? sa->min_leaf_radius : sb->min_leaf_radius,
                                 fast[b] ? sb->min_leaf_radius : sa->min_leaf_radius);
  if (!(relative > in.threshold * finest)) return;
  // Only a hit earlier than a fast body's earliest so far matters.
  const double latest = std::max(fast[a] ? lane.hits[a].t : 0.0, fast[b] ? lane.hits[b].t : 0.0);
  Sweeper s{*sa, *sb, p0.orientation.toRotationMatrix(), p1.orientation.toRotationMatrix(),
            q0.orientation.toRotationMatrix(), q1.orientation.toRotationMatrix(),
            p0.position, p1.position, q0.position, q1.position, latest, lane.stack};
  s.anchor_first = fast[a] != 0;
  s.turn_first = turn_a;
  s.turn_second = turn_b;
  if (!sweepOnce(s, in, lane)) return;
  for (const std::uint32_t i : {a, b}) {
    if (fast[i]) recordHit(lane, i, k, s.best, s.point, s.normal, s.overlap);  // normal from a (the sweeper's first body) towards b
  }
}

// Later rounds: `mover`, fast, from its start to where it now is, against
// `held`, put back in the last round and standing where it was put (it
// stopped there first: a body falling onto it holds back the one falling,
// never the one below). A hit holds back the mover alone.
void sweepAgainstHeld(const SweepInput& in, std::size_t k, std::uint32_t mover, std::uint32_t held,
                      SweepLane& lane) {
  const ShapeBounds* sm = in.shapes[mover];
  const ShapeBounds* sh = in.shapes[held];
  if (!sweepable(sm) || !sweepable(sh)) return;
  const Pose& p0 = in.start[mover];
  const Pose& p1 = in.bodies[mover].pose;
  const Pose& q = in.bodies[held].pose;
  const double turn = p0.orientation.angularDistance(p1.orientation);
  const double moved = (p1.position - p0.position).norm() + turn * sm->bound_radius;
  if (!(moved > in.threshold * sm->min_leaf_radius)) return;
  const Mat3 rq = q.orientation.toRotationMatrix();
  Sweeper s{*sm, *sh, p0.orientation.toRotationMatrix(), p1.orientation.toRotationMatrix(), rq, rq,
            p0.position, p1.position, q.position, q.position, lane.hits[mover].t, lane.stack};
  s.turn_first = turn;
  if (!sweepOnce(s, in, lane)) return;
  recordHit(lane, mover, k, s.best, s.point, mover == in.pairs[k][0] ? s.normal : Vec3(-s.normal), s.overlap);
}

// Sweeps pairs [begin, end) in order into the lane's hits: in the first
// round every pair with a fast body, later only the pairs of a body put back
// in the last round, the other body against it when that one is fast and
// stopped later than it (a body never put back stopped at the tick's end).
// A body put back stands where it stopped from that instant on: one that
// stopped earlier never meets it there. Swept against bodies that stopped
// after it, touching cubes landing together held each other back in turns,
// round after round, each time further (the fractions multiply), until a
// whole cluster of a landing pile stood near its start with its velocities
// untouched; no contact of the tick turned them, so the next tick held them
// back again while gravity's gain piled up (cube_box 10,000: 43 m/s stored
// on cubes moving mm/s).
void sweepPairs(const SweepInput& in, std::size_t begin, std::size_t end, SweepLane& lane) {
  const std::vector<std::uint8_t>& fast = in.fast;
  for (std::size_t k = begin; k < end; ++k) {
    const std::uint32_t a = in.pairs[k][0];
    const std::uint32_t b = in.pairs[k][1];
    if (in.moved == nullptr) {
      if (fast[a] || fast[b]) sweepBoth(in, k, lane);
      continue;
    }
    if (in.moved[b] != 0 && fast[a] != 0 && in.held[b].t < in.held[a].t) sweepAgainstHeld(in, k, a, b, lane);
    if (in.moved[a] != 0 && fast[b] != 0 && in.held[a].t < in.held[b].t) sweepAgainstHeld(in, k, b, a, lane);
  }
}

// Runs of the pairs: one with one thread, a few per thread otherwise (runs
// differ in how many fast pairs they hold).
std::size_t laneCount(const Workers* workers, std::size_t pair_count) {
  if (workers == nullptr || workers->threads() <= 1) return 1;
  constexpr std::size_t kPairsPerLane = 256;
  return std::clamp<std::size_t>(pair_count / kPairsPerLane, 1, 4 * static_cast<std::size_t>(workers->threads()));
}

}  // namespace

SweepStats sweepFastBodies(std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes,
                           const std::vector<std::array<std::uint32_t, 2>>& pairs, std::size_t pair_count,
                           double threshold, SweepScratch& scratch, const Workers* workers) {
  SweepStats stats;
  scratch.hits.assign(bodies.size(), SweepHit{});
  scratch.clamped.clear();
  scratch.clamped.reserve(bodies.size());  // grows with the bodies only
  if (scratch.fast.size() != bodies.size()) return stats;  // markFastBodies not run on these bodies
  for (const std::uint8_t f : scratch.fast) stats.fast_bodies += f;
  if (stats.fast_bodies == 0) return stats;
  // Rounds of sweeps (sweepPairs says which pairs, and how). Every pair of a
  // round sees the poses the round started with (bodies are put back after
  // all its pairs): the result does not depend on the pair order.
  const std::size_t lanes = laneCount(workers, pair_count);
  if (scratch.lanes.size() < lanes) scratch.lanes.resize(lanes);
  for (std::size_t l = 0; l < lanes; ++l) {
    SweepLane& lane = scratch.lanes[l];
    if (lane.hits.size() != bodies.size()) lane.hits.assign(bodies.size(), SweepHit{});
    lane.touched.reserve(bodies.size());
  }
  scratch.round.assign(bodies.size(), SweepHit{});
  scratch.moved.assign(bodies.size(), 0);
  SweepInput in{bodies, start, shapes, pairs, scratch.fast, threshold, scratch.prune_by_boxes};
  const auto run = [&](std::size_t l, std::size_t) {
    const auto [begin, end] = chunkRange(pair_count, l, lanes);
    sweepPairs(in, begin, end, scratch.lanes[l]);
  };
  while (stats.rounds < kMaxSweepRounds) {
    ++stats.rounds;
    for (std::size_t l = 0; l < lanes; ++l) {
      scratch.lanes[l].touched.clear();
      scratch.lanes[l].stats = SweepStats{};
    }
    if (lanes == 1) {
      run(0, 1);
    } else {
      workers->forChunks(lanes, run);
    }
    // Lanes in pair order, a later one taking a body only when strictly earlier.
    for (std::size_t l = 0; l < lanes; ++l) {
      SweepLane& lane = scratch.lanes[l];
      stats.pairs += lane.stats.pairs;
      stats.leaf_tests += lane.stats.leaf_tests;
      for (const std::uint32_t i : lane.touched) {
        if (lane.hits[i].t < scratch.round[i].t) scratch.round[i] = lane.hits[i];
        lane.hits[i] = SweepHit{};
      }
    }
    // Each body hit this round back to its hit on the path it swept (start to
    // where it was), so over the rounds hits[i].t is the fraction of the tick.
    bool held = false;
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      scratch.moved[i] = 0;
      SweepHit& hit = scratch.round[i];
      const double t = hit.t;
      if (!(t < 1.0)) continue;
      BodyState& body = bodies[i];
      const Pose& p0 = start[i];
      const Pose p1 = body.pose;
      body.pose.position = p0.position + t * (p1.position - p0.position);
      body.pose.orientation = p0.orientation.slerp(t, p1.orientation).normalized();
      refreshWorldInertia(body);
      SweepHit& kept = scratch.hits[i];
      if (!(kept.t < 1.0)) {
        scratch.clamped.push_back(static_cast<std::uint32_t>(i));
        ++stats.clamped;
      }
      hit.t *= kept.t;
      kept = hit;
      hit = SweepHit{};
      scratch.moved[i] = 1;
      held = true;
    }
    if (!held) break;
    in.moved = scratch.moved.data();
    in.held = scratch.hits.data();
  }
  return stats;
}

}  // namespace stc
