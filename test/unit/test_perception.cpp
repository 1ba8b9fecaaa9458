// Perception: pinhole projection, input checks, f(e, g), and the rule for
// pairs behind the camera or off screen.
#include "thrown_field.hpp"

#include "pair_test.hpp"
#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/perception_ray.hpp"
#include "sphere_tree_collision/sphere_tree.hpp"
#include "sphere_tree_collision/voxel_shape.hpp"
#include "sphere_tree_collision/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace stc {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Default camera: at the origin, optical axis +z (world), 1280x720, 60 deg.
Perception defaultPerception() {
  Perception p;
  p.setCamera(Camera{});
  return p;
}

VoxelShape presetShape(const char* name, int resolution, double voxel_size) {
  PresetParams params;
  params.resolution = resolution;
  params.voxel_size = voxel_size;
  return makePreset(name, params);
}

TEST(Perception, ProjectsThroughThePinholeWithYDown) {
  const Perception p = defaultPerception();
  const double focal = 360.0 / std::tan(3.14159265358979323846 / 6.0);
  EXPECT_NEAR(p.focalPx(), focal, 1e-9);

  const auto centre = p.project(Vec3(0, 0, 5));
  ASSERT_TRUE(centre);
  EXPECT_NEAR(centre->x(), 640.0, 1e-9);
  EXPECT_NEAR(centre->y(), 360.0, 1e-9);

  const auto right_down = p.project(Vec3(1, 0.5, 5));
  ASSERT_TRUE(right_down);
  EXPECT_NEAR(right_down->x(), 640.0 + focal * 1.0 / 5.0, 1e-9);
  EXPECT_NEAR(right_down->y(), 360.0 + focal * 0.5 / 5.0, 1e-9);  // +y is down the image
}

TEST(Perception, PointsOnOrBehindTheCameraPlaneDoNotProject) {
  const Perception p = defaultPerception();
  EXPECT_FALSE(p.project(Vec3(0, 0, -1)));
  EXPECT_FALSE(p.project(Vec3(3, 1, 0)));
  EXPECT_FALSE(p.project(Vec3(0, 0, 0.5 * Perception::kNearDepth)));
  EXPECT_TRUE(p.project(Vec3(0, 0, 2.0 * Perception::kNearDepth)));
  EXPECT_FALSE(p.depthOf(Vec3(0, 0, -2)));
  ASSERT_TRUE(p.depthOf(Vec3(7, -3, 2)));
  EXPECT_NEAR(*p.depthOf(Vec3(7, -3, 2)), 2.0, 1e-12);
}

TEST(Perception, LookAtPutsTheTargetAtTheImageCentreWithUpUp) {
  Perception p;
  Camera camera;
  camera.camera_to_world = opticalLookAt(Vec3(-10, 2, 3), Vec3(0, 2, 3), Vec3::UnitZ());
  p.setCamera(camera);
  const auto target = p.project(Vec3(0, 2, 3));
  ASSERT_TRUE(target);
  EXPECT_NEAR(target->x(), 640.0, 1e-9);
  EXPECT_NEAR(target->y(), 360.0, 1e-9);
  // Looking along +x with z up: +z world is up the image (smaller v), -y world is right.
  EXPECT_LT(p.project(Vec3(0, 2, 4))->y(), 360.0);
  EXPECT_GT(p.project(Vec3(0, 1, 3))->x(), 640.0);
  EXPECT_EQ(thrownField([] { opticalLookAt(Vec3(1, 1, 1), Vec3(1, 1, 1)); }), "target");
  // Up parallel to the view direction still gives a proper rotation.
  const Pose down = opticalLookAt(Vec3(0, 0, 10), Vec3(0, 0, 0), Vec3::UnitZ());
  EXPECT_NEAR(down.orientation.norm(), 1.0, 1e-12);
  EXPECT_TRUE((down.orientation * Vec3::UnitZ() - Vec3(0, 0, -1)).norm() < 1e-12);
}

