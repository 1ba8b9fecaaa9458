// Accuracy against the mesh (issue 14 item 2): sphere-trees of the two
// generated meshes, checked against FCL on the ORIGINAL triangles over 5,001
// random poses at full depth: no collision is missed, every tree level covers
// the mesh's outer surface to within the shape's surface margin, and the gap
// bound h_a + h_b (which includes the margins) bounds the true mesh gap.
#include "mesh_accuracy.hpp"
#include "mesh_generators.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace stc::truth {
namespace {

constexpr int kResolution = 32;
constexpr int kLevels = 6;           // single-voxel leaves
constexpr int kPosesPerPair = 1667;  // three pairings: 5,001 poses

class MeshAccuracy : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    bodies_ = new std::vector<MeshBody>{makeMeshBody("robot link", robotLinkMesh(), kResolution, kLevels),
                                        makeMeshBody("bumpy scan", bumpyScanMesh(), kResolution, kLevels)};
  }
  static void TearDownTestSuite() {
    delete bodies_;
    bodies_ = nullptr;
  }
  static std::vector<MeshBody>* bodies_;
};
std::vector<MeshBody>* MeshAccuracy::bodies_ = nullptr;

TEST_F(MeshAccuracy, EveryLevelCoversTheMeshWithinTheSurfaceMargin) {
  for (const MeshBody& b : *bodies_) {
    const double a = b.voxels.shape.voxelSize();
    const std::vector<Vec3> surface = outerSurfacePoints(b, a);  // a voxel apart: a few seconds
    ASSERT_GT(surface.size(), 1000u) << b.name;
    for (int level = 0; level < b.tree.levelCount(); ++level) {
      const double excess = coverageExcess(b, level, surface);
      EXPECT_LE(excess, b.voxels.shape.surfaceMargin()) << b.name << " level " << level;
      std::printf("%s level %d: coverage excess %.3f mm (%.2f voxel)\n", b.name.c_str(), level, excess * 1e3,
                  excess / a);
    }
  }
}

TEST_F(MeshAccuracy, NoCollisionIsMissedAndHBoundsTheMeshGap) {
  const std::pair<int, int> pairings[3] = {{0, 1}, {0, 0}, {1, 1}};
  long poses = 0, colliding = 0;
  for (int k = 0; k < 3; ++k) {
    const MeshBody& a = (*bodies_)[static_cast<std::size_t>(pairings[k].first)];
    const MeshBody& b = (*bodies_)[static_cast<std::size_t>(pairings[k].second)];
    const PairAccuracy p = measurePairs(a, b, kPosesPerPair, 2000u + static_cast<unsigned>(k));
    EXPECT_EQ(p.missed, 0) << a.name << " / " << b.name;
    EXPECT_EQ(p.bound_violations, 0) << a.name << " / " << b.name;
    EXPECT_LE(p.worst_bound_ratio, 1.0) << a.name << " / " << b.name;
    poses += p.poses;
    colliding += p.colliding;
    std::printf("%s / %s: %ld poses, %ld nested, %ld colliding, %ld missed, %ld false positives, "
                "%ld h-without-margin violations\n",
                a.name.c_str(), b.name.c_str(), p.poses, p.nested, p.colliding, p.missed, p.false_positive,
                p.voxel_bound_violations);
  }
  EXPECT_GE(poses, 5000);
  EXPECT_GT(colliding, poses / 5);  // the poses do test contact, not only clear misses
}

}  // namespace
}  // namespace stc::truth
