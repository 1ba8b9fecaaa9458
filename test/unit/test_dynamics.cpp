// Integration, contact building, impulse solver and swept test, each on flat
// arrays of BodyState / Contact without a World.
#include "thrown_field.hpp"

#include "contact_builder.hpp"
#include "contact_solver.hpp"
#include "continuous.hpp"
#include "dynamics.hpp"
#include "pair_test.hpp"
#include "response.hpp"
#include "shape_bounds.hpp"
#include "workers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace stc {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A free body with the inertia of a solid box of side lengths `size`.
BodyState boxBody(double mass, const Vec3& size, const Vec3& position = Vec3::Zero()) {
  BodyState b;
  b.inv_mass = 1.0 / mass;
  const Vec3 s2 = size.cwiseProduct(size);
  const Vec3 inertia = mass / 12.0 * Vec3(s2.y() + s2.z(), s2.x() + s2.z(), s2.x() + s2.y());
  b.inv_inertia_body = inertia.cwiseInverse().asDiagonal();
  b.pose.position = position;
  refreshWorldInertia(b);
  return b;
}

BodyState staticBody(const Vec3& position = Vec3::Zero()) {
  BodyState b;
  b.is_static = true;
  b.pose.position = position;
  return b;
}

Contact contactBetween(std::uint32_t a, std::uint32_t b, const Vec3& point, const Vec3& normal,
                       double separation) {
  Contact c;
  c.a = a;
  c.b = b;
  c.index_a = a;
  c.index_b = b;
  c.point = point;
  c.normal = normal;
  c.separation = separation;
  c.gap_bound = 0.01;
  return c;
}

SphereTree cubeTree(int n, double voxel, Vec3* origin = nullptr) {
  const VoxelShape shape = VoxelShape::create(n, n, n, voxel, std::vector<std::uint8_t>(n * n * n, 1));
  const Vec3 centre = Vec3::Constant(0.5 * n * voxel);
  if (origin != nullptr) *origin = centre;
  return SphereTree::build(shape, centre);
}

// ---------------------------------------------------------------------------
// Integration

TEST(Dynamics, SemiImplicitEulerFallsExactlyAndStaticBodiesNeverMove) {
  std::vector<BodyState> bodies = {boxBody(2.0, Vec3::Ones()), staticBody(Vec3(1, 2, 3))};
  bodies[0].linear_velocity = Vec3(1.0, 0.0, 0.0);
  IntegrationOptions options;
  options.gravity = Vec3(0.0, 0.0, -9.81);
  const double dt = 0.01;
  for (int n = 0; n < 100; ++n) {
    integratePositions(bodies, options, dt);
    integrateVelocities(bodies, options, dt);
  }
  // Positions move with the previous velocity: z = -g dt^2 n (n - 1) / 2.
  EXPECT_NEAR(bodies[0].pose.position.x(), 1.0, 1e-12);
  EXPECT_NEAR(bodies[0].pose.position.z(), -9.81 * dt * dt * 100 * 99 / 2.0, 1e-12);
  EXPECT_NEAR(bodies[0].linear_velocity.z(), -9.81, 1e-12);
  EXPECT_EQ(bodies[1].pose.position, Vec3(1, 2, 3));
  EXPECT_EQ(bodies[1].linear_velocity, Vec3::Zero());
  // Positions lag the velocities by half a tick: the energy taken at x + v dt/2 is conserved.
  std::vector<BodyState> start = {boxBody(2.0, Vec3::Ones())};
  start[0].linear_velocity = Vec3(1.0, 0.0, 0.0);
  EXPECT_NEAR(totalEnergy(bodies, options.gravity, dt), totalEnergy(start, options.gravity, dt), 1e-9);
}

TEST(Dynamics, ZeroGravityLeavesVelocitiesAlone) {
  std::vector<BodyState> bodies = {boxBody(1.0, Vec3::Ones())};
  bodies[0].linear_velocity = Vec3(0.5, -0.25, 2.0);
  integrateVelocities(bodies, IntegrationOptions{}, 0.1);
  EXPECT_EQ(bodies[0].linear_velocity, Vec3(0.5, -0.25, 2.0));
}

