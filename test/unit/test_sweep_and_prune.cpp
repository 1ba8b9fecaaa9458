// SweepAndPrune: the incremental pair set must equal a brute-force O(n^2)
// Aabb::overlaps test after every update(), through coherent motion, teleports,
// adds and removes; bad input is rejected with the field named.
#include "sweep_and_prune.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <map>
#include <new>
#include <random>
#include <unordered_set>
#include <vector>

// Counting allocator: proves update() does not allocate in steady state.
namespace {
std::atomic<bool> g_count_allocations{false};
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  if (g_count_allocations.load(std::memory_order_relaxed)) ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace stc {
namespace {

Aabb box(double x0, double y0, double z0, double x1, double y1, double z1) {
  Aabb b;
  b.min = Vec3(x0, y0, z0);
  b.max = Vec3(x1, y1, z1);
  return b;
}

Aabb cube(const Vec3& centre, double half) {
  Aabb b;
  b.min = centre - Vec3::Constant(half);
  b.max = centre + Vec3::Constant(half);
  return b;
}

using PairList = std::vector<std::pair<EntityId, EntityId>>;

PairList sorted(const std::vector<BroadPair>& pairs) {
  PairList out;
  out.reserve(pairs.size());
  for (const BroadPair& p : pairs) out.emplace_back(p.first, p.second);
  std::sort(out.begin(), out.end());
  return out;
}

PairList bruteForce(const std::vector<EntityId>& ids, const std::vector<Aabb>& boxes) {
  PairList out;
  for (std::size_t i = 0; i < ids.size(); ++i)
    for (std::size_t j = i + 1; j < ids.size(); ++j)
      if (boxes[i].overlaps(boxes[j]))
        out.emplace_back(std::min(ids[i], ids[j]), std::max(ids[i], ids[j]));
  std::sort(out.begin(), out.end());
  return out;
}

template <typename F>
void expectInputError(F&& f, const std::string& field) {
  try {
    f();
    ADD_FAILURE() << "expected InputError(" << field << ")";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
  }
}

TEST(SweepAndPrune, RejectsDuplicateAndUnknownIds) {
  SweepAndPrune sap;
  sap.add(7, cube(Vec3::Zero(), 1.0));
  sap.add(9, cube(Vec3(0.5, 0, 0), 1.0));
  expectInputError([&] { sap.add(7, cube(Vec3(5, 5, 5), 1.0)); }, "id");
  expectInputError([&] { sap.remove(8); }, "id");
  expectInputError([&] { sap.setBox(8, cube(Vec3::Zero(), 1.0)); }, "id");
  EXPECT_EQ(sap.size(), 2u);
  sap.update();
  // The rejected add did not move entity 7 away: the pair is still there.
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{7, 9}}));
  sap.remove(9);
  expectInputError([&] { sap.remove(9); }, "id");
  EXPECT_FALSE(sap.contains(9));
  EXPECT_TRUE(sap.contains(7));
}

TEST(SweepAndPrune, RejectsBadBoxes) {
  SweepAndPrune sap;
  const double nan = std::nan("");
  expectInputError([&] { sap.add(1, box(nan, 0, 0, 1, 1, 1)); }, "box");
  expectInputError([&] { sap.add(1, box(0, 0, 0, 1, INFINITY, 1)); }, "box");
  expectInputError([&] { sap.add(1, box(0, 2, 0, 1, 1, 1)); }, "box");
  EXPECT_FALSE(sap.contains(1));
  EXPECT_EQ(sap.size(), 0u);
  sap.add(1, cube(Vec3::Zero(), 1));
  sap.add(2, cube(Vec3(1.5, 0, 0), 1));
  sap.update();
  expectInputError([&] { sap.setBox(1, box(0, 0, nan, 1, 1, 1)); }, "box");
  sap.update();  // the rejected setBox left entity 1 where it was
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 2}}));
}

TEST(SweepAndPrune, TouchingBoxesOverlapLikeAabbOverlaps) {
  SweepAndPrune sap;
  sap.add(1, box(0, 0, 0, 1, 1, 1));
  sap.add(2, box(1, 0, 0, 2, 1, 1));  // shares a face with 1
  sap.add(3, box(2, 1, 1, 3, 2, 2));  // shares an edge... corner with 2
  sap.add(4, box(5, 5, 5, 5, 5, 5));  // a point
  sap.add(5, box(5, 5, 5, 6, 6, 6));  // touches the point at its corner
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 2}, {2, 3}, {4, 5}}));
  // Part by the smallest step: touching stops.
  sap.setBox(2, box(std::nextafter(1.0, 2.0), 0, 0, 2, 1, 1));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{2, 3}, {4, 5}}));
  // And back to touching from the other side of the ordering.
  sap.setBox(2, box(1, 0, 0, 2, 1, 1));
  sap.setBox(5, box(std::nextafter(5.0, 6.0), 5, 5, 6, 6, 6));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 2}, {2, 3}}));
}

