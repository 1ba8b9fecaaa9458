// The steps of ContactBuilder::append, each on its own: gathering and
// refining candidates (face normals), picking spread-out representatives,
// clustering, and a cluster's normal and separation.
#include "contact_builder.hpp"
#include "pair_test.hpp"
#include "solid_cube.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace stc;

namespace {

// Two 40 cm cubes of 10 cm voxels, B at `offset` (turned by `turn`), tested to the leaves.
struct TwoCubes : stc_test::SolidCube {
  Pose pose_a, pose_b;
  PairTest test;

  explicit TwoCubes(const Vec3& offset, const Quat& turn = Quat::Identity()) {
    pose_b.position = offset;
    pose_b.orientation = turn;
    test.reset(PairBody{0, &tree, &pose_a}, PairBody{1, &tree, &pose_b});
    while (!test.resolved()) test.step();
  }
  PairGeometry geometry() const { return PairGeometry(test, &bounds, &bounds); }
  // gatherCandidates of the test.
  std::vector<ContactCandidate> candidates(const PairGeometry& geometry) const {
    std::vector<ContactCandidate> out;
    gatherCandidates(test, geometry, out);
    return out;
  }
};

// A refined candidate at `point` with the given overlap and normal.
ContactCandidate at(const Vec3& point, double overlap = 0.01, const Vec3& normal = Vec3::UnitX()) {
  ContactCandidate c;
  c.point = point;
  c.ca = point - 0.05 * normal;  // reach (overlap + |cb - ca|) of 0.1 + overlap: a 1e-4 m tie band
  c.cb = point + 0.05 * normal;
  c.normal = normal;
  c.overlap = overlap;
  c.refined = true;
  return c;
}

// A 5 x 5 grid of equally deep candidates on the plane x = 0, 10 cm apart.
std::vector<ContactCandidate> faceGrid() {
  std::vector<ContactCandidate> grid;
  for (int j = 0; j < 5; ++j) {
    for (int k = 0; k < 5; ++k) grid.push_back(at(Vec3(0.0, 0.1 * j - 0.2, 0.1 * k - 0.2)));
  }
  return grid;
}

}  // namespace

TEST(ContactSteps, GatherTakesTheLastPairsOrTheRootsOfAnUntestedPair) {
  TwoCubes cubes(Vec3(0.39, 0.0, 0.0));
  ASSERT_EQ(cubes.test.status(), PairStatus::Colliding);
  const PairGeometry geometry = cubes.geometry();
  std::vector<ContactCandidate> candidates = cubes.candidates(geometry);
  ASSERT_EQ(candidates.size(), cubes.test.lastPairs().size());
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    EXPECT_EQ(candidates[i].node_a, cubes.test.lastPairs()[i].a);
    EXPECT_TRUE(cubes.tree.isLeaf(candidates[i].node_a));
    EXPECT_TRUE(cubes.tree.isLeaf(candidates[i].node_b));
    EXPECT_FALSE(candidates[i].refined);
  }
  EXPECT_GT(deepestOverlap(candidates), 0.0);

  PairTest untested;
  untested.reset(PairBody{0, &cubes.tree, &cubes.pose_a}, PairBody{1, &cubes.tree, &cubes.pose_b});
  gatherCandidates(untested, PairGeometry(untested, nullptr, nullptr), candidates);
  ASSERT_EQ(candidates.size(), 1u);
  EXPECT_EQ(candidates[0].node_a, 0);
  EXPECT_EQ(candidates[0].node_b, 0);
  // Paper Fig. 4: the point divides the line of centres in proportion to the radii (equal here).
  EXPECT_NEAR(candidates[0].point.x(), 0.195, 1e-12);
  EXPECT_NEAR(candidates[0].normal.x(), 1.0, 1e-12);
}

TEST(ContactSteps, RefineTurnsTiltedLinesOfCentresToTheFaceAxisOfEitherBox) {
  // B half a voxel off sideways: the deep leaf pairs' lines of centres tilt by
  // about 30 degrees. Turned a quarter about z, B's box axes are still A's.
  const Quat quarter(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitZ()));
  for (const Quat& turn : {Quat::Identity(), quarter}) {
    TwoCubes cubes(Vec3(0.39, 0.05, 0.0), turn);
    const PairGeometry geometry = cubes.geometry();
    std::vector<ContactCandidate> candidates = cubes.candidates(geometry);
    const double deepest = deepestOverlap(candidates);
    std::size_t tilted = 0;
    for (ContactCandidate c : candidates) {
      if (c.overlap < 0.5 * deepest) continue;  // what the builder refines
      if (c.normal.x() < 0.9) ++tilted;
      ContactCandidate paper = c;
      geometry.refine(paper, false);
      EXPECT_TRUE(paper.refined);
      EXPECT_EQ(paper.normal, c.normal);  // the paper's rule keeps the line of centres
      EXPECT_NEAR(paper.separation, geometry.gapAlong(c, c.normal), 1e-15);
      geometry.refine(c, true);
      EXPECT_NEAR(c.normal.x(), 1.0, 1e-12);
      EXPECT_NEAR(c.separation, -0.01, 1e-12);  // the true face overlap
      EXPECT_NEAR(c.point.x(), 0.195, 1e-9);    // halfway between the faces
      EXPECT_GE(c.separation, paper.separation);  // the face axis separates more
    }
    EXPECT_GT(tilted, 0u);
  }
}