TEST(Dynamics, ExponentialMapTurnsByExactlyWDtEvenForFastSpin) {
  const Vec3 w(0.0, 0.0, 100.0);
  const double dt = 1.0 / 60.0;  // 1.67 rad per tick
  Quat q = Quat::Identity();
  for (int n = 0; n < 7; ++n) q = integrateOrientation(q, w, dt);
  const Quat expected(Eigen::AngleAxisd(100.0 * 7 * dt, Vec3::UnitZ()));
  EXPECT_NEAR(q.angularDistance(expected), 0.0, 1e-12);
  EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  // World inertia follows the orientation.
  BodyState b = boxBody(1.0, Vec3(4, 1, 1));
  b.pose.orientation = Quat(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));
  refreshWorldInertia(b);
  EXPECT_NEAR(b.inv_inertia_world(1, 1), b.inv_inertia_body(0, 0), 1e-12);  // long axis now along y
}

TEST(Dynamics, FreeRotationKeepsEnergyAndAngularMomentumAndTumblesAboutTheIntermediateAxis) {
  // Box 16 x 3 x 1: x least, y intermediate, z most inertia.
  BodyState b = boxBody(1.0, Vec3(1.6, 0.3, 0.1));
  b.angular_velocity = Vec3(0.1, 100.0, 0.1);
  const double e0 = kineticEnergy(b);
  const Mat3 inertia0 = worldInertia(b);
  const Vec3 l0 = inertia0 * b.angular_velocity;
  std::vector<BodyState> bodies = {b};
  IntegrationOptions options;  // gyroscopic on, no gravity
  double min_axis = 1.0;
  for (int n = 0; n < 600; ++n) {
    integratePositions(bodies, options, 1.0 / 60.0);
    integrateVelocities(bodies, options, 1.0 / 60.0);
    const double e = kineticEnergy(bodies[0]);
    ASSERT_LE(e, e0 * (1.0 + 1e-12)) << "energy grew at tick " << n;
    const Vec3 l = worldInertia(bodies[0]) * bodies[0].angular_velocity;
    ASSERT_LE((l - l0).norm(), 1e-9 * l0.norm()) << "world angular momentum drifted at tick " << n;
    const Vec3 body_w = bodies[0].pose.orientation.conjugate() * bodies[0].angular_velocity;
    min_axis = std::min(min_axis, body_w.y() / 100.0);
  }
  EXPECT_NEAR(kineticEnergy(bodies[0]), e0, 1e-9 * e0);  // midpoint rule: conserved, not dissipated
  EXPECT_LT(min_axis, -0.5);  // the spin axis flipped (Dzhanibekov effect)

  // Isotropic bodies have no gyroscopic term: w unchanged, exact exponential map.
  BodyState cube = boxBody(1.0, Vec3::Ones());
  cube.angular_velocity = Vec3(3, -2, 7);
  const FreeRotation turned = rotateFreely(cube, 0.1);
  EXPECT_EQ(turned.angular_velocity, cube.angular_velocity);
  EXPECT_NEAR(turned.orientation.angularDistance(integrateOrientation(cube.pose.orientation, cube.angular_velocity, 0.1)), 0.0, 1e-15);
}

// ---------------------------------------------------------------------------
// Impulses

TEST(Response, HeadOnElasticContactSwapsEqualMassesAndInelasticEndsTogether) {
  for (const SolverKind kind : {SolverKind::Sequential, SolverKind::Jacobi}) {
    for (const double e : {1.0, 0.0}) {
      std::vector<BodyState> bodies = {boxBody(1.0, Vec3::Ones(), Vec3(-0.5, 0, 0)),
                                       boxBody(1.0, Vec3::Ones(), Vec3(0.5, 0, 0))};
      bodies[0].linear_velocity = Vec3(2.0, 0, 0);
      bodies[1].linear_velocity = Vec3(-1.0, 0, 0);
      for (BodyState& b : bodies) b.material = Material{e, 0.0};
      std::vector<Contact> contacts = {contactBetween(0, 1, Vec3::Zero(), Vec3::UnitX(), 0.0)};
      ResponseOptions options;
      options.solver = kind;
      solveContacts(bodies, contacts, options, 0.01);
      if (e == 1.0) {
        EXPECT_NEAR(bodies[0].linear_velocity.x(), -1.0, 1e-12) << toString(kind);
        EXPECT_NEAR(bodies[1].linear_velocity.x(), 2.0, 1e-12);
      } else {
        EXPECT_NEAR(bodies[0].linear_velocity.x(), 0.5, 1e-12) << toString(kind);
        EXPECT_NEAR(bodies[1].linear_velocity.x(), 0.5, 1e-12);
      }
      EXPECT_GT(contacts[0].normal_impulse, 0.0);
    }
  }
}

