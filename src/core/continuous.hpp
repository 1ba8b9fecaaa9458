// Anti-tunnelling: swept test of fast bodies (paper: backtrack to the instant
// of collision), after the broad phase.
#pragma once

#include "shape_bounds.hpp"
#include "sphere_tree_collision/body.hpp"
#include "sphere_tree_collision/types.hpp"
#include "workers.hpp"

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace stc {

struct SweepStats {
  std::size_t fast_bodies = 0;
  std::size_t clamped = 0;  // moved back to their first contact
  std::size_t pairs = 0;    // pairs swept (relative motion fast)
  std::size_t leaf_tests = 0;  // leaf box pairs tested
  std::size_t rounds = 0;      // sweeps of the pairs run: the first, and one after each that held a body back
};

// Rounds of the sweep at most in one tick (sweepFastBodies): a hold-back
// passes one body up a column a round, and a tick's fall closes few gaps.
constexpr std::size_t kMaxSweepRounds = 16;

// A fast body's earliest hit of the tick.
struct SweepHit {
  double t = 1.0;              // fraction of the tick at the hit; 1: none
  std::uint32_t pair = 0;      // index into the candidate pairs
  Vec3 point = Vec3::Zero();   // halfway between the two leaf boxes' faces, below the held body's box centre
  Vec3 normal = Vec3::UnitZ(); // face axis the boxes met on, from pairs[pair][0] towards [1]
  double separation = 0.0;     // the two boxes' along the normal at the hit (< 0: they overlap)
};

// One task's run of the pairs: its own node stack and earliest hits, merged
// after all runs are done. A cache line of its own: lanes run side by side.
struct alignas(64) SweepLane {
  std::vector<std::pair<std::int32_t, std::int32_t>> stack;  // node pairs of one sweep
  std::vector<SweepHit> hits;            // per body; t = 1 except at `touched`
  std::vector<std::uint32_t> touched;    // bodies this lane found a hit for
  SweepStats stats;
};

// Kept between ticks so a tick allocates nothing.
struct SweepScratch {
  std::vector<std::uint8_t> fast;        // per body: moved far enough to be swept
  std::vector<SweepHit> hits;            // per body: the earliest over all lanes
  std::vector<std::uint32_t> clamped;    // bodies put back this tick
  std::vector<SweepHit> round;           // per body: the earliest of the round being merged
  std::vector<std::uint8_t> moved;       // per body: put back in the last round
  std::vector<SweepLane> lanes;          // runs of the pairs, in pair order
  // Node pairs whose leaves' boxes cannot reach a hit are not opened (the
  // same hits, far fewer leaf tests). false: every node pair the spheres let
  // through is opened (tests compare the two).
  bool prune_by_boxes = true;
};

// A body moved from `start` to body.pose this tick is fast when it moved
// (rotation counted at its farthest leaf) more than `threshold` of its
// smallest leaf radius (ResponseOptions::sweep_threshold). A static body and
// shape == nullptr never are.
bool movesFast(const BodyState& body, const Pose& start, const ShapeBounds* shape, double threshold);
// movesFast for each of bodies (from start[i], shapes[i]) into `fast`; returns the count.
std::size_t markFastBodies(const std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes, double threshold,
                           std::vector<std::uint8_t>& fast);

// Sweeps each fast body (scratch.fast, from markFastBodies) against its
// partners in pairs[0..pair_count) (dense body indices: the broad phase's
// pairs, found with swept boxes), never against all bodies, and only where
// the pair's relative motion is fast by the same threshold. Both bodies of a
// pair move along their chords from start to end pose; the leaves' voxel boxes
// are tested in that relative motion (hierarchy pruned by ShapeBounds::reach).
// A hit is the first instant a pair of leaf boxes overlaps deeper than a
// quarter of the thinner box, when at the end they would have passed through
// each other or sunk in deeper than the thinner box's half extent (a graze
// the discrete step resolves is left to it). The body is put back at its
// earliest hit (position lerp, orientation slerp). Its velocity is kept: the
// narrow phase of the same tick finds the contact there, and the response
// turns the approach (Physics::buildContacts adds the hit as a contact when the
// narrow phase gave that pair none proven at the leaves: an interrupted pair's
// frontier contacts need not turn it, and the body, held back tick after
// tick, stored gravity's gain without moving). scratch.hits and scratch.clamped say
// where. Pairs already overlapping at the start are resting contacts, left to
// the solver.
// A body held back changes its pairs' relative motion: cubes falling side by
// side or in a column are not fast against each other, until the lowest is
// stopped and the next falls the rest of the tick into it. So the pairs of
// the bodies put back are swept again: the other body, when fast, from its
// start to where it now is, against the one put back standing where it was
// put (it stopped there first), and a hit holds back the moving one alone,
// further along that path. Rounds until none holds a body back, at most
// kMaxSweepRounds (what is left is the solver's).
// With `workers` the pairs are cut into runs swept in parallel, each into its
// own hits; a body takes the earliest hit, on a tie the one of the lowest pair
// index, as the one run in pair order does: the result is the same bit for bit
// whatever the thread count.
SweepStats sweepFastBodies(std::vector<BodyState>& bodies, const std::vector<Pose>& start,
                           const std::vector<const ShapeBounds*>& shapes,
                           const std::vector<std::array<std::uint32_t, 2>>& pairs, std::size_t pair_count,
                           double threshold, SweepScratch& scratch, const Workers* workers = nullptr);

}  // namespace stc
