// Continuous collision (issue 9, item 1): the swept test holds back only
// bodies that would pass through or sink into another, the response of the
// same tick turns them, so the stored velocity always agrees with the real
// motion; it sweeps only the broad phase's pairs.
#include "cube_overlap.hpp"
#include "stability_scenes.hpp"

#include "continuous.hpp"
#include "dynamics.hpp"
#include "physics.hpp"
#include "shape_bounds.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace stc {
namespace {

constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 60.0;
constexpr double kVoxel = 0.05;

ShapeId preset(World& w, const std::string& name, int resolution = 8, double voxel = kVoxel) {
  PresetParams p;
  p.resolution = resolution;
  p.voxel_size = voxel;
  return w.addShape(name + std::to_string(resolution) + "_" + std::to_string(voxel), makePreset(name, p));
}

// A static slab 3.2 x 3.2 x 0.2 m (voxels of 10 cm), centred at `centre`.
EntityId addSlab(World& w, const Vec3& centre, const Quat& orientation, const Material& m) {
  const ShapeId slab = w.addShape("slab", VoxelShape::create(32, 32, 2, 0.1, std::vector<std::uint8_t>(32 * 32 * 2, 1)));
  EntitySpec spec;
  spec.shape = slab;
  spec.pose.position = centre;
  spec.pose.orientation = orientation;
  spec.material = m;
  spec.is_static = true;
  return w.addEntity(spec);
}

// Mean over movable bodies and ticks of the stored speed a tick moves with
// and of the distance it moved over dt.
struct SpeedAgreement {
  double stored = 0.0;
  double real = 0.0;
};

SpeedAgreement measure(World& w, int steps) {
  double stored = 0.0, real = 0.0;
  long samples = 0;
  std::vector<Vec3> before;
  std::vector<double> speed;
  for (int s = 0; s < steps; ++s) {
    const std::vector<BodyState>& b = w.bodies();
    before.resize(b.size());
    speed.resize(b.size());
    for (std::size_t i = 0; i < b.size(); ++i) {
      before[i] = b[i].pose.position;
      speed[i] = b[i].linear_velocity.norm();
    }
    w.step(kDt, Budget::unlimited());
    for (std::size_t i = 0; i < b.size(); ++i) {
      if (b[i].is_static) continue;
      stored += speed[i];
      real += (b[i].pose.position - before[i]).norm() / kDt;
      ++samples;
    }
  }
  return {stored / static_cast<double>(samples), real / static_cast<double>(samples)};
}

// Every built-in scene, 10 s: the bodies move as fast as their velocities say.
// Scaled down from the scenes' defaults (500 in the boxes, 1,000 cubes) to
// keep the test short; rockfall and bouncing_box at their defaults.
TEST(Continuous, StoredSpeedAgreesWithRealMotionOnEveryBuiltInScene) {
  const std::pair<SceneKind, int> scenes[] = {
      {SceneKind::PackedBox, 64},     {SceneKind::BouncingBox, 100}, {SceneKind::Rockfall, 200},
      {SceneKind::CornerDrift, 125}, {SceneKind::CubeBox, 300}};
  for (const auto& [kind, count] : scenes) {
    SceneParams params;
    params.entities = count;
    SceneWorld scene = makeSceneWorld(kind, params);
    const SpeedAgreement m = measure(scene.world, static_cast<int>(10.0 / kDt));
    SCOPED_TRACE(toString(kind));
    EXPECT_GT(m.stored, 0.0);
    EXPECT_LE(std::abs(m.stored - m.real), 0.1 * m.real + 0.05) << "stored " << m.stored << " real " << m.real;
  }
}

// A rock hitting a ledge of the ravine (a one-voxel plate like the rockfall
// scene's wall tiles, 12.5 cm thick; the scene's rock material) at 30 m/s,
// about as fast as the rocks that used to stall in mid-air: it moves 0.5 m a
// tick, through the plate without the swept test. Held at the plate, it
// bounces (e = 0.3) and is at rest on the ledge within 3 s. Several heights:
// the hit falls at different instants of a tick.
TEST(Continuous, RockHittingARavineLedgeComesToRestOnIt) {
  int clamped = 0;
  for (const double height : {2.0, 2.1, 2.2, 2.3, 2.4}) {
    SCOPED_TRACE(height);
    WorldConfig config;
    config.gravity = Vec3(0.0, 0.0, -kG);
    World w(config);
    const Material rock{0.3, 0.6};
    EntitySpec ledge;
    ledge.shape = w.addShape("ledge", VoxelShape::create(32, 32, 1, 0.125, std::vector<std::uint8_t>(32 * 32, 1)));
    ledge.material = rock;
    ledge.is_static = true;
    w.addEntity(ledge);  // top face at z = 0.0625
    EntitySpec spec;
    spec.shape = preset(w, "rock");
    spec.pose.position = Vec3(0.0, 0.0, height);
    spec.linear_velocity = Vec3(0.0, 0.0, -30.0);
    spec.material = rock;
    const std::size_t index = *w.indexOf(w.addEntity(spec));
    for (int s = 0; s < static_cast<int>(3.0 / kDt); ++s) {
      w.step(kDt, Budget::unlimited());
      clamped += static_cast<int>(physicsReport(w).sweep.clamped);
    }
    const BodyState& b = w.bodies()[index];
    EXPECT_LT(b.linear_velocity.norm(), 0.05);
    EXPECT_GT(b.pose.position.z(), 0.0625);  // on the ledge, not under it
    const Vec3 x = b.pose.position;
    w.step(kDt, Budget::unlimited());
    EXPECT_LT((w.bodies()[index].pose.position - x).norm() / kDt, 0.05);  // and really still
  }
  EXPECT_GT(clamped, 0);  // the swept test caught it
}

// A world under gravity with a vertical slab of material m whose +x face is at x = 0.
World besideAWall(const Material& m) {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -kG);
  World w(config);
  addSlab(w, Vec3(-0.1, 0.0, 0.0), Quat(Eigen::AngleAxisd(-0.5 * M_PI, Vec3::UnitY())), m);
  return w;
}