TEST(Response, FrictionIsBoundedByMuTimesTheNormalImpulse) {
  // A box sliding at 5 m/s lands on a static floor: friction takes mu * dv_n of its speed.
  std::vector<BodyState> bodies = {staticBody(), boxBody(1.0, Vec3::Ones(), Vec3(0, 0, 0.5))};
  bodies[1].linear_velocity = Vec3(5.0, 0.0, -1.0);
  for (BodyState& b : bodies) b.material = Material{0.0, 0.4};
  std::vector<Contact> contacts = {contactBetween(0, 1, Vec3::Zero(), Vec3::UnitZ(), 0.0)};
  solveContacts(bodies, contacts, ResponseOptions{}, 0.01);
  EXPECT_NEAR(contacts[0].normal_impulse, 1.0, 1e-12);  // stops the 1 m/s approach of 1 kg
  EXPECT_NEAR(contacts[0].friction_impulse.norm(), 0.4, 1e-12);  // saturated: sliding
  EXPECT_LT(contacts[0].friction_impulse.x(), 0.0);
  EXPECT_NEAR(bodies[1].linear_velocity.z(), 0.0, 1e-12);
  EXPECT_NEAR(bodies[1].linear_velocity.x(), 5.0 - 0.4, 1e-12);
  EXPECT_GT(bodies[1].angular_velocity.y(), 0.0);  // friction below the centre pitches it forward (+y)

  // Slow enough to stick: friction below its limit stops the slip.
  bodies[1].linear_velocity = Vec3(0.01, 0.0, -1.0);
  bodies[1].angular_velocity.setZero();
  solveContacts(bodies, contacts, ResponseOptions{}, 0.01);
  EXPECT_LT(contacts[0].friction_impulse.norm(), 0.4 * contacts[0].normal_impulse);
  const Vec3 slip = bodies[1].linear_velocity + bodies[1].angular_velocity.cross(Vec3(0, 0, -0.5));
  EXPECT_NEAR(slip.x(), 0.0, 1e-9);
}

TEST(Response, RollingResistanceIsACoupleBoundedByCTimesRTimesTheNormalImpulse) {
  // Two free unit cubes (1 kg, I = 1/6) stacked along z, touching at the
  // point between their centres (r = 0.5 each), closing at 1 m/s, spinning
  // relative to each other; no friction and no bounce, so only the rolling
  // resistance turns them: normal impulse 0.5 N s (the reduced mass, 0.5 kg,
  // stopped), rolling limit c r N = 0.5 * 0.5 * 0.5 = 0.125 N m s.
  for (const SolverKind kind : {SolverKind::Sequential, SolverKind::Jacobi}) {
    for (const double c : {0.0, 0.5}) {
      for (const double spin : {6.0, 0.5}) {  // the limit stops 0.125 * 12 = 1.5 rad/s of relative spin
        std::vector<BodyState> bodies = {boxBody(1.0, Vec3::Ones()), boxBody(1.0, Vec3::Ones(), Vec3(0, 0, 1))};
        bodies[1].linear_velocity = Vec3(0, 0, -1);
        const Vec3 w_rel0 = spin * Vec3(2.0, -1.0, -2.0) / 3.0;
        bodies[0].angular_velocity = Vec3(0.3, 0.2, 1.0);
        bodies[1].angular_velocity = bodies[0].angular_velocity + w_rel0;
        for (BodyState& b : bodies) b.material = Material{0.0, 0.0, 0.0, c};
        const Vec3 p0 = linearMomentum(bodies), l0 = angularMomentum(bodies);
        std::vector<Contact> contacts = {contactBetween(0, 1, Vec3(0, 0, 0.5), Vec3::UnitZ(), 0.0)};
        ResponseOptions options;
        options.solver = kind;
        solveContacts(bodies, contacts, options, 0.01);
        const std::string where = std::string(toString(kind)) + " c " + std::to_string(c) + " spin " +
                                  std::to_string(spin);
        EXPECT_NEAR(contacts[0].normal_impulse, 0.5, 1e-12) << where;
        EXPECT_NEAR((linearMomentum(bodies) - p0).norm(), 0.0, 1e-12) << where;
        EXPECT_NEAR((angularMomentum(bodies) - l0).norm(), 0.0, 1e-12) << where;  // a couple
        const Vec3 w_rel = bodies[1].angular_velocity - bodies[0].angular_velocity;
        const double stopped = c == 0.0 ? 0.0 : std::min(spin, 0.125 * 12.0);
        EXPECT_NEAR((w_rel - w_rel0 * (1.0 - stopped / spin)).norm(), 0.0, 1e-9) << where;
      }
    }
  }
}

