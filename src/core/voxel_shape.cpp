// VoxelShape construction (validated) and the surface-voxel predicate.
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cmath>
#include <sstream>

namespace stc {

void validateVoxelSize(double voxel_size, const VoxelLimits& limits, const std::string& source,
                       const std::string& note) {
  if (std::isfinite(voxel_size) && voxel_size > 0.0 && voxel_size >= limits.min_voxel_size &&
      voxel_size <= limits.max_voxel_size) {
    return;
  }
  std::ostringstream out;
  out << source << "must be finite and within [" << limits.min_voxel_size << ", " << limits.max_voxel_size
      << "] m, got " << voxel_size << note;
  throw InputError("voxel_size", out.str());
}

void validateGridCells(int nx, int ny, int nz, const VoxelLimits& limits) {
  // In double: the int64 product of three ints can overflow, the double one cannot.
  const double cells = static_cast<double>(nx) * ny * nz;
  if (cells > static_cast<double>(limits.max_voxels)) {
    throw InputError("max_voxels", "grid has " + std::to_string(cells) + " voxels, limit is " +
                                       std::to_string(limits.max_voxels));
  }
}

VoxelShape VoxelShape::create(int nx, int ny, int nz, double voxel_size,
                              std::vector<std::uint8_t> occupancy, const VoxelLimits& limits) {
  if (nx <= 0 || ny <= 0 || nz <= 0) {
    throw InputError("dims", "every grid dimension must be positive, got " + std::to_string(nx) +
                                 " x " + std::to_string(ny) + " x " + std::to_string(nz));
  }
  validateVoxelSize(voxel_size, limits);
  validateGridCells(nx, ny, nz, limits);
  const std::size_t count = static_cast<std::size_t>(nx) * ny * nz;
  if (occupancy.size() != count) {
    throw InputError("occupancy", "size " + std::to_string(occupancy.size()) +
                                      " does not match nx*ny*nz = " + std::to_string(count));
  }
  std::int64_t occupied = 0;
  for (std::uint8_t& v : occupancy) {
    v = v != 0 ? 1 : 0;  // any non-zero byte means occupied; store as 0/1
    occupied += v;
  }
  if (occupied == 0) throw InputError("occupancy", "no voxel is occupied");

  VoxelShape shape;
  shape.nx_ = nx;
  shape.ny_ = ny;
  shape.nz_ = nz;
  shape.voxel_size_ = voxel_size;
  shape.occupancy_ = std::move(occupancy);
  shape.occupied_count_ = occupied;
  return shape;
}

bool VoxelShape::isSurfaceVoxel(int i, int j, int k) const {
  if (!occupied(i, j, k)) return false;
  return !occupied(i - 1, j, k) || !occupied(i + 1, j, k) || !occupied(i, j - 1, k) ||
         !occupied(i, j + 1, k) || !occupied(i, j, k - 1) || !occupied(i, j, k + 1);
}

}  // namespace stc