TEST(SweepAndPrune, IdenticalBoxes) {
  SweepAndPrune sap;
  for (EntityId id : {40u, 10u, 30u}) sap.add(id, box(0, 0, 0, 1, 1, 1));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{10, 30}, {10, 40}, {30, 40}}));
  for (const BroadPair& p : sap.pairs()) EXPECT_LT(p.first, p.second);
  EXPECT_EQ(sap.lastSwapCount(), 0u);
  sap.update();  // nothing moved: nothing swapped, nothing changed
  EXPECT_EQ(sap.lastSwapCount(), 0u);
  EXPECT_EQ(sap.pairs().size(), 3u);
  sap.setBox(30, box(3, 0, 0, 4, 1, 1));
  sap.update();
  EXPECT_GT(sap.lastSwapCount(), 0u);
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{10, 40}}));
}

TEST(SweepAndPrune, AddAndRemoveBetweenTicks) {
  SweepAndPrune sap;
  sap.add(1, cube(Vec3::Zero(), 1));
  sap.add(2, cube(Vec3(1, 0, 0), 1));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 2}}));
  // Removed and re-added with another box before the next update.
  sap.remove(2);
  sap.add(2, cube(Vec3(10, 0, 0), 1));
  // Added and removed again before the next update: never appears.
  sap.add(3, cube(Vec3::Zero(), 1));
  sap.remove(3);
  sap.add(4, cube(Vec3(11, 0, 0), 1));
  sap.update();
  EXPECT_EQ(sap.size(), 3u);
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{2, 4}}));
  sap.remove(4);
  sap.remove(1);
  sap.update();
  EXPECT_TRUE(sap.pairs().empty());
  EXPECT_EQ(sap.size(), 1u);
  // Ids are arbitrary, the largest included.
  sap.add(kInvalidEntity, cube(Vec3(10.5, 0, 0), 1));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{2, kInvalidEntity}}));
}

TEST(SweepAndPrune, RemovingABatchLeavesThePairsOfOneBuiltWithoutIt) {
  // The broad phase drops a removed box's pairs through its own list, and
  // the pairs stay in the order a walk over all of them would leave: a fifth
  // of 4,000 boxes removed in one batch (many of them partners of each
  // other), between moves, must leave the pairs a fresh broad phase of the
  // rest finds, and each box's partners must be those of the pair list.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(0.0, 25.0);
  std::vector<EntityId> ids;
  std::vector<Aabb> boxes;
  SweepAndPrune sap;
  for (EntityId id = 0; id < 4000; ++id) {
    ids.push_back(id);
    boxes.push_back(cube(Vec3(coord(rng), coord(rng), coord(rng)), 0.6));
    sap.add(id, boxes.back());
  }
  sap.update();
  const std::size_t pairs_before = sap.pairs().size();
  ASSERT_GT(pairs_before, 4000u);
  std::vector<std::size_t> order(ids.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<EntityId> partners;
  for (int batch = 0; batch < 2; ++batch) {
    for (int k = 0; k < 400; ++k) {
      const std::size_t i = order.back();
      order.pop_back();
      sap.remove(ids[i]);
      ids[i] = kInvalidEntity;
    }
    // The survivors move a little: the removal and the sort share the update.
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] == kInvalidEntity || i % 3 != 0) continue;
      boxes[i].min.x() += 0.05;
      boxes[i].max.x() += 0.05;
      sap.setBox(ids[i], boxes[i]);
    }
    sap.update();
  }
  std::vector<EntityId> kept_ids;
  std::vector<Aabb> kept_boxes;
  SweepAndPrune fresh;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == kInvalidEntity) continue;
    kept_ids.push_back(ids[i]);
    kept_boxes.push_back(boxes[i]);
    fresh.add(ids[i], boxes[i]);
  }
  fresh.update();
  EXPECT_LT(sap.pairs().size(), pairs_before);
  EXPECT_EQ(sorted(sap.pairs()), sorted(fresh.pairs()));
  EXPECT_EQ(sorted(sap.pairs()), bruteForce(kept_ids, kept_boxes));
  // Each survivor's partners, from its own list, against the pair list.
  std::map<EntityId, std::vector<EntityId>> expected;
  for (const BroadPair& p : sap.pairs()) {
    expected[p.first].push_back(p.second);
    expected[p.second].push_back(p.first);
  }
  for (const EntityId id : kept_ids) {
    sap.partnersOf(id, &partners);
    std::sort(partners.begin(), partners.end());
    std::vector<EntityId>& want = expected[id];
    std::sort(want.begin(), want.end());
    EXPECT_EQ(partners, want) << "entity " << id;
  }
  // A removed box is unknown; its partners still name it until the next update.
  expectInputError([&] { sap.partnersOf(ids.size() + 1, &partners); }, "id");
  const EntityId gone = sap.pairs().front().first;
  const EntityId other = sap.pairs().front().second;
  sap.remove(gone);
  sap.partnersOf(other, &partners);
  EXPECT_NE(std::find(partners.begin(), partners.end(), gone), partners.end());
  sap.update();
  sap.partnersOf(other, &partners);
  EXPECT_EQ(std::find(partners.begin(), partners.end(), gone), partners.end());
}

