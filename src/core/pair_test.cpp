// PairTest: the paper's Collision object (3.3.2, 3.4.1). One step() tests
// every sphere hit's target against its test list and builds the next hits.
#include "pair_test.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {
namespace {

inline bool isLeaf(const SphereNode& n) { return n.child_count == 0; }

// The deepest of a step's pairs: the smallest spheres; among equally small
// ones, the one that overlaps most (face-on rather than across an edge), so
// the contact normal of a face contact is the face normal.
struct DeepestPair {
  double reach = std::numeric_limits<double>::infinity();
  double overlap = -std::numeric_limits<double>::infinity();
  std::size_t index = 0;

  void offer(double pair_reach, double distance_sq, std::size_t pair_index) {
    if (pair_reach > reach * (1.0 + 1e-12)) return;
    const double pair_overlap = pair_reach - std::sqrt(distance_sq);
    if (pair_reach < reach * (1.0 - 1e-12) || pair_overlap > overlap) {
      reach = std::min(reach, pair_reach);
      overlap = pair_overlap;
      index = pair_index;
    }
  }
};

// Tests a target against one test list. Every candidate is written and the
// write index advances only on an intersection: no unpredictable branch per
// sphere test. The tree side and whether the target is a leaf are template
// arguments, so each of the four loops is straight-line code. Intersections
// that make a new hit are not written as pairs here: the pair is the hit's
// target and the parent of its test list (see step()).
template <int kTargetSide, bool kTargetLeaf, bool kMembersLeaves = false>
void testList(const SphereHit& hit, const SphereNode& target, const Vec3& target_centre,
              const SphereNode* members, SphereHit* hit_out, SpherePair* leaf_out, std::size_t& hit_count,
              std::size_t& leaf_pairs) {
  constexpr auto kMemberSide = static_cast<std::uint8_t>(1 - kTargetSide);
  const std::int32_t end = hit.test_first + hit.test_count;
  for (std::int32_t m = hit.test_first; m < end; ++m) {
    const SphereNode& member = members[m];
    const double reach = target.radius + member.radius;
    const bool touching = (member.centre - target_centre).squaredNorm() <= reach * reach;
    if constexpr (!kTargetLeaf) {
      // Crossover: the member becomes the target, the target's children the test list.
      hit_out[hit_count] = SphereHit{m, target.first_child, target.child_count, kMemberSide};
      hit_count += touching;
    } else if constexpr (kMembersLeaves) {
      // Leaf against leaves (the last level of equal-height trees): leaf pairs only.
      leaf_out[leaf_pairs] = kTargetSide == 0 ? SpherePair{hit.target, m} : SpherePair{m, hit.target};
      leaf_pairs += touching;
    } else {
      // Unequal heights: a leaf target stays, the member's children become
      // the test list; a leaf member makes a leaf pair instead (a on tree A).
      const bool member_leaf = isLeaf(member);
      hit_out[hit_count] = SphereHit{hit.target, member.first_child, member.child_count,
                                     static_cast<std::uint8_t>(kTargetSide)};
      hit_count += touching && !member_leaf;
      leaf_out[leaf_pairs] = kTargetSide == 0 ? SpherePair{hit.target, m} : SpherePair{m, hit.target};
      leaf_pairs += touching && member_leaf;
    }
  }
}

}  // namespace

void PairTest::reset(const PairBody& a, const PairBody& b, PairArena* arena) {
  a_ = a;
  b_ = b;
  shared_arena_ = arena;
  if (!arena) {
    if (!own_arena_ || own_arena_.use_count() > 1) own_arena_ = std::make_shared<PairArena>();
    own_arena_->clear();
  }
  PairArena& store = this->arena();
  // Paper: the root of tree A is the target, the root of tree B the test list.
  *store.hits.room(1, hits_begin_) = SphereHit{0, 0, 1, 0};
  store.hits.commit(1);
  hits_count_ = 1;
  last_begin_ = last_count_ = best_last_ = 0;
  best_valid_ = false;
  status_ = PairStatus::Unresolved;
  steps_ = 0;
  next_tests_ = 1;
  track_gap_ = false;
  frontier_gap_ = 0.0;
  deepest_level_ = -1;
  sphere_tests_ = 0;
}

