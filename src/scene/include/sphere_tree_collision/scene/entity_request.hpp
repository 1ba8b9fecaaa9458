// EntityRequest: one entity to add to the World, as a scene file or a spawn
// message describes it (a shape preset, an explicit grid or a mesh, a body
// state, a colour). One type and one validate for every source, so a topic, a
// service and a scene file accept and refuse alike and share shapes.
// ROS-free: the ROS layer only turns a message into a request.
#pragma once

#include "sphere_tree_collision/mesh_loader.hpp"
#include "sphere_tree_collision/world.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace stc {

using Rgba = std::array<float, 4>;

struct ExplicitGrid {
  int nx = 0, ny = 0, nz = 0;
  double voxel_size = 0.0;
  std::vector<std::uint8_t> occupancy;  // x fastest, non-zero = solid
};

// What a request's fields left at 0 (where 0 means nothing) become: one rule
// for the spawn topic, ~spawn and scene files (the node's ~default_resolution,
// ~default_density and ~default_voxel_size; docs/ros_interface.md).
struct RequestDefaults {
  int resolution = 8;        // resolution 0: voxels along a preset's (or a mesh's) largest extent
  double density = 1000.0;   // density 0: kg/m^3
  double voxel_size = 0.05;  // a preset's voxel_size 0: m (a mesh's 0 means "by resolution")
};

// Largest `resolution` a request may ask for: a preset's, and a mesh's (whose
// voxelising costs more per voxel along its side).
constexpr int kMaxPresetResolution = 4096;
constexpr int kMaxMeshResolution = 1024;

struct EntityRequest {
  // The shape: exactly one of a preset, an explicit grid or a mesh.
  std::string preset;
  // resolution and voxel_size 0 here and density 0 in spec: the RequestDefaults.
  PresetParams preset_params{0, 0.0, 1};
  std::optional<ExplicitGrid> grid;
  // A mesh (package://, file:// or a path), scaled per axis, voxelised at
  // mesh_voxel_size, or when 0 at preset_params.resolution voxels along its longest side.
  std::string mesh_resource;
  std::optional<Vec3> mesh_scale;              // mesh only; unset: 1 on each axis
  double mesh_voxel_size = 0.0;
  std::optional<ColladaUpAxis> mesh_up_axis;   // mesh only; unset: as the DAE says (mesh_loader.hpp)

  EntitySpec spec = [] {
    EntitySpec unset;
    unset.density = 0.0;
    return unset;
  }();                                 // spec.shape is filled in by addRequest
  std::optional<Rgba> color;           // unset: the ROS layer's palette colour by id
};

// How a mesh_resource becomes a file path: meshPathWithinRoots reads files
// under the WorldConfig's mesh_roots; the ROS layer adds package://.
using MeshResolver = std::string (*)(const std::string& resource, const std::vector<std::string>& roots);

// Shape cache key of a preset: equal keys share one shape and one tree.
std::string presetShapeKey(const std::string& preset, const PresetParams& params);

// Names become tf frames: letters, digits and '_' only, at most 64 characters,
// and not of the form "entity_<digits>" (the frames of unnamed entities).
// Throws InputError("name").
void validateEntityName(const std::string& name);

// A quaternion of four zeros (a pose's orientation left out) is the identity;
// any other is returned as it is (validated later).
Quat orientationOrIdentity(const Quat& q);

// Throws InputError(field) when `text` holds a NUL or another control byte
// (a path would be cut at the NUL, a name would carry it into logs and tf).
void validateText(const std::string& text, const std::string& field);

// Fills the fields left at 0 where 0 means nothing: resolution, density, a
// preset's voxel_size, an all-zero orientation. restitution, friction and
// strength 0 are real values and stay.
void applyDefaults(EntityRequest& request, const RequestDefaults& defaults);

// Every field of a request (defaults applied) against `world`: its shape
// source, text, body state, limits and name. Throws InputError naming the
// field. addRequest calls it before any shape cache is asked, so a cached
// shape never lets a bad field through.
void validateRequest(const World& world, const EntityRequest& request);

// Applies the defaults, validates the whole request, then builds (or reuses)
// the shape and adds the entity. Throws InputError naming the field; the
// entity set is unchanged on throw (a valid shape may stay cached for reuse).
EntityId addRequest(World& world, EntityRequest request, const RequestDefaults& defaults = {},
                    MeshResolver resolve_mesh = meshPathWithinRoots);

}  // namespace stc
