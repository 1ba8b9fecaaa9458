// Per-shape bounds of every sphere-tree node: the voxels' box inside each
// sphere (contact surfaces) and the leaves' reach below each node (sweeps).
#include "shape_bounds.hpp"

#include <cmath>
#include <limits>

namespace stc {

ShapeBounds makeShapeBounds(const SphereTree& tree, const VoxelShape* voxels, const Vec3& body_origin) {
  ShapeBounds bounds;
  bounds.tree = &tree;
  const auto& nodes = tree.nodes();
  const std::size_t count = nodes.size();
  bounds.box_offset.assign(count, Vec3::Zero());
  bounds.box_half.resize(count);
  bounds.reach.assign(count, 0.0);
  bounds.thinnest.assign(count, 0.0);
  bounds.leaves_centre.assign(count, Vec3::Zero());
  bounds.leaves_half.assign(count, Vec3::Zero());
  bounds.min_leaf_radius = std::numeric_limits<double>::infinity();

  for (std::size_t n = 0; n < count; ++n) {
    const SphereNode& node = nodes[n];
    bounds.box_half[n] = Vec3::Constant(node.radius);  // no voxels: the sphere's cube
    if (voxels == nullptr) continue;
    // Box of the occupied voxels whose centres lie in the sphere (grid frame).
    const double a = voxels->voxelSize();
    const Vec3 c = node.centre + body_origin;
    const double r = node.radius * (1.0 + 1e-9);
    const Eigen::Vector3i lo = ((c.array() - r) / a - 0.5).ceil().cast<int>().max(0).matrix();
    const Eigen::Vector3i hi =
        ((c.array() + r) / a - 0.5).floor().cast<int>().min(Eigen::Array3i(voxels->nx() - 1, voxels->ny() - 1,
                                                                        voxels->nz() - 1)).matrix();
    Vec3 box_min = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 box_max = -box_min;
    for (int k = lo.z(); k <= hi.z(); ++k) {
      for (int j = lo.y(); j <= hi.y(); ++j) {
        for (int i = lo.x(); i <= hi.x(); ++i) {
          if (!voxels->occupied(i, j, k)) continue;
          const Vec3 corner(i * a, j * a, k * a);
          if ((corner + Vec3::Constant(0.5 * a) - c).squaredNorm() > r * r) continue;
          box_min = box_min.cwiseMin(corner);
          box_max = box_max.cwiseMax(corner + Vec3::Constant(a));
        }
      }
    }
    if (!(box_min.x() <= box_max.x())) continue;  // no voxel centre inside: keep the cube
    bounds.box_offset[n] = 0.5 * (box_min + box_max) - c;
    bounds.box_half[n] = 0.5 * (box_max - box_min);
  }

  // Reach of the leaves below each node; children follow their parent
  // (breadth-first), so fill from the back.
  for (std::size_t i = count; i-- > 0;) {
    const SphereNode& n = nodes[i];
    if (n.child_count == 0) {
      // A voxel box may poke out of its sphere (only voxel centres lie inside).
      bounds.reach[i] = std::max(n.radius, bounds.box_offset[i].norm() + bounds.box_half[i].norm());
      bounds.min_leaf_radius = std::min(bounds.min_leaf_radius, n.radius);
      bounds.bound_radius = std::max(bounds.bound_radius, n.centre.norm() + bounds.reach[i]);
      bounds.thinnest[i] = bounds.box_half[i].minCoeff();
      bounds.leaves_centre[i] = n.centre + bounds.box_offset[i];
      bounds.leaves_half[i] = bounds.box_half[i];
      continue;
    }
    double reach = 0.0;
    double thinnest = std::numeric_limits<double>::infinity();
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 hi = -lo;
    for (std::int32_t c = n.first_child; c < n.first_child + n.child_count; ++c) {
      const std::size_t ci = static_cast<std::size_t>(c);
      reach = std::max(reach, (nodes[ci].centre - n.centre).norm() + bounds.reach[ci]);
      thinnest = std::min(thinnest, bounds.thinnest[ci]);
      lo = lo.cwiseMin(bounds.leaves_centre[ci] - bounds.leaves_half[ci]);
      hi = hi.cwiseMax(bounds.leaves_centre[ci] + bounds.leaves_half[ci]);
    }
    bounds.reach[i] = reach;
    bounds.thinnest[i] = thinnest;
    bounds.leaves_centre[i] = 0.5 * (lo + hi);
    bounds.leaves_half[i] = 0.5 * (hi - lo);
  }
  if (!std::isfinite(bounds.min_leaf_radius)) bounds.min_leaf_radius = 0.0;
  return bounds;
}

}  // namespace stc
