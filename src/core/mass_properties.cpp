// Exact mass properties of a voxel shape: the union of solid cubes.
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cmath>

namespace stc {

MassProperties computeMassProperties(const VoxelShape& shape, double density) {
  if (!std::isfinite(density) || density <= 0.0) {
    throw InputError("density", "must be finite and positive, got " + std::to_string(density));
  }
  const double a = shape.voxelSize();
  const double voxel_mass = density * a * a * a;

  // Two passes (centre, then second moments about it) keep the sums small and
  // the result accurate even for large grids far from the origin.
  Vec3 sum = Vec3::Zero();
  for (int k = 0; k < shape.nz(); ++k)
    for (int j = 0; j < shape.ny(); ++j)
      for (int i = 0; i < shape.nx(); ++i)
        if (shape.occupied(i, j, k)) sum += Vec3(i + 0.5, j + 0.5, k + 0.5);
  const double n = static_cast<double>(shape.occupiedCount());
  const Vec3 centre_vox = sum / n;

  Mat3 second = Mat3::Zero();  // sum of d d^T over voxel centres, voxel units
  for (int k = 0; k < shape.nz(); ++k)
    for (int j = 0; j < shape.ny(); ++j)
      for (int i = 0; i < shape.nx(); ++i)
        if (shape.occupied(i, j, k)) {
          const Vec3 d = Vec3(i + 0.5, j + 0.5, k + 0.5) - centre_vox;
          second += d * d.transpose();
        }

  MassProperties mp;
  mp.mass = voxel_mass * n;
  mp.centre_of_mass = centre_vox * a;
  // Each cube about its own centre: m a^2 / 6 on the diagonal; parallel axis:
  // m (|d|^2 I - d d^T).
  mp.inertia = (voxel_mass * a * a) *
               (second.trace() * Mat3::Identity() - second + (n / 6.0) * Mat3::Identity());
  return mp;
}

}  // namespace stc