TEST(ContactSteps, CoincidentCentresGiveTheBodyDirectionThenPlusZNeverNaN) {
  TwoCubes same(Vec3::Zero());
  const PairGeometry geometry(same.test, &same.bounds, &same.bounds);
  ContactCandidate roots = geometry.candidate(0, 0);
  EXPECT_EQ(roots.normal, Vec3::UnitZ());
  EXPECT_TRUE(roots.point.allFinite());
  geometry.refine(roots, true);
  EXPECT_TRUE(roots.normal.allFinite());
  EXPECT_NEAR(roots.normal.norm(), 1.0, 1e-12);
  EXPECT_TRUE(roots.point.allFinite());
  EXPECT_TRUE(std::isfinite(roots.separation));
  EXPECT_LT(roots.separation, 0.0);

  // Node centres that coincide on bodies apart: the direction between the bodies.
  VoxelShape one = VoxelShape::create(1, 1, 1, 0.1, {1});
  const SphereTree small = SphereTree::build(one, Vec3::Constant(0.05));
  Pose pose_a, pose_b;
  pose_b.position = Vec3(0.0, 0.3, 0.0);
  // B's tree built about a point 0.3 m off its voxel: its node sits on A's.
  const SphereTree shifted = SphereTree::build(one, Vec3(0.05, 0.35, 0.05));
  PairTest far;
  far.reset(PairBody{0, &small, &pose_a}, PairBody{1, &shifted, &pose_b});
  const ContactCandidate c = PairGeometry(far, nullptr, nullptr).candidate(0, 0);
  ASSERT_NEAR((c.cb - c.ca).norm(), 0.0, 1e-12);
  EXPECT_NEAR(c.normal.y(), 1.0, 1e-12);
  EXPECT_TRUE(c.point.allFinite());
}

TEST(ContactSteps, RefineDeepCandidatesSkipsThoseUnderHalfTheDeepestOverlap) {
  TwoCubes cubes(Vec3(0.39, 0.0, 0.0));
  const PairGeometry geometry = cubes.geometry();
  std::vector<ContactCandidate> candidates = cubes.candidates(geometry);
  const double deepest = deepestOverlap(candidates);
  refineDeepCandidates(candidates, deepest, geometry, true);
  std::size_t refined = 0;
  for (const ContactCandidate& c : candidates) {
    EXPECT_EQ(c.refined, c.overlap >= 0.5 * deepest);
    refined += c.refined ? 1u : 0u;
  }
  EXPECT_GT(refined, 0u);
  EXPECT_LT(refined, candidates.size());  // the tilted neighbour pairs overlap about half as much
}

// Face-on and turned 30 degrees about the contact normal: the contacts built
// from the deep candidates alone (measured from the whole set's spread) are
// those built from all of them, in the same order.
TEST(ContactSteps, DroppingTheShallowCandidatesKeepsTheContactsAndTheirOrder) {
  const Quat turned(Eigen::AngleAxisd(0.5235987755982988, Vec3::UnitX()));
  for (const Quat& turn : {Quat::Identity(), turned}) {
    TwoCubes cubes(Vec3(0.39, 0.0, 0.0), turn);
    const PairGeometry geometry = cubes.geometry();
    std::vector<ContactCandidate> all = cubes.candidates(geometry);
    const double deepest = deepestOverlap(all);
    refineDeepCandidates(all, deepest, geometry, true);
    std::vector<ContactCandidate> deep = all;
    const CandidateSpread spread = spreadOf(deep);
    dropShallowCandidates(deep);
    ASSERT_LT(deep.size(), all.size());
    std::size_t next = 0;  // the kept ones are the refined ones, in their order
    for (const ContactCandidate& c : all) {
      if (!c.refined) continue;
      ASSERT_LT(next, deep.size());
      EXPECT_EQ(deep[next].node_a, c.node_a);
      EXPECT_EQ(deep[next].node_b, c.node_b);
      ++next;
    }
    EXPECT_EQ(next, deep.size());

    std::vector<int> reps_all, reps_deep;
    pickRepresentatives(all, deepest, 4, reps_all);
    pickRepresentatives(deep, deepest, 4, spread, reps_deep);
    ASSERT_EQ(reps_all.size(), 4u);
    ASSERT_EQ(reps_deep.size(), reps_all.size());
    std::vector<Vec3> normals_all, normals_deep;
    std::vector<double> separations_all, separations_deep;
    clusterNormals(all, reps_all, normals_all);
    clusterNormals(deep, reps_deep, normals_deep);
    clusterSeparations(all, reps_all, normals_all, geometry, separations_all);
    clusterSeparations(deep, reps_deep, normals_deep, geometry, separations_deep);
    for (std::size_t r = 0; r < reps_all.size(); ++r) {
      EXPECT_EQ(deep[reps_deep[r]].point, all[reps_all[r]].point) << r;
      EXPECT_EQ(normals_deep[r], normals_all[r]) << r;
      EXPECT_EQ(separations_deep[r], separations_all[r]) << r;
    }
  }
}

