// PairTest: the paper's Collision object (3.3.2, 3.4.1). Holds the sphere-hit
// list of one broad-phase pair and descends one level per step().
#pragma once

#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/types.hpp"

#include <vector>

namespace stc {

enum class PairStatus : std::uint8_t { Unresolved, Colliding, Separate };
const char* toString(PairStatus s);

// A target sphere on one tree and a test list (a contiguous run of nodes,
// the children of one node, or a root) on the other tree.
struct SphereHit {
  std::int32_t target = 0;       // node index in tree `target_side`
  std::int32_t test_first = 0;   // first node of the test list, other tree
  std::int32_t test_count = 1;
  std::uint8_t target_side = 0;  // 0: target on tree A, 1: on tree B
};

// Two spheres found intersecting: node a on tree A, node b on tree B.
struct SpherePair {
  std::int32_t a = 0;
  std::int32_t b = 0;
};

// Inputs a PairTest reads; owned by the World, stable during a tick.
struct PairBody {
  EntityId id = kInvalidEntity;
  const SphereTree* tree = nullptr;
  const Pose* pose = nullptr;  // body frame (tree frame) to world
};

class PairTest {
 public:
  // Start a fresh test at the roots. Keeps vector capacity (no allocation once warm).
  void reset(const PairBody& a, const PairBody& b);

  // Descend one level: test every sphere hit's target against its test list.
  // Outcomes (paper 3.4.1): a leaf-leaf intersection -> Colliding; no
  // intersection at all -> Separate; otherwise new hits (crossover between
  // trees; when the target is a leaf the target stays and the test list
  // becomes the children of the intersecting member) -> stays Unresolved.
  // Returns the number of sphere-sphere tests done. No-op when resolved.
  int step();

  PairStatus status() const { return status_; }
  bool resolved() const { return status_ != PairStatus::Unresolved; }
  int stepsDone() const { return steps_; }
  int deepestLevel() const { return deepest_level_; }  // max tree level tested
  std::int64_t sphereTests() const { return sphere_tests_; }

  // Intersecting sphere pairs found by the last step that found any: leaf
  // pairs when Colliding, the current frontier when Unresolved.
  const std::vector<SpherePair>& lastPairs() const { return last_pairs_; }
  // Deepest (smallest combined radius) of lastPairs(); valid when hasLastPair().
  bool hasLastPair() const { return !last_pairs_.empty(); }
  SpherePair lastPair() const { return last_pairs_[best_last_]; }
  // World centres of the spheres of lastPair() (entity origins if none).
  Vec3 lastCentreA() const;
  Vec3 lastCentreB() const;
  // Midpoint of the segment of the line of centres inside both spheres of lastPair().
  Vec3 centreOfCollision() const;
  // Paper's gap estimate: distance between the last intersecting centres
  // (entity origins before any sphere was tested).
  double gapEstimate() const;
  // Rigorous bound on the true gap: h_a + h_b of lastPair(). Without a last
  // pair (no test yet, or separate at the roots): |c_A - c_B| + h_A + h_B of
  // the roots, which holds whether or not the roots touch.
  double gapBound() const;

  const PairBody& bodyA() const { return a_; }
  const PairBody& bodyB() const { return b_; }

 private:
  void chooseBestLastPair();

  PairBody a_, b_;
  std::vector<SphereHit> hits_, next_hits_;
  std::vector<SpherePair> last_pairs_;
  // Scratch of one step, kept for its capacity: leaf pairs and other intersecting pairs.
  std::vector<SpherePair> step_leaf_pairs_, step_pairs_;
  std::size_t best_last_ = 0;
  PairStatus status_ = PairStatus::Unresolved;
  int steps_ = 0;
  int deepest_level_ = -1;
  std::int64_t sphere_tests_ = 0;
};

}  // namespace stc