// Free fall beside a wall and beside another falling rock, 1 mm apart: both
// are fast, neither moves towards the other, so nothing holds them back and
// they fall at exactly g. The wall and the neighbour are the only sweep
// partners of each (bodies far away never are).
TEST(Continuous, RockFallingNearOtherBodiesAcceleratesAtG) {
  const Material m{0.3, 0.6};
  World w = besideAWall(m);
  const ShapeId rock = preset(w, "rock");
  const ShapeId cube = preset(w, "cube");
  for (int k = 0; k < 50; ++k) {  // far-away bodies: never swept against
    EntitySpec far;
    far.shape = cube;
    far.pose.position = Vec3(20.0 + 0.5 * k, 0.0, 0.0);
    far.linear_velocity = Vec3(0.0, 0.0, -5.0);
    w.addEntity(far);
  }
  const ShapeInfo& info = w.shape(rock);
  const double lo = -info.body_origin.x();  // the rock's lowest x in its body frame
  const double width = info.voxels.extent().x();
  const double v0 = -5.0;
  EntitySpec spec;
  spec.shape = rock;
  spec.material = m;
  spec.linear_velocity = Vec3(0.0, 0.0, v0);
  spec.pose.position = Vec3(0.001 - lo, 0.0, 1.0);
  const std::size_t a = *w.indexOf(w.addEntity(spec));
  spec.pose.position.x() += width + 0.001;
  const std::size_t b = *w.indexOf(w.addEntity(spec));
  const Vec3 a0 = w.bodies()[a].pose.position;
  const int steps = 30;
  std::size_t most_pairs = 0;
  for (int s = 0; s < steps; ++s) {
    w.step(kDt, Budget::unlimited());
    most_pairs = std::max(most_pairs, physicsReport(w).sweep.pairs);
  }
  const double t = steps * kDt;
  for (const std::size_t i : {a, b}) {
    const BodyState& body = w.bodies()[i];
    EXPECT_NEAR(body.linear_velocity.z(), v0 - kG * t, 1e-9);
    EXPECT_NEAR(body.linear_velocity.x(), 0.0, 1e-12);
  }
  // x_N = x_0 + v0 N dt - g dt^2 N (N - 1) / 2 (positions move with the velocity before gravity).
  const double fallen = v0 * t - kG * kDt * kDt * steps * (steps - 1) / 2.0;
  EXPECT_NEAR(w.bodies()[a].pose.position.z() - a0.z(), fallen, 1e-9);
  EXPECT_LE(most_pairs, 2u);  // rock-wall and, at most, rock-rock: never the far cubes
}

// Sliding fast down a frictionless wall while pressing into it: a graze,
// not a hit. The wall takes the sideways approach; the fall is not held back.
TEST(Continuous, CubeGrazingAFrictionlessWallKeepsFalling) {
  const Material frictionless{0.0, 0.0};
  World w = besideAWall(frictionless);
  EntitySpec spec;
  spec.shape = preset(w, "cube");
  spec.material = frictionless;
  spec.pose.position = Vec3(0.2 + 0.001, 0.0, 1.0);  // 1 mm off the wall
  spec.linear_velocity = Vec3(-1.0, 0.0, -20.0);  // 0.3 voxel into the wall in its first tick
  const std::size_t index = *w.indexOf(w.addEntity(spec));
  const int steps = 20;
  for (int s = 0; s < steps; ++s) w.step(kDt, Budget::unlimited());
  const BodyState& b = w.bodies()[index];
  EXPECT_NEAR(b.linear_velocity.z(), -20.0 - kG * steps * kDt, 1e-9);
  EXPECT_NEAR(b.linear_velocity.x(), 0.0, 1e-6);  // stopped by the wall
  EXPECT_GT(b.pose.position.x(), 0.2 - 0.25 * kVoxel);  // and not through it (a quarter voxel, as the fast sphere of test_stability)
  const double fallen = -20.0 * steps * kDt - kG * kDt * kDt * steps * (steps - 1) / 2.0;
  EXPECT_NEAR(b.pose.position.z() - 1.0, fallen, 1e-9);
}

