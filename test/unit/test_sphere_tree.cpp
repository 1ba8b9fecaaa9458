// SphereTree: coverage of the surface at every level, occluded cells removed,
// breadth-first layout, tight vs paper fits, and the gap bound h checked
// against dense sampling. Everything is checked by brute force from the voxels.
#include "sphere_tree_collision/sphere_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>

namespace stc {
namespace {

using Voxel = std::array<int, 3>;

std::vector<Voxel> surfaceVoxels(const VoxelShape& s) {
  std::vector<Voxel> out;
  for (int k = 0; k < s.nz(); ++k)
    for (int j = 0; j < s.ny(); ++j)
      for (int i = 0; i < s.nx(); ++i)
        if (s.isSurfaceVoxel(i, j, k)) out.push_back({i, j, k});
  return out;
}

// Side of the octree's bounding cube in voxels: the smallest power of two >= every dimension.
int cubeSide(const VoxelShape& s) {
  int n = 1;
  while (n < std::max({s.nx(), s.ny(), s.nz()})) n *= 2;
  return n;
}

struct Built {
  VoxelShape shape;
  Vec3 origin;
  SphereTree tree;
};

Built build(const std::string& preset, int res, SphereFit fit, int max_levels = 4) {
  PresetParams p;
  p.resolution = res;
  p.voxel_size = 0.04;
  p.seed = 3;
  VoxelShape shape = makePreset(preset, p);
  const Vec3 origin = computeMassProperties(shape, 1000.0).centre_of_mass;
  SphereTreeOptions options;
  options.fit = fit;
  options.max_levels = max_levels;
  SphereTree tree = SphereTree::build(shape, origin, options);
  return {std::move(shape), origin, std::move(tree)};
}

// Grid voxel units -> body frame.
Vec3 toBody(const Built& b, const Vec3& p) { return p * b.shape.voxelSize() - b.origin; }

// Points every level must cover: each surface voxel's corners, face centres,
// and random points of its exposed faces (body frame).
std::vector<Vec3> surfaceSamples(const Built& b, int random_per_face, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> out;
  for (const Voxel& v : surfaceVoxels(b.shape)) {
    const Vec3 lo(v[0], v[1], v[2]);
    for (int o = 0; o < 8; ++o) out.push_back(toBody(b, lo + Vec3(o & 1, (o >> 1) & 1, (o >> 2) & 1)));
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        Vec3 c = lo + Vec3::Constant(0.5);
        c[axis] = lo[axis] + side;
        out.push_back(toBody(b, c));
        Voxel n = v;
        n[axis] += side ? 1 : -1;
        if (b.shape.occupied(n[0], n[1], n[2])) continue;  // face not exposed
        for (int r = 0; r < random_per_face; ++r) {
          Vec3 q = lo;
          q[axis] += side;
          q[(axis + 1) % 3] += u(rng);
          q[(axis + 2) % 3] += u(rng);
          out.push_back(toBody(b, q));
        }
      }
  }
  return out;
}

bool inside(const SphereNode& n, const Vec3& p) {
  const double r = n.radius * (1.0 + 1e-9) + 1e-12;
  return (p - n.centre).squaredNorm() <= r * r;
}

// Number of points not inside any sphere of the level (nodes sorted by x to
// keep the brute force quick).
int uncovered(const SphereTree& tree, int level, const std::vector<Vec3>& points) {
  std::vector<SphereNode> nodes(tree.nodes().begin() + tree.levelBegin(level),
                                tree.nodes().begin() + tree.levelBegin(level + 1));
  std::sort(nodes.begin(), nodes.end(), [](const SphereNode& a, const SphereNode& b) {
    return a.centre.x() < b.centre.x();
  });
  double rmax = 0.0;
  for (const SphereNode& n : nodes) rmax = std::max(rmax, n.radius);
  int missing = 0;
  for (const Vec3& p : points) {
    SphereNode probe;
    probe.centre.x() = p.x() - 2.0 * rmax;
    auto it = std::lower_bound(nodes.begin(), nodes.end(), probe, [](const SphereNode& a, const SphereNode& b) {
      return a.centre.x() < b.centre.x();
    });
    bool hit = false;
    for (; it != nodes.end() && it->centre.x() <= p.x() + 2.0 * rmax && !hit; ++it) hit = inside(*it, p);
    missing += !hit;
  }
  return missing;
}

// The octree cell (voxel units: min corner index at that level) a paper node was fitted to.
Voxel cellOf(const Built& paper, const SphereNode& n) {
  const int side = cubeSide(paper.shape) >> n.level;
  const Vec3 c = (n.centre + paper.origin) / paper.shape.voxelSize();
  return {static_cast<int>(std::floor(c.x() / side)), static_cast<int>(std::floor(c.y() / side)),
          static_cast<int>(std::floor(c.z() / side))};
}

void expectValidLayout(const SphereTree& tree) {
  ASSERT_GE(tree.levelCount(), 1);
  EXPECT_EQ(tree.levelBegin(0), 0);
  EXPECT_EQ(tree.levelBegin(1), 1);
  EXPECT_EQ(tree.levelBegin(tree.levelCount()), static_cast<std::int32_t>(tree.nodes().size()));
  EXPECT_EQ(tree.root().parent, -1);
  for (int level = 0; level < tree.levelCount(); ++level) {
    EXPECT_LT(tree.levelBegin(level), tree.levelBegin(level + 1)) << "empty level " << level;
    for (std::int32_t i = tree.levelBegin(level); i < tree.levelBegin(level + 1); ++i) {
      const SphereNode& n = tree.node(i);
      EXPECT_EQ(n.level, level);
      EXPECT_GT(n.radius, 0.0);
      EXPECT_GE(n.h, 0.0);
      if (level > 0) {
        EXPECT_GE(n.parent, tree.levelBegin(level - 1));
        EXPECT_LT(n.parent, tree.levelBegin(level));
      }
      const bool deepest = level + 1 == tree.levelCount();
      EXPECT_EQ(tree.isLeaf(i), deepest) << "leaves only at the deepest level";
      for (std::int32_t c = n.first_child; c < n.first_child + n.child_count; ++c) {
        EXPECT_EQ(tree.node(c).parent, i);  // children contiguous and pointing back
      }
      // Breadth first: the next node's children follow this node's.
      if (!deepest && i + 1 < tree.levelBegin(level + 1)) {
        EXPECT_EQ(tree.node(i + 1).first_child, n.first_child + n.child_count);
      }
    }
  }
}

const SphereFit kFits[] = {SphereFit::Paper, SphereFit::Tight};

TEST(SphereTreeCoverage, EverySurfaceVoxelInsideSomeSphereOfEveryLevel) {
  std::mt19937 rng(11);
  for (int res : {8, 12}) {  // 12: cells clipped by the grid
    for (const std::string& name : presetNames()) {
      for (SphereFit fit : kFits) {
        const Built b = build(name, res, fit);
        const std::vector<Vec3> points = surfaceSamples(b, 3, rng);
        for (int level = 0; level < b.tree.levelCount(); ++level) {
          EXPECT_EQ(uncovered(b.tree, level, points), 0)
              << name << " res " << res << " " << toString(fit) << " level " << level;
        }
      }
    }
  }
}

TEST(SphereTreeCells, PaperNodesAreExactlyTheCellsHoldingSurfaceVoxels) {
  for (int res : {8, 12}) {
    for (const std::string& name : presetNames()) {
      if (name == "sphere") continue;  // one exact sphere, not octree cells
      const Built b = build(name, res, SphereFit::Paper);
      expectValidLayout(b.tree);
      const std::vector<Voxel> surface = surfaceVoxels(b.shape);
      const int n = cubeSide(b.shape);
      ASSERT_EQ(b.tree.levelCount(), std::min(4, static_cast<int>(std::log2(n)) + 1));
      for (int level = 0; level < b.tree.levelCount(); ++level) {
        const int side = n >> level;
        std::set<Voxel> holding;  // cells of this level holding a surface voxel
        for (const Voxel& v : surface) holding.insert({v[0] / side, v[1] / side, v[2] / side});
        std::set<Voxel> nodes;
        for (std::int32_t i = b.tree.levelBegin(level); i < b.tree.levelBegin(level + 1); ++i) {
          const SphereNode& node = b.tree.node(i);
          const Voxel cell = cellOf(b, node);
          EXPECT_TRUE(holding.count(cell)) << name << " node " << i << " holds no surface voxel";
          EXPECT_TRUE(nodes.insert(cell).second) << "cell used twice";
          // Paper radius: half the diagonal of the cell clipped to the grid.
          const Vec3 lo = Vec3(cell[0], cell[1], cell[2]) * side;
          const Vec3 hi = (lo + Vec3::Constant(side)).cwiseMin(Vec3(b.shape.nx(), b.shape.ny(), b.shape.nz()));
          EXPECT_NEAR(node.radius, 0.5 * (hi - lo).norm() * b.shape.voxelSize(), 1e-12);
          EXPECT_TRUE(node.centre.isApprox(toBody(b, 0.5 * (lo + hi)), 1e-12) ||
                      (node.centre - toBody(b, 0.5 * (lo + hi))).norm() < 1e-12);
          if (level > 0) {
            const Voxel parent = cellOf(b, b.tree.node(node.parent));
            EXPECT_EQ(parent, (Voxel{cell[0] / 2, cell[1] / 2, cell[2] / 2}));
          }
        }
        EXPECT_EQ(nodes.size(), holding.size()) << name << " level " << level;
      }
    }
  }
}

TEST(SphereTreeCells, SolidCubeKeepsNoInteriorNode) {
  const Built b8 = build("cube", 8, SphereFit::Paper, 4);
  ASSERT_EQ(b8.tree.levelCount(), 4);
  const std::int32_t expected[] = {1, 8, 64 - 8, 8 * 8 * 8 - 6 * 6 * 6};  // 2x2x2 cells: the 8 central ones are interior
  for (int level = 0; level < 4; ++level) {
    EXPECT_EQ(b8.tree.levelBegin(level + 1) - b8.tree.levelBegin(level), expected[level]) << level;
  }
  const Built b16 = build("cube", 16, SphereFit::Tight, 5);
  ASSERT_EQ(b16.tree.levelCount(), 5);
  EXPECT_EQ(b16.tree.levelBegin(5) - b16.tree.levelBegin(4),
            static_cast<std::int32_t>(surfaceVoxels(b16.shape).size()));
  // No leaf sphere centre sits in the interior block.
  const double a = b16.shape.voxelSize();
  for (std::int32_t i = b16.tree.levelBegin(4); i < b16.tree.levelBegin(5); ++i) {
    const Vec3 c = (b16.tree.node(i).centre + b16.origin) / a;
    EXPECT_TRUE(c.minCoeff() < 1.0 || c.maxCoeff() > 15.0) << c.transpose();
  }
}

TEST(SphereTreeFits, TightIsNeverLooserThanPaperNodeByNodeInRadiusOrGap) {
  for (int res : {8, 12, 16}) {
    for (const std::string& name : presetNames()) {
      const Built paper = build(name, res, SphereFit::Paper, 5);
      const Built tight = build(name, res, SphereFit::Tight, 5);
      ASSERT_EQ(paper.tree.nodes().size(), tight.tree.nodes().size()) << name;
      double sum_paper = 0.0, sum_tight = 0.0, gap_paper = 0.0, gap_tight = 0.0;
      for (std::size_t i = 0; i < paper.tree.nodes().size(); ++i) {
        const SphereNode& p = paper.tree.nodes()[i];
        const SphereNode& t = tight.tree.nodes()[i];
        EXPECT_EQ(p.parent, t.parent);  // same octree cells, same order
        EXPECT_LE(t.radius, p.radius * (1.0 + 1e-12)) << name << " node " << i;
        EXPECT_LE(t.h, p.h * (1.0 + 1e-12)) << name << " node " << i;  // nor a larger gap bound
        sum_paper += p.radius;
        sum_tight += t.radius;
        gap_paper += p.h;
        gap_tight += t.h;
      }
      if (name == "rock" || name == "ring") {  // cells the shape does not fill: tight must gain
        EXPECT_LT(sum_tight, sum_paper) << name << " res " << res;
        EXPECT_LT(gap_tight, 0.95 * gap_paper) << name << " res " << res;
      }
    }
  }
}

TEST(SphereTreeFits, SpherePresetIsOneExactSphere) {
  for (SphereFit fit : kFits) {
    const Built b = build("sphere", 16, fit, 4);
    ASSERT_EQ(b.tree.levelCount(), 1);
    ASSERT_EQ(b.tree.nodes().size(), 1u);
    const SphereNode& s = b.tree.root();
    const double a = b.shape.voxelSize();
    // The voxelised ball of radius 8 voxels: its smallest enclosing sphere lies
    // between the ball and the ball grown by a voxel diagonal.
    EXPECT_GE(s.radius, 8.0 * a);
    EXPECT_LE(s.radius, (8.0 + std::sqrt(3.0) / 2.0) * a);
    EXPECT_LT((s.centre - toBody(b, Vec3::Constant(8.0))).norm(), 1e-9);
    std::mt19937 rng(5);
    EXPECT_EQ(uncovered(b.tree, 0, surfaceSamples(b, 2, rng)), 0);
  }
}

TEST(SphereTreeLayout, DepthsOneToSixAreValid) {
  for (const char* name : {"L", "rock"}) {
    for (int levels = 1; levels <= 6; ++levels) {
      const Built b = build(name, 32, SphereFit::Tight, levels);  // 32 voxels: up to 6 levels
      EXPECT_EQ(b.tree.levelCount(), levels);
      expectValidLayout(b.tree);
      std::mt19937 rng(levels);
      EXPECT_EQ(uncovered(b.tree, levels - 1, surfaceSamples(b, 0, rng)), 0) << name << " " << levels;
    }
  }
  // Subdivision stops at single voxels: 8 voxels allow 4 levels at most.
  EXPECT_EQ(build("cube", 8, SphereFit::Paper, 8).tree.levelCount(), 4);
}

TEST(SphereTreeLayout, BodyOriginShiftsCentresOnly) {
  const VoxelShape shape = makePreset("ring", PresetParams{});
  const Vec3 shift(0.3, -1.2, 2.0);
  const SphereTree at_grid = SphereTree::build(shape, Vec3::Zero());
  const SphereTree shifted = SphereTree::build(shape, shift);
  ASSERT_EQ(at_grid.nodes().size(), shifted.nodes().size());
  for (std::size_t i = 0; i < at_grid.nodes().size(); ++i) {
    EXPECT_LT((at_grid.nodes()[i].centre - shift - shifted.nodes()[i].centre).norm(), 1e-12);
    EXPECT_DOUBLE_EQ(at_grid.nodes()[i].radius, shifted.nodes()[i].radius);
    EXPECT_DOUBLE_EQ(at_grid.nodes()[i].h, shifted.nodes()[i].h);
  }
  EXPECT_EQ(shifted.fit(), SphereFit::Tight);
  EXPECT_EQ(shifted.levelCount(), 4);  // the default depth
}

TEST(SphereTreeLayout, RejectsBadOptionsNamingTheField) {
  const VoxelShape shape = makePreset("cube", PresetParams{});
  for (int bad : {0, -1, 9}) {
    SphereTreeOptions o;
    o.max_levels = bad;
    try {
      SphereTree::build(shape, Vec3::Zero(), o);
      ADD_FAILURE() << "max_levels " << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "max_levels");
    }
  }
  try {
    SphereTree::build(shape, Vec3(std::nan(""), 0, 0));
    ADD_FAILURE() << "NaN origin accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "body_origin");
  }
}

