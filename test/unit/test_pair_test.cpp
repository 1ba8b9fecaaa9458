// PairTest: the paper's Collision object on hand-built shapes whose sphere
// trees are simple enough to reason about by hand.
#include "pair_test.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <utility>

namespace stc {
namespace {

const double kSqrt3 = std::sqrt(3.0);

VoxelShape makeGrid(int nx, int ny, int nz, double voxel,
                    const std::function<bool(int, int, int)>& filled) {
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(nx * ny * nz), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) occ[i + nx * (j + ny * k)] = filled(i, j, k) ? 1 : 0;
  return VoxelShape::create(nx, ny, nz, voxel, std::move(occ));
}

VoxelShape makeBlock(int nx, int ny, int nz, double voxel = 1.0) {
  return makeGrid(nx, ny, nz, voxel, [](int, int, int) { return true; });
}

// A shape, its tree about its centre of mass, and a pose.
struct Body {
  VoxelShape shape;
  SphereTree tree;
  Pose pose;

  Body(VoxelShape s, int levels, const Vec3& position = Vec3::Zero())
      : shape(std::move(s)),
        tree(SphereTree::build(shape, computeMassProperties(shape, 1.0).centre_of_mass,
                               SphereTreeOptions{levels, SphereFit::Tight})) {
    pose.position = position;
  }
  PairBody view(EntityId id) const { return PairBody{id, &tree, &pose}; }
};

// Run to resolution; returns the statuses after each step.
std::vector<PairStatus> runToEnd(PairTest& t) {
  std::vector<PairStatus> out;
  for (int guard = 0; guard < 64 && !t.resolved(); ++guard) {
    t.step();
    out.push_back(t.status());
  }
  return out;
}

bool anyLeafPairIntersects(const Body& a, const Body& b) {
  for (std::int32_t i = 0; i < static_cast<std::int32_t>(a.tree.nodes().size()); ++i) {
    if (!a.tree.isLeaf(i)) continue;
    for (std::int32_t j = 0; j < static_cast<std::int32_t>(b.tree.nodes().size()); ++j) {
      if (!b.tree.isLeaf(j)) continue;
      const double d = (a.pose.apply(a.tree.node(i).centre) - b.pose.apply(b.tree.node(j).centre)).norm();
      if (d <= a.tree.node(i).radius + b.tree.node(j).radius) return true;
    }
  }
  return false;
}

// Two 2x2x2 unit-voxel blocks with two-level trees: the root is the block's
// circumscribed sphere (r = sqrt 3), the 8 leaves the voxels' (r = sqrt 3 / 2).
class TinyBlocks : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(a.tree.levelCount(), 2);
    ASSERT_EQ(a.tree.nodes().size(), 9u);
    EXPECT_NEAR(a.tree.root().radius, kSqrt3, 1e-9);
    for (std::int32_t n = 1; n < 9; ++n) {
      ASSERT_TRUE(a.tree.isLeaf(n));
      EXPECT_NEAR(a.tree.node(n).radius, kSqrt3 / 2, 1e-9);
    }
  }
  Body a{makeBlock(2, 2, 2), 2};
  Body b{makeBlock(2, 2, 2), 2};
};

