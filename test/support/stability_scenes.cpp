// Stiff and extreme scenes for the stability test and bench.
#include "stability_scenes.hpp"

#include "dynamics.hpp"
#include "physics.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "world_access.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace stc::stability {
namespace {

constexpr double kGravity = 9.81;
constexpr int kCubeVoxels = 8;
constexpr int kFloorCell = 5;  // floor voxels are this many cube voxels wide

std::unique_ptr<World> makeWorld(const Vec3& gravity, const ResponseOptions& response) {
  WorldConfig config;
  config.gravity = gravity;
  config.response = response;
  return std::make_unique<World>(config);
}

ShapeId solidBox(World& world, const std::string& key, int nx, int ny, int nz, double voxel) {
  return world.addShape(key, VoxelShape::create(nx, ny, nz, voxel,
                                                std::vector<std::uint8_t>(static_cast<std::size_t>(nx * ny * nz), 1)));
}

// Static 8 x 8 x 1 floor of coarse voxels, top face at z = 0.
void addFloor(World& world, double voxel) {
  const double cell = kFloorCell * voxel;
  EntitySpec floor;
  floor.shape = solidBox(world, "floor", 8, 8, 1, cell);
  floor.pose.position = Vec3(0.0, 0.0, -0.5 * cell);
  floor.is_static = true;
  world.addEntity(floor);
}

std::size_t addMover(World& world, Scene& scene, const EntitySpec& spec) {
  const EntityId id = world.addEntity(spec);
  const std::size_t index = *world.indexOf(id);
  scene.movers.push_back(index);
  return index;
}

}  // namespace

Scene stack(int count, double voxel, double dt, double seconds, double settle_seconds,
            const ResponseOptions& response) {
  Scene scene;
  scene.name = "stack of " + std::to_string(count);
  scene.world = makeWorld(Vec3(0.0, 0.0, -kGravity), response);
  scene.dt = dt;
  scene.steps = static_cast<int>(std::lround(seconds / dt));
  scene.settle_steps = static_cast<int>(std::lround(settle_seconds / dt));
  scene.voxel = voxel;
  World& world = *scene.world;
  addFloor(world, voxel);
  const double side = kCubeVoxels * voxel;
  const ShapeId cube = solidBox(world, "cube", kCubeVoxels, kCubeVoxels, kCubeVoxels, voxel);
  for (int k = 0; k < count; ++k) {
    EntitySpec spec;
    spec.shape = cube;
    spec.pose.position = Vec3(0.0, 0.0, side * (0.5 + k));
    addMover(world, scene, spec);
  }
  scene.speed_bound = 1.1 * std::sqrt(2.0 * kGravity * side * count);
  return scene;
}

Scene massRatio(double ratio, double seconds, const ResponseOptions& response, double gap) {
  Scene scene;
  scene.name = "mass ratio " + std::to_string(static_cast<int>(ratio)) + ":1";
  scene.world = makeWorld(Vec3(0.0, 0.0, -kGravity), response);
  scene.steps = static_cast<int>(std::lround(seconds / scene.dt));
  World& world = *scene.world;
  const double voxel = scene.voxel;
  addFloor(world, voxel);
  const int light_voxels = kCubeVoxels / 2;
  const double light_side = light_voxels * voxel;
  const ShapeId light = solidBox(world, "light", light_voxels, light_voxels, light_voxels, voxel);
  const ShapeId heavy = solidBox(world, "heavy", kCubeVoxels, kCubeVoxels, kCubeVoxels, voxel);
  const double light_density = 100.0;
  for (int i = 0; i < 4; ++i) {
    EntitySpec spec;
    spec.shape = light;
    spec.density = light_density;
    const double pitch = light_side + gap;
    spec.pose.position = Vec3(((i % 2) - 0.5) * pitch, ((i / 2) - 0.5) * pitch, 0.5 * light_side);
    addMover(world, scene, spec);
  }
  // Same voxel volume ratio 8:1, so the density ratio is ratio / 8.
  EntitySpec spec;
  spec.shape = heavy;
  spec.density = light_density * ratio / 8.0;
  spec.pose.position = Vec3(0.0, 0.0, light_side + 0.5 * kCubeVoxels * voxel);
  addMover(world, scene, spec);
  scene.speed_bound = 1.1 * std::sqrt(2.0 * kGravity * (light_side + kCubeVoxels * voxel));
  return scene;
}

Scene fastSphere(double speed, double seconds, const ResponseOptions& response) {
  Scene scene;
  scene.name = "1-voxel sphere at " + std::to_string(static_cast<int>(speed)) + " m/s";
  scene.world = makeWorld(Vec3::Zero(), response);
  scene.steps = static_cast<int>(std::lround(seconds / scene.dt));
  scene.settle_steps = scene.steps;  // no drift measure: it flies away
  World& world = *scene.world;
  const double voxel = scene.voxel;
  EntitySpec plate;
  plate.shape = solidBox(world, "plate", 16, 16, 1, voxel);
  plate.is_static = true;
  world.addEntity(plate);  // centred at the origin, faces at z = +-voxel/2
  PresetParams ball_params;
  ball_params.resolution = 1;
  ball_params.voxel_size = voxel;
  EntitySpec ball;
  ball.shape = world.addShape("ball", makePreset("sphere", ball_params));
  ball.pose.position = Vec3(0.3 * voxel, -0.2 * voxel, 1.0);  // off the leaf centres
  ball.linear_velocity = Vec3(0.0, 0.0, -speed);
  ball.material.restitution = 0.5;
  addMover(world, scene, ball);
  scene.speed_bound = 1.1 * speed;
  return scene;
}