TEST(ContactSteps, RepresentativesAreTheCornersOfAFaceAndNeverTwoAtOnePoint) {
  std::vector<ContactCandidate> grid = faceGrid();
  std::vector<int> reps;
  pickRepresentatives(grid, deepestOverlap(grid), 4, reps);
  ASSERT_EQ(reps.size(), 4u);
  // All four corners of the face, the deepest-and-farthest first.
  for (int r : reps) {
    EXPECT_NEAR(std::abs(grid[r].point.y()), 0.2, 1e-12);
    EXPECT_NEAR(std::abs(grid[r].point.z()), 0.2, 1e-12);
  }
  for (std::size_t i = 0; i < reps.size(); ++i) {
    for (std::size_t j = i + 1; j < reps.size(); ++j) EXPECT_NE(reps[i], reps[j]);
  }
  // The second is the far corner (farthest from the first).
  EXPECT_NEAR((grid[reps[1]].point - grid[reps[0]].point).norm(), std::sqrt(2.0) * 0.4, 1e-12);

  // A deeper candidate is always the first.
  grid[12].overlap = 0.02;  // the centre
  pickRepresentatives(grid, deepestOverlap(grid), 4, reps);
  ASSERT_FALSE(reps.empty());
  EXPECT_EQ(reps[0], 12);

  // The limit is clamped to 1..16.
  pickRepresentatives(grid, deepestOverlap(grid), 0, reps);
  EXPECT_EQ(reps.size(), 1u);
  pickRepresentatives(grid, deepestOverlap(grid), 100, reps);
  EXPECT_EQ(reps.size(), 16u);

  // Candidates at one point are one representative, whatever the limit.
  std::vector<ContactCandidate> stacked(6, at(Vec3(1.0, 2.0, 3.0)));
  pickRepresentatives(stacked, deepestOverlap(stacked), 4, reps);
  EXPECT_EQ(reps.size(), 1u);

  // Unrefined candidates never represent beyond the first; none at all: nothing picked.
  std::vector<ContactCandidate> shallow = faceGrid();
  for (ContactCandidate& c : shallow) c.refined = false;
  pickRepresentatives(shallow, deepestOverlap(shallow), 4, reps);
  EXPECT_EQ(reps.size(), 1u);
  std::vector<ContactCandidate> none;
  pickRepresentatives(none, deepestOverlap(none), 4, reps);
  EXPECT_TRUE(reps.empty());
}

TEST(ContactSteps, EveryCandidateJoinsItsNearestRepresentative) {
  std::vector<ContactCandidate> grid = faceGrid();
  const std::vector<int> reps = {0, 24};  // opposite corners: (-0.2, -0.2) and (0.2, 0.2)
  assignClusters(grid, reps);
  for (const ContactCandidate& c : grid) {
    const double to_first = (c.point - grid[0].point).squaredNorm();
    const double to_second = (c.point - grid[24].point).squaredNorm();
    if (to_first < to_second) EXPECT_EQ(c.cluster, 0);
    if (to_second < to_first) EXPECT_EQ(c.cluster, 1);
  }
  EXPECT_EQ(grid[0].cluster, 0);
  EXPECT_EQ(grid[24].cluster, 1);
  EXPECT_EQ(grid[1].cluster, 0);   // (-0.2, -0.1)
  EXPECT_EQ(grid[23].cluster, 1);  // (0.2, 0.1)
  // The middle row is as far from both corners: a tie stays with the first.
  EXPECT_EQ(grid[4].cluster, 0);   // (-0.2, 0.2)
  EXPECT_EQ(grid[20].cluster, 0);  // (0.2, -0.2)
}

