// Octree sphere-tree construction (paper 3.3.1).
//
// The bounding cube has 2^D voxels per side (2^D >= max(nx, ny, nz)), so cells
// of every level align with voxels; level L cells have side 2^(D-L) voxels and
// subdivision stops at single voxels. A cell becomes a node only if it holds a
// SURFACE voxel (occupied, with an empty or outside face neighbour). This is
// the paper's "remove nodes occluded on all six sides" made exact: a cell whose
// occupied voxels are all interior is enclosed by other occupied voxels, so
// nothing can reach it without first touching a cell that does hold surface
// voxels, and dropping it loses no coverage of the surface.
#include "sphere_tree_collision/sphere_tree.hpp"

#include "enclosing_sphere.hpp"
#include "voxel_pyramid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace stc {
namespace {

constexpr int kMaxLevels = 8;
constexpr double kNoLimit = std::numeric_limits<double>::infinity();

// h is refined to within this many voxels (plus 3% of the radius, so huge
// spheres do not cost a huge number of samples).
double gapTolerance(double radius_vox) { return 0.1 + 0.03 * radius_vox; }

// Cells up to kMemoSide voxels repeat the same few patterns all over a shape
// (faces, edges, corners of the same slab); their sphere and h depend only on
// which voxels are surface and which occupied, and on the clipped cell size,
// so they are computed once per pattern (relative to the cell's corner).
constexpr int kMemoSide = 16;
struct PatternKey {
  std::array<int, 3> clipped;       // cell size in voxels after clipping to the grid
  std::vector<std::uint64_t> bits;  // 2 bits per voxel: surface, occupied
  bool operator==(const PatternKey& o) const { return clipped == o.clipped && bits == o.bits; }
};
struct PatternHash {
  std::size_t operator()(const PatternKey& k) const {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (int v : k.clipped) h = (h ^ static_cast<std::uint64_t>(v)) * 0x100000001B3ull;
    for (std::uint64_t w : k.bits) h = (h ^ w ^ (w >> 32)) * 0x100000001B3ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};
struct FittedCell {
  Vec3 centre_from_corner;  // voxel units
  double radius;
  double h;
};

// Corners of the occupied voxels of the cell that can lie on its convex hull:
// per (i, j) column only the lowest and highest occupied voxels matter (the
// others sit on the segment between them).
void appendOccupiedColumnCorners(const VoxelShape& shape, const Vec3& lo, const Vec3& hi,
                                 std::vector<Vec3>& out) {
  const int i0 = int(lo.x()), j0 = int(lo.y()), k0 = int(lo.z());
  const int i1 = int(hi.x()), j1 = int(hi.y()), k1 = int(hi.z());
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) {
      int kmin = k1, kmax = k0 - 1;
      for (int k = k0; k < k1; ++k)
        if (shape.occupied(i, j, k)) {
          kmin = std::min(kmin, k);
          kmax = k;
        }
      if (kmax < kmin) continue;
      for (int o = 0; o < 4; ++o) {
        out.emplace_back(i + (o & 1), j + (o >> 1), kmin);
        out.emplace_back(i + (o & 1), j + (o >> 1), kmax + 1);
      }
    }
}

// Sphere and gap bound of one cell, in voxel units (grid frame).
//   Paper: circumscribed sphere of the cell clipped to the grid's cuboid,
//          r = sqrt(x^2 + y^2 + z^2) / 2 (= sqrt(3) a / 2 for a whole cube).
//   Tight: of three valid covers -- the smallest sphere around the cell's
//          surface voxels, the smallest around its occupied voxels, and the
//          paper sphere -- the one with the smallest h (then radius). The
//          surface-only sphere alone is not enough: on a solid face it centres
//          on the one-voxel shell and bulges out further than the paper sphere,
//          so it would be a worse fit (larger gap) despite its smaller radius.
//          All three enclose the surface voxels and none is larger than the
//          paper sphere (they enclose subsets of the clipped cell), so tight
//          is never looser than paper, by radius or by h.
FittedCell fitCell(const VoxelShape& shape, const detail::VoxelPyramid& surface,
                   const detail::VoxelPyramid& solid, const detail::VoxelPyramid& empty, int level, const detail::CellIndex& cell, SphereFit fit,
                   std::vector<Vec3>& corners) {
  Vec3 lo, hi;
  surface.cellBox(level, cell, lo, hi);
  const auto withGap = [&](const Sphere& s, double give_up_above) {
    return FittedCell{s.centre, s.radius,
                      detail::sphereGapBound(solid, empty, level, cell, s.centre, s.radius,
                                             gapTolerance(s.radius), give_up_above)};
  };
  const Sphere paper{0.5 * (lo + hi), 0.5 * (hi - lo).norm()};
  if (fit == SphereFit::Paper) return withGap(paper, kNoLimit);

  corners.clear();
  appendOccupiedColumnCorners(shape, lo, hi, corners);
  const Sphere around_occupied = minimalEnclosingSphere(corners);
  corners.clear();
  surface.appendCorners(level, cell, corners);
  const Sphere around_surface = minimalEnclosingSphere(corners);
  // Candidates in the order they usually win; a later one is abandoned as soon
  // as its h is known to exceed the best so far.
  FittedCell best{paper.centre, paper.radius, kNoLimit};
  std::vector<Sphere> tried;
  for (const Sphere& s : {around_occupied, around_surface, paper}) {
    if (s.radius > paper.radius) continue;  // cannot happen but for rounding
    const bool repeat = std::any_of(tried.begin(), tried.end(), [&](const Sphere& t) {
      return t.radius == s.radius && (t.centre - s.centre).norm() <= 1e-12;
    });
    if (repeat) continue;
    tried.push_back(s);
    const FittedCell c = withGap(s, best.h);
    if (c.h < best.h || (c.h == best.h && c.radius < best.radius)) best = c;
  }
  return best;
}

}  // namespace

