// Contacts carried over between ticks (PairContactCache,
// ResponseOptions::reuse_tolerance): when an entry is found, where its
// contacts are placed again, and what a World does with it.
#include "contact_builder.hpp"
#include "dynamics.hpp"
#include "pair_contact_cache.hpp"
#include "pair_test.hpp"
#include "physics.hpp"
#include "solid_cube.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

using namespace stc;

namespace {

constexpr double kDt = 1.0 / 60.0;

// Two 40 cm cubes of 10 cm voxels; B beside A along +x, overlapping it by
// 1 cm, tested to the leaves; its contacts built and recorded in a cache.
struct CachedCubes : stc_test::SolidCube {
  Pose pose_a, pose_b;
  std::vector<Contact> built;
  PairContactCache cache;
  double tolerance = 0.0;

  CachedCubes() {
    pose_b.position = Vec3(0.39, 0.0, 0.0);
    built = build(pose_b);
    tolerance = 0.05 * bounds.min_leaf_radius;
    PairTest test = tested(pose_b);
    PairContactCache::Pending pending;
    PairContactCache::record(test, body(0, pose_a), body(1, pose_b), tolerance, built.data(),
                             built.data() + built.size(), pending);
    const PairContactCache::Pending* all[] = {&pending};
    cache.commit(all, 1);
  }
  PairTest tested(const Pose& b) const {
    PairTest test;
    test.reset(PairBody{0, &tree, &pose_a}, PairBody{1, &tree, &b});
    while (!test.resolved()) test.step();
    return test;
  }
  // The contacts ContactBuilder makes with B at `b`.
  std::vector<Contact> build(const Pose& b) const {
    const PairTest test = tested(b);
    std::vector<Contact> out;
    ContactBuilder builder;
    builder.append(test, 0, 1, 0.0, &bounds, &bounds, ContactBuildOptions{}, out);
    return out;
  }
  ReuseBody body(EntityId id, const Pose& pose, const Vec3& v = Vec3::Zero(), const Vec3& w = Vec3::Zero()) const {
    return ReuseBody{id, &pose, v, w, bounds.bound_radius};
  }
  std::uint32_t find(const Pose& b, const Vec3& vb = Vec3::Zero(), const Vec3& wb = Vec3::Zero()) const {
    return cache.find(body(0, pose_a), body(1, b, vb, wb), kDt);
  }
  std::vector<Contact> place(std::uint32_t entry, const Pose& b) const {
    Contact base;
    base.a = 0;
    base.b = 1;
    base.index_b = 1;
    std::vector<Contact> out;
    cache.place(entry, base, pose_a, b, out);
    return out;
  }
};

Pose shifted(const Pose& p, const Vec3& by) {
  Pose out = p;
  out.position += by;
  return out;
}

}  // namespace

TEST(PairContactCache, PlacedAtTheSamePosesTheContactsAreTheBuiltOnes) {
  CachedCubes cubes;
  ASSERT_FALSE(cubes.built.empty());
  ASSERT_EQ(cubes.cache.size(), 1u);
  const std::uint32_t entry = cubes.find(cubes.pose_b);
  ASSERT_NE(entry, PairContactCache::kNone);
  const std::vector<Contact> placed = cubes.place(entry, cubes.pose_b);
  ASSERT_EQ(placed.size(), cubes.built.size());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    EXPECT_LT((placed[i].point - cubes.built[i].point).norm(), 1e-12);
    EXPECT_LT((placed[i].normal - cubes.built[i].normal).norm(), 1e-12);
    EXPECT_NEAR(placed[i].separation, cubes.built[i].separation, 1e-12);
    EXPECT_NEAR(placed[i].depth, cubes.built[i].depth, 1e-12);
    EXPECT_EQ(placed[i].node_a, cubes.built[i].node_a);  // the feature ids the warm start matches
    EXPECT_EQ(placed[i].node_b, cubes.built[i].node_b);
    EXPECT_TRUE(placed[i].resolved);
  }
}