TEST(Perception, ValidateCameraNamesTheBadField) {
  auto with = [](auto edit) {
    Camera c;
    edit(c);
    return thrownField([&] { validateCamera(c); });
  };
  EXPECT_EQ(with([](Camera&) {}), "<no throw>");
  EXPECT_EQ(with([](Camera& c) { c.width = 0; }), "width");
  EXPECT_EQ(with([](Camera& c) { c.height = -3; }), "height");
  EXPECT_EQ(with([](Camera& c) { c.fov_y_deg = 0.0; }), "fov_y_deg");
  EXPECT_EQ(with([](Camera& c) { c.fov_y_deg = 180.0; }), "fov_y_deg");
  EXPECT_EQ(with([](Camera& c) { c.fov_y_deg = kNaN; }), "fov_y_deg");
  // Found by fuzz_gaze: a subnormal field of view overflows the focal length,
  // a camera far enough out overflows every projection.
  EXPECT_EQ(with([](Camera& c) { c.fov_y_deg = 5e-324; }), "fov_y_deg");
  EXPECT_EQ(with([](Camera& c) { c.camera_to_world.position.z() = 1e300; }), "camera_pose");
  EXPECT_EQ(with([](Camera& c) { c.camera_to_world.position.x() = kNaN; }), "camera_pose");
  EXPECT_EQ(with([](Camera& c) { c.camera_to_world.orientation = Quat(0, 0, 0, 0); }), "camera_pose");
  EXPECT_EQ(with([](Camera& c) { c.camera_to_world.orientation = Quat(2, 0, 0, 0); }), "camera_pose");
}

TEST(Perception, RejectedCameraChangesNothing) {
  Perception p = defaultPerception();
  Camera bad;
  bad.width = 640;
  bad.fov_y_deg = -1.0;
  EXPECT_THROW(p.setCamera(bad), InputError);
  EXPECT_EQ(p.camera().width, 1280);
  EXPECT_NEAR(p.project(Vec3(0, 0, 1))->x(), 640.0, 1e-9);
}

TEST(Perception, FixationMustBeFiniteAndOnScreen) {
  Perception p = defaultPerception();
  EXPECT_FALSE(p.hasFixation());
  p.setFixation(Vec2(0, 0));
  p.setFixation(Vec2(1280, 720));  // the image edges are on screen
  p.setFixation(Vec2(100, 200));
  EXPECT_EQ(thrownField([&] { p.setFixation(Vec2(kNaN, 3)); }), "fixation");
  EXPECT_EQ(thrownField([&] { p.setFixation(Vec2(3, std::numeric_limits<double>::infinity())); }),
            "fixation");
  EXPECT_EQ(thrownField([&] { p.setFixation(Vec2(-0.5, 10)); }), "fixation");
  EXPECT_EQ(thrownField([&] { p.setFixation(Vec2(10, 720.5)); }), "fixation");
  EXPECT_EQ(thrownField([&] { p.setFixation(Vec2(1281, 10)); }), "fixation");
  ASSERT_TRUE(p.hasFixation());  // a rejected fixation keeps the previous one
  EXPECT_EQ(*p.fixation(), Vec2(100, 200));
  p.clearFixation();
  EXPECT_FALSE(p.hasFixation());
}

TEST(Perception, SmallerImageKeepsTheFixationOnIt) {
  Perception p = defaultPerception();
  p.setFixation(Vec2(1200, 700));
  Camera small;
  small.width = 640;
  small.height = 480;
  p.setCamera(small);
  ASSERT_TRUE(p.hasFixation());
  EXPECT_EQ(*p.fixation(), Vec2(640, 480));
}

TEST(Perception, PerceivedInaccuracyIsThePapersFunction) {
  EXPECT_DOUBLE_EQ(perceivedInaccuracy(0.0, 12.0), 12.0);
  EXPECT_NEAR(perceivedInaccuracy(100.0, 12.0), 12.0 / std::exp(1.0), 1e-12);
  EXPECT_NEAR(perceivedInaccuracy(320.0, 30.0), 30.0 * std::exp(-3.2), 1e-12);
  EXPECT_DOUBLE_EQ(perceivedInaccuracy(50.0, 0.0), 0.0);
}

