// Scenes as data and the gaze model: what each scene puts in a World, input
// checks, determinism, and where the gaze lands over time.
#include "thrown_field.hpp"

#include "sphere_tree_collision/gaze_model.hpp"
#include "sphere_tree_collision/scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace stc {
namespace {

WorldConfig configFor(SceneKind kind) {
  WorldConfig c;
  c.gravity = sceneGravity(kind);
  return c;
}

constexpr SceneKind kAllScenes[] = {SceneKind::PackedBox, SceneKind::BouncingBox,
                                    SceneKind::Rockfall, SceneKind::CornerDrift,
                                    SceneKind::CubeBox, SceneKind::Pyramid};

bool inside(const Aabb& box, const Vec3& p) {
  return p.allFinite() && (p.array() >= box.min.array()).all() && (p.array() <= box.max.array()).all();
}

TEST(Scenes, NamesRoundTrip) {
  for (SceneKind kind : kAllScenes) EXPECT_EQ(parseScene(toString(kind)), kind);
  EXPECT_EQ(thrownField([] { parseScene("ravine"); }), "scene");
  for (GazeMode mode : {GazeMode::Fixed, GazeMode::Saccades, GazeMode::Follow}) {
    EXPECT_EQ(parseGazeMode(toString(mode)), mode);
  }
  EXPECT_EQ(thrownField([] { parseGazeMode("stare"); }), "gaze_mode");
}

TEST(Scenes, EachSceneHasMoversInsideItsBoundsStaticWallsAndACameraOnThem) {
  for (SceneKind kind : kAllScenes) {
    SCOPED_TRACE(toString(kind));
    World world(configFor(kind));
    SceneParams params;
    params.entities = 60;  // small: the layout logic is the same at 500
    const SceneSpec spec = populateScene(world, kind, params);
    EXPECT_EQ(spec.kind, kind);
    EXPECT_EQ(spec.movers.size(), 60u);
    EXPECT_GE(spec.walls.size(), 5u);
    EXPECT_EQ(world.entityCount(), spec.movers.size() + spec.walls.size());
    world.perception().setCamera(spec.camera);
    std::size_t on_screen = 0;
    for (EntityId id : spec.movers) {
      const BodyState& body = world.bodies()[*world.indexOf(id)];
      EXPECT_FALSE(body.is_static);
      const Vec3& p = body.pose.position;
      EXPECT_TRUE(inside(spec.bounds, p));
      const auto pixel = world.perception().project(p);
      if (pixel && world.perception().onScreen(*pixel)) ++on_screen;
    }
    EXPECT_EQ(on_screen, spec.movers.size());
    for (EntityId id : spec.walls) EXPECT_TRUE(world.bodies()[*world.indexOf(id)].is_static);
  }
}

TEST(Scenes, PackedBoxIsTightlyPackedAndMoving) {
  World world(configFor(SceneKind::PackedBox));
  const SceneSpec spec = populateScene(world, SceneKind::PackedBox);
  EXPECT_EQ(spec.movers.size(), 500u);
  // Homogeneous: one shape for every mover.
  const ShapeId shape = world.bodyShapes()[*world.indexOf(spec.movers.front())];
  double min_speed = 1e9;
  for (EntityId id : spec.movers) {
    const std::size_t i = *world.indexOf(id);
    EXPECT_EQ(world.bodyShapes()[i], shape);
    min_speed = std::min(min_speed, world.bodies()[i].linear_velocity.norm());
  }
  EXPECT_GT(min_speed, 0.4);
  // Tightly packed: on average every mover's box overlaps several others.
  const TickReport report = world.step(0.0, Budget::unlimited());
  EXPECT_GT(report.detection.broad_pairs, 3 * spec.movers.size());
  EXPECT_GT(report.detection.colliding, 0u);
}

TEST(Scenes, CornerDriftGravityPointsIntoABoxCorner) {
  World world(configFor(SceneKind::CornerDrift));
  const SceneSpec spec = populateScene(world, SceneKind::CornerDrift);
  const Vec3 g = spec.gravity.normalized();
  EXPECT_NEAR(spec.gravity.norm(), 9.81, 1e-9);
  const Vec3 to_corner = (spec.bounds.min - 0.5 * (spec.bounds.min + spec.bounds.max)).normalized();
  EXPECT_NEAR(g.dot(to_corner), 1.0, 1e-9);
}

TEST(Scenes, RockfallUsesSeveralRockShapesAboveTheRavineFloor) {
  World world(configFor(SceneKind::Rockfall));
  const SceneSpec spec = populateScene(world, SceneKind::Rockfall);
  EXPECT_EQ(spec.movers.size(), 200u);
  EXPECT_LT(spec.gravity.z(), 0.0);
  std::vector<ShapeId> shapes;
  double lowest = std::numeric_limits<double>::infinity();
  for (EntityId id : spec.movers) {
    const std::size_t i = *world.indexOf(id);
    shapes.push_back(world.bodyShapes()[i]);
    lowest = std::min(lowest, world.bodies()[i].pose.position.z());
  }
  std::sort(shapes.begin(), shapes.end());
  EXPECT_EQ(std::unique(shapes.begin(), shapes.end()) - shapes.begin(), 4);
  EXPECT_GT(lowest, 0.0);  // every rock starts above the run-out floor (z = 0)
  // Nothing starts in contact, rock on rock or rock on wall (full depth).
  const TickReport report = world.step(0.0, Budget::unlimited());
  EXPECT_GT(report.detection.broad_pairs, 0u);
  EXPECT_EQ(report.detection.colliding, 0u);
}

TEST(Scenes, RockfallRavineGrowsWithTheRockCountSoTheColumnStartsInside) {
  auto spec = [](int rocks, World& world) {
    SceneParams p;
    p.entities = rocks;
    return populateScene(world, SceneKind::Rockfall, p);
  };
  World w60(configFor(SceneKind::Rockfall)), w200(configFor(SceneKind::Rockfall)),
      w5000(configFor(SceneKind::Rockfall));
  const SceneSpec small = spec(60, w60), base = spec(200, w200), large = spec(5000, w5000);
  // Up to 200 rocks: one ravine.
  EXPECT_EQ(small.bounds.min, base.bounds.min);
  EXPECT_EQ(small.bounds.max, base.bounds.max);
  EXPECT_EQ(small.walls.size(), base.walls.size());
  // 5,000 rocks: every length 25^(1/3) times the base, and every rock starts
  // inside (a column of fixed footprint would reach 59 m up).
  const Vec3 base_size = base.bounds.max - base.bounds.min, large_size = large.bounds.max - large.bounds.min;
  EXPECT_NEAR(large_size.y() / base_size.y(), std::cbrt(25.0), 1e-9);
  ASSERT_EQ(large.movers.size(), 5000u);
  std::size_t outside = 0;
  for (EntityId id : large.movers) {
    if (!inside(large.bounds, w5000.bodies()[*w5000.indexOf(id)].pose.position)) ++outside;
  }
  EXPECT_EQ(outside, 0u);
}

TEST(Scenes, RockfallRocksStayInTheSceneThroughTheDrop) {
  World world(configFor(SceneKind::Rockfall));
  SceneParams p;
  p.entities = 300;
  const SceneSpec spec = populateScene(world, SceneKind::Rockfall, p);
  // 4 s: the rocks land, slide down the ravine and pile up at the run-out;
  // the first reach the tray's far wall.
  double start = -1e9;
  for (EntityId id : spec.movers) start = std::max(start, world.bodies()[*world.indexOf(id)].pose.position.x());
  double farthest = start;
  for (int tick = 0; tick < 240; ++tick) {
    world.step(spec.dt, Budget::unlimited());
    for (EntityId id : spec.movers) {
      const Vec3& at = world.bodies()[*world.indexOf(id)].pose.position;
      ASSERT_TRUE(inside(spec.bounds, at)) << "tick " << tick << " rock " << id << " at " << at.transpose();
      farthest = std::max(farthest, at.x());
    }
  }
  // They did go somewhere: down the ravine into the run-out.
  EXPECT_GT(farthest, start + 5.0);
}

TEST(Scenes, CubeBoxIsOneCubeShapeUnderGravityStartingApart) {
  World world(configFor(SceneKind::CubeBox));
  SceneParams p;
  p.entities = 125;
  const SceneSpec spec = populateScene(world, SceneKind::CubeBox, p);
  EXPECT_EQ(spec.gravity, Vec3(0.0, 0.0, -9.81));
  const ShapeId shape = world.bodyShapes()[*world.indexOf(spec.movers.front())];
  const VoxelShape& voxels = world.shape(shape).voxels;
  EXPECT_EQ(voxels.occupiedCount(), static_cast<std::int64_t>(voxels.nx()) * voxels.ny() * voxels.nz());
  EXPECT_EQ(voxels.nx(), voxels.nz());
  for (EntityId id : spec.movers) EXPECT_EQ(world.bodyShapes()[*world.indexOf(id)], shape);
  const TickReport report = world.step(0.0, Budget::unlimited());
  EXPECT_GT(report.detection.broad_pairs, 0u);
  EXPECT_EQ(report.detection.colliding, 0u);
}

// Box2D's large_pyramid: a base of 100 cubes, each row one shorter and half a
// cube along, the cubes touching, at rest, on a floor at z = 0.
TEST(Scenes, PyramidIsBox2DsLargePyramid) {
  World world(configFor(SceneKind::Pyramid));
  const SceneSpec spec = populateScene(world, SceneKind::Pyramid);
  ASSERT_EQ(spec.movers.size(), 5050u);
  const ShapeId shape = world.bodyShapes()[*world.indexOf(spec.movers.front())];
  const VoxelShape& voxels = world.shape(shape).voxels;
  EXPECT_EQ(voxels.occupiedCount(), static_cast<std::int64_t>(voxels.nx()) * voxels.ny() * voxels.nz());
  const double size = voxels.extent().x();
  EXPECT_NEAR(size, SceneParams{}.entity_size, 1e-12);
  std::map<long, std::vector<double>> rows;  // row -> x of its cubes
  for (EntityId id : spec.movers) {
    const BodyState& b = world.bodies()[*world.indexOf(id)];
    EXPECT_EQ(world.bodyShapes()[*world.indexOf(id)], shape);
    EXPECT_EQ(b.linear_velocity, Vec3::Zero());
    EXPECT_EQ(b.angular_velocity, Vec3::Zero());
    EXPECT_NEAR(b.pose.position.y(), 0.0, 1e-12);
    const double row = b.pose.position.z() / size - 0.5;
    EXPECT_NEAR(row, std::round(row), 1e-9);
    rows[std::lround(row)].push_back(b.pose.position.x());
  }
  ASSERT_EQ(rows.size(), 100u);
  for (auto& [row, xs] : rows) {
    SCOPED_TRACE(row);
    std::sort(xs.begin(), xs.end());
    ASSERT_EQ(xs.size(), static_cast<std::size_t>(100 - row));
    for (std::size_t j = 1; j < xs.size(); ++j) EXPECT_NEAR(xs[j] - xs[j - 1], size, 1e-9);  // touching
    if (row > 0) EXPECT_NEAR(xs.front() - rows[row - 1].front(), 0.5 * size, 1e-9);
  }
  EXPECT_NEAR(rows[0].front() + rows[0].back(), 0.0, 1e-9);  // centred on x = 0
  // Smaller counts fill the rows from the base up: 60 cubes stand on a base of 11.
  World small(configFor(SceneKind::Pyramid));
  SceneParams p;
  p.entities = 60;
  const SceneSpec s = populateScene(small, SceneKind::Pyramid, p);
  std::size_t base = 0;
  for (EntityId id : s.movers) base += small.bodies()[*small.indexOf(id)].pose.position.z() < size ? 1 : 0;
  EXPECT_EQ(base, 11u);
}

// A small pyramid of the same layout stands: after 2 s no cube has moved more
// than one of its voxels.
TEST(Scenes, PyramidStands) {
  World world(configFor(SceneKind::Pyramid));
  SceneParams p;
  p.entities = 55;  // a base of 10
  const SceneSpec spec = populateScene(world, SceneKind::Pyramid, p);
  std::vector<Vec3> start;
  for (EntityId id : spec.movers) start.push_back(world.bodies()[*world.indexOf(id)].pose.position);
  for (int tick = 0; tick < 120; ++tick) world.step(spec.dt, Budget::unlimited());
  const double voxel = p.entity_size / p.resolution;
  double moved = 0.0;
  for (std::size_t k = 0; k < spec.movers.size(); ++k) {
    moved = std::max(moved, (world.bodies()[*world.indexOf(spec.movers[k])].pose.position - start[k]).norm());
  }
  EXPECT_LT(moved, voxel);
}

TEST(Scenes, SameSeedSamePosesOtherSeedOtherPoses) {
  auto positions = [](std::uint32_t seed) {
    World world(configFor(SceneKind::BouncingBox));
    SceneParams p;
    p.seed = seed;
    p.entities = 20;
    const SceneSpec spec = populateScene(world, SceneKind::BouncingBox, p);
    std::vector<double> out;
    for (EntityId id : spec.movers) {
      const BodyState& b = world.bodies()[*world.indexOf(id)];
      out.push_back(b.pose.orientation.w());
      out.push_back(b.linear_velocity.x());
    }
    return out;
  };
  EXPECT_EQ(positions(7), positions(7));
  EXPECT_NE(positions(7), positions(8));
}

TEST(Scenes, BadParamsNameTheFieldAndAddNoEntity) {
  auto field = [](SceneKind kind, const WorldConfig& config, auto edit) {
    World world(config);
    SceneParams p;
    edit(p);
    const std::string f = thrownField([&] { populateScene(world, kind, p); });
    EXPECT_EQ(world.entityCount(), 0u) << f;
    return f;
  };
  const WorldConfig packed = configFor(SceneKind::PackedBox);
  EXPECT_EQ(field(SceneKind::PackedBox, packed, [](SceneParams& p) { p.entities = -2; }), "entities");
  EXPECT_EQ(field(SceneKind::PackedBox, packed, [](SceneParams& p) { p.entity_size = 0.0; }),
            "entity_size");
  EXPECT_EQ(field(SceneKind::PackedBox, packed, [](SceneParams& p) { p.resolution = 1; }),
            "resolution");
  EXPECT_EQ(field(SceneKind::PackedBox, packed, [](SceneParams& p) { p.speed = std::nan(""); }),
            "speed");
  EXPECT_EQ(field(SceneKind::Rockfall, packed, [](SceneParams&) {}), "gravity");
  WorldConfig small = packed;
  small.max_entities = 100;
  EXPECT_EQ(field(SceneKind::PackedBox, small, [](SceneParams&) {}), "entities");
}

TEST(Scenes, SceneWorldHasTheScenesGravityAndCameraAndKeepsTheRestOfTheConfig) {
  WorldConfig config;
  config.gravity = Vec3(1.0, 2.0, 3.0);  // replaced by the scene's
  config.threads = 2;
  config.sleeping.enabled = false;
  SceneParams params;
  params.entities = 20;
  const SceneWorld scene = makeSceneWorld(SceneKind::CornerDrift, params, config);
  EXPECT_EQ(scene.world.config().gravity, sceneGravity(SceneKind::CornerDrift));
  EXPECT_EQ(scene.world.config().threads, 2);
  EXPECT_FALSE(scene.world.config().sleeping.enabled);
  EXPECT_EQ(scene.spec.movers.size(), 20u);
  EXPECT_EQ(scene.world.entityCount(), scene.spec.movers.size() + scene.spec.walls.size());
  const Camera& camera = scene.world.perception().camera();
  ASSERT_FALSE(scene.spec.camera.camera_to_world.position.isZero());  // not the default camera
  EXPECT_TRUE(camera.camera_to_world.position.isApprox(scene.spec.camera.camera_to_world.position));
  EXPECT_EQ(camera.width, scene.spec.camera.width);
  // The same world as populateScene builds into a World of the scene's gravity.
  World direct(configFor(SceneKind::CornerDrift));
  populateScene(direct, SceneKind::CornerDrift, params);
  ASSERT_EQ(direct.entityCount(), scene.world.entityCount());
  for (std::size_t i = 0; i < direct.entityCount(); ++i) {
    EXPECT_EQ(direct.bodies()[i].pose.position, scene.world.bodies()[i].pose.position);
  }
  params.entities = -1;
  EXPECT_EQ(thrownField([&] { makeSceneWorld(SceneKind::PackedBox, params); }), "entities");
}

// ---------------------------------------------------------------------------
// Gaze

class Gaze : public ::testing::Test {
 protected:
  void SetUp() override {
    Camera c;  // at the origin looking along +z, 1280x720
    world_.perception().setCamera(c);
    PresetParams p;
    p.resolution = 4;
    p.voxel_size = 0.05;
    shape_ = world_.addShape("cube", makePreset("cube", p));
  }
  EntityId add(const Vec3& at) {
    EntitySpec e;
    e.shape = shape_;
    e.pose.position = at;
    return world_.addEntity(e);
  }
  World world_;
  ShapeId shape_ = 0;
};

TEST_F(Gaze, FixedIsThePixelOrTheImageCentre) {
  GazeModel centre(GazeParams{});
  EXPECT_EQ(centre.fixationAt(3.0, world_), Vec2(640, 360));
  GazeParams p;
  p.pixel = Vec2(100, 50);
  GazeModel fixed(p);
  EXPECT_EQ(fixed.fixationAt(0.0, world_), Vec2(100, 50));
  EXPECT_EQ(fixed.fixationAt(99.0, world_), Vec2(100, 50));
}

TEST_F(Gaze, SaccadesHoldForAPeriodThenJumpReproducibly) {
  GazeParams p;
  p.mode = GazeMode::Saccades;
  p.saccade_period_s = 0.3;
  p.seed = 5;
  GazeModel a(p), b(p);
  EXPECT_EQ(a.fixationAt(0.01, world_), a.fixationAt(0.29, world_));
  int jumps = 0;
  for (int k = 0; k < 50; ++k) {
    const Vec2 now = a.fixationAt(0.3 * k + 0.15, world_);
    const Vec2 next = a.fixationAt(0.3 * (k + 1) + 0.15, world_);
    if ((now - next).norm() > 1.0) ++jumps;
    EXPECT_EQ(now, b.fixationAt(0.3 * k + 0.15, world_));  // same seed, same path
    EXPECT_GE(now.x(), 0.1 * 1280 - 1e-9);
    EXPECT_LE(now.x(), 0.9 * 1280 + 1e-9);
    EXPECT_GE(now.y(), 0.1 * 720 - 1e-9);
    EXPECT_LE(now.y(), 0.9 * 720 + 1e-9);
  }
  EXPECT_GE(jumps, 48);
  p.seed = 6;
  GazeModel other(p);
  EXPECT_NE(other.fixationAt(0.15, world_), a.fixationAt(0.15, world_));
}

TEST_F(Gaze, FollowTracksTheEntityAndHoldsWhenItIsBehind) {
  const EntityId id = add(Vec3(1.0, -0.5, 5.0));
  GazeParams p;
  p.mode = GazeMode::Follow;
  p.target = id;
  GazeModel follow(p);
  const Vec2 seen = follow.fixationAt(0.0, world_);
  EXPECT_TRUE((seen - *world_.perception().project(Vec3(1.0, -0.5, 5.0))).norm() < 1e-9);
  world_.bodies()[*world_.indexOf(id)].pose.position = Vec3(0, 0, -3);  // behind the camera
  EXPECT_EQ(follow.fixationAt(0.1, world_), seen);
  world_.bodies()[*world_.indexOf(id)].pose.position = Vec3(100, 0, 1);  // far right: clamped
  EXPECT_EQ(follow.fixationAt(0.2, world_).x(), 1280.0);
  world_.removeEntity(id);
  EXPECT_EQ(follow.fixationAt(0.3, world_).x(), 1280.0);  // gone: holds the last
}

TEST_F(Gaze, BadParamsNameTheField) {
  GazeParams p;
  p.saccade_period_s = 0.0;
  EXPECT_EQ(thrownField([&] { GazeModel g(p); }), "saccade_period_s");
  p = GazeParams{};
  p.saccade_margin = 0.5;
  EXPECT_EQ(thrownField([&] { GazeModel g(p); }), "saccade_margin");
  p = GazeParams{};
  p.pixel = Vec2(std::nan(""), 1);
  EXPECT_EQ(thrownField([&] { GazeModel g(p); }), "pixel");
}

}  // namespace
}  // namespace stc