// Hand count, B shifted by d along x:
//  step 1: root vs root                      1 test, they intersect (d < 2 sqrt 3);
//  step 2: root B vs the 8 leaves of A       8 tests, the 4 leaves at x = +0.5 intersect;
//  step 3: each of those 4 vs the 8 leaves of B  32 tests.
// d = 2.5: leaves facing each other with equal y, z are 1.5 apart (< sqrt 3): 4 leaf pairs.
TEST_F(TinyBlocks, SphereTestsCountedExactlyWhenColliding) {
  b.pose.position = Vec3(2.5, 0, 0);
  PairTest t;
  t.reset(a.view(1), b.view(2));
  EXPECT_EQ(t.deepestLevel(), -1);
  EXPECT_EQ(t.step(), 1);
  EXPECT_EQ(t.status(), PairStatus::Unresolved);
  EXPECT_EQ(t.step(), 8);
  EXPECT_EQ(t.status(), PairStatus::Unresolved);
  ASSERT_EQ(t.lastPairs().size(), 4u);
  for (const SpherePair& p : t.lastPairs()) {
    EXPECT_EQ(p.b, 0);  // root of B was the target (crossover)
    EXPECT_GT(a.tree.node(p.a).centre.x(), 0.0);
  }
  EXPECT_EQ(t.step(), 32);
  EXPECT_EQ(t.status(), PairStatus::Colliding);
  EXPECT_EQ(t.sphereTests(), 41);
  EXPECT_EQ(t.stepsDone(), 3);
  EXPECT_EQ(t.deepestLevel(), 1);
  ASSERT_EQ(t.lastPairs().size(), 4u);
  for (const SpherePair& p : t.lastPairs()) {
    const Vec3 ca = a.pose.apply(a.tree.node(p.a).centre);
    const Vec3 cb = b.pose.apply(b.tree.node(p.b).centre);
    EXPECT_NEAR((cb - ca).norm(), 1.5, 1e-9);
  }
  EXPECT_EQ(t.step(), 0);  // resolved: no-op
  EXPECT_EQ(t.sphereTests(), 41);
}

// d = 2.9: the same 41 tests, but facing leaves are 1.9 apart (> sqrt 3):
// separate only at the leaves.
TEST_F(TinyBlocks, SeparateOnlyAtTheLeaves) {
  b.pose.position = Vec3(2.9, 0, 0);
  PairTest t;
  t.reset(a.view(1), b.view(2));
  EXPECT_EQ(runToEnd(t), (std::vector<PairStatus>{PairStatus::Unresolved, PairStatus::Unresolved,
                                                  PairStatus::Separate}));
  EXPECT_EQ(t.sphereTests(), 41);
  // The deepest pairs found (before the leaves) are kept for the gap estimate.
  ASSERT_TRUE(t.hasLastPair());
  EXPECT_EQ(t.lastPair().b, 0);
}

TEST_F(TinyBlocks, SeparateAtTheRootsTakesOneTest) {
  b.pose.position = Vec3(3.5, 0, 0);  // > 2 sqrt 3
  PairTest t;
  t.reset(a.view(1), b.view(2));
  EXPECT_EQ(t.step(), 1);
  EXPECT_EQ(t.status(), PairStatus::Separate);
  EXPECT_FALSE(t.hasLastPair());
  EXPECT_EQ(t.deepestLevel(), 0);
  // No pair: the paper's estimate falls back to the entity origins.
  EXPECT_NEAR(t.gapEstimate(), 3.5, 1e-12);
}

TEST_F(TinyBlocks, CentreOfCollisionIsTheMiddleOfTheLensOnTheLineOfCentres) {
  b.pose.position = Vec3(2.5, 0, 0);
  PairTest t;
  t.reset(a.view(1), b.view(2));
  t.step();
  // Roots at 0 and 2.5, both r = sqrt 3: inside both from 2.5 - sqrt 3 to sqrt 3.
  EXPECT_TRUE(t.centreOfCollision().isApprox(Vec3(1.25, 0, 0), 1e-12));
  EXPECT_NEAR(t.gapEstimate(), 2.5, 1e-12);
  t.step();
  // Leaf of A (r = sqrt3/2) at (0.5, +-0.5, +-0.5) against root B at (2.5, 0, 0):
  // d = sqrt 4.5; overlap runs from d - sqrt 3 to sqrt 3 / 2 measured from the leaf.
  const Vec3 ca = t.lastCentreA();
  const Vec3 cb = t.lastCentreB();
  EXPECT_NEAR(ca.x(), 0.5, 1e-12);
  EXPECT_TRUE(cb.isApprox(Vec3(2.5, 0, 0), 1e-12));
  const double d = std::sqrt(4.5);
  const double s = 0.5 * ((d - kSqrt3) + kSqrt3 / 2);
  EXPECT_TRUE(t.centreOfCollision().isApprox(ca + (cb - ca) / d * s, 1e-12));
  EXPECT_NEAR(t.gapEstimate(), d, 1e-12);
}

