// Implicit voxel-set octree: one flag array per level, each flag the OR of
// its (up to) eight children, so empty regions are skipped in O(1).
#include "voxel_pyramid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace stc::detail {

VoxelPyramid::VoxelPyramid(const VoxelShape& shape, VoxelSet set) {
  const int largest = std::max({shape.nx(), shape.ny(), shape.nz()});
  while ((1 << depth_) < largest) ++depth_;
  grid_max_ = Vec3(shape.nx(), shape.ny(), shape.nz());
  levels_.resize(static_cast<std::size_t>(depth_) + 1);

  Level& finest = levels_.back();
  finest.nx = shape.nx();
  finest.ny = shape.ny();
  finest.nz = shape.nz();
  finest.has_voxel.assign(shape.occupancy().size(), 0);
  for (int k = 0; k < shape.nz(); ++k)
    for (int j = 0; j < shape.ny(); ++j)
      for (int i = 0; i < shape.nx(); ++i)
        finest.has_voxel[shape.index(i, j, k)] = set == VoxelSet::Surface    ? shape.isSurfaceVoxel(i, j, k)
                                                 : set == VoxelSet::Occupied ? shape.occupied(i, j, k)
                                                                             : !shape.occupied(i, j, k);

  for (int level = depth_ - 1; level >= 0; --level) {
    const Level& fine = levels_[static_cast<std::size_t>(level) + 1];
    Level& coarse = levels_[static_cast<std::size_t>(level)];
    coarse.nx = (fine.nx + 1) / 2;
    coarse.ny = (fine.ny + 1) / 2;
    coarse.nz = (fine.nz + 1) / 2;
    coarse.has_voxel.assign(static_cast<std::size_t>(coarse.nx) * coarse.ny * coarse.nz, 0);
    for (int k = 0; k < fine.nz; ++k)
      for (int j = 0; j < fine.ny; ++j)
        for (int i = 0; i < fine.nx; ++i) {
          if (!fine.has_voxel[static_cast<std::size_t>(i) + static_cast<std::size_t>(fine.nx) *
                                                                  (j + static_cast<std::size_t>(fine.ny) * k)])
            continue;
          coarse.has_voxel[static_cast<std::size_t>(i / 2) +
                             static_cast<std::size_t>(coarse.nx) *
                                 (j / 2 + static_cast<std::size_t>(coarse.ny) * (k / 2))] = 1;
        }
  }
}

bool VoxelPyramid::has(int level, const CellIndex& c) const {
  const Level& l = levels_[static_cast<std::size_t>(level)];
  if (c[0] < 0 || c[1] < 0 || c[2] < 0 || c[0] >= l.nx || c[1] >= l.ny || c[2] >= l.nz) return false;
  return l.has_voxel[static_cast<std::size_t>(c[0]) +
                       static_cast<std::size_t>(l.nx) * (c[1] + static_cast<std::size_t>(l.ny) * c[2])] != 0;
}

void VoxelPyramid::cellBox(int level, const CellIndex& c, Vec3& lo, Vec3& hi) const {
  const double side = cellSide(level);
  lo = Vec3(c[0], c[1], c[2]) * side;
  hi = (lo + Vec3::Constant(side)).cwiseMin(grid_max_);
}

namespace {
double boxDistanceSquared(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 d = (lo - p).cwiseMax(p - hi).cwiseMax(0.0);
  return d.squaredNorm();
}
}  // namespace

double VoxelPyramid::distanceToSet(const Vec3& p, int level, const CellIndex& c, double bound,
                                   Vec3* nearest) const {
  if (nearest) *nearest = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  // Fast path: p inside a voxel of the set that lies in the cell.
  const CellIndex v = {static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())),
                       static_cast<int>(std::floor(p.z()))};
  const int shift = depth_ - level;
  if (v[0] >= 0 && v[1] >= 0 && v[2] >= 0 && (v[0] >> shift) == c[0] && (v[1] >> shift) == c[1] &&
      (v[2] >> shift) == c[2] && has(depth_, v)) {
    if (nearest) *nearest = p;
    return 0.0;
  }
  struct Entry {
    int level;
    CellIndex cell;
    double d2;
  };
  // Depth-first, nearest child first; at most 8 pending entries per level.
  Entry stack[8 * 32];
  int top = 0;
  double best2 = std::isfinite(bound) ? bound * bound : std::numeric_limits<double>::infinity();
  Vec3 lo, hi;
  cellBox(level, c, lo, hi);
  stack[top++] = {level, c, boxDistanceSquared(p, lo, hi)};
  while (top > 0) {
    const Entry e = stack[--top];
    if (e.d2 >= best2) continue;
    if (e.level == depth_) {
      best2 = e.d2;  // a voxel of the set: its box distance is the exact distance
      if (nearest) {
        cellBox(e.level, e.cell, lo, hi);
        *nearest = p.cwiseMax(lo).cwiseMin(hi);
      }
      continue;
    }
    Entry kids[8];
    int count = 0;
    for (int o = 0; o < 8; ++o) {
      const CellIndex child = {2 * e.cell[0] + (o & 1), 2 * e.cell[1] + ((o >> 1) & 1),
                               2 * e.cell[2] + ((o >> 2) & 1)};
      if (!has(e.level + 1, child)) continue;
      cellBox(e.level + 1, child, lo, hi);
      const double d2 = boxDistanceSquared(p, lo, hi);
      if (d2 < best2) kids[count++] = {e.level + 1, child, d2};
    }
    // Farthest pushed first so the nearest is explored first (insertion sort:
    // at most eight entries).
    for (int i = 1; i < count; ++i)
      for (int j = i; j > 0 && kids[j - 1].d2 < kids[j].d2; --j) std::swap(kids[j - 1], kids[j]);
    for (int i = 0; i < count; ++i) stack[top++] = kids[i];
  }
  return std::sqrt(best2);
}

void VoxelPyramid::appendCorners(int level, const CellIndex& c, std::vector<Vec3>& out) const {
  if (!has(level, c)) return;
  if (level == depth_) {
    for (int o = 0; o < 8; ++o)
      out.emplace_back(c[0] + (o & 1), c[1] + ((o >> 1) & 1), c[2] + ((o >> 2) & 1));
    return;
  }
  for (int o = 0; o < 8; ++o)
    appendCorners(level + 1, {2 * c[0] + (o & 1), 2 * c[1] + ((o >> 1) & 1), 2 * c[2] + ((o >> 2) & 1)},
                         out);
}

}  // namespace stc::detail
