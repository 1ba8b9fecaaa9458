// The contact manifold of a body pair (issue 9, item 3): at most
// max_contacts_per_pair points spread over the contact, kept from tick to
// tick by feature id (the leaf sphere pair of each point) for warm starting,
// and enough to hold a box on a plane and a stack at rest.
#include "stability_scenes.hpp"

#include "contact_solver.hpp"
#include "dynamics.hpp"
#include "physics.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <utility>
#include <vector>

namespace stc::stability {
namespace {

using PairPoints = std::map<std::pair<EntityId, EntityId>, std::vector<const Contact*>>;

PairPoints pointsByPair(const World& world) {
  PairPoints out;
  for (const Contact& c : world.contacts()) out[{c.a, c.b}].push_back(&c);
  return out;
}

// Steps the scene with every mover kept awake (a resting body would fall
// asleep after half a second and drop its contacts); `observe` after each
// tick. Returns the deepest penetration seen, in voxels.
double runAwake(Scene& scene, const std::function<void(const World&, int step)>& observe = {}) {
  World& world = *scene.world;
  double deepest = 0.0;
  for (int step = 0; step < scene.steps; ++step) {
    for (const std::size_t i : scene.movers) world.wake(world.entityIds()[i]);
    world.step(scene.dt, scene.budget);
    deepest = std::max(deepest, physicsReport(world).solve.max_penetration / scene.voxel);
    if (observe) observe(world, step);
  }
  return deepest;
}

// Largest distance between two points of a manifold, along x and along y.
Eigen::Vector2d spread(const std::vector<const Contact*>& points) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (const Contact* c : points) {
    lo = lo.cwiseMin(c->point.head<2>());
    hi = hi.cwiseMax(c->point.head<2>());
  }
  return hi - lo;
}

TEST(ContactManifold, EveryBodyPairHasAtMostFourPointsSpreadOverTheFace) {
  Scene scene = stack(3, 0.05, 1.0 / 60.0, 1.0);
  const double side = 8 * scene.voxel;
  std::size_t face_pairs = 0;
  runAwake(scene, [&](const World& world, int) {
    const PairPoints pairs = pointsByPair(world);
    EXPECT_EQ(physicsReport(world).solve.manifolds, pairs.size());
    for (const auto& [key, points] : pairs) {
      EXPECT_LE(points.size(), 4u);
      // A cube face down on a face: four points reaching out to its corners
      // (the leaf spheres' centres lie half a voxel inside the edges).
      if (points.size() == 4) {
        ++face_pairs;
        const Eigen::Vector2d extent = spread(points);
        EXPECT_GE(extent.x(), side - 2 * scene.voxel);
        EXPECT_GE(extent.y(), side - 2 * scene.voxel);
      }
    }
  });
  EXPECT_GT(face_pairs, 0u);
}

TEST(ContactManifold, RockPairsKeepAtMostFourPointsInAPile) {
  Scene scene = cornerPile(60, 4, 1.5);
  std::size_t most = 0;
  runAwake(scene, [&](const World& world, int) {
    for (const auto& [key, points] : pointsByPair(world)) most = std::max(most, points.size());
  });
  EXPECT_GE(most, 2u);  // rocks touch with more than one point somewhere
  EXPECT_LE(most, 4u);
}

// A capsule of 2.5 cm voxels, `length` voxels along x and `diameter` across.
VoxelShape capsule(int length, int diameter, double voxel) {
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(length) * diameter * diameter, 0);
  const double r = 0.5 * diameter;
  for (int k = 0; k < diameter; ++k)
    for (int j = 0; j < diameter; ++j)
      for (int i = 0; i < length; ++i) {
        const Vec3 p(i + 0.5, j + 0.5, k + 0.5);
        const double x = std::clamp(p.x(), r, length - r);
        occupied[(static_cast<std::size_t>(k) * diameter + j) * length + i] = (p - Vec3(x, r, r)).norm() <= r ? 1 : 0;
      }
  return VoxelShape::create(length, diameter, diameter, voxel, occupied);
}

// A long thin body lying on a static plate of many spheres, kept awake: its
// points (up to 4 of the many sphere pairs along it) share the pair's gap
// bound, the solver's slop being a fraction of it (with each point's own
// bound, position correction lifted config/meshes.yaml's rolling link about
// 1 mm a tick until it rolled off the floor), and it stays where it lies for 5 s.
TEST(ContactManifold, ALongCapsuleLyingOnAStaticPlateStaysAtRest) {
  const double voxel = 0.025;
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  World world(config);
  EntitySpec plate;
  plate.shape = world.addShape("plate", VoxelShape::create(32, 16, 2, 0.05, std::vector<std::uint8_t>(32 * 16 * 2, 1)));
  plate.pose.position = Vec3(0.0, 0.0, -0.05);
  plate.is_static = true;
  world.addEntity(plate);
  EntitySpec rod;
  rod.shape = world.addShape("capsule", capsule(32, 8, voxel));
  rod.pose.position = Vec3(0.0, 0.0, 4 * voxel);
  const EntityId id = world.addEntity(rod);
  const std::size_t index = *world.indexOf(id);
  double lowest = 1e9, highest = -1e9, fastest = 0.0;
  std::size_t multi_point_pairs = 0;
  for (int step = 0; step < 300; ++step) {
    world.wake(id);
    world.step(1.0 / 60.0, Budget::unlimited());
    for (const auto& [key, points] : pointsByPair(world)) {
      if (points.size() < 2) continue;
      ++multi_point_pairs;
      for (const Contact* c : points) EXPECT_EQ(c->gap_bound, points.front()->gap_bound);
    }
    const BodyState& body = world.bodies()[index];
    if (step < 30) continue;  // settling into the slop
    lowest = std::min(lowest, body.pose.position.z());
    highest = std::max(highest, body.pose.position.z());
    fastest = std::max(fastest, body.linear_velocity.norm() + 4 * voxel * body.angular_velocity.norm());
  }
  EXPECT_GT(multi_point_pairs, 0u);
  EXPECT_GT(lowest, 4 * voxel - 0.1 * voxel) << "sank";
  EXPECT_LT(highest, 4 * voxel + 0.1 * voxel) << "lifted";
  EXPECT_LT(fastest, 0.01) << "moved";
}

