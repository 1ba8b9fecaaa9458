// A shape of the World (World::shape): its voxels, how it was made, its mass
// properties per unit density, its sphere-tree and bounding radius. The
// World's ShapeLibrary (src/core/shape_library.hpp) builds each once.
#pragma once

#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/types.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"

#include <cstdint>
#include <string>

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

}  // namespace stc