// A column of cubes falling together onto a floor (as cube_box's lattice
// lands): the lowest is held back at the floor; the ones above fall no
// faster than it did relative to them, so their pair is not fast, yet it
// closes by the rest of the tick's fall once the one below is stopped. A
// cube is a shell of leaf spheres one voxel thick: a cube sinking a voxel
// into the one below it is inside it, and stays there. Each cube above is
// held back by the one below: no pair overlaps by more than half a voxel,
// and the column comes to rest stacked. Several speeds and gaps: the hits fall
// at different instants of a tick.
TEST(Continuous, ACubeColumnLandingTogetherStaysStacked) {
  for (const double speed : {3.0, 5.0, 8.0}) {
    for (const double gap : {0.005, 0.02}) {
      SCOPED_TRACE(testing::Message() << "speed " << speed << " gap " << gap);
      WorldConfig config;
      config.gravity = Vec3(0.0, 0.0, -kG);
      World w(config);
      const Material m{0.2, 0.5};
      addSlab(w, Vec3(0.0, 0.0, -0.1), Quat::Identity(), m);  // top face at z = 0
      const ShapeId cube = preset(w, "cube");
      std::vector<std::size_t> column;
      for (int k = 0; k < 4; ++k) {
        EntitySpec spec;
        spec.shape = cube;
        spec.material = m;
        spec.pose.position = Vec3(0.0, 0.0, 0.2 + 0.03 + k * (0.4 + gap));
        spec.linear_velocity = Vec3(0.0, 0.0, -speed);
        column.push_back(*w.indexOf(w.addEntity(spec)));
      }
      double deepest = -1.0;
      for (int s = 0; s < static_cast<int>(2.0 / kDt); ++s) {
        w.step(kDt, Budget::unlimited());
        for (std::size_t k = 0; k + 1 < column.size(); ++k) {
          deepest = std::max(deepest, cubeOverlap(w.bodies()[column[k]].pose, w.bodies()[column[k + 1]].pose, 0.2));
        }
      }
      EXPECT_LT(deepest, 0.5 * kVoxel);
      for (std::size_t k = 0; k < column.size(); ++k) {
        const BodyState& b = w.bodies()[column[k]];
        EXPECT_NEAR(b.pose.position.z(), 0.2 + 0.4 * static_cast<double>(k), 0.5 * kVoxel) << "cube " << k;
        EXPECT_LT(b.linear_velocity.norm(), 0.05) << "cube " << k;
      }
    }
  }
}

// cube_box as built (1,000 cubes of 8 voxels on a lattice, falling into a
// pile), its first 3 s: at the end of every tick no two cubes overlap by a
// voxel, the thickness of a cube's shell of leaf spheres. Before the rounds,
// cubes landing together sank into the ones below (0.1 m at 0.8 s) and ended
// inside them (0.35 m, for good), and a cube held back by one landing on it
// hung in the air with a stored speed that grew by g dt a tick.
TEST(Continuous, CubeBoxCubesNeverSinkIntoEachOther) {
  SceneWorld scene = makeSceneWorld(SceneKind::CubeBox);
  World& w = scene.world;
  const CubeOverlapRun run = deepestCubeOverlap(w, static_cast<int>(3.0 / kDt), kDt, 0.2);
  EXPECT_GT(run.held_back, 0);
  EXPECT_LT(run.deepest, kVoxel);
}

// With no detection budget and unresolved pairs rejected, the narrow phase
// gives no contact at all: the sweep's hit is the contact, so the ball held
// at the plate still bounces (e = 0.5) instead of hanging there at 100 m/s.
TEST(Continuous, AHitWithoutANarrowPhaseContactIsTheContact) {
  stability::Scene scene = stability::fastSphere(100.0);
  World& w = *scene.world;
  w.setUnresolvedPolicy(UnresolvedPolicy::Reject);
  const std::size_t ball = scene.movers.front();
  double lowest = 1e9;
  int clamped = 0;
  for (int s = 0; s < 30; ++s) {
    const TickReport r = w.step(scene.dt, Budget::ofSphereTests(0));
    EXPECT_EQ(r.detection.colliding, 0u);
    clamped += static_cast<int>(physicsReport(w).sweep.clamped);
    lowest = std::min(lowest, w.bodies()[ball].pose.position.z());
  }
  EXPECT_GT(clamped, 0);
  EXPECT_GT(lowest, 0.5 * scene.voxel);  // never past the plate's top face
  EXPECT_NEAR(w.bodies()[ball].linear_velocity.z(), 50.0, 0.5);
  EXPECT_LT(w.bodies()[ball].angular_velocity.norm(), 1e-6);  // pushed through its centre, not spun
  EXPECT_GT(w.bodies()[ball].pose.position.z(), 1.0);  // and flew back up
}