// Two overlapping sphere-preset bodies (one-level trees), stepped once so the
// last intersecting spheres are the roots, centred at the body origins.
class MeasurePair : public ::testing::Test {
 protected:
  void SetUp() override {
    const VoxelShape shape = presetShape("sphere", 8, 0.05);  // 0.4 m across
    const Vec3 origin = computeMassProperties(shape, 1.0).centre_of_mass;
    tree_ = SphereTree::build(shape, origin);
    ASSERT_EQ(tree_.levelCount(), 1);
  }

  // Places the pair with centres at `centre` +- half of `offset`, steps it once.
  void place(const Vec3& centre, const Vec3& offset) {
    pose_a_.position = centre - 0.5 * offset;
    pose_b_.position = centre + 0.5 * offset;
    test_.reset(PairBody{0, &tree_, &pose_a_}, PairBody{1, &tree_, &pose_b_});
    test_.step();
    ASSERT_EQ(test_.status(), PairStatus::Colliding);
  }

  SphereTree tree_;
  Pose pose_a_, pose_b_;
  PairTest test_;
};

TEST_F(MeasurePair, EccentricityGapAndPriorityOnScreen) {
  Perception p = defaultPerception();
  const double depth = 10.0;
  place(Vec3(0, 0, depth), Vec3(0.3, 0, 0));
  const double gap_px = 0.3 * p.focalPx() / depth;

  p.setFixation(Vec2(640, 360));
  PairPerception m = p.measure(test_);
  EXPECT_TRUE(m.visible);
  EXPECT_NEAR(m.eccentricity_px, 0.0, 1e-9);
  EXPECT_NEAR(m.gap_estimate_px, gap_px, 1e-9);
  EXPECT_NEAR(m.gap_bound_px, test_.gapBound() * p.focalPx() / depth, 1e-9);
  EXPECT_NEAR(m.priority, gap_px, 1e-9);

  p.setFixation(Vec2(640, 460));  // 100 px below the centre of collision
  m = p.measure(test_);
  EXPECT_NEAR(m.eccentricity_px, 100.0, 1e-9);
  EXPECT_NEAR(m.priority, gap_px / std::exp(1.0), 1e-9);

  // The gap is measured on screen: along the view direction it projects to (almost) nothing.
  place(Vec3(0, 0, depth), Vec3(0, 0, 0.3));
  m = p.measure(test_);
  EXPECT_LT(m.gap_estimate_px, 0.01 * gap_px);
  EXPECT_GT(m.gap_bound_px, 0.0);
}

TEST_F(MeasurePair, GazeWeightAndProjectedGapAgreeWithMeasure) {
  Perception p = defaultPerception();
  p.setFixation(Vec2(500, 300));
  place(Vec3(0.4, -0.2, 6.0), Vec3(0.25, 0.1, 0.05));
  const PairPerception m = p.measure(test_);
  const Perception::GazeWeight gw = p.gazeWeight(test_.centreOfCollision());
  EXPECT_NEAR(gw.weight, std::exp(-m.eccentricity_px / 100.0), 1e-12);
  EXPECT_NEAR(gw.px_per_metre, m.px_per_metre, 1e-9);
  EXPECT_NEAR(p.projectedGap(test_, gw.px_per_metre), m.gap_estimate_px, 1e-9);
  EXPECT_NEAR(gw.weight * m.gap_estimate_px, m.priority, 1e-9);
  const Perception::GazeWeight behind = p.gazeWeight(Vec3(0, 0, -1));
  EXPECT_EQ(behind.weight, 0.0);
  EXPECT_EQ(behind.px_per_metre, 0.0);
}