SphereTree SphereTree::build(const VoxelShape& shape, const Vec3& body_origin,
                             const SphereTreeOptions& options) {
  if (options.max_levels < 1 || options.max_levels > kMaxLevels) {
    throw InputError("max_levels", "must be in [1, " + std::to_string(kMaxLevels) + "], got " +
                                       std::to_string(options.max_levels));
  }
  if (!body_origin.allFinite()) throw InputError("body_origin", "must be finite");
  if (shape.occupiedCount() == 0) throw InputError("occupancy", "no voxel is occupied");

  const detail::VoxelPyramid pyramid(shape, detail::VoxelSet::Surface);  // which cells are nodes
  const detail::VoxelPyramid solid(shape, detail::VoxelSet::Occupied);    // what h measures to
  const detail::VoxelPyramid empty(shape, detail::VoxelSet::Empty);       // how deep inside it
  const int levels =
      shape.isSphere() ? 1 : std::min(options.max_levels, pyramid.depth() + 1);
  const double a = shape.voxelSize();

  SphereTree tree;
  tree.fit_ = options.fit;
  std::vector<detail::CellIndex> cells;  // octree cell of each node, parallel to nodes_
  std::vector<Vec3> corners;             // scratch for the tight fit

  std::unordered_map<PatternKey, FittedCell, PatternHash> patterns;
  // A sphere shape's single node is its smallest enclosing sphere: the
  // circumscribed cube would be sqrt(3) times too big.
  const SphereFit fit = shape.isSphere() ? SphereFit::Tight : options.fit;
  const auto fitWithGap = [&](int level, const detail::CellIndex& cell) {
    return fitCell(shape, pyramid, solid, empty, level, cell, fit, corners);
  };
  const auto addNode = [&](int level, const detail::CellIndex& cell, std::int32_t parent) {
    Vec3 lo, hi;
    pyramid.cellBox(level, cell, lo, hi);
    FittedCell f;
    const int side = pyramid.cellSide(level);
    if (side <= kMemoSide) {
      PatternKey key{{int(hi.x() - lo.x()), int(hi.y() - lo.y()), int(hi.z() - lo.z())}, {}};
      key.bits.assign((2 * static_cast<std::size_t>(key.clipped[0]) * key.clipped[1] * key.clipped[2] + 63) / 64, 0);
      std::size_t bit = 0;
      for (int k = int(lo.z()); k < int(hi.z()); ++k)
        for (int j = int(lo.y()); j < int(hi.y()); ++j)
          for (int i = int(lo.x()); i < int(hi.x()); ++i, bit += 2) {
            const std::uint64_t pair = (pyramid.has(pyramid.depth(), {i, j, k}) ? 1u : 0u) |
                                       (shape.occupied(i, j, k) ? 2u : 0u);
            key.bits[bit / 64] |= pair << (bit % 64);
          }
      auto it = patterns.find(key);
      if (it == patterns.end()) {
        f = fitWithGap(level, cell);
        f.centre_from_corner = f.centre_from_corner - lo;
        it = patterns.emplace(std::move(key), f).first;
      }
      f = it->second;
      f.centre_from_corner += lo;
    } else {
      f = fitWithGap(level, cell);
    }
    SphereNode node;
    node.centre = f.centre_from_corner * a - body_origin;
    node.radius = f.radius * a;
    node.h = f.h * a + shape.surfaceMargin();  // the gap bound covers the original surface
    node.parent = parent;
    node.level = level;
    tree.nodes_.push_back(node);
    cells.push_back(cell);
  };

  tree.level_begin_.push_back(0);
  addNode(0, {0, 0, 0}, -1);
  for (int level = 1; level < levels; ++level) {
    const std::int32_t begin = tree.level_begin_.back();
    const std::int32_t end = static_cast<std::int32_t>(tree.nodes_.size());
    tree.level_begin_.push_back(end);
    // Breadth first: the children of each node of the previous level are
    // appended together, so they are contiguous and levels are contiguous.
    for (std::int32_t parent = begin; parent < end; ++parent) {
      const detail::CellIndex pc = cells[static_cast<std::size_t>(parent)];
      const std::int32_t first = static_cast<std::int32_t>(tree.nodes_.size());
      for (int o = 0; o < 8; ++o) {
        const detail::CellIndex child = {2 * pc[0] + (o & 1), 2 * pc[1] + ((o >> 1) & 1),
                                         2 * pc[2] + ((o >> 2) & 1)};
        if (pyramid.has(level, child)) addNode(level, child, parent);
      }
      SphereNode& p = tree.nodes_[static_cast<std::size_t>(parent)];
      p.first_child = first;
      p.child_count = static_cast<std::int32_t>(tree.nodes_.size()) - first;
    }
  }
  tree.level_begin_.push_back(static_cast<std::int32_t>(tree.nodes_.size()));
  return tree;
}

}  // namespace stc
