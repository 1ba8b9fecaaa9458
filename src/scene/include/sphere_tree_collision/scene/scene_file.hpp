// Scene files (YAML): gravity and a list of entities, each a preset shape with
// its pose, velocities and material. The node's default scene is one of these,
// embedded. Schema (every key optional except preset or mesh_resource; unknown keys rejected):
//
//   gravity: [0, 0, -9.81]
//   entities:
//     - name: rock_1             # letters, digits, '_'; becomes the tf frame
//       preset: rock             # cube sphere rock rod plate L ring
//       resolution: 8            # voxels along the largest extent (absent or 0: ~default_resolution)
//       voxel_size: 0.05         # metres (absent or 0: ~default_voxel_size)
//       seed: 1                  # rock only
//       position: [0, 0, 1]      # of the centre of mass, world frame
//       orientation: {rpy: [0, 0, 0]}   # or {quat: [x, y, z, w]}, or {unit_quat: [x, y, z, w]} (not normalised)
//       velocity: [0, 0, 0]
//       angular_velocity: [0, 0, 0]
//       density: 1000            # kg/m^3 (absent or 0: ~default_density)
//       restitution: 0.3
//       friction: 0.5
//       color: [0.8, 0.5, 0.2, 1.0]
//       static: false
//       box_mode: auto           # auto | fixed | dynamic
//       repeat: {count: [3, 1, 1], spacing: [0.5, 0, 0]}   # copies on a grid, names get _i
//       sleep: 0                 # a saved world's: EntitySpec::restored, sleep_group (not with repeat)
//       id: 7                    # a saved world's: the id it keeps (EntitySpec::id; not with repeat)
//     - mesh_resource: package://pkg/meshes/link.stl   # instead of preset: STL, OBJ, DAE
//       scale: [1, 1, 1]         # mesh only, per axis
//       resolution: 32           # voxels along the mesh's longest side, unless voxel_size is given
//     - grid: {size: [2, 1, 1], voxel_size: 0.05, runs: [0, 2]}   # instead of preset: voxels, x fastest,
//                                # as run lengths alternating empty and solid, empty first
//   contact_state:               # a saved world's (carriedState, world_access.hpp), bodies by place in entities:
//     next_group: 4              # the group the next island to fall asleep takes
//     rest: [[body, moving, rest_time, age, 3 x (ball centre x, y, z, radius)], ...]   # awake bodies
//     banding: [origin x, y, z, scale x, y, z, top x, y, z, boxes]   # the broad phase's bands
//     slot_order: [body, ...]    # the broad phase's boxes in the order of their slots
//     band_order: [[[2 body + is_max, ...], ...], [...], [...]]   # per list, each band's endpoints in order
//     boxes: [[min x, y, z, max x, y, z], ...]   # one a body: its broad-phase box
//     broad_pairs: [a, b, a, b, ...]             # the broad phase's pairs, in order
//     carried: [[a, b, B in A x, y, z, A to B quat x, y, z, w, tolerance, leaf a, leaf b, level, points], ...]
//     carried_points: [[on a x, y, z, on b x, y, z, normal x, y, z, depth, separation, sphere bound,
//                       node a, node b, level, normal of b, resolved], ...]   # the entries' points in turn
//     warm: [[a, b, held, rolling x, y, z, points], ...]   # the solver's warm start
//     warm_points: [[node a, node b, local a x, y, z, normal, friction x, y, z], ...]
//     breaks: [[body, point x, y, z, normal x, y, z], ...]   # fractures waiting for their pieces' trees, oldest first
#pragma once

#include "sphere_tree_collision/scene/entity_request.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace stc {

struct CarriedState;  // the core's, internal (src/core/carried_state.hpp)

struct SceneEntry {
  std::string path;  // "entities[3]" or "entities[3].repeat[5]", for error messages
  EntityRequest request;
};

struct Scene {
  Vec3 gravity = Vec3::Zero();
  std::vector<SceneEntry> entities;  // repeats already expanded
  // A saved world's contact_state: what its next tick carries over (bodies by
  // place in `entities`); none: it starts afresh. CarriedState is the core's
  // (internal: src/core/carried_state.hpp), so it is held by pointer here.
  std::shared_ptr<const CarriedState> carried;
};

// Throws InputError naming the field, e.g. "entities[2].position".
Scene parseSceneYaml(const std::string& yaml_text);
Scene loadSceneYaml(const std::string& path);

// The colour an entity is written with; nullopt: none (the loader's palette).
using ColorOf = std::function<std::optional<Rgba>(EntityId)>;

// The world as a scene file that parseSceneYaml and addScene load back into
// a new World as it is: gravity, then every entity in dense order, each with
// its id, name, shape (its recipe: a preset, a mesh resource as requested, or
// else its voxels as a grid), pose (orientation as unit_quat: kept bit for
// bit), velocities, density, material, colour (by `color_of`), static flag,
// box mode (as resolved), closed faces and sleep group. Numbers are written
// to 17 significant digits: they read back as the same bits. Then what the
// next tick carries over (carriedState, world_access.hpp) as contact_state: the
// contacts carried between ticks, the warm start, awake bodies' rest timers
// and the broad phase's boxes, bands and pair order (written when the
// broad phase is settled: World::settleBroadPhase), and the fractures waiting
// for their pieces' trees. The new World's
// entities keep their ids (docs/ros_interface.md, "Saved worlds").
std::string writeSceneYaml(const World& world, const ColorOf& color_of = nullptr);

// `text` into `path` atomically: a temporary file beside it, flushed, then
// renamed over it, so a reader sees the old file or the new, never a part.
// Throws InputError(field) when it cannot be written; the path is then untouched.
void writeFileAtomically(const std::string& path, const std::string& text, const std::string& field = "path");

// The embedded default: a handful of presets spread out on a static floor.
const std::string& defaultSceneYaml();

// Adds every entity (addRequest, with `defaults` for the fields left out or
// at 0), returns their ids in scene order. Throws
// InputError("entities[i].<field>") on the first bad one. A contact_state
// is then put back (restoreCarried, world_access.hpp; into a World that held no entity);
// refused, InputError("contact_state.<field>"), the entities are removed again.
std::vector<EntityId> addScene(World& world, const Scene& scene, const RequestDefaults& defaults = {},
                               MeshResolver resolve_mesh = meshPathWithinRoots);

}  // namespace stc