Scene spinningRod(double spin, double seconds, const ResponseOptions& response) {
  Scene scene;
  scene.name = "rod spinning at " + std::to_string(static_cast<int>(spin)) + " rad/s";
  scene.world = makeWorld(Vec3::Zero(), response);
  scene.steps = static_cast<int>(std::lround(seconds / scene.dt));
  scene.settle_steps = scene.steps;  // no drift measure: it spins
  World& world = *scene.world;
  EntitySpec rod;
  rod.shape = solidBox(world, "rod", 16, 3, 1, scene.voxel);
  // Body axes = grid axes: x long (least inertia), y intermediate, z most.
  rod.angular_velocity = Vec3(1e-3 * spin, spin, 1e-3 * spin);
  addMover(world, scene, rod);
  scene.speed_bound = 1e-9;  // spins in place
  return scene;
}

Scene newtonsCradle(int count, double seconds, const ResponseOptions& response) {
  Scene scene;
  scene.name = "Newton's cradle of " + std::to_string(count);
  scene.world = makeWorld(Vec3::Zero(), response);
  scene.steps = static_cast<int>(std::lround(seconds / scene.dt));
  scene.settle_steps = scene.steps;  // outcome: speeds, not drift
  World& world = *scene.world;
  PresetParams params;
  params.resolution = kCubeVoxels;
  params.voxel_size = scene.voxel;
  const ShapeId ball = world.addShape("cradle_ball", makePreset("sphere", params));
  const double diameter = kCubeVoxels * scene.voxel;
  for (int k = 0; k < count; ++k) {
    EntitySpec spec;
    spec.shape = ball;
    spec.pose.position = Vec3(diameter * k, 0.0, 0.0);  // touching
    spec.linear_velocity = Vec3(k == 0 ? 1.0 : 0.0, 0.0, 0.0);
    spec.material = Material{1.0, 0.0};
    addMover(world, scene, spec);
  }
  scene.speed_bound = 1.1;
  return scene;
}

Scene cornerPile(int count, int resolution, double seconds, const Budget& budget,
                 const ResponseOptions& response) {
  Scene scene;
  scene.name = std::to_string(count) + " rocks into a corner";
  scene.world = makeWorld(sceneGravity(SceneKind::CornerDrift), response);
  scene.budget = budget;
  World& world = *scene.world;
  SceneParams params;
  params.entities = count;
  params.resolution = resolution;
  const SceneSpec spec = populateScene(world, SceneKind::CornerDrift, params);
  scene.dt = spec.dt;
  scene.steps = static_cast<int>(std::lround(seconds / scene.dt));
  scene.settle_steps = scene.steps;  // outcome: speeds, not drift
  scene.voxel = params.entity_size / resolution;
  for (const EntityId id : spec.movers) scene.movers.push_back(*world.indexOf(id));
  double fastest = 0.0;
  for (const std::size_t i : scene.movers) fastest = std::max(fastest, world.bodies()[i].linear_velocity.norm());
  const double extent = (spec.bounds.max - spec.bounds.min).norm();
  scene.speed_bound = 1.1 * (fastest + std::sqrt(2.0 * kGravity * extent));
  return scene;
}

Metrics run(Scene& scene, const std::function<void(const World&, int step)>& observe) {
  World& world = *scene.world;
  const Vec3 gravity = world.config().gravity;
  const double dt = scene.dt;
  Metrics m;

  // Energy reference: kinetic energy plus the potential above the lowest movable body.
  const std::vector<BodyState>& start = world.bodies();
  double lowest = std::numeric_limits<double>::infinity();
  const Vec3 down = gravity.isZero(0.0) ? Vec3::Zero() : Vec3(gravity.normalized());
  for (const std::size_t i : scene.movers) lowest = std::min(lowest, -down.dot(start[i].pose.position));
  double reference = 0.0;
  for (const std::size_t i : scene.movers) {
    const BodyState& b = start[i];
    reference += kineticEnergy(b) + gravity.norm() * (-down.dot(b.pose.position) - lowest) / b.inv_mass;
  }
  if (!(reference > 0.0)) reference = 1.0;
  const double e0 = totalEnergy(world.bodies(), gravity, dt);

  std::vector<Vec3> settled(world.bodies().size(), Vec3::Zero());
  const auto t0 = std::chrono::steady_clock::now();
  for (int step = 0; step < scene.steps; ++step) {
    if (step == scene.settle_steps) {
      for (const std::size_t i : scene.movers) settled[i] = world.bodies()[i].pose.position;
    }
    world.step(dt, scene.budget);
    m.max_penetration = std::max(m.max_penetration, physicsReport(world).solve.max_penetration / scene.voxel);
    for (const BodyState& b : world.bodies()) {
      if (!isFinite(b)) ++m.nan_count;
      m.max_speed = std::max(m.max_speed, b.linear_velocity.norm());
    }
    m.energy_gain = std::max(m.energy_gain, (totalEnergy(world.bodies(), gravity, dt) - e0) / reference);
    if (observe) observe(world, step);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  m.steps = scene.steps;
  m.steps_per_second = wall > 0.0 ? scene.steps / wall : 0.0;
  for (const std::size_t i : scene.movers) m.final_max_speed = std::max(m.final_max_speed, world.bodies()[i].linear_velocity.norm());
  if (scene.settle_steps < scene.steps) {
    const double span = (scene.steps - scene.settle_steps) * dt;
    for (const std::size_t i : scene.movers) {
      m.drift = std::max(m.drift, (world.bodies()[i].pose.position - settled[i]).norm() / scene.voxel / span);
    }
  }
  return m;
}

}  // namespace stc::stability