TEST_F(TinyBlocks, CoincidentCentresGiveTheSharedCentre) {
  a.pose.position = b.pose.position = Vec3(1, 2, 3);
  PairTest t;
  t.reset(a.view(1), b.view(2));
  t.step();
  EXPECT_TRUE(t.centreOfCollision().allFinite());
  EXPECT_TRUE(t.centreOfCollision().isApprox(Vec3(1, 2, 3), 1e-12));
  EXPECT_EQ(runToEnd(t).back(), PairStatus::Colliding);  // same surface
}

TEST_F(TinyBlocks, GapBoundHoldsBeforeAndDuringTheTest) {
  b.pose.position = Vec3(2.9, 0, 0);  // true gap between the blocks: 0.9
  PairTest t;
  t.reset(a.view(1), b.view(2));
  // Before any test: |cA - cB| + h_A + h_B of the roots.
  EXPECT_NEAR(t.gapBound(), 2.9 + a.tree.root().h + b.tree.root().h, 1e-12);
  EXPECT_GE(t.gapBound(), 0.9);
  t.step();
  EXPECT_NEAR(t.gapBound(), a.tree.root().h + b.tree.root().h, 1e-12);
  EXPECT_GE(t.gapBound(), 0.9);
  t.step();
  const SpherePair p = t.lastPair();
  EXPECT_NEAR(t.gapBound(), a.tree.node(p.a).h + b.tree.node(p.b).h, 1e-12);
  EXPECT_GE(t.gapBound(), 0.9);
}

TEST_F(TinyBlocks, ResetStartsOverAtTheRoots) {
  b.pose.position = Vec3(2.5, 0, 0);
  PairTest t;
  t.reset(a.view(1), b.view(2));
  runToEnd(t);
  ASSERT_EQ(t.status(), PairStatus::Colliding);
  b.pose.position = Vec3(10, 0, 0);
  t.reset(a.view(1), b.view(2));
  EXPECT_EQ(t.status(), PairStatus::Unresolved);
  EXPECT_EQ(t.sphereTests(), 0);
  EXPECT_EQ(t.stepsDone(), 0);
  EXPECT_FALSE(t.hasLastPair());
  EXPECT_EQ(t.step(), 1);
  EXPECT_EQ(t.status(), PairStatus::Separate);
}

// Preset cubes (8^3 voxels, four levels): the crossover alternates trees,
// so levels are reached in the order 0, 1, 1, 2, 2, 3, 3.
class Cubes : public ::testing::Test {
 protected:
  PresetParams params() const {
    PresetParams p;
    p.resolution = 8;
    p.voxel_size = 0.1;
    return p;
  }
  Body a{makePreset("cube", params()), 4};
  Body b{makePreset("cube", params()), 4};
};

TEST_F(Cubes, ApartTouchingAndOverlapping) {
  const double side = 0.8;
  const struct {
    double dx;
    PairStatus expected;
  } cases[] = {{3.0 * side, PairStatus::Separate},
               {side, PairStatus::Colliding},          // faces touch
               {0.5 * side, PairStatus::Colliding},    // half overlap
               {0.0, PairStatus::Colliding}};          // same place
  for (const auto& c : cases) {
    b.pose.position = Vec3(c.dx, 0, 0);
    PairTest t;
    t.reset(a.view(1), b.view(2));
    runToEnd(t);
    EXPECT_EQ(t.status(), c.expected) << "dx = " << c.dx;
    if (c.expected == PairStatus::Colliding) {
      EXPECT_EQ(t.deepestLevel(), 3);
      for (const SpherePair& p : t.lastPairs()) {
        EXPECT_TRUE(a.tree.isLeaf(p.a));
        EXPECT_TRUE(b.tree.isLeaf(p.b));
      }
    }
  }
}

