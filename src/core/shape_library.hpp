// ShapeLibrary: the shapes entities are made of, one per key, each built
// once: its voxels, exact mass properties, sphere-tree, and the bounds the
// tick reads of every node (shape_bounds.hpp, static_cover.hpp), and its
// interior (interior_field.hpp). Every
// entity of a shape shares them (EntitySpec::shape); the body frame is the
// shape's centre of mass. World::Parts holds the library (world_parts.hpp);
// the tick reads its arrays through the inline calls below.
#pragma once

#include "interior_field.hpp"
#include "shape_bounds.hpp"
#include "sphere_tree_collision/shape_info.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"
#include "static_cover.hpp"

#include <deque>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace stc {

class ShapeLibrary {
 public:
  // The same key returns the same id (the shape is built once). Throws
  // InputError("max_voxels") for a grid beyond limits.max_voxels and
  // InputError("voxel_size") outside the limits' voxel sizes; on throw
  // nothing changes.
  ShapeId addShape(const std::string& key, VoxelShape voxels, const VoxelLimits& limits,
                   const SphereTreeOptions& tree);
  std::optional<ShapeId> findShape(const std::string& key) const;
  const ShapeInfo& shape(ShapeId id) const;  // throws InputError("shape") for an unknown id
  std::size_t shapeCount() const { return shapes_.size(); }
  // Records how shape `id` was made (ShapeInfo::recipe); the first recipe
  // of a shape stays (a shape found again by its key was made by it).
  void setShapeRecipe(ShapeId id, const ShapeRecipe& recipe);

  // For the tick, by a shape id of a row (not checked, as shape() does): the
  // shape, the bounds of its nodes, and what StaticCover reads of each shape.
  const ShapeInfo& shapeAt(ShapeId id) const { return shapes_[id]; }
  const std::deque<ShapeBounds>& shapeBounds() const { return shape_bounds_; }
  const std::deque<InteriorField>& interiorFields() const { return interior_fields_; }
  const std::vector<CoverShape>& coverShapes() const { return cover_shapes_; }

 private:
  // By shape id. Deques: a shape (and its tree) keeps its address as shapes
  // are added, so the bounds can point at the trees and the cover shapes at both.
  std::deque<ShapeInfo> shapes_;
  std::deque<ShapeBounds> shape_bounds_;
  std::deque<InteriorField> interior_fields_;
  std::vector<CoverShape> cover_shapes_;  // what StaticCover reads of each
  std::unordered_map<std::string, ShapeId> shape_by_key_;
};

}  // namespace stc