TEST(PairContactCache, PlacedAfterADriftTheContactsMoveWithTheBodies) {
  CachedCubes cubes;
  // B pressed 0.6 tolerance further into A and slid 0.3 along the face: the
  // face contacts' separations drop by exactly that much, as a fresh build's.
  const Vec3 drift(-0.6 * cubes.tolerance, 0.3 * cubes.tolerance, 0.0);
  const Pose moved = shifted(cubes.pose_b, drift);
  const std::uint32_t entry = cubes.find(moved);
  ASSERT_NE(entry, PairContactCache::kNone);
  const std::vector<Contact> placed = cubes.place(entry, moved);
  const std::vector<Contact> fresh = cubes.build(moved);
  ASSERT_EQ(placed.size(), cubes.built.size());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    EXPECT_NEAR(placed[i].normal.x(), 1.0, 1e-12);  // A's face normal
    EXPECT_NEAR(placed[i].separation, cubes.built[i].separation + drift.x(), 1e-12);
    EXPECT_NEAR(placed[i].separation, fresh[0].separation, 1e-9);
    // The point stays halfway between the surface points, which moved with their bodies.
    EXPECT_LT((placed[i].point - (cubes.built[i].point + 0.5 * drift)).norm(), 1e-12);
  }
}

TEST(PairContactCache, DriftTurnOrSpeedBeyondTheToleranceRebuild) {
  CachedCubes cubes;
  const double tol = cubes.tolerance;
  EXPECT_NE(cubes.find(shifted(cubes.pose_b, Vec3(0.0, 0.0, 0.9 * tol))), PairContactCache::kNone);
  EXPECT_EQ(cubes.find(shifted(cubes.pose_b, Vec3(0.0, 0.0, 1.1 * tol))), PairContactCache::kNone);
  // A turn moves B's far corners by the chord at its bound radius.
  const double r = cubes.bounds.bound_radius;
  for (const double share : {0.9, 1.1}) {
    Pose turned = cubes.pose_b;
    turned.orientation = Quat(Eigen::AngleAxisd(2.0 * std::asin(share * tol / (2.0 * r)), Vec3::UnitZ()));
    EXPECT_EQ(cubes.find(turned) != PairContactCache::kNone, share < 1.0) << share;
  }
  // Moving now at a speed that would take it past the tolerance within
  // kMotionTicks ticks: built anew, though it has not drifted yet.
  const double too_fast = 1.1 * tol / (PairContactCache::kMotionTicks * kDt);
  EXPECT_NE(cubes.find(cubes.pose_b, Vec3(0.0, 0.9 * too_fast / 1.1, 0.0)), PairContactCache::kNone);
  EXPECT_EQ(cubes.find(cubes.pose_b, Vec3(0.0, too_fast, 0.0)), PairContactCache::kNone);
  EXPECT_EQ(cubes.find(cubes.pose_b, Vec3::Zero(), Vec3(0.0, 0.0, too_fast / r)), PairContactCache::kNone);
  // Both at that speed together: no relative motion.
  const Vec3 v(0.0, too_fast, 0.0);
  EXPECT_NE(cubes.cache.find(cubes.body(0, cubes.pose_a, v), cubes.body(1, cubes.pose_b, v), kDt),
            PairContactCache::kNone);
}

TEST(PairContactCache, OnlyTheSamePairInTheSameOrderAndNeverANaNPose) {
  CachedCubes cubes;
  EXPECT_EQ(cubes.cache.find(cubes.body(1, cubes.pose_b), cubes.body(0, cubes.pose_a), kDt), PairContactCache::kNone);
  EXPECT_EQ(cubes.cache.find(cubes.body(0, cubes.pose_a), cubes.body(2, cubes.pose_b), kDt), PairContactCache::kNone);
  Pose nan = cubes.pose_b;
  nan.position.x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(cubes.find(nan), PairContactCache::kNone);
  cubes.cache.clear();
  EXPECT_EQ(cubes.find(cubes.pose_b), PairContactCache::kNone);
}

TEST(PairContactCache, ACarriedEntryKeepsTheReferenceItWasBuiltAt) {
  CachedCubes cubes;
  // 0.6 tolerance a tick, twice: the second is 1.2 from where the contacts
  // were built, though only 0.6 from the tick before.
  const Vec3 step(0.0, 0.6 * cubes.tolerance, 0.0);
  const Pose once = shifted(cubes.pose_b, step);
  const std::uint32_t entry = cubes.find(once);
  ASSERT_NE(entry, PairContactCache::kNone);
  PairContactCache::Pending pending;
  cubes.cache.carry(entry, pending);
  const PairContactCache::Pending* all[] = {&pending};
  cubes.cache.commit(all, 1);
  ASSERT_NE(cubes.find(once), PairContactCache::kNone);
  EXPECT_EQ(cubes.find(shifted(once, step)), PairContactCache::kNone);
  // The carried points are the built ones.
  const std::vector<Contact> placed = cubes.place(cubes.find(cubes.pose_b), cubes.pose_b);
  ASSERT_EQ(placed.size(), cubes.built.size());
  for (std::size_t i = 0; i < placed.size(); ++i) EXPECT_LT((placed[i].point - cubes.built[i].point).norm(), 1e-12);
}

