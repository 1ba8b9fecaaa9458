// ShapeLibrary: each shape built once, by key (shape_library.hpp).
#include "shape_library.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace stc {
namespace {

// Auto box mode: a shape whose occupied extent is this much longer along its
// longest axis than along its shortest gets a dynamic box (paper 3.2: long,
// thin objects are bounded badly by a fixed cube). With the presets at
// resolution 8: rod, plate and the flat L and ring pass; cube, sphere, rock do not.
constexpr double kElongationRatio = 2.5;

// Max distance from `origin` to a corner of an occupied voxel: the radius of
// a ball about the centre of mass that holds the shape in any orientation.
double boundingRadius(const VoxelShape& shape, const Vec3& origin) {
  const double s = shape.voxelSize();
  double max_sq = 0.0;
  for (int k = 0; k < shape.nz(); ++k) {
    for (int j = 0; j < shape.ny(); ++j) {
      for (int i = 0; i < shape.nx(); ++i) {
        if (!shape.occupied(i, j, k)) continue;
        const Vec3 lo = Vec3(i, j, k) * s - origin;
        const Vec3 hi = lo + Vec3::Constant(s);
        max_sq = std::max(max_sq, lo.cwiseAbs().cwiseMax(hi.cwiseAbs()).squaredNorm());
      }
    }
  }
  return std::sqrt(max_sq);
}

// Longest over shortest extent of the occupied voxels' bounding box (the
// grid may be padded, the occupied part is what moves).
bool isElongated(const VoxelShape& shape) {
  Eigen::Vector3i lo(shape.nx(), shape.ny(), shape.nz());
  Eigen::Vector3i hi(-1, -1, -1);
  for (int k = 0; k < shape.nz(); ++k) {
    for (int j = 0; j < shape.ny(); ++j) {
      for (int i = 0; i < shape.nx(); ++i) {
        if (!shape.occupied(i, j, k)) continue;
        lo = lo.cwiseMin(Eigen::Vector3i(i, j, k));
        hi = hi.cwiseMax(Eigen::Vector3i(i, j, k));
      }
    }
  }
  const Eigen::Vector3i extent = hi - lo + Eigen::Vector3i::Ones();
  return extent.maxCoeff() >= kElongationRatio * extent.minCoeff();
}

}  // namespace

ShapeId ShapeLibrary::addShape(const std::string& key, VoxelShape voxels, const VoxelLimits& limits,
                               const SphereTreeOptions& tree) {
  if (const auto found = findShape(key)) return *found;
  const std::int64_t cells = static_cast<std::int64_t>(voxels.nx()) * voxels.ny() * voxels.nz();
  if (cells > limits.max_voxels) {
    throw InputError("max_voxels", "grid of " + std::to_string(cells) + " voxels exceeds " +
                                       std::to_string(limits.max_voxels));
  }
  if (!(voxels.voxelSize() >= limits.min_voxel_size && voxels.voxelSize() <= limits.max_voxel_size)) {
    throw InputError("voxel_size", "outside [" + std::to_string(limits.min_voxel_size) + ", " +
                                       std::to_string(limits.max_voxel_size) + "]");
  }

  ShapeInfo info;
  info.key = key;
  info.unit_mass = computeMassProperties(voxels, 1.0);
  info.body_origin = info.unit_mass.centre_of_mass;
  info.tree = SphereTree::build(voxels, info.body_origin, tree);
  info.bounding_radius = boundingRadius(voxels, info.body_origin);
  info.elongated = isElongated(voxels);

  // Bounds of every node, once per shape (contacts and sweeps read them each tick).
  ShapeBounds bounds = makeShapeBounds(info.tree, &voxels, info.body_origin);
  InteriorField interior(voxels, info.body_origin);
  info.voxels = std::move(voxels);

  const auto id = static_cast<ShapeId>(shapes_.size());
  shapes_.push_back(std::move(info));  // deque: earlier shapes (and trees) stay put
  bounds.tree = &shapes_.back().tree;  // the tree moved into the deque
  shape_bounds_.push_back(std::move(bounds));
  interior_fields_.push_back(std::move(interior));
  cover_shapes_.push_back(CoverShape{&shapes_.back().voxels, shapes_.back().body_origin, &shape_bounds_.back()});
  shape_by_key_.emplace(key, id);
  return id;
}

std::optional<ShapeId> ShapeLibrary::findShape(const std::string& key) const {
  const auto it = shape_by_key_.find(key);
  if (it == shape_by_key_.end()) return std::nullopt;
  return it->second;
}

const ShapeInfo& ShapeLibrary::shape(ShapeId id) const {
  if (id >= shapes_.size()) throw InputError("shape", "unknown shape id " + std::to_string(id));
  return shapes_[id];
}

void ShapeLibrary::setShapeRecipe(ShapeId id, const ShapeRecipe& recipe) {
  ShapeInfo& info = shapes_.at(id);
  if (info.recipe.preset.empty() && info.recipe.mesh_resource.empty()) info.recipe = recipe;
}

}  // namespace stc
