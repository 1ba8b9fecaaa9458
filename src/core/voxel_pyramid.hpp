// Private to the core: an implicit octree over a set of a shape's voxels (its
// surface voxels, or all occupied ones), used to build sphere-trees and to
// bound their gap h. Level D holds single voxels, level 0 the whole bounding
// cube (side 2^D voxels, 2^D >= max(nx, ny, nz)). Coordinates are in voxel
// units in the grid frame.
#pragma once

#include "sphere_tree_collision/voxel_shape.hpp"

#include <array>
#include <limits>
#include <vector>

namespace stc::detail {

using CellIndex = std::array<int, 3>;

enum class VoxelSet : std::uint8_t { Surface, Occupied, Empty };

class VoxelPyramid {
 public:
  VoxelPyramid(const VoxelShape& shape, VoxelSet set);

  int depth() const { return depth_; }
  int cellSide(int level) const { return 1 << (depth_ - level); }
  // True if the cell holds at least one voxel of the set (false outside the grid).
  bool has(int level, const CellIndex& c) const;
  // The cell's box clipped to the grid, in voxel units.
  void cellBox(int level, const CellIndex& c, Vec3& lo, Vec3& hi) const;
  // Distance from p to the union of the set's voxels inside the cell. `bound`
  // must be >= that distance (pass infinity if unknown); it only prunes, and is
  // returned when no voxel is nearer. `nearest`, if given, receives the nearest
  // point of the set, or NaN when none was nearer than `bound`.
  double distanceToSet(const Vec3& p, int level, const CellIndex& c, double bound,
                       Vec3* nearest = nullptr) const;
  // Appends the 8 corners of every voxel of the set inside the cell.
  void appendCorners(int level, const CellIndex& c, std::vector<Vec3>& out) const;

 private:
  struct Level {
    int nx = 0, ny = 0, nz = 0;
    std::vector<std::uint8_t> has_voxel;
  };
  std::vector<Level> levels_;
  int depth_ = 0;
  Vec3 grid_max_ = Vec3::Zero();
};

// Upper bound on max over points p of the sphere S(centre, radius) of
// dist(p, the occupied voxels in the cell), within `tolerance` of the true
// value (voxel units). See sphere_gap.cpp for the argument.
// `solid` holds the occupied voxels, `empty` the unoccupied ones (its depth
// inside the solid sharpens the bound). Returns infinity as soon as the true
// value is known to exceed `give_up_above` (for picking the best of several
// spheres without finishing the losers).
double sphereGapBound(const VoxelPyramid& solid, const VoxelPyramid& empty, int level,
                      const CellIndex& cell, const Vec3& centre, double radius, double tolerance,
                      double give_up_above = std::numeric_limits<double>::infinity());

}  // namespace stc::detail