// Each placed contact is measured again from its anchors at this tick's
// poses: pressed, slid and spun within the tolerance, its separation is the
// one a fresh build finds, where the separation it was built with is off by
// the press.
TEST(PairContactCache, AReusedContactsSeparationFollowsTheBodies) {
  CachedCubes cubes;
  const double tol = cubes.tolerance;
  Pose moved = shifted(cubes.pose_b, Vec3(-0.5 * tol, 0.2 * tol, -0.1 * tol));
  // A spin about the face normal whose chord at B's bound radius is 0.2 tol.
  moved.orientation = Quat(Eigen::AngleAxisd(0.2 * tol / cubes.bounds.bound_radius, Vec3::UnitX()));
  const std::uint32_t entry = cubes.find(moved);
  ASSERT_NE(entry, PairContactCache::kNone);
  const std::vector<Contact> placed = cubes.place(entry, moved);
  const std::vector<Contact> fresh = cubes.build(moved);
  ASSERT_EQ(placed.size(), fresh.size());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    const Contact* nearest = &fresh[0];  // the fresh point where this one is
    for (const Contact& f : fresh) {
      if ((f.point - placed[i].point).norm() < (nearest->point - placed[i].point).norm()) nearest = &f;
    }
    EXPECT_LT((nearest->point - placed[i].point).norm(), 0.5 * tol);
    EXPECT_NEAR(placed[i].separation, nearest->separation, 1e-9 * tol) << i;
    EXPECT_GT(placed[i].normal.dot(nearest->normal), 1.0 - 1e-12);
    // The separation it was built with (a contact carried as it was) misses by the press.
    EXPECT_GT(std::abs(cubes.built[i].separation - nearest->separation), 0.45 * tol);
  }
}

// A corner of A pressed 5 mm into the middle of a voxel of B's -x face (A
// turned to point its corner along +x): the normal is B's face's, +x. B then
// turned a little about z, about its centre: the placed normal turns with B
// and the separation is the corner's depth below B's face now, as a fresh
// build finds them (the separation to first order: the anchor on A is the
// contact point's, a little off the corner). A normal kept in A's frame would still be +x.
TEST(PairContactCache, AReusedNormalTurnsWithTheBodyWhoseFaceItIs) {
  stc_test::SolidCube cube;
  Pose pose_a;
  pose_a.orientation = Quat::FromTwoVectors(Vec3(1.0, 1.0, 1.0).normalized(), Vec3::UnitX());
  const double corner = 0.2 * std::sqrt(3.0);  // A's corner on the x axis
  const auto poseB = [&](double turn) {
    Pose b;
    b.orientation = Quat(Eigen::AngleAxisd(turn, Vec3::UnitZ()));
    b.position = Vec3(corner - 0.005 + 0.2, 0.05, 0.05);
    return b;
  };
  const auto build = [&](const Pose& b, PairTest& test) {
    test.reset(PairBody{0, &cube.tree, &pose_a}, PairBody{1, &cube.tree, &b});
    while (!test.resolved()) test.step();
    std::vector<Contact> out;
    ContactBuilder builder;
    builder.append(test, 0, 1, 0.0, &cube.bounds, &cube.bounds, ContactBuildOptions{}, out);
    return out;
  };
  const Pose built_at = poseB(0.0);
  PairTest test;
  const std::vector<Contact> built = build(built_at, test);
  ASSERT_FALSE(built.empty());
  for (const Contact& c : built) {
    ASSERT_GT(c.normal.x(), 1.0 - 1e-12) << "B's face normal";
    ASSERT_NEAR(c.separation, -0.005, 1e-12);
  }
  const ReuseBody a{0, &pose_a, Vec3::Zero(), Vec3::Zero(), cube.bounds.bound_radius};
  const ReuseBody b{1, &built_at, Vec3::Zero(), Vec3::Zero(), cube.bounds.bound_radius};
  const double tol = 0.05 * cube.bounds.min_leaf_radius;
  PairContactCache cache;
  PairContactCache::Pending pending;
  PairContactCache::record(test, a, b, tol, built.data(), built.data() + built.size(), pending);
  const PairContactCache::Pending* all[] = {&pending};
  cache.commit(all, 1);

  const double turn = 0.8 * tol / cube.bounds.bound_radius;
  const Pose turned = poseB(turn);
  const ReuseBody b_now{1, &turned, Vec3::Zero(), Vec3::Zero(), cube.bounds.bound_radius};
  const std::uint32_t entry = cache.find(a, b_now, kDt);
  ASSERT_NE(entry, PairContactCache::kNone);
  Contact base;
  base.a = 0;
  base.b = 1;
  std::vector<Contact> placed;
  cache.place(entry, base, pose_a, turned, placed);
  PairTest fresh_test;
  const std::vector<Contact> fresh = build(turned, fresh_test);
  ASSERT_EQ(placed.size(), fresh.size());
  const Vec3 turned_normal = turned.orientation * Vec3::UnitX();
  ASSERT_LT(turned_normal.x(), std::cos(0.9 * turn));  // off the built normal by the turn
  for (std::size_t i = 0; i < placed.size(); ++i) {
    ASSERT_GT(fresh[i].normal.dot(turned_normal), 1.0 - 1e-12);
    EXPECT_GT(placed[i].normal.dot(turned_normal), 1.0 - 1e-12) << i;
    // To first order in the turn: within the turn squared times B's bound radius.
    EXPECT_NEAR(placed[i].separation, fresh[i].separation, turn * turn * cube.bounds.bound_radius) << i;
    // The separation moved with the turn (B's face at the corner moved by
    // 5 cm x the turn), which the one it was built with misses.
    EXPECT_GT(std::abs(fresh[i].separation - built[i].separation), 0.03 * turn);
  }
}

