// ShapeLibrary: the shapes entities are made of, one per key, each built
// once: its voxels, exact mass properties, sphere-tree, and the bounds the
// tick reads of every node (shape_bounds.hpp, static_cover.hpp). Every
// entity of a shape shares them (EntitySpec::shape); the body frame is the
// shape's centre of mass. The World derives from the library privately, so
// the tick reads its arrays by their names.
#pragma once

#include "sphere_tree_collision/shape_bounds.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/static_cover.hpp"
#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <deque>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace stc {

// How a shape was made, so a saved world makes it again (scene_file.hpp
// writes it): a preset by name and parameters, a mesh by its resource as
// requested and how it was voxelised, or, with neither (a grid of a spawn
// message, a fracture piece), its voxels as they are.
struct ShapeRecipe {
  std::string preset;            // e.g. "rock"
  PresetParams preset_params;    // a preset's; of a mesh, the resolution
  std::string mesh_resource;     // package://, file:// or a path, unresolved
  Vec3 mesh_scale = Vec3::Ones();
  double mesh_voxel_size = 0.0;  // 0: by resolution
  std::uint8_t mesh_up_axis = 0; // ColladaUpAxis (mesh_loader.hpp)
};

struct ShapeInfo {
  std::string key;
  ShapeRecipe recipe;         // empty (preset and mesh_resource ""): its voxels
  VoxelShape voxels;
  MassProperties unit_mass;   // density 1
  Vec3 body_origin;           // centre of mass in the grid frame
  SphereTree tree;
  double bounding_radius = 0; // max distance from the body origin to the shape
  bool elongated = false;     // Auto box mode picks Dynamic
};

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

 protected:
  // By shape id. Deques: a shape (and its tree) keeps its address as shapes
  // are added, so the bounds can point at the trees and the cover shapes at both.
  std::deque<ShapeInfo> shapes_;
  std::deque<ShapeBounds> shape_bounds_;
  std::vector<CoverShape> cover_shapes_;  // what StaticCover reads of each

 private:
  std::unordered_map<std::string, ShapeId> shape_by_key_;
};

}  // namespace stc
