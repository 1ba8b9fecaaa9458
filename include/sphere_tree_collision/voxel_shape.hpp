// VoxelShape: an occupancy grid of solid cubes (paper 3.1), its exact mass
// properties, and the named presets a scene can use.
#pragma once

#include "sphere_tree_collision/types.hpp"

#include <string>
#include <vector>

namespace stc {

// Limits a caller may tighten; grids beyond them are rejected, not clipped.
struct VoxelLimits {
  std::int64_t max_voxels = 4'000'000;  // nx*ny*nz
  double min_voxel_size = 1e-5;         // metres
  double max_voxel_size = 1e3;          // metres
};

// Throws InputError("voxel_size") unless `voxel_size` is finite, > 0 and within
// [min_voxel_size, max_voxel_size]; the message starts with `source` ("" or
// "<file>: ") and ends with `note`. The one check of a voxel size: grids,
// presets, meshes and requests (before any shape cache is asked) use it.
void validateVoxelSize(double voxel_size, const VoxelLimits& limits, const std::string& source = "",
                       const std::string& note = "");

// Throws InputError("max_voxels") when an nx x ny x nz grid has more cells
// than limits.max_voxels: the one check of a grid's size, made before a grid
// is built (presets) as well as when a shape is made of it.
void validateGridCells(int nx, int ny, int nz, const VoxelLimits& limits);

// Grid frame: voxel (i,j,k) occupies [i,i+1]x[j,j+1]x[k,k+1] * voxel_size,
// so the grid's min corner is the origin.
class VoxelShape {
 public:
  // Throws InputError naming the field: "dims" (any n <= 0), "voxel_size"
  // (<= 0, NaN, outside limits), "occupancy" (size != nx*ny*nz, or no voxel
  // set), "max_voxels" (grid larger than the limit).
  static VoxelShape create(int nx, int ny, int nz, double voxel_size,
                           std::vector<std::uint8_t> occupancy,
                           const VoxelLimits& limits = VoxelLimits{});

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  int nz() const { return nz_; }
  double voxelSize() const { return voxel_size_; }
  Vec3 extent() const { return Vec3(nx_, ny_, nz_) * voxel_size_; }

  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx_) *
           (static_cast<std::size_t>(j) + static_cast<std::size_t>(ny_) * k);
  }
  // False outside the grid.
  bool occupied(int i, int j, int k) const {
    if (i < 0 || j < 0 || k < 0 || i >= nx_ || j >= ny_ || k >= nz_) return false;
    return occupancy_[index(i, j, k)] != 0;
  }
  // Occupied with at least one of its six face neighbours empty (or outside).
  bool isSurfaceVoxel(int i, int j, int k) const;
  std::int64_t occupiedCount() const { return occupied_count_; }
  const std::vector<std::uint8_t>& occupancy() const { return occupancy_; }

  // The sphere preset is flagged so it gets a one-level tree (exact sphere).
  bool isSphere() const { return is_sphere_; }
  void markSphere() { is_sphere_ = true; }

  // How far a point of the voxels may lie from the surface they approximate
  // (0 for shapes defined by their voxels; a voxelised mesh sets its voxel
  // diagonal). SphereTree::build adds it to every node's gap bound h.
  double surfaceMargin() const { return surface_margin_; }
  void setSurfaceMargin(double metres) { surface_margin_ = metres; }

 private:
  int nx_ = 0, ny_ = 0, nz_ = 0;
  double voxel_size_ = 0.0;
  std::vector<std::uint8_t> occupancy_;
  std::int64_t occupied_count_ = 0;
  bool is_sphere_ = false;
  double surface_margin_ = 0.0;
};

// Mass properties of the shape treated as the union of its solid voxels.
struct MassProperties {
  double mass = 0.0;
  Vec3 centre_of_mass = Vec3::Zero();    // grid frame
  Mat3 inertia = Mat3::Zero();           // about the centre of mass, grid axes
};

// Exact: each voxel a solid cube, summed with the parallel-axis theorem.
// Throws InputError("density") if density <= 0 or not finite.
MassProperties computeMassProperties(const VoxelShape& shape, double density);

// Presets: "cube", "sphere", "rock", "rod", "plate", "L", "ring".
struct PresetParams {
  int resolution = 8;        // voxels along the preset's largest extent
  double voxel_size = 0.05;  // metres
  std::uint32_t seed = 1;    // rock only
};
const std::vector<std::string>& presetNames();
// Throws InputError("preset") for an unknown name, InputError("resolution")
// outside 1..256 (the ring needs >= 3 to have a hole), and the create() errors.
// The rock is a seeded random blob, 6-connected, the same for the same seed.
VoxelShape makePreset(const std::string& name, const PresetParams& params = PresetParams{},
                      const VoxelLimits& limits = VoxelLimits{});

}  // namespace stc