TEST(PairContactCache, AResumedTestIsCollidingAtItsLeafPairWithNoSphereTested) {
  CachedCubes cubes;
  const PairTest tested = cubes.tested(cubes.pose_b);
  const PairContactCache::Entry& e = cubes.cache.entry(cubes.find(cubes.pose_b));
  EXPECT_EQ(e.leaf.a, tested.lastPair().a);
  EXPECT_EQ(e.leaf.b, tested.lastPair().b);
  PairTest resumed;
  resumed.resumeColliding(PairBody{0, &cubes.tree, &cubes.pose_a}, PairBody{1, &cubes.tree, &cubes.pose_b}, nullptr,
                          e.leaf, e.level);
  EXPECT_EQ(resumed.status(), PairStatus::Colliding);
  EXPECT_EQ(resumed.sphereTests(), 0);
  EXPECT_EQ(resumed.nextStepTests(), 0);
  EXPECT_EQ(resumed.step(), 0);
  EXPECT_EQ(resumed.deepestLevel(), tested.deepestLevel());
  // What perception and the reports read of it: the leaf pair's.
  EXPECT_LT((resumed.centreOfCollision() - tested.centreOfCollision()).norm(), 1e-12);
  EXPECT_NEAR(resumed.gapBound(), tested.gapBound(), 1e-12);
}

// ---------------------------------------------------------------------------------
// Through the World

namespace {

// A 40 cm cube (8 voxels of 5 cm) dropped 1 cm onto a static plate, g = 9.81.
World cubeOnPlate(double reuse_tolerance, int threads = 1) {
  WorldConfig config;
  config.gravity = Vec3(0.0, 0.0, -9.81);
  config.response.reuse_tolerance = reuse_tolerance;
  config.sleeping.enabled = false;  // its pair stays in the tick
  config.threads = threads;
  World w(config);
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 0.05;
  const ShapeId cube = w.addShape("cube", makePreset("cube", p));
  p.resolution = 16;
  const ShapeId plate = w.addShape("plate", makePreset("cube", p));
  EntitySpec floor;
  floor.shape = plate;
  floor.is_static = true;
  floor.pose.position = Vec3(0.0, 0.0, -0.4);  // top face at z = 0
  w.addEntity(floor);
  EntitySpec box;
  box.shape = cube;
  box.pose.position = Vec3(0.0, 0.0, 0.21);
  w.addEntity(box);
  return w;
}

}  // namespace

