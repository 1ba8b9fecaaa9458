// EntityRequest: one entity to add to the World, as a scene file or a spawn
// message describes it (shape preset or explicit grid, body state, colour).
// One path for both, so scenes and spawns validate and share shapes alike.
#pragma once

#include "sphere_tree_collision/mesh_loader.hpp"
#include "sphere_tree_collision/world.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace stc_ros {

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

struct EntityRequest {
  std::string preset;                  // empty: `grid` or `mesh_resource` gives the shape
  // resolution and voxel_size 0 here and density 0 in spec: the RequestDefaults.
  stc::PresetParams preset_params{0, 0.0, 1};
  std::optional<ExplicitGrid> grid;
  stc::EntitySpec spec = [] {
    stc::EntitySpec unset;
    unset.density = 0.0;
    return unset;
  }();                                 // spec.shape is filled in by addRequest
  std::optional<Rgba> color;           // unset: a palette colour by id
  // A mesh (package://, file:// or a path), scaled per axis, voxelised at
  // mesh_voxel_size, or when 0 at preset_params.resolution voxels along its longest side.
  std::string mesh_resource;
  stc::Vec3 mesh_scale = stc::Vec3::Ones();
  double mesh_voxel_size = 0.0;
  stc::ColladaUpAxis mesh_up_axis = stc::ColladaUpAxis::AsWritten;  // of a DAE (mesh_loader.hpp)
};

// Shape cache key of a preset: equal keys share one shape and one tree.
std::string presetShapeKey(const std::string& preset, const stc::PresetParams& params);

// Names become tf frames: letters, digits and '_' only, at most 64 characters,
// and not of the form "entity_<digits>" (the frames of unnamed entities).
// Throws InputError("name").
void validateEntityName(const std::string& name);

// Frame of an entity: its name when it has one, else "entity_<id>".
std::string entityFrame(stc::EntityId id, const std::string& name);

// A quaternion of four zeros (a pose's orientation left out) is the identity;
// any other is returned as it is (validated later).
stc::Quat orientationOrIdentity(const stc::Quat& q);

// Throws InputError(field) when `text` holds a NUL or another control byte
// (a path would be cut at the NUL, a name would carry it into logs and tf).
void validateText(const std::string& text, const std::string& field);

// Fills the fields left at 0 where 0 means nothing: resolution, density, a
// preset's voxel_size, an all-zero orientation. restitution, friction and
// strength 0 are real values and stay.
void applyDefaults(EntityRequest& request, const RequestDefaults& defaults);

// Applies the defaults, validates the whole request (before any shape cache is
// asked: a cached shape never lets a bad field through), then builds (or
// reuses) the shape and adds the entity. Throws stc::InputError naming the
// field; the entity set is unchanged on throw (a valid shape may stay cached
// for reuse).
stc::EntityId addRequest(stc::World& world, EntityRequest request, const RequestDefaults& defaults = {});

// Distinct colours for entities without one (golden-ratio hue steps).
Rgba paletteColor(stc::EntityId id);

}  // namespace stc_ros
