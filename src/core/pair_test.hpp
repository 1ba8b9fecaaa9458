// PairTest: the paper's Collision object (3.3.2, 3.4.1). Holds the sphere-hit
// list of one broad-phase pair and descends one level per step().
#pragma once

#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/types.hpp"

#include <algorithm>
#include <memory>
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

// Read-only view of a run of sphere pairs (what lastPairs() returns).
class SpherePairSpan {
 public:
  SpherePairSpan() = default;
  SpherePairSpan(const SpherePair* data, std::size_t size) : data_(data), size_(size) {}
  const SpherePair* begin() const { return data_; }
  const SpherePair* end() const { return data_ + size_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const SpherePair& operator[](std::size_t i) const { return data_[i]; }

 private:
  const SpherePair* data_ = nullptr;
  std::size_t size_ = 0;
};

// Runs of T handed out one after another, in blocks that never move: a
// growth adds a block instead of reallocating, so it copies nothing and
// touches only the new block's pages. (Doubling one vector instead cost a
// 10,000-cube tick 200 ms of copying and page faults, twice while its pile
// formed.) A run is named by a handle, its block and offset, which stays
// valid until clear(); its address stays valid too.
template <typename T>
class RunBlocks {
 public:
  // The largest block made for runs that fit in one: 1 MB of hits.
  static constexpr std::size_t kBlockElements = std::size_t{1} << 16;

  // Room for a run of up to `most` elements, named `handle`; commit() takes
  // the part used. Blocks start small and each new one is as big as the ones
  // before together (up to kBlockElements, or `most` when larger).
  T* room(std::size_t most, std::size_t& handle) {
    while (block_ >= blocks_.size() || blocks_[block_].size() - used_ < most) {
      if (block_ < blocks_.size()) {  // the rest of this block is too short
        ++block_;
        used_ = 0;
        continue;
      }
      blocks_.emplace_back(std::max(most, std::clamp(capacity_, std::size_t{64}, kBlockElements)));
      capacity_ += blocks_.back().size();
    }
    handle = (block_ << 32) | used_;
    return blocks_[block_].data() + used_;
  }
  void commit(std::size_t count) { used_ += count; }
  const T* at(std::size_t handle) const { return blocks_[handle >> 32].data() + (handle & 0xFFFFFFFFu); }
  void clear() { block_ = used_ = 0; }
  std::size_t capacity() const { return capacity_; }

 private:
  std::vector<std::vector<T>> blocks_;
  std::size_t block_ = 0, used_ = 0;  // where the next run starts
  std::size_t capacity_ = 0;
};

// Storage of the hits and pairs of many PairTests during one tick. Steps
// only append; clear() once per tick, before the tests are reset. Shared by
// all pair tests of a World's chunk, its blocks settle at the largest tick's
// total, so steady-state ticks do not allocate (per-test vectors would each
// have to grow to their own worst frontier, one at a time).
struct PairArena {
  RunBlocks<SphereHit> hits;
  RunBlocks<SpherePair> pairs;
  void clear() {
    hits.clear();
    pairs.clear();
  }
};

// Inputs a PairTest reads; owned by the World, stable during a tick.
struct PairBody {
  EntityId id = kInvalidEntity;
  const SphereTree* tree = nullptr;
  const Pose* pose = nullptr;  // body frame (tree frame) to world
};

class PairTest {
 public:
  // Start a fresh test at the roots. With an arena, hits and pairs go there
  // (the caller clears it between ticks, and the pairs stay valid until
  // then); without one, the test uses and clears its own. No allocation once warm.
  void reset(const PairBody& a, const PairBody& b, PairArena* arena = nullptr);

  // A pair whose contacts are carried over from an earlier tick
  // (PairContactCache): Colliding at once, with no sphere tested, its last
  // pair the deepest leaf pair found then and its deepest level that one's.
  void resumeColliding(const PairBody& a, const PairBody& b, PairArena* arena, const SpherePair& leaf, int level);