TEST(PairContactCache, ARestingCubeReusesItsContactsAndRestsWhereItWouldHave) {
  World reusing = cubeOnPlate(0.05);
  World building = cubeOnPlate(0.0);
  std::size_t reused = 0, built_reused = 0;
  std::int64_t reused_tests = 0, built_tests = 0;
  for (int t = 0; t < 180; ++t) {
    const TickReport r = reusing.step(kDt, Budget::unlimited());
    const TickReport b = building.step(kDt, Budget::unlimited());
    ASSERT_EQ(r.detection.colliding + r.detection.separate + r.detection.unresolved, reusing.pairCount());
    if (t < 120) continue;
    reused += r.detection.reused;
    built_reused += b.detection.reused;
    reused_tests += r.detection.sphere_tests;
    built_tests += b.detection.sphere_tests;
    if (r.detection.reused > 0) {
      // The solver matched every carried point to last tick's impulse.
      EXPECT_EQ(physicsReport(reusing).solve.warm_started, physicsReport(reusing).solve.contacts);
    }
  }
  EXPECT_GT(reused, 50u);  // of 60 resting ticks
  EXPECT_EQ(built_reused, 0u);
  EXPECT_LT(reused_tests, built_tests / 5);
  const BodyState& a = reusing.bodies()[1];
  const BodyState& b = building.bodies()[1];
  // At rest, where the cube that rebuilt its contacts every tick rests (to a
  // tenth of a millimetre, within the 2 mm tolerance), not turned.
  EXPECT_LT(a.linear_velocity.norm(), 1e-3);
  EXPECT_LT(a.angular_velocity.norm(), 1e-2);
  EXPECT_LT((a.pose.position - b.pose.position).norm(), 1e-4);
  EXPECT_LT(a.pose.orientation.angularDistance(b.pose.orientation), 1e-3);
}

// Under a limited narrow phase a pair reached at its leaves in one tick and
// at its roots in the next keeps its leaf contacts (points, normals,
// separations), placed anew, while its bodies stay put
// (Physics::kFrontierTolerance; without contact reuse); moved away, it takes
// its roots' again. A kept contact reports this tick's level, gap bound and
// the pair as unresolved, so the levels still show where the narrow phase
// went and the bounds add up to the tick's (proof_live). A pile whose budget varies from tick to
// tick flowed on frontier contacts that changed with it
// (docs/error_vs_runtime.md).
TEST(SteadyFrontier, AnUnresolvedPairKeepsItsDeepestContactsWhileItStaysPut) {
  World w = cubeOnPlate(0.0);
  for (int t = 0; t < 120; ++t) w.step(kDt, Budget::unlimited());  // at rest on the plate
  const TickReport leaves = w.step(kDt, Budget::ofSphereTests(std::int64_t{1} << 40));  // limited, never reached
  ASSERT_EQ(leaves.detection.unresolved, 0u);
  EXPECT_EQ(leaves.response.frontier_kept, 0u);
  const std::vector<Contact> resolved = w.contacts();
  ASSERT_FALSE(resolved.empty());
  ASSERT_GT(resolved.front().level, 0);

  const TickReport roots = w.step(kDt, Budget::ofSphereTests(0));
  ASSERT_EQ(roots.detection.unresolved, 1u);
  EXPECT_EQ(roots.response.frontier_kept, 1u);
  ASSERT_EQ(w.contacts().size(), resolved.size());
  for (std::size_t k = 0; k < resolved.size(); ++k) {
    const Contact& c = w.contacts()[k];
    EXPECT_EQ(c.node_a, resolved[k].node_a) << "the leaves' points, not the roots'";
    EXPECT_EQ(c.node_b, resolved[k].node_b);
    EXPECT_LT((c.point - resolved[k].point).norm(), 1e-3);
    EXPECT_GT(c.normal.dot(resolved[k].normal), 0.9999);
    EXPECT_EQ(c.level, 0);
    EXPECT_FALSE(c.resolved);
    EXPECT_NEAR(c.separation, resolved[k].separation, 1e-3);
    // Its gap bound is this tick's roots', the one the report sums (the
    // error_bounds markers draw it); the solver's scale stays the leaves'.
    EXPECT_EQ(c.gap_bound, roots.accuracy.geometric_bound);
    EXPECT_EQ(c.sphere_bound, resolved[k].gap_bound);
    EXPECT_GT(c.gap_bound, c.sphere_bound);
  }
  const Vec3 rest = w.bodies()[1].pose.position;

  // Moved by more than the tolerance, the pair is taken at its roots.
  w.bodies()[1].pose.position += Vec3(0.05, 0.0, 0.0);
  EXPECT_EQ(w.step(kDt, Budget::ofSphereTests(0)).response.frontier_kept, 0u);
  ASSERT_FALSE(w.contacts().empty());
  for (const Contact& c : w.contacts()) {
    EXPECT_EQ(c.node_a, 0) << "the roots' contact";
    EXPECT_EQ(c.node_b, 0);
  }
  // Back where it rested it does not find the leaves' contacts again: the
  // tick at the moved pose replaced them with its roots'.
  w.bodies()[1].pose.position = rest;
  w.step(kDt, Budget::ofSphereTests(0));
  for (const Contact& c : w.contacts()) EXPECT_EQ(c.node_a, 0);
}