TEST(Response, SplitImpulseRemovesPenetrationWithoutAddingVelocity) {
  std::vector<BodyState> bodies = {staticBody(), boxBody(1.0, Vec3::Ones(), Vec3(0, 0, 0.45))};
  std::vector<Contact> contacts;
  for (const double x : {-0.5, 0.5}) {
    for (const double y : {-0.5, 0.5}) {
      contacts.push_back(contactBetween(0, 1, Vec3(x, y, -0.05), Vec3::UnitZ(), -0.05));
    }
  }
  ResponseOptions options;
  options.allowed_penetration = 0.01;
  options.position_correction = 0.5;
  const double dt = 0.01;
  const SolveStats stats = solveContacts(bodies, contacts, options, dt);
  EXPECT_NEAR(stats.max_penetration, 0.05, 1e-12);
  EXPECT_EQ(bodies[1].linear_velocity, Vec3::Zero());  // pseudo-velocities are discarded
  EXPECT_EQ(kineticEnergy(bodies[1]), 0.0);
  EXPECT_NEAR(bodies[1].pose.position.z(), 0.45 + 0.5 * (0.05 - 0.01), 1e-6);
  EXPECT_NEAR(bodies[1].pose.position.x(), 0.0, 1e-9);
}

TEST(Response, SplitImpulseMovesOutOfPenetrationWithoutTurningUnlessAskedTo) {
  // One corner of a box 5 cm into the floor: the position pass lifts the
  // box by translation alone (default), never turning it, which would set a
  // resting body rocking by pseudo-velocities the velocity solve does not
  // see; with position_turns it lifts and turns it (the pass before).
  for (const bool turns : {false, true}) {
    std::vector<BodyState> bodies = {staticBody(), boxBody(1.0, Vec3::Ones(), Vec3(0, 0, 0.45))};
    std::vector<Contact> contacts = {contactBetween(0, 1, Vec3(0.5, 0.5, -0.05), Vec3::UnitZ(), -0.05)};
    ResponseOptions options;
    options.allowed_penetration = 0.01;
    options.position_correction = 0.5;
    options.position_turns = turns;
    solveContacts(bodies, contacts, options, 0.01);
    const BodyState& box = bodies[1];
    EXPECT_EQ(box.linear_velocity, Vec3::Zero()) << "turns " << turns;  // pseudo-velocities are discarded
    EXPECT_EQ(box.angular_velocity, Vec3::Zero()) << "turns " << turns;
    const double turned = box.pose.orientation.angularDistance(Quat::Identity());
    if (turns) {
      EXPECT_GT(turned, 1e-3);
      EXPECT_GT(box.pose.position.z(), 0.45);
    } else {
      EXPECT_EQ(turned, 0.0);
      EXPECT_NEAR(box.pose.position.z(), 0.45 + 0.5 * (0.05 - 0.01), 1e-9);  // half the excess, at once
      EXPECT_EQ(box.pose.position.x(), 0.0);
    }
  }
}

TEST(Response, SpeculativeGapLetsABodyCloseItButNotMore) {
  std::vector<BodyState> bodies = {staticBody(), boxBody(1.0, Vec3::Ones(), Vec3(0, 0, 0.52))};
  bodies[1].linear_velocity = Vec3(0, 0, -0.1);  // 1 mm per 10 ms tick, gap 20 mm: untouched
  std::vector<Contact> contacts = {contactBetween(0, 1, Vec3(0, 0, 0.01), Vec3::UnitZ(), 0.02)};
  const double dt = 0.01;
  solveContacts(bodies, contacts, ResponseOptions{}, dt);
  EXPECT_EQ(bodies[1].linear_velocity, Vec3(0, 0, -0.1));
  bodies[1].linear_velocity = Vec3(0, 0, -5.0);  // would pass 50 mm: stopped at the surface
  for (BodyState& b : bodies) b.material.restitution = 0.0;
  solveContacts(bodies, contacts, ResponseOptions{}, dt);
  EXPECT_NEAR(bodies[1].linear_velocity.z(), -0.02 / dt, 1e-9);
}

TEST(Response, WarmStartingFindsLastTicksImpulse) {
  std::vector<BodyState> bodies = {staticBody(), boxBody(1.0, Vec3::Ones(), Vec3(0, 0, 0.5))};
  std::vector<Contact> contacts = {contactBetween(0, 1, Vec3(0, 0, 0), Vec3::UnitZ(), 0.0)};
  ContactSolver solver;
  ResponseOptions options;
  bodies[1].linear_velocity = Vec3(0, 0, -0.1);
  SolveStats first = solver.solve(bodies, contacts, options, 0.01);
  EXPECT_EQ(first.warm_started, 0u);
  bodies[1].linear_velocity = Vec3(0, 0, -0.1);
  SolveStats second = solver.solve(bodies, contacts, options, 0.01);
  EXPECT_EQ(second.warm_started, 1u);
  EXPECT_NEAR(contacts[0].normal_impulse, 0.1, 1e-12);
  solver.forget();
  EXPECT_EQ(solver.solve(bodies, contacts, options, 0.01).warm_started, 0u);
}

