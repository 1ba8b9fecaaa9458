#include "sphere_tree_collision/scene/entity_request.hpp"

#include "sphere_tree_collision/mesh_loader.hpp"

#include <cmath>
#include <cstdio>

namespace stc {

std::string presetShapeKey(const std::string& preset, const PresetParams& params) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "/r%d/v%.9g", params.resolution, params.voxel_size);
  std::string key = preset + buf;
  if (preset == "rock") key += "/s" + std::to_string(params.seed);
  return key;
}

void validateEntityName(const std::string& name) {
  if (name.size() > 64) throw InputError("name", "longer than 64 characters");
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) throw InputError("name", "'" + name + "' may hold only letters, digits and '_'");
  }
  const std::string reserved = "entity_";
  if (name.size() > reserved.size() && name.compare(0, reserved.size(), reserved) == 0 &&
      name.find_first_not_of("0123456789", reserved.size()) == std::string::npos) {
    throw InputError("name", "'" + name + "' is reserved for the frame of an unnamed entity");
  }
}

namespace {

// Explicit grids are keyed by their content; a key clash with a different grid
// gets a suffix, so equal grids share a shape and different ones never do.
ShapeId gridShape(World& world, ExplicitGrid grid) {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over the occupancy bits
  for (std::uint8_t v : grid.occupancy) hash = (hash ^ (v != 0 ? 1u : 0u)) * 1099511628211ull;
  char buf[128];
  std::snprintf(buf, sizeof buf, "grid/%dx%dx%d/v%.9g/%016llx", grid.nx, grid.ny, grid.nz,
                grid.voxel_size, static_cast<unsigned long long>(hash));
  VoxelShape shape = VoxelShape::create(grid.nx, grid.ny, grid.nz, grid.voxel_size, std::move(grid.occupancy),
                                        world.config().voxel_limits);
  for (int suffix = 0;; ++suffix) {
    const std::string key = suffix == 0 ? std::string(buf) : std::string(buf) + "#" + std::to_string(suffix);
    const auto found = world.findShape(key);
    if (!found) return world.addShape(key, std::move(shape));
    const VoxelShape& other = world.shape(*found).voxels;
    if (other.nx() == shape.nx() && other.ny() == shape.ny() && other.nz() == shape.nz() &&
        other.voxelSize() == shape.voxelSize() && other.occupancy() == shape.occupancy()) {
      return *found;
    }
  }
}

}  // namespace

Quat orientationOrIdentity(const Quat& q) {
  return q.coeffs().isZero(0.0) ? Quat::Identity() : q;
}

void validateText(const std::string& text, const std::string& field) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte < 0x20 || byte == 0x7f) {
      throw InputError(field, "holds a control byte (" + std::to_string(byte) + ") at offset " + std::to_string(i));
    }
  }
}

void applyDefaults(EntityRequest& request, const RequestDefaults& defaults) {
  if (request.preset_params.resolution == 0) request.preset_params.resolution = defaults.resolution;
  if (!request.preset.empty() && request.preset_params.voxel_size == 0.0) {
    request.preset_params.voxel_size = defaults.voxel_size;
  }
  if (request.spec.density == 0.0) request.spec.density = defaults.density;
  request.spec.pose.orientation = orientationOrIdentity(request.spec.pose.orientation);
}

namespace {

// Exactly one shape source, and the fields that belong to only one of them.
void validateShapeSource(const EntityRequest& request) {
  const bool mesh = !request.mesh_resource.empty(), preset = !request.preset.empty();
  const bool grid = request.grid.has_value();
  if (mesh && (preset || grid)) throw InputError("mesh_resource", "give one of a mesh, a preset or an explicit grid");
  if (preset && grid) throw InputError("preset", "give either a preset or an explicit grid, not both");
  if (!mesh && !preset && !grid) throw InputError("preset", "missing: give a preset, an explicit grid or a mesh_resource");
  if (!mesh && request.mesh_scale) throw InputError("scale", "only for a mesh_resource");
  if (!mesh && request.mesh_up_axis) throw InputError("up_axis", "only for a mesh_resource");
  const int max_resolution = mesh ? kMaxMeshResolution : kMaxPresetResolution;
  const int resolution = request.preset_params.resolution;
  if (!grid && !(resolution >= 1 && resolution <= max_resolution)) {
    throw InputError("resolution", "must be in [1, " + std::to_string(max_resolution) + "]" +
                                       (mesh ? " for a mesh" : ""));
  }
}

}  // namespace

void validateRequest(const World& world, const EntityRequest& request) {
  if (!request.spec.name.empty()) validateEntityName(request.spec.name);
  validateText(request.preset, "preset");
  validateText(request.mesh_resource, "mesh_resource");
  validateShapeSource(request);
  world.validateEntity(request.spec);
  if (request.color) {
    for (float c : *request.color) {
      if (!(c >= 0.0f && c <= 1.0f)) throw InputError("color", "components must be in [0, 1]");
    }
  }
  const VoxelLimits& voxel_limits = world.config().voxel_limits;
  if (!request.mesh_resource.empty()) {
    // 0: `resolution` voxels along the mesh's longest side; anything else is a size.
    if (request.mesh_voxel_size != 0.0) validateVoxelSize(request.mesh_voxel_size, voxel_limits);
  } else if (!request.preset.empty()) {
    validateVoxelSize(request.preset_params.voxel_size, voxel_limits);
  } else {
    validateVoxelSize(request.grid->voxel_size, voxel_limits);
  }
}

EntityId addRequest(World& world, EntityRequest request, const RequestDefaults& defaults,
                    MeshResolver resolve_mesh) {
  applyDefaults(request, defaults);
  validateRequest(world, request);
  if (!request.mesh_resource.empty()) {
    VoxeliseOptions options;
    options.voxel_size = request.mesh_voxel_size;
    options.resolution = request.preset_params.resolution;
    options.limits = world.config().voxel_limits;
    request.spec.shape = addMeshShape(world, resolve_mesh(request.mesh_resource, world.config().mesh_roots),
                                      request.mesh_scale.value_or(Vec3::Ones()), options,
                                      request.mesh_up_axis.value_or(ColladaUpAxis::AsWritten));
    ShapeRecipe recipe;
    recipe.mesh_resource = request.mesh_resource;
    recipe.preset_params.resolution = request.preset_params.resolution;
    recipe.mesh_scale = request.mesh_scale.value_or(Vec3::Ones());
    recipe.mesh_voxel_size = request.mesh_voxel_size;
    recipe.mesh_up_axis = static_cast<std::uint8_t>(request.mesh_up_axis.value_or(ColladaUpAxis::AsWritten));
    world.setShapeRecipe(request.spec.shape, recipe);
  } else if (!request.preset.empty()) {
    const std::string key = presetShapeKey(request.preset, request.preset_params);
    const auto found = world.findShape(key);
    request.spec.shape = found ? *found
                               : world.addShape(key, makePreset(request.preset, request.preset_params,
                                                                world.config().voxel_limits));
    ShapeRecipe recipe;
    recipe.preset = request.preset;
    recipe.preset_params = request.preset_params;
    world.setShapeRecipe(request.spec.shape, recipe);
  } else {
    request.spec.shape = gridShape(world, std::move(*request.grid));
  }
  return world.addEntity(request.spec);
}

}  // namespace stc
