// Bodies inside each other (docs/response.md, "Bodies inside each other"):
// the interior field's depths against a brute-force search, and contacts that
// push out a body pressed deeper than its shell of leaf spheres, or wholly
// nested in another.
#include "interior_field.hpp"
#include "world_access.hpp"

#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace stc {
namespace {

// Distance from a point (grid frame) to the nearest empty voxel of the grid
// padded by one empty layer, by trying every one.
double bruteDepth(const VoxelShape& v, const Vec3& point) {
  const double s = v.voxelSize();
  double best = std::numeric_limits<double>::infinity();
  for (int k = -1; k <= v.nz(); ++k) {
    for (int j = -1; j <= v.ny(); ++j) {
      for (int i = -1; i <= v.nx(); ++i) {
        if (v.occupied(i, j, k)) continue;
        const Vec3 lo = Vec3(i, j, k) * s, hi = lo + Vec3::Constant(s);
        best = std::min(best, (point.cwiseMax(lo).cwiseMin(hi) - point).norm());
      }
    }
  }
  return best;
}

TEST(InteriorField, DepthAtEveryVoxelCentreIsTheBruteForceDistanceToAnEmptyVoxel) {
  for (const std::string name : {"cube", "rock", "L", "ring", "sphere"}) {
    PresetParams params;
    params.resolution = 9;
    params.voxel_size = 0.1;
    params.seed = 7;
    const VoxelShape v = makePreset(name, params);
    const Vec3 origin(0.3, -0.2, 0.45);  // any body origin: the field works in the body frame
    const InteriorField field(v, origin);
    int inside = 0;
    for (int k = 0; k < v.nz(); ++k) {
      for (int j = 0; j < v.ny(); ++j) {
        for (int i = 0; i < v.nx(); ++i) {
          const Vec3 centre = (Vec3(i, j, k) + Vec3::Constant(0.5)) * v.voxelSize();
          const InteriorProbe probe = field.probe(centre - origin);
          ASSERT_EQ(probe.inside, v.occupied(i, j, k)) << name << " " << i << " " << j << " " << k;
          if (!probe.inside) {
            EXPECT_LT(probe.depth, 0.0);
            continue;
          }
          ++inside;
          const double expected = bruteDepth(v, centre);
          EXPECT_NEAR(probe.depth, expected, 1e-9) << name << " " << i << " " << j << " " << k;
          // The way out leads to an empty voxel that far along it.
          const Vec3 beyond = centre + probe.out * (probe.depth + 1e-6);
          const Eigen::Vector3i cell = (beyond / v.voxelSize()).array().floor().cast<int>();
          EXPECT_FALSE(v.occupied(cell.x(), cell.y(), cell.z())) << name;
          EXPECT_NEAR(probe.out.norm(), 1.0, 1e-12);
        }
      }
    }
    EXPECT_GT(inside, 0) << name;
  }
}

TEST(InteriorField, PointsOutsideTheGridAreOutsideByAtLeastTheirDistanceToIt) {
  const VoxelShape v = makePreset("cube", PresetParams{5, 0.1, 1});  // [0, 0.5]^3
  const InteriorField field(v, Vec3::Constant(0.25));
  const InteriorProbe far = field.probe(Vec3(0.25 + 0.3, 0.0, 0.0));
  EXPECT_FALSE(far.inside);
  EXPECT_NEAR(far.depth, -0.3, 1e-9);
  const InteriorProbe nan = field.probe(Vec3(std::nan(""), 0.0, 0.0));
  EXPECT_FALSE(nan.inside);
  const InteriorProbe centre = field.probe(Vec3::Zero());
  EXPECT_TRUE(centre.inside);
  EXPECT_NEAR(centre.depth, 0.25, 1e-12);
  const InteriorProbe near_top = field.probe(Vec3(0.01, -0.02, 0.2));
  EXPECT_TRUE(near_top.inside);
  EXPECT_NEAR(near_top.depth, 0.05, 1e-12);
  EXPECT_NEAR(near_top.out.z(), 1.0, 1e-12);
}

TEST(InteriorField, AGridBeyondTheCellLimitGetsNoField) {
  // 1 x 1 x n: padded to 3 x 3 x (n + 2) cells.
  const int n = static_cast<int>(InteriorField::kMaxCells / 9);
  const VoxelShape thin = VoxelShape::create(1, 1, n, 0.01, std::vector<std::uint8_t>(n, 1));
  const InteriorField none(thin, Vec3::Zero());
  EXPECT_FALSE(none.built());
  EXPECT_FALSE(none.probe(Vec3(0.005, 0.005, 0.5)).inside);  // says nothing, never "inside"
  const VoxelShape fits = VoxelShape::create(1, 1, n - 10, 0.01, std::vector<std::uint8_t>(n - 10, 1));
  const InteriorField field(fits, Vec3::Zero());
  EXPECT_TRUE(field.built());
  const InteriorProbe probe = field.probe(Vec3(0.005, 0.005, 0.5));
  EXPECT_TRUE(probe.inside);
  EXPECT_NEAR(probe.depth, 0.005, 1e-12);  // half the rod's width
}

constexpr double kVoxel = 0.05;
constexpr int kCubeVoxels = 8;
constexpr double kSide = kCubeVoxels * kVoxel;

ShapeId cubeShape(World& world, const std::string& key, int n) {
  return world.addShape(key, VoxelShape::create(n, n, n, kVoxel, std::vector<std::uint8_t>(n * n * n, 1)));
}

struct Pair {
  World world;
  EntityId lower = kInvalidEntity, upper = kInvalidEntity;
};

// Two cubes, no gravity, the upper one pressed `depth` metres into the lower
// one and turned by `tilt` about x.
void pressed(Pair& p, double depth, double tilt) {
  const ShapeId cube = cubeShape(p.world, "cube", kCubeVoxels);
  EntitySpec lower;
  lower.shape = cube;
  p.lower = p.world.addEntity(lower);
  EntitySpec upper;
  upper.shape = cube;
  upper.pose.position = Vec3(0.03, -0.02, kSide - depth);
  upper.pose.orientation = Quat(Eigen::AngleAxisd(tilt, Vec3::UnitX()));
  p.upper = p.world.addEntity(upper);
}

WorldConfig noGravity() {
  WorldConfig config;
  config.gravity = Vec3::Zero();
  return config;
}

// Deepest separation among the contacts, and whether any was measured against a solid.
struct Seen {
  double least = 0.0;
  bool interior = false;
  std::size_t interior_count = 0;
  Vec3 normal = Vec3::Zero();
};
Seen contactsOf(const World& world) {
  Seen seen;
  for (const Contact& c : world.contacts()) {
    if (c.separation < seen.least) {
      seen.least = c.separation;
      seen.normal = c.normal;
    }
    if (c.node_a == kInteriorNode || c.node_b == kInteriorNode) ++seen.interior_count;
  }
  seen.interior = seen.interior_count > 0;
  return seen;
}

Vec3 momentum(const World& world) {
  Vec3 p = Vec3::Zero();
  for (const BodyState& b : world.bodies()) {
    if (b.inv_mass > 0.0) p += b.linear_velocity / b.inv_mass;
  }
  return p;
}

// Pressed through its shell, a cube is pushed back out along the way out of
// the other one, momentum kept, and nothing is launched.
void expectPushedOut(double depth, double tilt) {
  Pair p{World(noGravity())};
  pressed(p, depth, tilt);
  const double dt = 1.0 / 60.0;
  const TickReport report = p.world.step(dt, Budget::unlimited());
  const Seen first = contactsOf(p.world);
  EXPECT_TRUE(first.interior) << depth;
  EXPECT_EQ(report.response.interior_contacts, first.interior_count);
  // The lower one is a (index 0): the normal a -> b points up, out of it.
  EXPECT_GT(std::abs(first.normal.z()), 0.9);
  EXPECT_LT(first.least, -0.5 * depth) << "measured as deep as it is";
  double fastest = 0.0;
  for (int tick = 0; tick < 120; ++tick) {
    p.world.step(dt, Budget::unlimited());
    for (const BodyState& b : p.world.bodies()) fastest = std::max(fastest, b.linear_velocity.norm());
    EXPECT_LE(momentum(p.world).norm(), 1e-9);
  }
  const Vec3 apart = p.world.bodies()[*p.world.indexOf(p.upper)].pose.position -
                     p.world.bodies()[*p.world.indexOf(p.lower)].pose.position;
  // Out of each other: no contact deeper than half a voxel, and apart along z.
  for (const Contact& c : p.world.contacts()) EXPECT_GT(c.separation, -0.5 * kVoxel);
  EXPECT_GT(apart.z(), 0.5 * kSide);
  // Pushing out moves the bodies; it does not throw them (depth per tick, at most).
  EXPECT_LT(fastest, depth / dt);
}

TEST(InteriorContacts, ACubePressedThreeVoxelsIntoAnotherIsPushedOut) { expectPushedOut(3 * kVoxel, 0.0); }

TEST(InteriorContacts, ATurnedCubePressedHalfwayIntoAnotherIsPushedOut) { expectPushedOut(0.45 * kSide, 0.4); }

TEST(InteriorContacts, ASmallCubeWhollyInsideALargeOneIsPushedOut) {
  World world(noGravity());
  EntitySpec large;
  large.shape = cubeShape(world, "large", 16);
  const EntityId outer = world.addEntity(large);
  EntitySpec small;
  small.shape = cubeShape(world, "small", 4);
  small.pose.position = Vec3(0.02, 0.1, 0.2);  // nearest face: +z, 0.2 m away (the small one's half side 0.1)
  const EntityId inner = world.addEntity(small);
  const double dt = 1.0 / 60.0;
  world.step(dt, Budget::unlimited());
  ASSERT_TRUE(contactsOf(world).interior);
  EXPECT_LT(contactsOf(world).least, -0.2);
  for (int tick = 0; tick < 240; ++tick) world.step(dt, Budget::unlimited());
  const Vec3 d = world.bodies()[*world.indexOf(inner)].pose.position - world.bodies()[*world.indexOf(outer)].pose.position;
  // Out through the nearest face: its centre beyond the large cube's top less half a voxel.
  EXPECT_GT(d.z(), 0.4 + 0.1 - 0.5 * kVoxel);
  EXPECT_LE(momentum(world).norm(), 1e-9);
}

TEST(InteriorContacts, CubesRestingFaceToFaceKeepTheirSurfaceContacts) {
  // Touching, not pressed in: no contact is measured against a solid.
  Pair p{World(noGravity())};
  pressed(p, 0.1 * kVoxel, 0.0);
  for (int tick = 0; tick < 10; ++tick) {
    const TickReport report = p.world.step(1.0 / 60.0, Budget::unlimited());
    EXPECT_FALSE(contactsOf(p.world).interior);
    EXPECT_GT(report.response.contacts, 0u);
    EXPECT_EQ(report.response.interior_contacts, 0u);
  }
}

}  // namespace
}  // namespace stc