TEST(Response, OptionsAndSolverNamesAreValidatedByField) {
  EXPECT_EQ(parseSolverKind("jacobi"), SolverKind::Jacobi);
  EXPECT_STREQ(toString(parseSolverKind("sequential")), "sequential");
  try {
    parseSolverKind("gauss");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "solver");
  }
  ResponseOptions o;
  validateResponseOptions(o);
  o.iterations = 0;
  try {
    validateResponseOptions(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "response.iterations");
  }
  o = ResponseOptions{};
  o.position_correction = 1.5;
  EXPECT_THROW(validateResponseOptions(o), InputError);
  o = ResponseOptions{};
  o.solver_task_manifolds = 0;
  EXPECT_EQ(thrownField([&] { validateResponseOptions(o); }), "response.solver_task_manifolds");
  EXPECT_EQ(parseSolverKind("soft"), SolverKind::Soft);
  EXPECT_STREQ(toString(SolverKind::Soft), "soft");
  o = ResponseOptions{};
  o.substeps = 0;
  EXPECT_EQ(thrownField([&] { validateResponseOptions(o); }), "response.substeps");
  o = ResponseOptions{};
  o.contact_hertz = -1.0;
  EXPECT_EQ(thrownField([&] { validateResponseOptions(o); }), "response.contact_hertz");
  o.contact_hertz = std::numeric_limits<double>::infinity();
  EXPECT_EQ(thrownField([&] { validateResponseOptions(o); }), "response.contact_hertz");
  o = ResponseOptions{};
  o.contact_damping_ratio = std::nan("");
  EXPECT_EQ(thrownField([&] { validateResponseOptions(o); }), "response.contact_damping_ratio");
  o = ResponseOptions{};
  o.max_push_speed = -1.0;
  EXPECT_EQ(thrownField([&] { validateResponseOptions(o); }), "response.max_push_speed");
  Vec3 t1, t2;
  for (const Vec3& n : {Vec3(Vec3::UnitX()), Vec3(Vec3::UnitZ()), Vec3(Vec3(1, 2, 3).normalized())}) {
    tangentBasis(n, t1, t2);
    EXPECT_NEAR(t1.dot(n), 0.0, 1e-15);
    EXPECT_NEAR(t2.dot(n), 0.0, 1e-15);
    EXPECT_NEAR(t1.norm(), 1.0, 1e-15);
    EXPECT_NEAR(t1.cross(t2).dot(n), 1.0, 1e-15);
  }
}

// ---------------------------------------------------------------------------
// Contacts from sphere pairs

struct TwoCubes {
  SphereTree tree;
  VoxelShape shape = VoxelShape::create(4, 4, 4, 0.1, std::vector<std::uint8_t>(64, 1));
  Vec3 origin;
  ShapeBounds bounds;
  Pose pose_a, pose_b;
  PairTest test;

  explicit TwoCubes(const Vec3& offset, const Quat& turn = Quat::Identity()) {
    origin = Vec3::Constant(0.2);
    tree = SphereTree::build(shape, origin);
    bounds = makeShapeBounds(tree, &shape, origin);
    pose_b.position = offset;
    pose_b.orientation = turn;
    test.reset(PairBody{0, &tree, &pose_a}, PairBody{1, &tree, &pose_b});
    while (!test.resolved()) test.step();
  }
};