// The sweep skips node pairs whose leaves' boxes cannot reach a hit. Two
// shapes thrown at each other from random poses, moving and turning (up to
// 0.8 rad a tick): with and without the pruning, the same bodies are put
// back at the same instant and place, bit for bit, with fewer leaf pairs
// tested (bench: 3 to 30 times fewer in cube_box). Without growing the
// boxes by the turn, hits of turning bodies were lost.
TEST(Continuous, PruningByBoxesKeepsEveryHit) {
  const std::vector<std::pair<std::string, std::uint32_t>> kinds = {{"rock", 3}, {"cube", 1}, {"rod", 1}, {"L", 1}};
  std::vector<VoxelShape> voxels;
  std::vector<SphereTree> trees;
  for (const auto& [name, seed] : kinds) {
    PresetParams p;
    p.resolution = 8;
    p.voxel_size = kVoxel;
    p.seed = seed;
    voxels.push_back(makePreset(name, p));
  }
  trees.reserve(voxels.size());
  std::vector<ShapeBounds> bounds;
  for (const VoxelShape& v : voxels) {
    const Vec3 origin = computeMassProperties(v, 1.0).centre_of_mass;
    trees.push_back(SphereTree::build(v, origin));
    bounds.push_back(makeShapeBounds(trees.back(), &v, origin));
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto direction = [&] {
    Vec3 d(unit(rng), unit(rng), unit(rng));
    return d.norm() > 1e-3 ? Vec3(d.normalized()) : Vec3(Vec3::UnitX());
  };
  const auto turn = [&](double most) { return Quat(Eigen::AngleAxisd(most * 0.5 * (1.0 + unit(rng)), direction())); };
  int hits = 0;
  std::size_t pruned_tests = 0, full_tests = 0;
  const std::vector<std::array<std::uint32_t, 2>> pairs = {{0u, 1u}};
  for (int trial = 0; trial < 6000; ++trial) {
    const std::size_t ka = static_cast<std::size_t>(trial) % bounds.size();
    const std::size_t kb = static_cast<std::size_t>(trial / 3) % bounds.size();
    std::vector<Pose> start(2);
    std::vector<BodyState> bodies(2);
    const double reach = bounds[ka].bound_radius + bounds[kb].bound_radius;
    start[0].orientation = turn(M_PI);
    start[1].orientation = turn(M_PI);
    start[1].position = direction() * reach * (0.6 + 0.5 * (1.0 + unit(rng)));
    for (std::size_t i = 0; i < 2; ++i) {
      bodies[i].inv_mass = 1.0;
      bodies[i].inv_inertia_body = Mat3::Identity();
      const Vec3 towards = (i == 0 ? 1.0 : -1.0) * start[1].position.normalized();
      const Vec3 move = 0.15 * (1.0 + unit(rng)) * (towards + 0.5 * direction());
      bodies[i].pose.position = start[i].position + move;
      bodies[i].pose.orientation = (turn(0.8) * start[i].orientation).normalized();
    }
    const std::vector<const ShapeBounds*> shapes = {&bounds[ka], &bounds[kb]};
    std::vector<BodyState> pruned = bodies, full = bodies;
    SweepScratch with, without;
    without.prune_by_boxes = false;
    markFastBodies(pruned, start, shapes, 0.5, with.fast);
    markFastBodies(full, start, shapes, 0.5, without.fast);
    const SweepStats a = sweepFastBodies(pruned, start, shapes, pairs, 1, 0.5, with);
    const SweepStats b = sweepFastBodies(full, start, shapes, pairs, 1, 0.5, without);
    pruned_tests += a.leaf_tests;
    full_tests += b.leaf_tests;
    ASSERT_EQ(a.clamped, b.clamped) << "trial " << trial;
    hits += a.clamped > 0;
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(with.hits[i].t, without.hits[i].t) << "trial " << trial;
      EXPECT_EQ(with.hits[i].point, without.hits[i].point) << "trial " << trial;
      EXPECT_EQ(with.hits[i].normal, without.hits[i].normal) << "trial " << trial;
      EXPECT_EQ(pruned[i].pose.position, full[i].pose.position) << "trial " << trial;
    }
  }
  EXPECT_GT(hits, 50);  // the trials do hit
  EXPECT_LT(pruned_tests, full_tests);
}

}  // namespace
}  // namespace stc
