#include "sphere_tree_collision/ros/entity_request.hpp"

#include "sphere_tree_collision/mesh_loader.hpp"
#include "sphere_tree_collision/ros/mesh_resource.hpp"

#include <cmath>
#include <cstdio>

namespace stc_ros {

std::string presetShapeKey(const std::string& preset, const stc::PresetParams& params) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "/r%d/v%.9g", params.resolution, params.voxel_size);
  std::string key = preset + buf;
  if (preset == "rock") key += "/s" + std::to_string(params.seed);
  return key;
}

void validateEntityName(const std::string& name) {
  if (name.size() > 64) throw stc::InputError("name", "longer than 64 characters");
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) throw stc::InputError("name", "'" + name + "' may hold only letters, digits and '_'");
  }
  const std::string reserved = "entity_";
  if (name.size() > reserved.size() && name.compare(0, reserved.size(), reserved) == 0 &&
      name.find_first_not_of("0123456789", reserved.size()) == std::string::npos) {
    throw stc::InputError("name", "'" + name + "' is reserved for the frame of an unnamed entity");
  }
}

std::string entityFrame(stc::EntityId id, const std::string& name) {
  return name.empty() ? "entity_" + std::to_string(id) : name;
}

namespace {

// Explicit grids are keyed by their content; a key clash with a different grid
// gets a suffix, so equal grids share a shape and different ones never do.
stc::ShapeId gridShape(stc::World& world, ExplicitGrid grid) {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over the occupancy bits
  for (std::uint8_t v : grid.occupancy) hash = (hash ^ (v != 0 ? 1u : 0u)) * 1099511628211ull;
  char buf[128];
  std::snprintf(buf, sizeof buf, "grid/%dx%dx%d/v%.9g/%016llx", grid.nx, grid.ny, grid.nz,
                grid.voxel_size, static_cast<unsigned long long>(hash));
  stc::VoxelShape shape = stc::VoxelShape::create(grid.nx, grid.ny, grid.nz, grid.voxel_size,
                                                  std::move(grid.occupancy),
                                                  world.config().voxel_limits);
  for (int suffix = 0;; ++suffix) {
    const std::string key = suffix == 0 ? std::string(buf) : std::string(buf) + "#" + std::to_string(suffix);
    const auto found = world.findShape(key);
    if (!found) return world.addShape(key, std::move(shape));
    const stc::VoxelShape& other = world.shape(*found).voxels;
    if (other.nx() == shape.nx() && other.ny() == shape.ny() && other.nz() == shape.nz() &&
        other.voxelSize() == shape.voxelSize() && other.occupancy() == shape.occupancy()) {
      return *found;
    }
  }
}

}  // namespace

stc::Quat orientationOrIdentity(const stc::Quat& q) {
  return q.coeffs().isZero(0.0) ? stc::Quat::Identity() : q;
}

void validateText(const std::string& text, const std::string& field) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte < 0x20 || byte == 0x7f) {
      throw stc::InputError(field, "holds a control byte (" + std::to_string(byte) + ") at offset " +
                                       std::to_string(i));
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

// Every field, before any shape is looked up or built: bad input builds nothing,
// and a cached shape answers only a valid request.
void validateRequest(const stc::World& world, const EntityRequest& request) {
  if (!request.spec.name.empty()) validateEntityName(request.spec.name);
  if (request.spec.name.empty() == false && world.findByName(request.spec.name)) {
    throw stc::InputError("name", "'" + request.spec.name + "' is already taken");
  }
  validateText(request.preset, "preset");
  validateText(request.mesh_resource, "mesh_resource");
  const stc::EntitySpec& spec = request.spec;
  stc::validateBodyInput(spec.pose, spec.linear_velocity, spec.angular_velocity, spec.density, spec.material,
                         world.config().limits);
  if (request.color) {
    for (float c : *request.color) {
      if (!(c >= 0.0f && c <= 1.0f)) throw stc::InputError("color", "components must be in [0, 1]");
    }
  }
  const stc::VoxelLimits& voxel_limits = world.config().voxel_limits;
  if (!request.mesh_resource.empty()) {
    // 0: `resolution` voxels along the mesh's longest side; anything else is a size.
    if (request.mesh_voxel_size != 0.0) stc::validateVoxelSize(request.mesh_voxel_size, voxel_limits);
  } else if (!request.preset.empty()) {
    stc::validateVoxelSize(request.preset_params.voxel_size, voxel_limits);
  } else if (request.grid) {
    stc::validateVoxelSize(request.grid->voxel_size, voxel_limits);
  }
  if (world.entityCount() >= world.config().max_entities) {
    throw stc::InputError("max_entities", "the world already holds " +
                                              std::to_string(world.entityCount()) + " entities");
  }
}

}  // namespace

stc::EntityId addRequest(stc::World& world, EntityRequest request, const RequestDefaults& defaults) {
  applyDefaults(request, defaults);
  validateRequest(world, request);

  if (!request.mesh_resource.empty()) {
    if (!request.preset.empty() || request.grid) {
      throw stc::InputError("mesh_resource", "give one of a mesh, a preset or an explicit grid");
    }
    stc::VoxeliseOptions options;
    options.voxel_size = request.mesh_voxel_size;
    options.resolution = request.preset_params.resolution;
    options.limits = world.config().voxel_limits;
    request.spec.shape =
        stc::addMeshShape(world, resolveMeshResource(request.mesh_resource, world.config().mesh_roots),
                          request.mesh_scale, options,
                          request.mesh_up_axis);
  } else if (!request.preset.empty()) {
    if (request.grid) throw stc::InputError("preset", "give either a preset or an explicit grid, not both");
    const std::string key = presetShapeKey(request.preset, request.preset_params);
    const auto found = world.findShape(key);
    request.spec.shape = found ? *found
                               : world.addShape(key, stc::makePreset(request.preset, request.preset_params,
                                                                     world.config().voxel_limits));
  } else if (request.grid) {
    request.spec.shape = gridShape(world, std::move(*request.grid));
  } else {
    throw stc::InputError("preset", "no preset and no explicit grid");
  }
  return world.addEntity(request.spec);
}

Rgba paletteColor(stc::EntityId id) {
  // HSV with golden-ratio hue steps, saturation 0.6, value 0.9.
  const double h = std::fmod(0.12 + 0.618033988749895 * id, 1.0) * 6.0;
  const double s = 0.6, v = 0.9;
  const int sector = static_cast<int>(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (sector) {
    case 0: r = v; g = t; b = p; break;
    case 1: r = q; g = v; b = p; break;
    case 2: r = p; g = v; b = t; break;
    case 3: r = p; g = q; b = v; break;
    case 4: r = t; g = p; b = v; break;
    default: r = v; g = p; b = q; break;
  }
  return {static_cast<float>(r), static_cast<float>(g), static_cast<float>(b), 1.0f};
}

}  // namespace stc_ros