TEST(Contacts, FaceOnCubesGiveSpreadContactsWithTheFaceNormalAndTheTrueOverlap) {
  TwoCubes cubes(Vec3(0.39, 0.0, 0.0));  // 40 cm cubes, 1 cm overlap along x
  ASSERT_EQ(cubes.test.status(), PairStatus::Colliding);
  ContactBuilder builder;
  std::vector<Contact> contacts;
  builder.append(cubes.test, 0, 1, 0.0, &cubes.bounds, &cubes.bounds, ContactBuildOptions{}, contacts);
  ASSERT_EQ(contacts.size(), 4u);
  for (const Contact& c : contacts) {
    EXPECT_NEAR(c.normal.x(), 1.0, 1e-12);
    EXPECT_NEAR(c.separation, -0.01, 1e-12);  // voxel boxes: exact face overlap
    EXPECT_GT(c.depth, 0.0);
    EXPECT_NEAR(c.point.x(), 0.195, 1e-9);   // halfway between the faces
    EXPECT_LE(std::abs(c.point.y()), 0.2);
    EXPECT_TRUE(c.resolved);
    EXPECT_EQ(c.a, 0u);
    EXPECT_EQ(c.b, 1u);
  }
  // Spread over the face: the four corners' quadrants.
  Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
  for (const Contact& c : contacts) {
    lo = lo.cwiseMin(c.point);
    hi = hi.cwiseMax(c.point);
  }
  EXPECT_GT(hi.y() - lo.y(), 0.2);
  EXPECT_GT(hi.z() - lo.z(), 0.2);

  // The paper's rule alone: normals along lines of centres, tilted off the face.
  ContactBuildOptions paper;
  paper.face_normals = false;
  contacts.clear();
  builder.append(cubes.test, 0, 1, 0.0, &cubes.bounds, &cubes.bounds, paper, contacts);
  ASSERT_FALSE(contacts.empty());
  for (const Contact& c : contacts) EXPECT_GT(c.normal.x(), 0.7);

  // Without bounds: sphere surfaces (the leaves' radius), a deeper overlap.
  contacts.clear();
  ContactBuildOptions one;
  one.max_contacts_per_pair = 1;
  builder.append(cubes.test, 0, 1, 0.0, nullptr, nullptr, one, contacts);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_LT(contacts[0].separation, -0.01);
}

TEST(Contacts, CoincidentCentresNeverGiveNaN) {
  TwoCubes cubes(Vec3::Zero());
  ContactBuilder builder;
  std::vector<Contact> contacts;
  builder.append(cubes.test, 0, 1, 0.0, &cubes.bounds, &cubes.bounds, ContactBuildOptions{}, contacts);
  ASSERT_FALSE(contacts.empty());
  for (const Contact& c : contacts) {
    EXPECT_TRUE(c.normal.allFinite());
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    EXPECT_TRUE(c.point.allFinite());
    EXPECT_TRUE(std::isfinite(c.separation));
    EXPECT_LT(c.separation, 0.0);
  }
  // And the solver pushes them apart with finite numbers.
  std::vector<BodyState> bodies = {boxBody(1.0, Vec3::Constant(0.4)), boxBody(1.0, Vec3::Constant(0.4))};
  solveContacts(bodies, contacts, ResponseOptions{}, 0.01);
  for (const BodyState& b : bodies) EXPECT_TRUE(isFinite(b));
  EXPECT_GT((bodies[1].pose.position - bodies[0].pose.position).norm(), 0.0);
}

TEST(Contacts, SeparateOrRejectedPairsGiveNoneAndUntestedPairsUseTheRoots) {
  ContactBuilder builder;
  std::vector<Contact> contacts;
  TwoCubes apart(Vec3(0.6, 0.0, 0.0));  // roots overlap, leaves do not
  EXPECT_EQ(apart.test.status(), PairStatus::Separate);
  builder.append(apart.test, 0, 1, 0.0, &apart.bounds, &apart.bounds, ContactBuildOptions{}, contacts);
  EXPECT_TRUE(contacts.empty());

  // Zero budget: never stepped, accepted unresolved -> one contact from the roots.
  PairTest untested;
  untested.reset(PairBody{0, &apart.tree, &apart.pose_a}, PairBody{1, &apart.tree, &apart.pose_b});
  ContactBuildOptions reject;
  reject.accept_unresolved = false;
  builder.append(untested, 0, 1, 0.0, &apart.bounds, &apart.bounds, reject, contacts);
  EXPECT_TRUE(contacts.empty());
  builder.append(untested, 0, 1, 0.0, &apart.bounds, &apart.bounds, ContactBuildOptions{}, contacts);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_FALSE(contacts[0].resolved);
  EXPECT_EQ(contacts[0].node_a, 0);
  EXPECT_NEAR(contacts[0].normal.x(), 1.0, 1e-12);
  EXPECT_NEAR(contacts[0].separation, 0.2, 1e-12);  // root boxes are the cubes: 20 cm apart
}

// ---------------------------------------------------------------------------
// Swept test

// A block of nx x ny x nz full voxels, its tree and bounds (which point into
// it: not copied or moved).
struct Block {
  VoxelShape shape;
  Vec3 origin;
  SphereTree tree;
  ShapeBounds bounds;
  Block(int nx, int ny, int nz, double voxel, const Vec3& at)
      : shape(VoxelShape::create(nx, ny, nz, voxel, std::vector<std::uint8_t>(static_cast<std::size_t>(nx * ny * nz), 1))),
        origin(at),
        tree(SphereTree::build(shape, origin)),
        bounds(makeShapeBounds(tree, &shape, origin)) {}
  Block(const Block&) = delete;
  Block& operator=(const Block&) = delete;
};