TEST(SweepAndPrune, FarFromOriginAddsFindTouchingNeighbours) {
  // Adds after the first update go through the local sweep, whose window must
  // be safe against rounding at large coordinates.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> cell(0, 40);
  SweepAndPrune sap;
  std::vector<EntityId> ids;
  std::vector<Aabb> boxes;
  const double offset = 1e9;
  for (EntityId id = 0; id < 600; ++id) {
    const double x = offset + 0.5 * cell(rng), y = 0.5 * cell(rng), z = 0.5 * cell(rng);
    const Aabb b = box(x, y, z, x + 0.5 * (1 + cell(rng) % 3), y + 0.5, z + 0.5);
    sap.add(id, b);
    ids.push_back(id);
    boxes.push_back(b);
    if (id % 100 == 99) {
      sap.update();
      ASSERT_EQ(sorted(sap.pairs()), bruteForce(ids, boxes)) << "after " << id + 1 << " adds";
    }
  }
}

TEST(SweepAndPrune, PairsFollowBoxesAcrossBands) {
  // The lists are split into bands along another axis (y lists by z, about 4
  // mean box extents wide here: bands [0, 4.5), [4.5, 9), ...). A box moving
  // to another band keeps, loses and finds pairs there.
  SweepAndPrune sap;
  for (EntityId i = 0; i < 20; ++i) {  // spread the boxes over 0..39 on every axis
    const double d = 2.0 * i;
    sap.add(100 + i, box(d + 40, d, d, d + 41, d + 1, d + 1));
  }
  sap.add(1, box(0, 0, 3.0, 1, 1, 3.5));  // A, band 0
  sap.add(2, box(0, 0.5, 2, 1, 1.5, 6));  // B, bands 0 and 1
  sap.add(3, box(0, -3, 7, 1, -2, 8));    // C, band 1
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 2}}));
  // A leaves band 0 for band 1 (still inside B's z range) and away from B in y.
  sap.setBox(1, box(0, -3, 5.0, 1, -2, 5.5));
  sap.update();
  EXPECT_TRUE(sap.pairs().empty());
  // A moves within band 1 onto C.
  sap.setBox(1, box(0, -3, 6.0, 1, -2, 7.0));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 3}}));
  // Far away, in other bands on every list...
  sap.setBox(1, box(30, 10, 20, 31, 11, 20.5));
  sap.update();
  EXPECT_TRUE(sap.pairs().empty());
  // ... and back in one jump onto B: no list saw a flip, the entry sweep finds it.
  sap.setBox(1, box(0, 0, 3.0, 1, 1, 3.5));
  sap.update();
  EXPECT_EQ(sorted(sap.pairs()), (PairList{{1, 2}}));
}