void PairTest::resumeColliding(const PairBody& a, const PairBody& b, PairArena* arena, const SpherePair& leaf,
                               int level) {
  reset(a, b, arena);
  hits_count_ = 0;  // the root hit reset() made stays unused in the arena
  PairArena& store = this->arena();
  *store.pairs.room(1, last_begin_) = leaf;
  store.pairs.commit(1);
  last_count_ = 1;
  status_ = PairStatus::Colliding;
  next_tests_ = 0;
  deepest_level_ = level;
}

int PairTest::step() {
  if (resolved()) return 0;

  // Distances do not change under a rigid motion, so each target centre is
  // taken into the body frame of the tree it is tested against, once per hit;
  // the members are then used as stored, with no transform per sphere test.
  // The poses are fixed for the test's lifetime (one tick): the relative
  // transforms are made at the first step.
  if (steps_ == 0) {
    const Mat3 ra = a_.pose->orientation.toRotationMatrix();
    const Mat3 rb = b_.pose->orientation.toRotationMatrix();
    const Vec3 pa_in_b = rb.transpose() * (a_.pose->position - b_.pose->position);
    rot_to_other_[0] = rb.transpose() * ra;
    rot_to_other_[1] = ra.transpose() * rb;
    pos_to_other_[0] = pa_in_b;
    pos_to_other_[1] = -(rot_to_other_[1] * pa_in_b);
  }
  const SphereNode* nodes[2] = {a_.tree->nodes().data(), b_.tree->nodes().data()};
  const std::int32_t last_level[2] = {a_.tree->levelCount() - 1, b_.tree->levelCount() - 1};

  // New hits and this step's intersecting pairs are appended to the arena,
  // with room for the worst case (every test intersects) made first.
  PairArena& store = arena();
  const auto most = static_cast<std::size_t>(next_tests_);  // tests if every hit is done
  std::size_t new_hits_begin = 0, pairs_begin = 0;
  SphereHit* hit_out = store.hits.room(most, new_hits_begin);
  SpherePair* pair_out = store.pairs.room(most, pairs_begin);
  const SphereHit* hits = store.hits.at(hits_begin_);
  std::size_t hit_count = 0, leaf_pairs = 0;
  int tests = 0;

  for (std::size_t h = 0; h < hits_count_; ++h) {
    if (first_contact_only_ && leaf_pairs > 0) break;  // the answer is known
    const SphereHit& hit = hits[h];
    tests += hit.test_count;
    const int ts = hit.target_side;
    const SphereNode& target = nodes[ts][hit.target];
    const Vec3 centre = rot_to_other_[ts] * target.centre + pos_to_other_[ts];
    const SphereNode* members = nodes[1 - ts];
    deepest_level_ = std::max({deepest_level_, target.level, members[hit.test_first].level});
    // 0: inner target, 1: leaf target, 2: leaf target and a test list on the
    // last level of its tree (all leaves: the last step of equal-height trees).
    int kind = 3 * ts;
    if (isLeaf(target)) kind += members[hit.test_first].level == last_level[1 - ts] ? 2 : 1;
    switch (kind) {
      case 0: testList<0, false>(hit, target, centre, members, hit_out, pair_out, hit_count, leaf_pairs); break;
      case 1: testList<0, true>(hit, target, centre, members, hit_out, pair_out, hit_count, leaf_pairs); break;
      case 2: testList<0, true, true>(hit, target, centre, members, hit_out, pair_out, hit_count, leaf_pairs); break;
      case 3: testList<1, false>(hit, target, centre, members, hit_out, pair_out, hit_count, leaf_pairs); break;
      case 4: testList<1, true>(hit, target, centre, members, hit_out, pair_out, hit_count, leaf_pairs); break;
      default: testList<1, true, true>(hit, target, centre, members, hit_out, pair_out, hit_count, leaf_pairs); break;
    }
  }

  ++steps_;
  sphere_tests_ += tests;
  best_valid_ = false;
  std::size_t pair_count = leaf_pairs;
  if (leaf_pairs > 0) {
    // Colliding: the last pairs are the leaf pairs; the new hits are dropped.
    status_ = PairStatus::Colliding;
    hits_count_ = 0;
    next_tests_ = 0;
  } else if (hit_count > 0) {
    // Every intersection made one new hit, whose target and the parent of
    // its test list are the two spheres that intersected.
    int next_tests = 0;
    for (std::size_t i = 0; i < hit_count; ++i) {
      const SphereHit& next = hit_out[i];
      const std::int32_t other = nodes[1 - next.target_side][next.test_first].parent;
      pair_out[i] = next.target_side == 0 ? SpherePair{next.target, other} : SpherePair{other, next.target};
      next_tests += next.test_count;
    }
    next_tests_ = next_tests;
    if (track_gap_) {  // centres compared in B's body frame, as the step tested them
      frontier_gap_ = (rot_to_other_[0] * nodes[0][pair_out[0].a].centre + pos_to_other_[0] -
                       nodes[1][pair_out[0].b].centre).norm();
    }
    pair_count = hit_count;
    store.hits.commit(hit_count);
    hits_begin_ = new_hits_begin;
    hits_count_ = hit_count;
  } else {
    // Nothing intersects: lastPairs() keeps the deepest pairs found before.
    status_ = PairStatus::Separate;
    hits_count_ = 0;
    next_tests_ = 0;
    return tests;
  }
  store.pairs.commit(pair_count);
  last_begin_ = pairs_begin;
  last_count_ = pair_count;
  return tests;
}