// Distance from p (voxel units) to the union of the given voxels.
double distanceToVoxels(const Vec3& p, const std::vector<Voxel>& voxels) {
  double best = std::numeric_limits<double>::infinity();
  for (const Voxel& v : voxels) {
    const Vec3 lo(v[0], v[1], v[2]);
    const Vec3 d = (lo - p).cwiseMax(p - lo - Vec3::Ones()).cwiseMax(0.0);
    best = std::min(best, d.squaredNorm());
  }
  return std::sqrt(best);
}

TEST(SphereTreeGap, HBoundsDenseSamplingAndIsNotLoose) {
  // Fibonacci points on the unit sphere: near-uniform and dense.
  const int kSamples = 1000;
  std::vector<Vec3> dirs;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < kSamples; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / kSamples, r = std::sqrt(1.0 - z * z);
    dirs.emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  int checked = 0;
  for (int res : {8, 12}) {
    for (const std::string& name : presetNames()) {
      const Built paper = build(name, res, SphereFit::Paper);
      std::vector<Voxel> solid;
      for (int k = 0; k < paper.shape.nz(); ++k)
        for (int j = 0; j < paper.shape.ny(); ++j)
          for (int i = 0; i < paper.shape.nx(); ++i)
            if (paper.shape.occupied(i, j, k)) solid.push_back({i, j, k});
      for (SphereFit fit : kFits) {
        const Built b = fit == SphereFit::Paper ? paper : build(name, res, fit);
        const double a = b.shape.voxelSize();
        for (std::size_t i = 0; i < b.tree.nodes().size(); ++i) {
          const SphereNode& node = b.tree.nodes()[i];
          // h: max distance from a point of the node's ball to the part it
          // covers, the occupied voxels of its octree cell (the paper tree has
          // the same cells in the same order).
          const int side = cubeSide(b.shape) >> node.level;
          const Voxel cell = name == "sphere" ? Voxel{0, 0, 0} : cellOf(paper, paper.tree.nodes()[i]);
          std::vector<Voxel> covered;
          for (const Voxel& v : solid)
            if (v[0] / side == cell[0] && v[1] / side == cell[1] && v[2] / side == cell[2]) covered.push_back(v);
          ASSERT_FALSE(covered.empty());
          const Vec3 c = (node.centre + b.origin) / a;
          const double r = node.radius / a;
          double sampled = 0.0;  // over the ball: its surface and concentric shells inside
          for (double t : {1.0, 0.8, 0.55, 0.3})
            for (const Vec3& d : dirs) sampled = std::max(sampled, distanceToVoxels(c + t * r * d, covered));
          sampled = std::max(sampled, distanceToVoxels(c, covered));
          sampled *= a;
          EXPECT_LE(sampled, node.h * (1.0 + 1e-9) + 1e-12) << name << " " << toString(fit) << " node " << i;
          EXPECT_LE(node.h, 1.5 * sampled + a) << name << " " << toString(fit) << " node " << i;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 1000);
}

TEST(SphereTreeGap, CoversTheWholeBallIncludingACavity) {
  // A closed hollow box: the root sphere's centre sits in the cavity, 7 voxels
  // from any wall, while every point of the sphere's surface is within
  // r - 8 = 5.86 voxels of the shape. h must still bound the centre: a gap
  // bound built from h holds for any point of the ball (nested spheres,
  // centre estimates).
  const int n = 16;
  std::vector<std::uint8_t> occ(n * n * n, 0);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const bool wall = i == 0 || j == 0 || k == 0 || i == n - 1 || j == n - 1 || k == n - 1;
        occ[static_cast<std::size_t>(i + n * (j + n * k))] = wall ? 1 : 0;
      }
  const double a = 0.1;
  const VoxelShape box = VoxelShape::create(n, n, n, a, occ);
  for (SphereFit fit : kFits) {
    SphereTreeOptions options;
    options.fit = fit;
    const SphereTree tree = SphereTree::build(box, Vec3::Zero(), options);
    const SphereNode& root = tree.root();
    EXPECT_LT((root.centre - Vec3::Constant(0.8)).norm(), 1e-9);
    EXPECT_NEAR(root.radius, std::sqrt(3.0) * 0.8, 1e-9);
    EXPECT_GE(root.h, 7.0 * a);
    EXPECT_LE(root.h, 7.0 * a + 0.1 * a + 0.03 * root.radius);  // within the documented tolerance
  }
}

}  // namespace
}  // namespace stc
