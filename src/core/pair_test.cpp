// PairTest: the paper's Collision object (3.3.2, 3.4.1). One step() tests
// every sphere hit's target against its test list and builds the next hits.
#include "sphere_tree_collision/pair_test.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace stc {
namespace {

// Room for a typical frontier, so a pooled PairTest stops growing early.
constexpr std::size_t kInitialCapacity = 32;

void reserveAtLeast(std::vector<SphereHit>& v) {
  if (v.capacity() < kInitialCapacity) v.reserve(kInitialCapacity);
}
void reserveAtLeast(std::vector<SpherePair>& v) {
  if (v.capacity() < kInitialCapacity) v.reserve(kInitialCapacity);
}

// World centre of a body-frame point, with the rotation as a matrix: one
// matrix per step is cheaper than a quaternion rotation per sphere.
inline Vec3 toWorld(const Mat3& r, const Vec3& p, const Vec3& body) { return r * body + p; }

}  // namespace

void PairTest::reset(const PairBody& a, const PairBody& b) {
  a_ = a;
  b_ = b;
  reserveAtLeast(hits_);
  reserveAtLeast(next_hits_);
  reserveAtLeast(last_pairs_);
  reserveAtLeast(step_leaf_pairs_);
  reserveAtLeast(step_pairs_);
  hits_.clear();
  next_hits_.clear();
  last_pairs_.clear();
  // Paper: the root of tree A is the target, the root of tree B the test list.
  hits_.push_back(SphereHit{0, 0, 1, 0});
  best_last_ = 0;
  status_ = PairStatus::Unresolved;
  steps_ = 0;
  deepest_level_ = -1;
  sphere_tests_ = 0;
}

int PairTest::step() {
  if (resolved()) return 0;

  const SphereNode* nodes[2] = {a_.tree->nodes().data(), b_.tree->nodes().data()};
  const Mat3 rotation[2] = {a_.pose->orientation.toRotationMatrix(),
                            b_.pose->orientation.toRotationMatrix()};
  const Vec3 position[2] = {a_.pose->position, b_.pose->position};

  next_hits_.clear();
  step_leaf_pairs_.clear();
  step_pairs_.clear();
  int tests = 0;

  for (const SphereHit& hit : hits_) {
    const int ts = hit.target_side;
    const int ms = 1 - ts;
    const SphereNode& target = nodes[ts][hit.target];
    const Vec3 target_centre = toWorld(rotation[ts], position[ts], target.centre);
    const bool target_leaf = target.child_count == 0;
    tests += hit.test_count;
    deepest_level_ = std::max({deepest_level_, target.level, nodes[ms][hit.test_first].level});

    for (std::int32_t m = hit.test_first; m < hit.test_first + hit.test_count; ++m) {
      const SphereNode& member = nodes[ms][m];
      const double reach = target.radius + member.radius;
      const Vec3 member_centre = toWorld(rotation[ms], position[ms], member.centre);
      if ((member_centre - target_centre).squaredNorm() > reach * reach) continue;

      // Keep a on tree A and b on tree B whichever tree holds the target.
      const SpherePair pair = ts == 0 ? SpherePair{hit.target, m} : SpherePair{m, hit.target};
      const bool member_leaf = member.child_count == 0;
      if (target_leaf && member_leaf) {
        step_leaf_pairs_.push_back(pair);
      } else if (!target_leaf) {
        // Crossover: the member becomes the target, the target's children the test list.
        step_pairs_.push_back(pair);
        next_hits_.push_back(SphereHit{m, target.first_child, target.child_count,
                                       static_cast<std::uint8_t>(ms)});
      } else {
        // Unequal heights: a leaf target stays, the member's children become the test list.
        step_pairs_.push_back(pair);
        next_hits_.push_back(SphereHit{hit.target, member.first_child, member.child_count,
                                       static_cast<std::uint8_t>(ts)});
      }
    }
  }

  ++steps_;
  sphere_tests_ += tests;
  if (!step_leaf_pairs_.empty()) {
    status_ = PairStatus::Colliding;
    last_pairs_.swap(step_leaf_pairs_);
    hits_.clear();
  } else if (!step_pairs_.empty()) {
    last_pairs_.swap(step_pairs_);
    hits_.swap(next_hits_);
  } else {
    // Nothing intersects: lastPairs() keeps the deepest pairs found before.
    status_ = PairStatus::Separate;
    hits_.clear();
    return tests;
  }
  chooseBestLastPair();
  return tests;
}

// The deepest pair is the one with the smallest spheres; among equally small
// ones, the one that overlaps most (face-on rather than across an edge), so
// the contact normal of a face contact is the face normal.
void PairTest::chooseBestLastPair() {
  const SphereTree& ta = *a_.tree;
  const SphereTree& tb = *b_.tree;
  double best_reach = std::numeric_limits<double>::infinity();
  double best_overlap = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < last_pairs_.size(); ++i) {
    const SphereNode& na = ta.node(last_pairs_[i].a);
    const SphereNode& nb = tb.node(last_pairs_[i].b);
    const double reach = na.radius + nb.radius;
    if (reach > best_reach * (1.0 + 1e-12)) continue;
    const double overlap = reach - (b_.pose->apply(nb.centre) - a_.pose->apply(na.centre)).norm();
    if (reach < best_reach * (1.0 - 1e-12) || overlap > best_overlap) {
      best_reach = std::min(best_reach, reach);
      best_overlap = overlap;
      best_last_ = i;
    }
  }
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