TEST(PairContactCache, AMovedBodyNewOptionsOrANewStaticBodyRebuild) {
  World w = cubeOnPlate(0.05);
  for (int t = 0; t < 150; ++t) w.step(kDt, Budget::unlimited());
  ASSERT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 1u);
  w.bodies()[1].pose.position.x() += 0.01;  // an edit: 1 cm aside
  EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 0u);
  ASSERT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 1u);
  w.setResponse(w.config().response);
  EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 0u);
  ASSERT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 1u);
  EntitySpec far;  // a static body far away: covered faces may change anywhere
  far.shape = w.bodyShapes()[1];
  far.is_static = true;
  far.pose.position = Vec3(10.0, 0.0, 0.0);
  const EntityId far_id = w.addEntity(far);
  EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 0u);
  ASSERT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 1u);
  w.bodies()[*w.indexOf(far_id)].pose.position.y() += 1.0;  // a static body moved: the same
  EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 0u);
  EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 1u);
  // Off: built every tick.
  ResponseOptions off = w.config().response;
  off.reuse_tolerance = 0.0;
  w.setResponse(off);
  for (int t = 0; t < 10; ++t) EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 0u);
  // Detection alone: nothing is carried, the test answers every tick.
  ResponseOptions detect = w.config().response;
  detect.reuse_tolerance = 0.05;
  detect.enabled = false;
  w.setResponse(detect);
  for (int t = 0; t < 10; ++t) EXPECT_EQ(w.step(kDt, Budget::unlimited()).detection.reused, 0u);
}

TEST(PairContactCache, ThreadCountDoesNotChangeTheResult) {
  // A cube pile settling with reuse: 1 and 2 threads, bit for bit.
  SceneParams params;
  params.entities = 64;
  std::vector<std::vector<BodyState>> finals;
  std::size_t reused = 0;
  for (const int threads : {1, 2}) {
    WorldConfig config;
    config.threads = threads;
    config.response.reuse_tolerance = 0.05;
    SceneWorld scene = makeSceneWorld(SceneKind::CubeBox, params, config);
    for (int t = 0; t < 300; ++t) reused += scene.world.step(scene.spec.dt, Budget::unlimited()).detection.reused;
    finals.push_back(scene.world.bodies());
  }
  EXPECT_GT(reused, 0u);
  ASSERT_EQ(finals[0].size(), finals[1].size());
  for (std::size_t i = 0; i < finals[0].size(); ++i) {
    EXPECT_EQ(finals[0][i].pose.position, finals[1][i].pose.position) << i;
    EXPECT_EQ(finals[0][i].pose.orientation.coeffs(), finals[1][i].pose.orientation.coeffs()) << i;
    EXPECT_EQ(finals[0][i].linear_velocity, finals[1][i].linear_velocity) << i;
  }
}