TEST_F(Cubes, CrossoverAlternatesTheTrees) {
  ASSERT_EQ(a.tree.levelCount(), 4);
  b.pose.position = Vec3(0.7, 0.1, 0.05);
  b.pose.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  PairTest t;
  t.reset(a.view(1), b.view(2));
  const int level_a[] = {0, 1, 1, 2, 2, 3, 3};
  const int level_b[] = {0, 0, 1, 1, 2, 2, 3};
  for (int s = 0; s < 7; ++s) {
    ASSERT_FALSE(t.resolved()) << "step " << s;
    t.step();
    ASSERT_TRUE(t.hasLastPair()) << "step " << s;
    for (const SpherePair& p : t.lastPairs()) {
      EXPECT_EQ(a.tree.node(p.a).level, level_a[s]) << "step " << s;
      EXPECT_EQ(b.tree.node(p.b).level, level_b[s]) << "step " << s;
    }
    EXPECT_EQ(t.deepestLevel(), std::max(level_a[s], level_b[s]));
  }
  EXPECT_EQ(t.status(), PairStatus::Colliding);
}

// What a scheduler reads after a step: the next step's tests exactly, and the
// paper's gap estimate for the frontier's first sphere pair (its centres' distance).
TEST_F(Cubes, NextStepCostAndFrontierGapAreWhatTheNextStepSees) {
  b.pose.position = Vec3(0.7, 0.1, 0.05);
  b.pose.orientation = Quat(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  PairTest t;
  t.reset(a.view(1), b.view(2));
  t.trackFrontierGap();
  EXPECT_EQ(t.nextStepTests(), 1);
  EXPECT_EQ(t.frontierGap(), 0.0);
  int unresolved_steps = 0;
  while (!t.resolved()) {
    const int expected = t.nextStepTests();
    EXPECT_EQ(t.step(), expected);
    if (t.resolved()) break;
    ++unresolved_steps;
    const SpherePair first = t.lastPairs()[0];
    const Vec3 ca = a.pose.apply(a.tree.node(first.a).centre);
    const Vec3 cb = b.pose.apply(b.tree.node(first.b).centre);
    EXPECT_NEAR(t.frontierGap(), (cb - ca).norm(), 1e-12);
    EXPECT_LE(t.frontierGap(), a.tree.node(first.a).radius + b.tree.node(first.b).radius);  // they intersect
  }
  EXPECT_EQ(t.nextStepTests(), 0);
  EXPECT_GE(unresolved_steps, 3);
  t.reset(a.view(1), b.view(2));  // tracking ends with the test it was asked of
  t.step();
  ASSERT_FALSE(t.resolved());
  EXPECT_EQ(t.frontierGap(), 0.0);
}

TEST_F(Cubes, SphereTestsAreTheSumOfTheSteps) {
  b.pose.position = Vec3(0.75, 0.2, -0.1);
  PairTest t;
  t.reset(a.view(1), b.view(2));
  std::int64_t sum = 0;
  while (!t.resolved()) sum += t.step();
  EXPECT_EQ(t.sphereTests(), sum);
  EXPECT_GT(sum, 7);
}

TEST_F(Cubes, FirstContactModeGivesTheSameAnswerWithFewerTests) {
  b.pose.position = Vec3(0.6, 0.15, -0.1);
  b.pose.orientation = Quat(Eigen::AngleAxisd(0.7, Vec3(1, -1, 2).normalized()));
  PairTest all, first;
  first.setFirstContactOnly(true);
  all.reset(a.view(1), b.view(2));
  first.reset(a.view(1), b.view(2));
  runToEnd(all);
  runToEnd(first);
  ASSERT_EQ(all.status(), PairStatus::Colliding);
  EXPECT_EQ(first.status(), PairStatus::Colliding);
  EXPECT_EQ(first.stepsDone(), all.stepsDone());
  EXPECT_EQ(first.deepestLevel(), all.deepestLevel());
  EXPECT_LT(first.sphereTests(), all.sphereTests());
  ASSERT_GE(all.lastPairs().size(), first.lastPairs().size());
  for (const SpherePair& p : first.lastPairs()) {
    bool found = false;
    for (const SpherePair& q : all.lastPairs()) found = found || (p.a == q.a && p.b == q.b);
    EXPECT_TRUE(found);
  }
}

// Pair tests sharing one arena, stepped interleaved (as a round-robin
// scheduler does), give what each gives alone; their pairs stay readable
// until the arena is cleared.
TEST_F(Cubes, PairTestsSharingAnArenaInterleaveCorrectly) {
  Body c(makePreset("rock", params()), 4);
  b.pose.position = Vec3(0.7, 0.1, 0.0);
  c.pose.position = Vec3(-0.1, 0.65, 0.2);
  c.pose.orientation = Quat(Eigen::AngleAxisd(1.1, Vec3(0, 1, 1).normalized()));
  PairTest alone_ab, alone_ac;
  alone_ab.reset(a.view(1), b.view(2));
  alone_ac.reset(a.view(1), c.view(3));
  runToEnd(alone_ab);
  runToEnd(alone_ac);

  PairArena arena;
  arena.clear();
  PairTest ab, ac;
  ab.reset(a.view(1), b.view(2), &arena);
  ac.reset(a.view(1), c.view(3), &arena);
  while (!ab.resolved() || !ac.resolved()) {
    ab.step();
    ac.step();
  }
  for (const auto& [shared, alone] : {std::pair<const PairTest*, const PairTest*>{&ab, &alone_ab},
                                      std::pair<const PairTest*, const PairTest*>{&ac, &alone_ac}}) {
    EXPECT_EQ(shared->status(), alone->status());
    EXPECT_EQ(shared->sphereTests(), alone->sphereTests());
    ASSERT_EQ(shared->lastPairs().size(), alone->lastPairs().size());
    for (std::size_t i = 0; i < alone->lastPairs().size(); ++i) {
      EXPECT_EQ(shared->lastPairs()[i].a, alone->lastPairs()[i].a);
      EXPECT_EQ(shared->lastPairs()[i].b, alone->lastPairs()[i].b);
    }
    EXPECT_DOUBLE_EQ(shared->gapBound(), alone->gapBound());
  }
}

// The arena's runs never move: a run taken before the store grew (many
// blocks later, and a run longer than any block) still holds what was
// written to it, at the same address, until clear(); after clear() the
// blocks are reused and nothing more is allocated for the same runs.
TEST(RunBlocks, RunsStayWhereTheyWereWrittenWhileTheStoreGrows) {
  RunBlocks<SpherePair> store;
  std::vector<std::pair<std::size_t, const SpherePair*>> runs;
  const std::size_t long_run = 3 * RunBlocks<SpherePair>::kBlockElements;
  auto takeAll = [&] {
    runs.clear();
    for (std::int32_t r = 0; r < 400; ++r) {
      const std::size_t most = r == 200 ? long_run : 1000 + static_cast<std::size_t>(r);
      std::size_t handle = 0;
      SpherePair* out = store.room(most, handle);
      const std::size_t used = most - static_cast<std::size_t>(r % 7);  // commit less than the room asked
      for (std::size_t i = 0; i < used; ++i) out[i] = SpherePair{r, static_cast<std::int32_t>(i)};
      store.commit(used);
      runs.emplace_back(handle, out);
    }
  };
  takeAll();
  const std::size_t grown = store.capacity();
  EXPECT_GE(grown, long_run + 399 * 1000);
  for (std::int32_t r = 0; r < 400; ++r) {
    const auto [handle, address] = runs[static_cast<std::size_t>(r)];
    EXPECT_EQ(store.at(handle), address) << "run " << r;
    const std::size_t used = (r == 200 ? long_run : 1000 + static_cast<std::size_t>(r)) - static_cast<std::size_t>(r % 7);
    EXPECT_EQ(address[0].a, r);
    EXPECT_EQ(address[used - 1].a, r) << "run " << r;
    EXPECT_EQ(address[used - 1].b, static_cast<std::int32_t>(used - 1)) << "run " << r;
  }
  store.clear();
  takeAll();
  EXPECT_EQ(store.capacity(), grown);  // the same runs fit in the same blocks
}

// Unequal heights: a one-level sphere against a four-level rock. The
// sphere's root stays the target whichever side it is on.
TEST(PairTestUnequalHeights, LeafTargetStaysUntilTheOtherTreesLeaves) {
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 0.1;
  Body ball(makePreset("sphere", p), 4);
  Body rock(makePreset("rock", p), 4);
  ASSERT_EQ(ball.tree.levelCount(), 1);
  ASSERT_EQ(rock.tree.levelCount(), 4);
  // Put the ball's centre on a leaf sphere of the rock: they must collide.
  std::int32_t leaf = rock.tree.levelBegin(3);
  ball.pose.position = rock.pose.apply(rock.tree.node(leaf).centre);

  for (int ball_side = 0; ball_side < 2; ++ball_side) {
    PairTest t;
    if (ball_side == 0) t.reset(ball.view(1), rock.view(2));
    else t.reset(rock.view(2), ball.view(1));
    int rock_level = 0;
    while (!t.resolved()) {
      t.step();
      ASSERT_TRUE(t.hasLastPair());
      for (const SpherePair& pair : t.lastPairs()) {
        const std::int32_t ball_node = ball_side == 0 ? pair.a : pair.b;
        const std::int32_t rock_node = ball_side == 0 ? pair.b : pair.a;
        EXPECT_EQ(ball_node, 0);
        EXPECT_EQ(rock.tree.node(rock_node).level, rock_level);
      }
      ++rock_level;
    }
    EXPECT_EQ(t.status(), PairStatus::Colliding) << "ball side " << ball_side;
    EXPECT_EQ(t.stepsDone(), 4);  // one level of the rock per step
    EXPECT_EQ(t.deepestLevel(), 3);
  }
}

// An L (8x8x2, arms 3 voxels wide) and a 4x4x2 block in its notch, one
// voxel clear of both arms: bigger spheres reach across the gap, leaves do not.
TEST(PairTestNonConvex, BlockInTheNotchOfAnLIsSeparateOnlyAtTheLeaves) {
  Body ell(makeGrid(8, 8, 2, 1.0, [](int i, int j, int) { return i < 3 || j < 3; }), 4);
  Body block(makeBlock(4, 4, 2), 3);
  const Vec3 ell_com = computeMassProperties(ell.shape, 1.0).centre_of_mass;
  // Block occupies grid x, y in [4, 8], z in [0, 2] of the L's grid (notch starts at 3).
  block.pose.position = Vec3(6, 6, 1) - ell_com;
  ASSERT_FALSE(anyLeafPairIntersects(ell, block));

  for (int ell_side = 0; ell_side < 2; ++ell_side) {
    PairTest t;
    if (ell_side == 0) t.reset(ell.view(1), block.view(2));
    else t.reset(block.view(2), ell.view(1));
    const std::vector<PairStatus> seq = runToEnd(t);
    ASSERT_GE(seq.size(), 3u);
    for (std::size_t s = 0; s + 1 < seq.size(); ++s) EXPECT_EQ(seq[s], PairStatus::Unresolved);
    EXPECT_EQ(seq.back(), PairStatus::Separate);
    // It got down to leaves on both trees before deciding.
    EXPECT_EQ(t.deepestLevel(), 3);
    EXPECT_GE(t.gapBound(), 1.0);  // the true gap is one voxel
  }
}

}  // namespace
}  // namespace stc