  // Descend one level: test every sphere hit's target against its test list.
  // Outcomes (paper 3.4.1): a leaf-leaf intersection -> Colliding; no
  // intersection at all -> Separate; otherwise new hits (crossover between
  // trees; when the target is a leaf the target stays and the test list
  // becomes the children of the intersecting member) -> stays Unresolved.
  // Returns the number of sphere-sphere tests done. No-op when resolved.
  int step();

  // Yes/no mode (like FCL's collide with one contact): the step that finds a
  // leaf pair stops at the end of that sphere hit, so lastPairs() holds the
  // leaf pairs of the hits done, not of the whole level. Off by default: the
  // response wants every leaf pair. Kept across reset().
  void setFirstContactOnly(bool on) { first_contact_only_ = on; }
  bool firstContactOnly() const { return first_contact_only_; }

  PairStatus status() const { return status_; }
  bool resolved() const { return status_ != PairStatus::Unresolved; }
  int stepsDone() const { return steps_; }
  int deepestLevel() const { return deepest_level_; }  // max tree level tested
  std::int64_t sphereTests() const { return sphere_tests_; }
  // What the next step() will cost, known from the last one: its sphere
  // tests (1 after reset; 0 once resolved). And, once asked for with
  // trackFrontierGap() (until the next reset), the distance of the centres of
  // the frontier's first sphere pair, the paper's gap estimate g for it, made
  // by each step while its spheres are in cache (0 before). A scheduler's
  // priority needs no more.
  int nextStepTests() const { return next_tests_; }
  void trackFrontierGap() { track_gap_ = true; }
  double frontierGap() const { return frontier_gap_; }
  // Asks the cache for what step() reads of this object: for a scheduler
  // that steps tests in no memory order, a few steps ahead.
  void prefetchForStep() const {
    const char* begin = reinterpret_cast<const char*>(this);
    const char* end = reinterpret_cast<const char*>(&best_last_);
    for (const char* line = begin; line < end; line += 64) __builtin_prefetch(line);
    __builtin_prefetch(end - 1);
  }

  // Intersecting sphere pairs found by the last step that found any: leaf
  // pairs when Colliding, the current frontier when Unresolved.
  SpherePairSpan lastPairs() const {
    return last_count_ != 0 ? SpherePairSpan(arena().pairs.at(last_begin_), last_count_) : SpherePairSpan();
  }
  // Deepest of lastPairs(): smallest combined radius, then largest overlap.
  // Valid when hasLastPair().
  bool hasLastPair() const { return last_count_ != 0; }
  SpherePair lastPair() const;
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
  const PairArena& arena() const { return shared_arena_ ? *shared_arena_ : *own_arena_; }
  PairArena& arena() { return shared_arena_ ? *shared_arena_ : *own_arena_; }

  // What step() and a scheduler read come first, in as few cache lines as
  // they fit (prefetchForStep() asks for them); the rest after best_last_.
  PairBody a_, b_;
  PairArena* shared_arena_ = nullptr;  // not owned
  // The frontier (what the next step tests) and the last pairs are runs of
  // the arena, named by their handles (RunBlocks).
  std::size_t hits_begin_ = 0, hits_count_ = 0;
  std::size_t last_begin_ = 0, last_count_ = 0;
  double frontier_gap_ = 0.0;
  std::int64_t sphere_tests_ = 0;
  int steps_ = 0;
  int next_tests_ = 1;  // sum of the frontier hits' test_count
  int deepest_level_ = -1;
  PairStatus status_ = PairStatus::Unresolved;
  bool first_contact_only_ = false;
  bool track_gap_ = false;
  mutable bool best_valid_ = false;
  // Body frame s to body frame 1 - s, made at the first step.
  Mat3 rot_to_other_[2] = {Mat3::Identity(), Mat3::Identity()};
  Vec3 pos_to_other_[2] = {Vec3::Zero(), Vec3::Zero()};
  // Cold: read only on request, or without a shared arena.
  mutable std::size_t best_last_ = 0;  // index in lastPairs(), chosen lazily
  // Used when reset() got no arena; made then (a World's tests share their
  // chunk's, and a smaller test is fewer cache lines to step).
  std::shared_ptr<PairArena> own_arena_;
};

}  // namespace stc