TEST(Sweep, AFastSmallBodyIsStoppedAtAThinPlateAndSlowOrSlidingOnesAreNot) {
  const double voxel = 0.05;
  const Block plate_block(16, 16, 1, voxel, Vec3(0.4, 0.4, 0.025));
  const Block ball_block(1, 1, 1, voxel, Vec3::Constant(0.025));
  const ShapeBounds& plate = plate_block.bounds;
  const ShapeBounds& ball = ball_block.bounds;

  std::vector<BodyState> bodies = {staticBody(), boxBody(1.0, Vec3::Constant(voxel))};
  std::vector<Pose> start(2);
  const std::vector<const ShapeBounds*> shapes = {&plate, &ball};
  const std::vector<std::array<std::uint32_t, 2>> pairs = {{0, 1}};  // the broad phase's pair
  SweepScratch scratch;
  const auto sweep = [&] {
    markFastBodies(bodies, start, shapes, 0.5, scratch.fast);
    return sweepFastBodies(bodies, start, shapes, pairs, pairs.size(), 0.5, scratch);
  };
  start[1].position = Vec3(0.01, 0.02, 0.5);
  bodies[1].pose.position = Vec3(0.01, 0.02, -1.0);  // straight through the plate in one tick
  SweepStats stats = sweep();
  EXPECT_EQ(stats.fast_bodies, 1u);
  EXPECT_EQ(stats.clamped, 1u);
  const double z = bodies[1].pose.position.z();
  EXPECT_GT(z, 0.025);         // centre still above the plate's top face
  EXPECT_LT(z, 0.05);          // and touching it (ball half + plate half = 1 voxel)
  ASSERT_EQ(scratch.clamped.size(), 1u);
  const SweepHit& hit = scratch.hits[1];
  EXPECT_EQ(hit.pair, 0u);
  EXPECT_NEAR(hit.normal.z(), 1.0, 1e-12);  // from the plate (pair's first body) up to the ball
  EXPECT_NEAR(hit.point.z(), 0.5 * z, 1e-12);  // between the two leaves (plate leaf at z = 0)

  // Not among its pairs: never swept against it (the broad phase culls).
  bodies[1].pose.position = Vec3(0.01, 0.02, -1.0);
  markFastBodies(bodies, start, shapes, 0.5, scratch.fast);
  stats = sweepFastBodies(bodies, start, shapes, pairs, 0, 0.5, scratch);
  EXPECT_EQ(stats.clamped, 0u);

  // Slow: moved less than half its smallest leaf radius -> not swept.
  bodies[1].pose.position = Vec3(0.01, 0.02, 0.49);
  stats = sweep();
  EXPECT_EQ(stats.fast_bodies, 0u);
  EXPECT_NEAR(bodies[1].pose.position.z(), 0.49, 1e-15);

  // Sliding fast along the plate while resting on it: nothing to stop.
  start[1].position = Vec3(-0.3, 0.02, 0.05);
  bodies[1].pose.position = Vec3(0.3, 0.02, 0.05);
  stats = sweep();
  EXPECT_EQ(stats.fast_bodies, 1u);
  EXPECT_EQ(stats.clamped, 0u);
  EXPECT_NEAR(bodies[1].pose.position.x(), 0.3, 1e-15);

  // Grazing: sliding fast and sinking a little into the plate (less than half
  // a box): the discrete step resolves that, the motion is kept.
  start[1].position = Vec3(-0.3, 0.02, 0.05);
  bodies[1].pose.position = Vec3(0.3, 0.02, 0.05 - 0.2 * voxel);
  stats = sweep();
  EXPECT_EQ(stats.clamped, 0u);
  EXPECT_NEAR(bodies[1].pose.position.x(), 0.3, 1e-15);

  // Both moving: the plate (as if movable) moves up to meet a slower ball; the
  // relative motion passes through, so the ball is held back.
  bodies[0].is_static = false;
  start[0].position = Vec3::Zero();
  bodies[0].pose.position = Vec3(0.0, 0.0, 0.5);
  start[1].position = Vec3(0.01, 0.02, 0.3);
  bodies[1].pose.position = Vec3(0.01, 0.02, 0.3 - 0.1 * voxel);
  markFastBodies(bodies, start, shapes, 0.5, scratch.fast);
  scratch.fast[0] = 0;  // only the ball is swept
  scratch.fast[1] = 1;
  stats = sweepFastBodies(bodies, start, shapes, pairs, pairs.size(), 0.5, scratch);
  EXPECT_EQ(stats.clamped, 1u);
  EXPECT_GT(bodies[1].pose.position.z(), 0.3 - 0.1 * voxel);
}