TEST_F(MeasurePair, BehindTheCameraIsInvisibleWithPriorityZero) {
  Perception p = defaultPerception();
  p.setFixation(Vec2(640, 360));
  place(Vec3(0, 0, -5), Vec3(0.3, 0, 0));
  const PairPerception m = p.measure(test_);
  EXPECT_FALSE(m.visible);
  EXPECT_TRUE(std::isinf(m.eccentricity_px));
  EXPECT_EQ(m.priority, 0.0);
  EXPECT_EQ(m.gap_estimate_px, 0.0);
}

TEST_F(MeasurePair, OffScreenIsInvisibleButKeepsADecayingPriority) {
  Perception p = defaultPerception();
  p.setFixation(Vec2(1280, 360));  // right edge of the image
  const double depth = 10.0;
  const double metres_per_px = depth / p.focalPx();

  // Just inside and just outside the right border: continuous priority.
  place(Vec3(639.0 * metres_per_px, 0, depth), Vec3(0.3, 0, 0));
  const PairPerception inside = p.measure(test_);
  place(Vec3(641.0 * metres_per_px, 0, depth), Vec3(0.3, 0, 0));
  const PairPerception outside = p.measure(test_);
  EXPECT_TRUE(inside.visible);
  EXPECT_FALSE(outside.visible);
  EXPECT_NEAR(outside.eccentricity_px, 1.0, 1e-6);
  EXPECT_GT(outside.priority, 0.9 * inside.priority);

  // 300 px past the border: e is measured to the off-screen pixel, f decays as exp(-e/100).
  place(Vec3(940.0 * metres_per_px, 0, depth), Vec3(0.3, 0, 0));
  const PairPerception far = p.measure(test_);
  EXPECT_FALSE(far.visible);
  EXPECT_NEAR(far.eccentricity_px, 300.0, 1e-6);
  EXPECT_NEAR(far.priority, far.gap_estimate_px * std::exp(-3.0), 1e-9);
  EXPECT_LT(far.priority, 0.06 * inside.priority);
}

TEST_F(MeasurePair, WithoutFixationPriorityIsZero) {
  Perception p = defaultPerception();
  place(Vec3(0, 0, 10), Vec3(0.3, 0, 0));
  const PairPerception m = p.measure(test_);
  EXPECT_EQ(m.priority, 0.0);
  EXPECT_FALSE(m.visible);
}

// A camera off the axes, tilted and rolled, so that no axis helps the round trip.
Perception tiltedPerception() {
  Perception p;
  Camera camera;
  camera.camera_to_world = opticalLookAt(Vec3(1.5, -2.0, 3.0), Vec3(-0.5, 4.0, 0.2), Vec3(0.3, 0.1, 1.0).normalized());
  camera.width = 800;
  camera.height = 600;
  camera.fov_y_deg = 45.0;
  p.setCamera(camera);
  return p;
}

TEST(PerceptionRay, ProjectThenUnprojectIsTheIdentity) {
  const Perception p = tiltedPerception();
  for (const Vec3& world : {Vec3(-0.5, 4.0, 0.2), Vec3(0.3, 2.0, 1.0), Vec3(-2.0, 6.0, -1.0), Vec3(2.5, 1.0, 2.5)}) {
    const auto pixel = p.project(world);
    ASSERT_TRUE(pixel);
    const Vec3 back = p.unproject(*pixel, *p.depthOf(world));
    EXPECT_LT((back - world).norm(), 1e-9) << world.transpose();
    // The ray through its pixel passes through the point.
    const Ray ray = p.rayThrough(*pixel);
    EXPECT_NEAR(ray.direction.norm(), 1.0, 1e-12);
    const double t = (world - ray.origin).dot(ray.direction);
    EXPECT_GT(t, 0.0);
    EXPECT_LT((ray.origin + t * ray.direction - world).norm(), 1e-9) << world.transpose();
  }
}