TEST(ContactSteps, PickingRepresentativesLeavesTheClustersAssignClustersGives) {
  std::vector<ContactCandidate> picked = faceGrid();
  picked[7].overlap = 0.02;  // an inner deepest: the clusters are not the corners' quarters
  std::vector<int> reps;
  for (int limit = 1; limit <= 5; ++limit) {
    for (ContactCandidate& c : picked) c.cluster = -1;
    pickRepresentatives(picked, deepestOverlap(picked), limit, reps);
    ASSERT_EQ(reps.size(), static_cast<std::size_t>(limit));
    std::vector<ContactCandidate> assigned = picked;
    for (ContactCandidate& c : assigned) c.cluster = -1;
    assignClusters(assigned, reps);
    for (std::size_t i = 0; i < picked.size(); ++i) {
      EXPECT_EQ(picked[i].cluster, assigned[i].cluster) << "limit " << limit << ", candidate " << i;
      EXPECT_EQ(picked[i].nearest, (picked[i].point - picked[reps[picked[i].cluster]].point).squaredNorm());
    }
  }
}

TEST(ContactSteps, ClusterNormalAveragesTheDeepestMembersOnly) {
  const Vec3 tilted = Vec3(1.0, 1.0, 0.0).normalized();
  std::vector<ContactCandidate> cluster = {at(Vec3::Zero(), 0.010, Vec3::UnitX()),
                                           at(Vec3(0.0, 0.1, 0.0), 0.0095, Vec3::UnitX()),
                                           at(Vec3(0.0, 0.2, 0.0), 0.005, tilted),  // edge-on neighbour
                                           at(Vec3(0.0, 0.3, 0.0), 0.010, -Vec3::UnitX())};
  cluster[3].cluster = 1;  // another cluster: never counted in the first
  const std::vector<int> reps = {0, 3};
  std::vector<Vec3> normals;
  clusterNormals(cluster, reps, normals);
  ASSERT_EQ(normals.size(), 2u);
  EXPECT_EQ(normals[0], Vec3::UnitX());
  EXPECT_EQ(normals[1], -Vec3::UnitX());

  // The tilted member within the deep band: the mean of the two directions.
  cluster[2].overlap = 0.0095;
  clusterNormals(cluster, reps, normals);
  const Vec3 mean = normals[0];
  EXPECT_NEAR(mean.norm(), 1.0, 1e-12);
  EXPECT_GT(mean.y(), 0.0);
  EXPECT_LT(mean.y(), tilted.y());

  // Opposite normals cancel, unrefined members do not count: the
  // representative's own normal.
  std::vector<ContactCandidate> opposed = {at(Vec3::Zero(), 0.01, Vec3::UnitX()),
                                           at(Vec3::Zero(), 0.01, -Vec3::UnitX()),
                                           at(Vec3::Zero(), 0.01, Vec3::UnitZ())};
  opposed[2].refined = false;
  clusterNormals(opposed, {2}, normals);
  EXPECT_EQ(normals[0], Vec3::UnitZ());
  opposed[0].refined = false;
  opposed[1].normal = Vec3::UnitY();
  opposed[1].refined = false;
  clusterNormals(opposed, {1}, normals);
  EXPECT_EQ(normals[0], Vec3::UnitY());
}

TEST(ContactSteps, ClusterSeparationIsTheClosestAlignedMembersGap) {
  TwoCubes cubes(Vec3(0.39, 0.0, 0.0));
  const PairGeometry geometry = cubes.geometry();
  std::vector<ContactCandidate> candidates = cubes.candidates(geometry);
  refineDeepCandidates(candidates, deepestOverlap(candidates), geometry, true);
  for (ContactCandidate& c : candidates) c.cluster = 0;
  candidates[0].separation = 0.5;
  candidates[1].separation = 0.25;
  const std::vector<int> reps = {0, 1};
  std::vector<double> separations;
  clusterSeparations(candidates, reps, {Vec3::UnitX(), Vec3::UnitX()}, geometry, separations);
  ASSERT_EQ(separations.size(), 2u);
  EXPECT_NEAR(separations[0], -0.01, 1e-12);
  // A cluster without members: its representative's separation.
  EXPECT_EQ(separations[1], 0.25);
  // No member's normal within about 18 degrees of the normal asked for: the same.
  clusterSeparations(candidates, reps, {Vec3::UnitZ(), Vec3::UnitX()}, geometry, separations);
  EXPECT_EQ(separations[0], 0.5);
}