TEST(PairContactCache, ABallRollingDownASlopeIsNotHeldBack) {
  // The slope of test_physics (10 degrees, rolling resistance 0.1 < tan 10):
  // a = 5 g (sin t - c cos t) / 7. A steadily rolling ball is built anew
  // (kMotionTicks), so its contacts never lag it for long: within 10 %.
  const double slope = 10.0 * M_PI / 180.0, c = 0.1, dt = 1.0 / 120.0;
  WorldConfig config;
  config.gravity = 9.81 * Vec3(std::sin(slope), 0.0, -std::cos(slope));
  config.response.reuse_tolerance = 0.05;
  World w(config);
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 250.0;
  Material m{0.0, 0.8};
  m.rolling_resistance = c;
  EntitySpec ground;
  ground.shape = w.addShape("globe", makePreset("sphere", p));
  ground.is_static = true;
  ground.material = m;
  ground.pose.position = Vec3(0.0, 0.0, -1000.0);
  w.addEntity(ground);
  p.voxel_size = 0.05;
  EntitySpec ball;
  ball.shape = w.addShape("ball", makePreset("sphere", p));
  ball.material = m;
  ball.pose.position = Vec3(0.0, 0.0, 0.2);
  w.addEntity(ball);
  std::size_t reused = 0;
  for (int i = 0; i < 120; ++i) reused += w.step(dt, Budget::unlimited()).detection.reused;
  const double a = 5.0 * 9.81 * (std::sin(slope) - c * std::cos(slope)) / 7.0;
  EXPECT_GT(reused, 0u);  // while it starts, slowly
  EXPECT_NEAR(w.bodies()[1].pose.position.x(), 0.5 * a, 0.1 * 0.5 * a);
  EXPECT_NEAR(w.bodies()[1].linear_velocity.x(), a, 0.1 * a);
}

TEST(PairContactCache, BadTolerancesAreRejectedNamingTheField) {
  for (const double bad : {-0.01, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    ResponseOptions o;
    o.reuse_tolerance = bad;
    try {
      validateResponseOptions(o);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "response.reuse_tolerance");
    }
    World w;
    EXPECT_THROW(w.setResponse(o), InputError);
    EXPECT_EQ(w.config().response.reuse_tolerance, ResponseOptions{}.reuse_tolerance);  // unchanged
  }
}

// A pile of cubes and a rockfall settle with their contacts recycled (the
// default tolerance) as they do with every pair's contacts built every tick: at rest, piled as high. A
// pile of 64 cubes ends 0.52-0.66 m high over the seeds, either way, and any
// one seed's two runs differ by up to 9 % (which cube lands on which is
// chaotic): the cubes' height is the mean over six seeds (+1.5 % recycled).
TEST(PairContactCache, APileSettlesTheSameWithAndWithoutRecycling) {
  const double on = ResponseOptions{}.reuse_tolerance;
  ASSERT_GT(on, 0.0) << "recycling is on by default";
  for (const SceneKind kind : {SceneKind::CubeBox, SceneKind::Rockfall}) {
    const std::uint32_t seeds = kind == SceneKind::CubeBox ? 6 : 1;
    double height[2] = {0.0, 0.0};
    std::size_t reused = 0;
    for (std::uint32_t seed = 1; seed <= seeds; ++seed) {
      for (const int recycled : {0, 1}) {
        SceneParams params;
        params.entities = kind == SceneKind::CubeBox ? 64 : 100;
        params.seed = seed;
        WorldConfig config;
        config.response.reuse_tolerance = recycled ? on : 0.0;
        SceneWorld scene = makeSceneWorld(kind, params, config);
        const int ticks = static_cast<int>(std::lround(8.0 / scene.spec.dt));
        for (int t = 0; t < ticks; ++t) {
          const TickReport r = scene.world.step(scene.spec.dt, Budget::unlimited());
          if (recycled)
            reused += r.detection.reused;
          else
            ASSERT_EQ(r.detection.reused, 0u);
        }
        const double floor = scene.spec.bounds.min.z();
        for (const EntityId id : scene.spec.movers) {
          const BodyState& body = scene.world.bodies()[*scene.world.indexOf(id)];
          ASSERT_TRUE(body.pose.position.allFinite());
          EXPECT_LT(body.linear_velocity.norm(), 0.05) << toString(kind) << " seed " << seed << " recycled "
                                                       << recycled << " mover " << id;
          height[recycled] += (body.pose.position.z() - floor) / static_cast<double>(scene.spec.movers.size() * seeds);
        }
      }
    }
    EXPECT_GT(reused, 0u) << toString(kind);
    EXPECT_NEAR(height[1], height[0], (kind == SceneKind::CubeBox ? 0.03 : 0.02) * height[0]) << toString(kind);
  }
}