TEST(PerceptionRay, UnprojectThenProjectIsTheIdentityOnAndOffTheImage) {
  const Perception p = tiltedPerception();
  for (const Vec2& pixel : {Vec2(0, 0), Vec2(400, 300), Vec2(800, 600), Vec2(-250, 900), Vec2(123.5, 77.25)}) {
    for (double depth : {0.01, 1.0, 37.0}) {
      const auto back = p.project(p.unproject(pixel, depth));
      ASSERT_TRUE(back);
      EXPECT_LT((*back - pixel).norm(), 1e-7) << pixel.transpose() << " at " << depth;
      EXPECT_NEAR(*p.depthOf(p.unproject(pixel, depth)), depth, 1e-9);
    }
  }
  // The image centre looks along the optical axis.
  const Ray centre = p.rayThrough(Vec2(400, 300));
  EXPECT_LT((centre.direction - p.camera().camera_to_world.orientation * Vec3::UnitZ()).norm(), 1e-12);
}

// 1 m cubes (bounding radius r): three along +x, one beside them, one behind the origin.
class CastRay : public ::testing::Test {
 protected:
  void SetUp() override {
    const ShapeId cube = world_.addShape("cube", presetShape("cube", 4, 0.25));
    radius_ = world_.shape(cube).bounding_radius;
    for (const Vec3& at : {Vec3(8, 0, 0), Vec3(4, 0, 0), Vec3(12, 0, 0), Vec3(4, 3, 0), Vec3(-3, 0, 0)}) {
      EntitySpec spec;
      spec.shape = cube;
      spec.pose.position = at;
      world_.addEntity(spec);
    }
  }
  World world_;
  double radius_ = 0.0;
};

TEST_F(CastRay, HitsTheNearestBodyInFrontOfTheOrigin) {
  ASSERT_GT(radius_, 0.5);
  Ray ray;
  ray.direction = Vec3::UnitX();
  const auto hit = castRay(world_, ray);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->body, 1u);  // the body at x = 4, not the one at x = -3 behind the origin
  EXPECT_NEAR(hit->distance, 4.0 - radius_, 1e-12);

  ray.direction = -Vec3::UnitX();
  ASSERT_TRUE(castRay(world_, ray));
  EXPECT_EQ(castRay(world_, ray)->body, 4u);

  ray.direction = Vec3(0, 0, 1);  // nothing above
  EXPECT_FALSE(castRay(world_, ray));

  ray.origin = Vec3(4, 0, 0);  // from inside a ball: where the ray leaves it
  ray.direction = Vec3::UnitY();
  ASSERT_TRUE(castRay(world_, ray));
  EXPECT_EQ(castRay(world_, ray)->body, 1u);
  EXPECT_NEAR(castRay(world_, ray)->distance, radius_, 1e-12);
}

TEST_F(CastRay, GazeTargetIsWhereTheFixationRayFirstMeetsTheScene) {
  Camera camera;
  camera.camera_to_world = opticalLookAt(Vec3(0, 0, 0), Vec3(1, 0, 0));
  world_.perception().setCamera(camera);
  EXPECT_FALSE(gazeTarget(world_));  // no fixation
  world_.perception().setFixation(Vec2(640, 360));  // the image centre: along +x
  const auto target = gazeTarget(world_);
  ASSERT_TRUE(target);
  EXPECT_LT((*target - Vec3(4.0 - radius_, 0, 0)).norm(), 1e-9);

  // Looking down from above at empty ground: the ground plane z = 0.
  camera.camera_to_world = opticalLookAt(Vec3(20, 20, 2), Vec3(22, 20, 0));
  world_.perception().setCamera(camera);
  const auto ground = gazeTarget(world_);
  ASSERT_TRUE(ground);
  EXPECT_LT((*ground - Vec3(22, 20, 0)).norm(), 1e-9);

  // Looking up at the empty sky: a point kGazeFallbackDistance out.
  camera.camera_to_world = opticalLookAt(Vec3(20, 20, 2), Vec3(20, 20, 9));
  world_.perception().setCamera(camera);
  const auto sky = gazeTarget(world_);
  ASSERT_TRUE(sky);
  EXPECT_LT((*sky - Vec3(20, 20, 2 + kGazeFallbackDistance)).norm(), 1e-9);
}

}  // namespace
}  // namespace stc