TEST(SweepAndPrune, GrowAndShrinkMatchBruteForce) {
  // Counts changing by more than 2x re-choose the bands; pairs survive it.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  SweepAndPrune sap;
  std::vector<EntityId> ids;
  std::vector<Aabb> boxes;
  auto check = [&](const char* when) {
    sap.update();
    ASSERT_EQ(sorted(sap.pairs()), bruteForce(ids, boxes)) << when << " at " << ids.size();
  };
  EntityId next = 0;
  while (ids.size() < 1500) {
    const std::size_t grow = 1 + ids.size() / 3;
    for (std::size_t k = 0; k < grow; ++k) {
      const Vec3 c(u(rng) * 12, u(rng) * 12, u(rng) * 12);
      ids.push_back(next++);
      boxes.push_back(cube(c, 0.2 + 0.4 * u(rng)));
      sap.add(ids.back(), boxes.back());
    }
    check("growing");
  }
  while (ids.size() > 3) {
    const std::size_t shrink = ids.size() / 2;
    for (std::size_t k = 0; k < shrink; ++k) {
      const std::size_t i = rng() % ids.size();
      sap.remove(ids[i]);
      ids[i] = ids.back();
      boxes[i] = boxes.back();
      ids.pop_back();
      boxes.pop_back();
    }
    for (std::size_t i = 0; i < ids.size(); ++i) {  // and everyone moves a little
      const Vec3 d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
      boxes[i].min += 0.3 * d;
      boxes[i].max += 0.3 * d;
      sap.setBox(ids[i], boxes[i]);
    }
    check("shrinking");
  }
}

// --- Random movers -----------------------------------------------------------

struct Mover {
  EntityId id;
  Vec3 centre;
  Vec3 half;
  Vec3 velocity;
  bool on_grid;  // coordinates on a 1/8 grid: exact touching and equal endpoints
};

class MoverScene {
 public:
  explicit MoverScene(unsigned seed) : rng_(seed) {}

  void addRandom(SweepAndPrune& sap) {
    Mover m;
    do m.id = static_cast<EntityId>(rng_()); while (!used_ids_.insert(m.id).second);
    m.on_grid = uniform(0, 1) < 0.5;
    m.half = Vec3(uniform(0.2, 0.9), uniform(0.2, 0.9), uniform(0.2, 0.9));
    if (uniform(0, 1) < 0.15) m.half[static_cast<int>(uniform(0, 2.999))] *= 4;  // rods
    if (uniform(0, 1) < 0.05) m.half.setZero();                                 // points
    m.centre = randomPoint();
    m.velocity = Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * 0.08;
    if (m.on_grid) snap(m);
    sap.add(m.id, boxOf(m));
    movers_.push_back(m);
  }

  void removeRandom(SweepAndPrune& sap) {
    if (movers_.empty()) return;
    const std::size_t i = rng_() % movers_.size();
    sap.remove(movers_[i].id);
    movers_[i] = movers_.back();
    movers_.pop_back();
  }

  void move(SweepAndPrune& sap, double teleport_fraction) {
    for (Mover& m : movers_) {
      if (uniform(0, 1) < teleport_fraction) {
        m.centre = randomPoint();
      } else {
        m.velocity += Vec3(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)) * 0.01;
        m.centre += m.velocity;
        for (int a = 0; a < 3; ++a) {
          if (m.centre[a] < 0 || m.centre[a] > side_) m.velocity[a] = -m.velocity[a];
          m.centre[a] = std::clamp(m.centre[a], 0.0, side_);
        }
      }
      if (m.on_grid) snap(m);
      sap.setBox(m.id, boxOf(m));
    }
  }

  // Most boxes at rest (set again to the box they had, as the world does for
  // a still body), `fraction` of them moving; a moving one jumps with
  // probability `teleport_fraction`, to anywhere in a region `reach` times
  // the scene's side (beyond the boxes' bounds when the last full update was made).
  void moveSome(SweepAndPrune& sap, double fraction, double teleport_fraction, double reach) {
    for (Mover& m : movers_) {
      if (uniform(0, 1) < fraction) {
        if (uniform(0, 1) < teleport_fraction) {
          m.centre = randomPoint() * reach;
        } else {
          m.centre += m.velocity;
        }
        if (m.on_grid) snap(m);
      }
      sap.setBox(m.id, boxOf(m));
    }
  }

  PairList bruteForcePairs() const {
    ids_.clear();
    boxes_.clear();
    for (const Mover& m : movers_) {
      ids_.push_back(m.id);
      boxes_.push_back(boxOf(m));
    }
    return bruteForce(ids_, boxes_);
  }

  std::size_t size() const { return movers_.size(); }
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }

 private:
  static Aabb boxOf(const Mover& m) {
    Aabb b;
    b.min = m.centre - m.half;
    b.max = m.centre + m.half;
    return b;
  }
  static double snapValue(double v) { return std::round(v * 8) / 8; }
  static void snap(Mover& m) {
    for (int a = 0; a < 3; ++a) {
      m.centre[a] = snapValue(m.centre[a]);
      m.half[a] = snapValue(m.half[a]);
    }
  }
  Vec3 randomPoint() { return Vec3(uniform(0, side_), uniform(0, side_), uniform(0, side_)); }

  std::mt19937 rng_;
  double side_ = 19.0;  // about 2 neighbours per box at 1,000 boxes
  std::vector<Mover> movers_;
  std::unordered_set<EntityId> used_ids_;
  mutable std::vector<EntityId> ids_;
  mutable std::vector<Aabb> boxes_;
};