TEST(ContactManifold, FeatureIdsCarryTheImpulsesOfARestingBoxFromTickToTick) {
  Scene scene = stack(1, 0.05, 1.0 / 60.0, 3.0);
  World& world = *scene.world;
  const BodyState& box = world.bodies()[scene.movers[0]];
  const double weight_impulse = -world.config().gravity.z() * scene.dt / box.inv_mass;
  std::vector<double> last;
  int checked = 0;
  runAwake(scene, [&](const World& w, int step) {
    std::vector<double> now;
    for (const Contact& c : w.contacts()) now.push_back(c.normal_impulse);
    if (step >= 60) {  // settled after a second
      const SolveStats& stats = physicsReport(w).solve;
      ASSERT_EQ(stats.contacts, 4u);
      // Every point found last tick's point by its leaf sphere pair.
      EXPECT_EQ(stats.warm_started, stats.contacts);
      EXPECT_EQ(stats.warm_by_feature, stats.contacts);
      // The points carry the box's weight, and each keeps its share.
      double sum = 0.0;
      for (double n : now) sum += n;
      EXPECT_NEAR(sum, weight_impulse, 1e-3 * weight_impulse);
      ASSERT_EQ(now.size(), last.size());
      for (std::size_t k = 0; k < now.size(); ++k) EXPECT_NEAR(now[k], last[k], 1e-3 * weight_impulse);
      ++checked;
    }
    last = now;
  });
  EXPECT_GT(checked, 100);
}

TEST(ContactManifold, WithoutWarmStartingNoPointIsMatched) {
  ResponseOptions response;
  response.warm_starting = false;
  Scene scene = stack(1, 0.05, 1.0 / 60.0, 0.5, 0.2, response);
  runAwake(scene, [&](const World& w, int) { EXPECT_EQ(physicsReport(w).solve.warm_started, 0u); });
}

// Positions of the movers now.
std::vector<Vec3> positionsOf(const Scene& scene) {
  std::vector<Vec3> out;
  for (const std::size_t i : scene.movers) out.push_back(scene.world->bodies()[i].pose.position);
  return out;
}

// The four points alone hold a box flat on a plane: no drift, no tilt.
TEST(ContactManifold, FourPointsHoldABoxAtRestOnAPlane) {
  Scene scene = stack(1, 0.05, 1.0 / 60.0, 5.0);
  std::vector<Vec3> settled;
  const double deepest = runAwake(scene, [&](const World&, int step) {
    if (step == 59) settled = positionsOf(scene);
  });
  EXPECT_LE(deepest, 0.1);  // voxels
  const BodyState& box = scene.world->bodies()[scene.movers[0]];
  EXPECT_TRUE(isFinite(box));
  EXPECT_LE((box.pose.position - settled[0]).norm(), 0.01 * scene.voxel);
  EXPECT_LE(box.pose.orientation.angularDistance(Quat::Identity()), 1e-3);
  EXPECT_LE(box.linear_velocity.norm(), 1e-3);
}

TEST(ContactManifold, FourPointsAPairHoldAStackAtRest) {
  Scene scene = stack(5, 0.05, 1.0 / 60.0, 5.0);
  std::size_t most = 0;
  std::vector<Vec3> settled;
  const double deepest = runAwake(scene, [&](const World& world, int step) {
    for (const auto& [key, points] : pointsByPair(world)) most = std::max(most, points.size());
    if (step == 59) settled = positionsOf(scene);
  });
  EXPECT_EQ(most, 4u);
  EXPECT_LE(deepest, 0.1);
  const std::vector<Vec3> end = positionsOf(scene);
  for (std::size_t k = 0; k < end.size(); ++k) EXPECT_LE((end[k] - settled[k]).norm(), 0.05 * scene.voxel) << k;
  for (std::size_t k = 1; k < end.size(); ++k) {
    const Vec3 step = end[k] - end[k - 1];
    EXPECT_NEAR(step.z(), 8 * scene.voxel, 0.1 * scene.voxel);
    EXPECT_LE(step.head<2>().norm(), 0.1 * scene.voxel);
  }
}

}  // namespace
}  // namespace stc::stability
