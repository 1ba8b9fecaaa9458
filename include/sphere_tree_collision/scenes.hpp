// Scenes as data: functions that fill a World with the benchmark scenes, each
// with a suggested camera (gaze_model.hpp says where a simulated viewer looks).
// Core only: no ROS, no FCL.
#pragma once

#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/world.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace stc {

enum class SceneKind : std::uint8_t {
  PackedBox,    // the paper's case: homogeneous entities tightly packed in a closed box,
                // random velocities, no gravity: moving and colliding all the time
  BouncingBox,  // a spread-out box of mixed presets bouncing under gravity
  Rockfall,     // rocks of a few seeded shapes falling down a sloped ravine onto a run-out,
                // in a walled tray that catches them; the ravine grows with the count
  CornerDrift,  // worst case: the packed box with gravity pointing into one corner
  CubeBox,      // cubes on a loose lattice in a closed box, falling into a pile under gravity
  Pyramid,      // Box2D's large_pyramid: a plane pyramid of cubes at rest on a floor, rows
                // offset by half a cube (5,050 cubes: a base of 100)
};
// "packed_box" | "bouncing_box" | "rockfall" | "corner_drift" | "cube_box" | "pyramid";
// throws InputError("scene").
SceneKind parseScene(const std::string& name);
const char* toString(SceneKind kind);

struct SceneParams {
  int entities = 0;            // movable entities; 0: the scene's default (500, 100, 200, 500, 1000, 5050)
  std::uint32_t seed = 1;      // poses, velocities and rock shapes
  double entity_size = 0.4;    // metres: largest extent of one entity
  int resolution = 8;          // voxels along an entity's largest extent
  double speed = 1.0;          // m/s: scale of the random initial velocities (pyramid: at rest)
};

struct SceneSpec {
  SceneKind kind = SceneKind::PackedBox;
  Vec3 gravity = Vec3::Zero();  // what sceneGravity(kind) returns
  Camera camera;                // sees the whole scene (1280x720, 60 deg)
  Aabb bounds;                  // where the movable entities' centres stay (inside the walls)
  std::vector<EntityId> movers; // movable entities, creation order
  std::vector<EntityId> walls;  // static plates (box walls, ravine walls and floor)
  double dt = 1.0 / 60.0;       // suggested tick
};

// The gravity a scene is made for: construct the World with it
// (WorldConfig::gravity); populateScene checks it.
Vec3 sceneGravity(SceneKind kind);

// Adds the scene's shapes and entities to `world`. Throws InputError naming
// the parameter ("entities", "entity_size", "resolution", "speed") or
// "gravity" when world.config().gravity is not sceneGravity(kind). On throw
// the world may hold the shapes already added, never a partial scene of entities.
SceneSpec populateScene(World& world, SceneKind kind, const SceneParams& params = SceneParams{});

// A World made for one built-in scene, as tests, benches and users start one.
struct SceneWorld {
  World world;
  SceneSpec spec;
};
// `config` with its gravity set to sceneGravity(kind), the scene populated
// from `params`, and the perception's camera set to the scene's (so a gaze on
// the image means the same in every World of the scene). Throws as populateScene.
SceneWorld makeSceneWorld(SceneKind kind, const SceneParams& params = SceneParams{},
                          WorldConfig config = WorldConfig{});

}  // namespace stc