TEST(SweepAndPrune, ThousandMoversMatchBruteForceEveryTick) {
  MoverScene scene(2024);
  SweepAndPrune sap;
  for (int i = 0; i < 1000; ++i) scene.addRandom(sap);
  std::size_t total_pairs = 0, max_pairs = 0;
  for (int tick = 0; tick < 1000; ++tick) {
    const bool teleport_burst = tick % 97 == 50;
    scene.move(sap, teleport_burst ? 0.2 : 0.002);
    // Adds and removes: a few most ticks, a burst now and then.
    const int burst = tick % 131 == 70 ? 150 : 0;
    const int adds = burst + static_cast<int>(scene.uniform(0, 3.999));
    const int removes = burst + static_cast<int>(scene.uniform(0, 3.999));
    for (int i = 0; i < removes; ++i) scene.removeRandom(sap);
    for (int i = 0; i < adds; ++i) scene.addRandom(sap);
    sap.update();
    ASSERT_EQ(sap.size(), scene.size());
    const PairList expected = scene.bruteForcePairs();
    ASSERT_EQ(sorted(sap.pairs()), expected) << "tick " << tick;
    total_pairs += expected.size();
    max_pairs = std::max(max_pairs, expected.size());
  }
  // The scene is dense enough to test something.
  EXPECT_GT(total_pairs / 1000, 500u);
  RecordProperty("mean_pairs", static_cast<int>(total_pairs / 1000));
  RecordProperty("max_pairs", static_cast<int>(max_pairs));
}

// releaseMemory (after most boxes left, some removals still pending) keeps
// the pair set, and the rebuilt lists go on finding the right pairs.
TEST(SweepAndPrune, ReleaseMemoryKeepsThePairsAndGoesOn) {
  MoverScene scene(77);
  SweepAndPrune sap;
  for (int i = 0; i < 1000; ++i) scene.addRandom(sap);
  sap.update();
  for (int i = 0; i < 700; ++i) scene.removeRandom(sap);
  sap.update();
  for (int i = 0; i < 100; ++i) scene.removeRandom(sap);  // pending at the release
  for (int i = 0; i < 20; ++i) scene.addRandom(sap);
  sap.releaseMemory();
  ASSERT_EQ(sap.size(), scene.size());
  ASSERT_EQ(sorted(sap.pairs()), scene.bruteForcePairs());
  ASSERT_GT(sap.pairs().size(), 0u);
  for (int tick = 0; tick < 200; ++tick) {
    scene.move(sap, tick % 50 == 25 ? 0.2 : 0.002);
    if (tick % 40 == 10) {
      for (int i = 0; i < 50; ++i) scene.addRandom(sap);
    }
    sap.update();
    ASSERT_EQ(sorted(sap.pairs()), scene.bruteForcePairs()) << "tick " << tick;
  }
}

// A world mostly at rest: updates that touch few boxes sort only the bands
// of the moved ones and quantise them with the last full update's maps, also
// when a box jumps out of the bounds those maps were made for.
TEST(SweepAndPrune, FewMoversAmongBoxesAtRestMatchBruteForceEveryTick) {
  MoverScene scene(77);
  SweepAndPrune sap;
  for (int i = 0; i < 1000; ++i) scene.addRandom(sap);
  sap.update();
  std::size_t total_pairs = 0;
  for (int tick = 0; tick < 400; ++tick) {
    const double reach = tick % 50 == 25 ? 1.6 : 1.0;
    scene.moveSome(sap, tick % 100 == 60 ? 0.5 : 0.03, 0.1, reach);
    if (tick % 7 == 3) scene.removeRandom(sap);
    if (tick % 5 == 1) scene.addRandom(sap);
    sap.update();
    const PairList expected = scene.bruteForcePairs();
    ASSERT_EQ(sorted(sap.pairs()), expected) << "tick " << tick;
    total_pairs += expected.size();
  }
  EXPECT_GT(total_pairs / 400, 300u);  // dense enough to test something
}