// Chosen on first use after a step (most pair tests are never asked), with
// the centres compared in B's body frame, as the steps tested them.
SpherePair PairTest::lastPair() const {
  const SpherePairSpan last = lastPairs();
  if (!best_valid_) {
    DeepestPair deepest;
    for (std::size_t i = 0; i < last.size(); ++i) {
      const SphereNode& na = a_.tree->node(last[i].a);
      const SphereNode& nb = b_.tree->node(last[i].b);
      const double distance_sq = (rot_to_other_[0] * na.centre + pos_to_other_[0] - nb.centre).squaredNorm();
      deepest.offer(na.radius + nb.radius, distance_sq, i);
    }
    best_last_ = deepest.index;
    best_valid_ = true;
  }
  return last[best_last_];
}

Vec3 PairTest::lastCentreA() const {
  if (!hasLastPair()) return a_.pose->position;
  return a_.pose->apply(a_.tree->node(lastPair().a).centre);
}

Vec3 PairTest::lastCentreB() const {
  if (!hasLastPair()) return b_.pose->position;
  return b_.pose->apply(b_.tree->node(lastPair().b).centre);
}

Vec3 PairTest::centreOfCollision() const {
  const Vec3 ca = lastCentreA();
  const Vec3 cb = lastCentreB();
  if (!hasLastPair()) return 0.5 * (ca + cb);
  const double ra = a_.tree->node(lastPair().a).radius;
  const double rb = b_.tree->node(lastPair().b).radius;
  const Vec3 d = cb - ca;
  const double dist = d.norm();
  if (dist <= 0.0) return ca;  // coincident centres: the shared centre
  // Along the line of centres, A covers [-ra, ra] and B covers [dist - rb, dist + rb]
  // (distances from ca); the collision centre is the middle of their overlap.
  const double lo = std::max(-ra, dist - rb);
  const double hi = std::min(ra, dist + rb);
  return ca + d * (0.5 * (lo + hi) / dist);
}

double PairTest::gapEstimate() const { return (lastCentreB() - lastCentreA()).norm(); }

double PairTest::gapBound() const {
  if (hasLastPair()) return a_.tree->node(lastPair().a).h + b_.tree->node(lastPair().b).h;
  // No intersecting pair known yet. The root centres are points of the root
  // spheres, each within h of its shape, so the gap is at most
  // |cA - cB| + h_A + h_B whether or not the roots touch (after a separate
  // first step this still holds; it is then merely loose).
  const Vec3 ca = a_.pose->apply(a_.tree->root().centre);
  const Vec3 cb = b_.pose->apply(b_.tree->root().centre);
  return (cb - ca).norm() + a_.tree->root().h + b_.tree->root().h;
}

}  // namespace stc