TEST(Sweep, LanesOnWorkersGiveTheOneRunsHitsBitForBit) {
  // 60 small cubes shot through 20 plates from random places: about 1,200
  // pairs, cut into several lanes on 3 threads. Each pair also comes again
  // later in the list (a tie on t in another lane): the first must win.
  const double voxel = 0.05;
  const Block plate(8, 8, 1, voxel, Vec3(0.2, 0.2, 0.025));
  const Block cube(2, 2, 2, voxel, Vec3::Constant(0.05));

  constexpr int kPlates = 20, kCubes = 60;
  std::vector<BodyState> bodies;
  std::vector<Pose> start;
  std::vector<const ShapeBounds*> shapes;
  std::uint32_t seed = 7;
  const auto uniform = [&seed](double lo, double hi) {  // small LCG: the same draws everywhere
    seed = seed * 1664525u + 1013904223u;
    return lo + (hi - lo) * static_cast<double>(seed >> 8) / static_cast<double>(1u << 24);
  };
  for (int i = 0; i < kPlates; ++i) {
    bodies.push_back(staticBody(Vec3(0.0, 0.0, 0.1 * i)));
    start.push_back(bodies.back().pose);
    shapes.push_back(&plate.bounds);
  }
  for (int i = 0; i < kCubes; ++i) {
    BodyState b = boxBody(1.0, Vec3::Constant(2 * voxel));
    Pose p0;
    p0.position = Vec3(uniform(-0.2, 0.2), uniform(-0.2, 0.2), uniform(1.5, 2.5));
    b.pose.position = Vec3(uniform(-0.2, 0.2), uniform(-0.2, 0.2), uniform(-0.5, 0.5));
    b.pose.orientation = Quat(Eigen::AngleAxisd(uniform(0.0, 3.0), Vec3(1.0, 2.0, 3.0).normalized()));
    bodies.push_back(b);
    start.push_back(p0);
    shapes.push_back(&cube.bounds);
  }
  std::vector<std::array<std::uint32_t, 2>> pairs;
  for (std::uint32_t c = kPlates; c < kPlates + kCubes; ++c) {
    for (std::uint32_t p = 0; p < kPlates; ++p) pairs.push_back({p, c});
  }
  const std::size_t once = pairs.size();
  for (std::size_t k = 0; k < once; ++k) pairs.push_back(pairs[k]);

  const auto sweep = [&](const Workers* workers, std::vector<BodyState>& out, SweepScratch& scratch) {
    out = bodies;
    markFastBodies(out, start, shapes, 0.5, scratch.fast);
    return sweepFastBodies(out, start, shapes, pairs, pairs.size(), 0.5, scratch, workers);
  };
  std::vector<BodyState> one_run, in_lanes;
  SweepScratch one_scratch, lane_scratch;
  const Workers workers(3);
  const SweepStats one = sweep(nullptr, one_run, one_scratch);
  const SweepStats lanes = sweep(&workers, in_lanes, lane_scratch);
  EXPECT_GT(one.clamped, static_cast<std::size_t>(kCubes / 2));  // most cubes hit a plate
  EXPECT_EQ(lanes.clamped, one.clamped);
  ASSERT_EQ(lane_scratch.clamped, one_scratch.clamped);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const SweepHit& a = one_scratch.hits[i];
    const SweepHit& b = lane_scratch.hits[i];
    EXPECT_EQ(a.t, b.t) << i;
    EXPECT_EQ(a.pair, b.pair) << i;
    EXPECT_LT(a.pair, once) << i;  // the first of the two equal pairs
    EXPECT_EQ(a.point, b.point) << i;
    EXPECT_EQ(a.normal, b.normal) << i;
    EXPECT_EQ(one_run[i].pose.position, in_lanes[i].pose.position) << i;
    EXPECT_EQ(one_run[i].pose.orientation.coeffs(), in_lanes[i].pose.orientation.coeffs()) << i;
  }
  // Again on the same scratch: the lanes were left clean.
  const SweepStats again = sweep(&workers, in_lanes, lane_scratch);
  EXPECT_EQ(again.clamped, one.clamped);
  for (std::size_t i = 0; i < bodies.size(); ++i) EXPECT_EQ(one_scratch.hits[i].t, lane_scratch.hits[i].t) << i;
}

}  // namespace
}  // namespace stc