// A broad phase rebuilt from another's boxes, slots, bands and pair order
// (restore: a saved world's) finds and drops pairs in the same order from
// then on, also among boxes on a grid whose endpoints tie; what is not the
// other's is refused by field and changes nothing.
TEST(SweepAndPrune, RestoredGoesOnInTheSameOrder) {
  MoverScene scene(5);
  SweepAndPrune sap;
  for (int i = 0; i < 600; ++i) scene.addRandom(sap);
  for (int tick = 0; tick < 30; ++tick) {
    scene.move(sap, 0.01);
    if (tick % 5 == 2) {
      scene.removeRandom(sap);
      scene.addRandom(sap);
    }
    sap.update();
  }
  ASSERT_TRUE(sap.settled());
  const SweepAndPrune::Banding banding = sap.banding();
  SweepAndPrune copy;
  EXPECT_FALSE(copy.settled());
  for (auto it = banding.slots.rbegin(); it != banding.slots.rend(); ++it) copy.add(*it, sap.box(*it));
  const std::vector<BroadPair> reversed(sap.pairs().rbegin(), sap.pairs().rend());
  ASSERT_GT(reversed.size(), 100u);
  expectInputError([&] { copy.restore(banding, {reversed.begin() + 1, reversed.end()}); }, "pairs");
  SweepAndPrune::Banding bad = banding;
  bad.top[1] += 0.5;
  expectInputError([&] { copy.restore(bad, sap.pairs()); }, "banding");
  bad = banding;
  std::swap(bad.endpoints[0][0].front(), bad.endpoints[0][0].back());
  expectInputError([&] { copy.restore(bad, sap.pairs()); }, "banding");
  bad = banding;
  bad.slots.pop_back();
  expectInputError([&] { copy.restore(bad, sap.pairs()); }, "banding");
  EXPECT_TRUE(copy.pairs().empty());
  copy.restore(banding, reversed);  // any order of the same pairs is taken
  EXPECT_EQ(copy.pairs(), reversed);
  copy.restore(banding, sap.pairs());
  ASSERT_EQ(copy.pairs(), sap.pairs());
  EXPECT_TRUE(copy.settled());
  for (int tick = 0; tick < 100; ++tick) {
    scene.move(sap, tick % 30 == 15 ? 0.2 : 0.01);
    for (const EntityId id : banding.slots) copy.setBox(id, sap.box(id));
    sap.update();
    copy.update();
    ASSERT_EQ(copy.pairs(), sap.pairs()) << "tick " << tick;
  }
}

TEST(SweepAndPrune, SteadyStateUpdateDoesNotAllocate) {
  // Periodic motion: after one period every tick repeats a previous one, so a
  // structure that reuses its storage never needs to grow again.
  constexpr int kPeriod = 40;
  constexpr int kCount = 800;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> base(kCount), amplitude(kCount);
  std::vector<EntityId> ids(kCount);
  std::vector<Aabb> boxes(kCount);
  SweepAndPrune sap;
  for (int i = 0; i < kCount; ++i) {
    base[i] = Vec3(u(rng), u(rng), u(rng)) * 16.0;
    amplitude[i] = Vec3(u(rng), u(rng), u(rng)) * 2.0;
    ids[i] = static_cast<EntityId>(1000 + 7 * i);
  }
  auto place = [&](int tick) {
    const double phase = 2 * M_PI * (tick % kPeriod) / kPeriod;
    for (int i = 0; i < kCount; ++i) {
      boxes[i] = cube(base[i] + amplitude[i] * std::sin(phase + i), 0.5);
      if (tick == 0)
        sap.add(ids[i], boxes[i]);
      else
        sap.setBox(ids[i], boxes[i]);
    }
  };
  for (int tick = 0; tick < 2 * kPeriod; ++tick) {
    place(tick);
    sap.update();
  }
  long allocations = 0;
  std::size_t swaps = 0;
  for (int tick = 2 * kPeriod; tick < 4 * kPeriod; ++tick) {
    place(tick);
    g_allocations = 0;
    g_count_allocations = true;
    sap.update();
    g_count_allocations = false;
    allocations += g_allocations;
    swaps += sap.lastSwapCount();
    ASSERT_EQ(sorted(sap.pairs()), bruteForce(ids, boxes)) << "tick " << tick;
  }
  EXPECT_GT(swaps, 0u);  // things did move
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace stc
