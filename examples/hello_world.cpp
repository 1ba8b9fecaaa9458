// hello_world: the ROS-free core on one page. A static floor, a stack of three
// cubes and four rocks dropped beside it; two seconds of 60 Hz ticks, each under
// a budget of sphere tests. Prints every 20th tick's report (contacts, and what
// the budget left unproven: geometric inaccuracy ∇ and perceived inaccuracy P)
// and one tick's contacts. Exits 1 when a body is not finite or the stack does
// not stand on the floor.
#include "sphere_tree_collision/world.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

int main() {
  using namespace stc;
  WorldConfig config;
  config.gravity = Vec3(0, 0, -9.81);
  World world(config);

  // Shapes: a voxel grid each; its sphere-tree is built here, once.
  const ShapeId floor = world.addShape("floor", VoxelShape::create(20, 20, 1, 0.1, std::vector<std::uint8_t>(400, 1)));
  const ShapeId cube = world.addShape("cube", makePreset("cube"));  // 8 voxels of 5 cm: 0.4 m
  const ShapeId rock = world.addShape("rock", makePreset("rock", PresetParams{8, 0.05, 7}));

  // Entities: a pose is that of the centre of mass.
  EntitySpec spec;
  spec.shape = floor;
  spec.is_static = true;
  spec.pose.position = Vec3(0, 0, -0.05);  // top face at z = 0
  const EntityId floor_id = world.addEntity(spec);
  spec.is_static = false;
  spec.shape = cube;
  std::vector<EntityId> stack;
  for (int k = 0; k < 3; ++k) {
    spec.pose.position = Vec3(0, 0, 0.2 + 0.4 * k);
    stack.push_back(world.addEntity(spec));
  }
  spec.shape = rock;
  for (int k = 0; k < 4; ++k) {
    spec.pose.position = Vec3(-0.6 + 0.4 * k, 0.6, 0.5 + 0.3 * k);
    world.addEntity(spec);
  }

  // The viewer: a camera looking at the stack, the gaze at the image centre.
  // Without a fixation P stays 0 and nothing is projected.
  Camera camera;  // 1280 x 720 pixels, 60 degrees vertical field of view
  camera.camera_to_world = opticalLookAt(Vec3(3, -3, 2), Vec3(0, 0, 0.4));
  world.perception().setCamera(camera);
  world.perception().setFixation(Vec2(640, 360));

  const Budget budget = Budget::ofSphereTests(1000);  // or Budget::ofTickSeconds(1.0 / 60)
  bool floor_contact = false;  // seen at some tick between the floor and the bottom cube
  for (int tick = 1; tick <= 120; ++tick) {
    const TickReport r = world.step(1.0 / 60, budget);
    for (const Contact& c : world.contacts())
      floor_contact = floor_contact || (c.a == floor_id && c.b == stack[0]) || (c.a == stack[0] && c.b == floor_id);
    if (tick % 20 == 0)
      std::printf(
          "tick %3d: %zu pairs, %zu colliding, %zu unresolved, %zu contacts, %zu asleep; "
          "nabla %.3f m, P %.1f px\n",
          tick, r.detection.broad_pairs, r.detection.colliding, r.detection.unresolved, r.response.contacts,
          r.bodies.sleeping, r.accuracy.geometric_inaccuracy, r.accuracy.perceived_inaccuracy);
    if (tick == 40)
      for (const Contact& c : world.contacts())
        std::printf("  contact %u-%u at (%.2f %.2f %.2f), normal (%.2f %.2f %.2f)%s\n", c.a, c.b, c.point.x(),
                    c.point.y(), c.point.z(), c.normal.x(), c.normal.y(), c.normal.z(),
                    c.resolved ? "" : ", accepted unresolved");
  }

  // Checks: every body finite, the stack standing, its bottom cube touching the floor.
  bool ok = true;
  for (const BodyState& b : world.bodies()) ok = ok && b.pose.position.allFinite() && b.linear_velocity.allFinite();
  for (int k = 0; k < 3; ++k) {
    const Vec3 p = world.bodies()[*world.indexOf(stack[k])].pose.position;
    if (std::abs(p.z() - (0.2 + 0.4 * k)) > 0.02 || std::hypot(p.x(), p.y()) > 0.02) {
      std::printf("FAIL: cube %d of the stack is at (%.3f %.3f %.3f)\n", k, p.x(), p.y(), p.z());
      ok = false;
    }
  }
  if (!floor_contact) std::printf("FAIL: no contact between the floor and the bottom cube\n");
  ok = ok && floor_contact;
  std::printf("%s\n", ok ? "hello_world: ok" : "hello_world: FAILED");
  return ok ? 0 : 1;
}
