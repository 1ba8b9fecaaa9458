// World: entity validation and bookkeeping, kinematic integration, and the
// narrow phase under a budget with the accept/reject policy.
#include "pair_test.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "sweep_and_prune.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>

namespace stc {
namespace {

constexpr double kPi = 3.14159265358979323846;

PresetParams smallPreset(std::uint32_t seed = 1) {
  PresetParams p;
  p.resolution = 8;
  p.voxel_size = 0.05;  // 0.4 m across
  p.seed = seed;
  return p;
}

ShapeId addPreset(World& w, const std::string& name) {
  return w.addShape(name, makePreset(name, smallPreset()));
}

EntitySpec specAt(ShapeId shape, const Vec3& position, const std::string& name = "") {
  EntitySpec s;
  s.shape = shape;
  s.pose.position = position;
  s.name = name;
  return s;
}

// Expect addEntity(spec) to throw naming `field` and to leave the world as it was.
void expectRejected(World& w, const EntitySpec& spec, const std::string& field) {
  const std::size_t before = w.entityCount();
  const std::vector<EntityId> ids = w.entityIds();
  try {
    w.addEntity(spec);
    ADD_FAILURE() << "accepted a bad " << field;
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), field);
  }
  EXPECT_EQ(w.entityCount(), before) << field;
  EXPECT_EQ(w.entityIds(), ids) << field;
  if (!spec.name.empty() && field != "name") EXPECT_FALSE(w.findByName(spec.name)) << field;
}

TEST(World, ShapesAreSharedByKeyWithMassPropertiesAndTree) {
  World w;
  const ShapeId cube = addPreset(w, "cube");
  EXPECT_EQ(addPreset(w, "cube"), cube);
  const ShapeId rod = addPreset(w, "rod");
  EXPECT_NE(rod, cube);
  EXPECT_EQ(w.findShape("rod"), rod);
  EXPECT_FALSE(w.findShape("ring"));

  const ShapeInfo& c = w.shape(cube);
  EXPECT_NEAR(c.unit_mass.mass, std::pow(0.4, 3), 1e-12);      // density 1
  EXPECT_TRUE(c.body_origin.isApprox(Vec3::Constant(0.2), 1e-12));
  EXPECT_NEAR(c.bounding_radius, 0.2 * std::sqrt(3.0), 1e-12);  // half diagonal
  EXPECT_EQ(c.tree.levelCount(), 4);
  EXPECT_FALSE(c.elongated);
  EXPECT_TRUE(w.shape(rod).elongated);
  EXPECT_THROW(w.shape(99), InputError);
}

TEST(World, AddEntityValidatesEveryFieldAndChangesNothingOnThrow) {
  WorldConfig config;
  config.max_entities = 2;
  World w(config);
  const ShapeId cube = addPreset(w, "cube");
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();

  EntitySpec s = specAt(cube, Vec3::Zero(), "first");
  s.shape = 7;
  expectRejected(w, s, "shape");
  s = specAt(cube, Vec3(nan, 0, 0), "first");
  expectRejected(w, s, "pose.position");
  s = specAt(cube, Vec3::Zero(), "first");
  s.pose.orientation = Quat(2, 0, 0, 0);
  expectRejected(w, s, "pose.orientation");
  s.pose.orientation = Quat(nan, 0, 0, 0);
  expectRejected(w, s, "pose.orientation");
  s = specAt(cube, Vec3::Zero(), "first");
  s.linear_velocity.y() = inf;
  expectRejected(w, s, "linear_velocity");
  s = specAt(cube, Vec3::Zero(), "first");
  s.angular_velocity.z() = nan;
  expectRejected(w, s, "angular_velocity");
  for (double d : {0.0, -1.0, nan, inf}) {
    s = specAt(cube, Vec3::Zero(), "first");
    s.density = d;
    expectRejected(w, s, "density");
  }
  for (double e : {-0.1, 1.1, nan}) {
    s = specAt(cube, Vec3::Zero(), "first");
    s.material.restitution = e;
    expectRejected(w, s, "material.restitution");
  }
  for (double mu : {-0.5, nan, inf}) {
    s = specAt(cube, Vec3::Zero(), "first");
    s.material.friction = mu;
    expectRejected(w, s, "material.friction");
  }
  for (double c : {-0.1, 1.5, nan, inf}) {
    s = specAt(cube, Vec3::Zero(), "first");
    s.material.rolling_resistance = c;
    expectRejected(w, s, "material.rolling_resistance");
  }

  // Nothing above used an id: the first real entity gets id 0.
  s = specAt(cube, Vec3::Zero(), "first");
  s.pose.orientation = Quat(1.0005, 0, 0, 0);  // slightly off: accepted and normalised
  const EntityId first = w.addEntity(s);
  EXPECT_EQ(first, 0u);
  EXPECT_NEAR(w.bodies()[0].pose.orientation.norm(), 1.0, 1e-15);
  expectRejected(w, specAt(cube, Vec3(1, 0, 0), "first"), "name");
  w.addEntity(specAt(cube, Vec3(2, 0, 0)));
  expectRejected(w, specAt(cube, Vec3(3, 0, 0), "third"), "max_entities");
  EXPECT_EQ(w.entityCount(), 2u);
}

// Two cubes closing head-on at 2 m/s: with the response off (switched while
// running) they pass into each other untouched; switched back on, they bounce.
TEST(World, SetResponseTakesEffectFromTheNextStepAndRejectsBadOptions) {
  World w;
  const ShapeId cube = addPreset(w, "cube");
  EntitySpec a = specAt(cube, Vec3(-0.3, 0, 0));
  a.linear_velocity = Vec3(1, 0, 0);
  EntitySpec b = specAt(cube, Vec3(0.3, 0, 0));
  b.linear_velocity = Vec3(-1, 0, 0);
  w.addEntity(a);
  w.addEntity(b);

  ResponseOptions bad = w.config().response;
  bad.iterations = 0;
  try {
    w.setResponse(bad);
    ADD_FAILURE() << "accepted 0 solver iterations";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "response.iterations");
  }
  EXPECT_EQ(w.config().response.iterations, ResponseOptions{}.iterations);  // unchanged

  ResponseOptions off = w.config().response;
  off.enabled = false;
  w.setResponse(off);
  for (int i = 0; i < 6; ++i) w.step(1.0 / 60.0, Budget{});  // 0.2 m closer: overlapping
  EXPECT_FALSE(w.contacts().empty());
  EXPECT_DOUBLE_EQ(w.bodies()[0].linear_velocity.x(), 1.0);
  EXPECT_DOUBLE_EQ(w.bodies()[1].linear_velocity.x(), -1.0);

  ResponseOptions on = off;
  on.enabled = true;
  w.setResponse(on);
  w.step(1.0 / 60.0, Budget{});
  EXPECT_LT(w.bodies()[0].linear_velocity.x(), 1.0 - 1e-3);  // the impulse acted
  EXPECT_GT(w.bodies()[1].linear_velocity.x(), -1.0 + 1e-3);
  EXPECT_NEAR(w.bodies()[0].linear_velocity.x() + w.bodies()[1].linear_velocity.x(), 0.0, 1e-9);  // momentum
}

TEST(World, MassPropertiesScaleWithDensityAndStaticBodiesHaveNone) {
  World w;
  const ShapeId cube = addPreset(w, "cube");
  EntitySpec s = specAt(cube, Vec3::Zero());
  s.density = 500.0;
  s.linear_velocity = Vec3(1, 0, 0);
  w.addEntity(s);
  s.is_static = true;
  s.pose.position.x() = 5;
  w.addEntity(s);
  const double mass = 500.0 * std::pow(0.4, 3);
  const BodyState& moving = w.bodies()[0];
  EXPECT_NEAR(moving.inv_mass, 1.0 / mass, 1e-9);
  // Solid cube: I = m a^2 / 6 about each axis.
  const double inertia = mass * 0.4 * 0.4 / 6.0;
  EXPECT_TRUE(moving.inv_inertia_body.isApprox(Mat3::Identity() / inertia, 1e-9));
  EXPECT_TRUE(moving.inv_inertia_world.isApprox(moving.inv_inertia_body, 1e-9));
  const BodyState& fixed = w.bodies()[1];
  EXPECT_TRUE(fixed.is_static);
  EXPECT_EQ(fixed.inv_mass, 0.0);
  EXPECT_TRUE(fixed.inv_inertia_body.isZero());
  EXPECT_TRUE(fixed.linear_velocity.isZero());
}

TEST(World, RemoveSwapsTheLastIntoTheHoleAndClearKeepsShapes) {
  World w;
  const ShapeId cube = addPreset(w, "cube");
  const EntityId a = w.addEntity(specAt(cube, Vec3(0, 0, 0), "a"));
  const EntityId b = w.addEntity(specAt(cube, Vec3(1, 0, 0), "b"));
  const EntityId c = w.addEntity(specAt(cube, Vec3(2, 0, 0), "c"));
  EXPECT_EQ(w.findByName("b"), b);

  EXPECT_TRUE(w.removeEntity(b));
  EXPECT_FALSE(w.removeEntity(b));
  EXPECT_EQ(w.entityCount(), 2u);
  EXPECT_FALSE(w.findByName("b"));
  EXPECT_FALSE(w.indexOf(b));
  ASSERT_TRUE(w.indexOf(c));
  const std::size_t ic = *w.indexOf(c);
  EXPECT_EQ(w.entityIds()[ic], c);
  EXPECT_EQ(w.bodyNames()[ic], "c");
  EXPECT_DOUBLE_EQ(w.bodies()[ic].pose.position.x(), 2.0);
  EXPECT_EQ(w.entityIds()[*w.indexOf(a)], a);

  // The name is free again; ids are never reused.
  const EntityId b2 = w.addEntity(specAt(cube, Vec3(1, 0, 0), "b"));
  EXPECT_GT(b2, c);
  w.step(0.01, Budget::unlimited());

  w.clear();
  EXPECT_EQ(w.entityCount(), 0u);
  EXPECT_FALSE(w.findByName("a"));
  EXPECT_EQ(w.pairCount(), 0u);
  EXPECT_EQ(w.findShape("cube"), cube);
  const EntityId d = w.addEntity(specAt(cube, Vec3::Zero(), "a"));
  EXPECT_GT(d, b2);
  const TickReport r = w.step(0.01, Budget::unlimited());
  EXPECT_EQ(r.bodies.entities, 1u);
  EXPECT_EQ(r.detection.broad_pairs, 0u);
}

// The broad phase's pairs keep their dense indices from tick to tick
// (setUpPairTests), so a removal, which moves the last body into the hole,
// must not leave a pair test reading another body's pose.
TEST(World, RemovingEntitiesLeavesThePairsOfAWorldBuiltWithoutThem) {
  // A lattice of cubes 1.2 sides apart: each one's fixed-cube box overlaps
  // all 26 neighbours' (the cubes do not touch; no gravity: nothing moves).
  // Two batches of removals, a tick apart, as the quarantine makes them,
  // must leave the broad-phase pairs of a world built with the rest alone.
  const int n = 12;
  const double spacing = 1.2 * 0.4;
  const auto build = [&](World& w, const std::vector<bool>& skip) {
    const ShapeId cube = addPreset(w, "cube");
    for (int k = 0; k < n * n * n; ++k) {
      if (skip[static_cast<std::size_t>(k)]) continue;
      w.addEntity(specAt(cube, Vec3(k % n, (k / n) % n, k / (n * n)) * spacing, "c" + std::to_string(k)));
    }
  };
  const auto namedPairs = [](const World& w) {
    std::set<std::pair<std::string, std::string>> out;
    for (const BroadPair& p : broadPhase(w).pairs()) {
      const std::string& a = w.bodyNames()[*w.indexOf(p.first)];
      const std::string& b = w.bodyNames()[*w.indexOf(p.second)];
      out.emplace(std::min(a, b), std::max(a, b));
    }
    return out;
  };
  std::vector<bool> removed(n * n * n, false);
  World big;
  build(big, removed);
  const double dt = 1.0 / 60.0;
  big.step(dt, Budget::unlimited());
  const std::size_t pairs_before = broadPhase(big).pairs().size();
  EXPECT_GT(pairs_before, static_cast<std::size_t>(10 * n * n * n));
  std::mt19937 rng(3);
  std::vector<int> order(n * n * n);
  for (int k = 0; k < n * n * n; ++k) order[static_cast<std::size_t>(k)] = k;
  std::shuffle(order.begin(), order.end(), rng);
  for (const int batch : {300, 100}) {
    for (int r = 0; r < batch; ++r) {
      const int k = order.back();
      order.pop_back();
      removed[static_cast<std::size_t>(k)] = true;
      EXPECT_TRUE(big.removeEntity(*big.findByName("c" + std::to_string(k))));
    }
    big.step(dt, Budget::unlimited());
  }
  World fresh;
  build(fresh, removed);
  fresh.step(dt, Budget::unlimited());
  ASSERT_EQ(big.entityCount(), fresh.entityCount());
  EXPECT_LT(broadPhase(big).pairs().size(), pairs_before);
  EXPECT_EQ(namedPairs(big), namedPairs(fresh));
}

TEST(World, PairTestsReadTheirOwnBodiesThroughRemovals) {
  SceneParams params;
  params.entities = 300;
  SceneWorld scene = makeSceneWorld(SceneKind::PackedBox, params);
  World& w = scene.world;
  for (int t = 0; t < 10; ++t) w.step(1.0 / 60.0, Budget::unlimited());
  std::size_t checked = 0;
  for (int t = 0; t < 40; ++t) {
    if (t % 4 == 1) ASSERT_TRUE(w.removeEntity(scene.spec.movers[static_cast<std::size_t>(t)]));
    w.step(1.0 / 60.0, Budget::unlimited());
    ASSERT_GT(w.pairCount(), 0u);
    for (std::size_t k = 0; k < w.pairCount(); ++k) {
      const PairTest& test = pairTests(w)[k];
      for (const PairBody* body : {&test.bodyA(), &test.bodyB()}) {
        const std::optional<std::size_t> index = w.indexOf(body->id);
        ASSERT_TRUE(index.has_value()) << "tick " << t << ": pair " << k << " of a removed body";
        ASSERT_EQ(body->pose, &w.bodies()[*index].pose) << "tick " << t << ": pair " << k;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
}

// World::releaseMemory (after a large removal) changes no state: of two equal
// rockfalls with three rocks of four removed, the one released has the same
// bodies and broad-phase pairs. Only the pairs' order may change (the broad
// phase is rebuilt), so the next ticks are not bit for bit the other's.
TEST(World, ReleaseMemoryChangesNoState) {
  SceneParams params;
  params.entities = 400;
  SceneWorld kept = makeSceneWorld(SceneKind::Rockfall, params);
  SceneWorld released = makeSceneWorld(SceneKind::Rockfall, params);
  for (SceneWorld* s : {&kept, &released}) {
    for (int t = 0; t < 60; ++t) s->world.step(1.0 / 60.0, Budget::unlimited());
    for (std::size_t k = 0; k < s->spec.movers.size(); ++k) {
      if (k % 4 != 0) ASSERT_TRUE(s->world.removeEntity(s->spec.movers[k]));
    }
    s->world.step(1.0 / 60.0, Budget::unlimited());
  }
  ASSERT_GT(broadPhase(released.world).pairs().size(), 0u);
  released.world.releaseMemory();
  const auto pairSet = [](const World& w) {
    std::set<std::pair<EntityId, EntityId>> out;
    for (const BroadPair& p : broadPhase(w).pairs()) out.insert({std::min(p.first, p.second), std::max(p.first, p.second)});
    return out;
  };
  EXPECT_EQ(pairSet(released.world), pairSet(kept.world));
  ASSERT_EQ(released.world.entityIds(), kept.world.entityIds());
  ASSERT_EQ(released.world.bodyNames(), kept.world.bodyNames());
  ASSERT_EQ(released.world.bodyShapes(), kept.world.bodyShapes());
  for (std::size_t i = 0; i < kept.world.entityCount(); ++i) {
    const BodyState& a = released.world.bodies()[i];
    const BodyState& b = kept.world.bodies()[i];
    ASSERT_EQ(a.pose.position, b.pose.position);
    ASSERT_EQ(a.pose.orientation.coeffs(), b.pose.orientation.coeffs());
    ASSERT_EQ(a.linear_velocity, b.linear_velocity);
    ASSERT_EQ(a.angular_velocity, b.angular_velocity);
    ASSERT_EQ(released.world.isSleeping(kept.world.entityIds()[i]), kept.world.isSleeping(kept.world.entityIds()[i]));
    ASSERT_EQ(released.world.indexOf(kept.world.entityIds()[i]), std::optional<std::size_t>(i));
  }
  for (const std::string& name : kept.world.bodyNames()) {
    if (!name.empty()) EXPECT_EQ(released.world.findByName(name), kept.world.findByName(name));
  }
  // It steps on: the same bodies, none lost or out of the scene.
  for (int t = 0; t < 60; ++t) released.world.step(1.0 / 60.0, Budget::unlimited());
  EXPECT_EQ(released.world.entityIds(), kept.world.entityIds());
}

TEST(World, KinematicIntegrationMovesAndTurnsOnlyMovableBodies) {
  World w;
  const ShapeId cube = addPreset(w, "cube");
  EntitySpec s = specAt(cube, Vec3(0, 0, 0));
  s.linear_velocity = Vec3(1, -2, 0.5);
  s.angular_velocity = Vec3(0, 0, kPi);  // half a turn per second about z
  w.addEntity(s);
  EntitySpec f = specAt(cube, Vec3(10, 0, 0));
  f.is_static = true;
  f.linear_velocity = Vec3(1, 0, 0);
  w.addEntity(f);
  for (int i = 0; i < 10; ++i) w.step(0.1, Budget::unlimited());

  const BodyState& m = w.bodies()[0];
  EXPECT_TRUE(m.pose.position.isApprox(Vec3(1, -2, 0.5), 1e-12));
  const Quat half_turn(Eigen::AngleAxisd(kPi, Vec3::UnitZ()));
  EXPECT_NEAR(std::abs(m.pose.orientation.dot(half_turn)), 1.0, 1e-12);
  EXPECT_NEAR(m.pose.orientation.norm(), 1.0, 1e-14);
  const Mat3 r = m.pose.orientation.toRotationMatrix();
  EXPECT_TRUE(m.inv_inertia_world.isApprox(r * m.inv_inertia_body * r.transpose(), 1e-12));
  EXPECT_EQ(w.bodies()[1].pose.position, Vec3(10, 0, 0));

  EXPECT_THROW(w.step(-0.1, Budget::unlimited()), InputError);
  EXPECT_THROW(w.step(std::nan(""), Budget::unlimited()), InputError);
}

// A packed block of n^3 entities of mixed shapes, every one touching its
// neighbours' boxes, plus a static floor row under it.
World packedWorld(int n, UnresolvedPolicy policy, std::uint32_t seed = 3) {
  WorldConfig config;
  config.unresolved_policy = policy;
  World w(config);
  const ShapeId shapes[] = {addPreset(w, "cube"), addPreset(w, "rock"), addPreset(w, "L"),
                            addPreset(w, "ring"), addPreset(w, "sphere"), addPreset(w, "rod")};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  std::uniform_int_distribution<int> pick(0, 5);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        EntitySpec s = specAt(shapes[pick(rng)], Vec3(0.38 * i + jitter(rng), 0.38 * j + jitter(rng),
                                                       0.38 * k + jitter(rng)));
        s.pose.orientation = Quat(Eigen::AngleAxisd(angle(rng), Vec3(jitter(rng), jitter(rng), 0.05).normalized()));
        s.linear_velocity = Vec3(jitter(rng), jitter(rng), jitter(rng));
        w.addEntity(s);
      }
  for (int i = 0; i < n; ++i) {  // static floor row: static-static pairs are skipped
    EntitySpec s = specAt(shapes[0], Vec3(0.38 * i, 0, -0.39));
    s.is_static = true;
    w.addEntity(s);
  }
  return w;
}

std::size_t staticStaticPairs(const World& w) {
  // Floor cubes 0.38 apart with 0.4 m boxes: each neighbour pair overlaps.
  std::size_t n = 0;
  for (std::size_t i = 0; i < w.entityCount(); ++i)
    for (std::size_t j = i + 1; j < w.entityCount(); ++j)
      if (w.bodies()[i].is_static && w.bodies()[j].is_static &&
          (w.bodies()[i].pose.position - w.bodies()[j].pose.position).cwiseAbs().maxCoeff() <
              2 * w.shape(w.bodyShapes()[i]).bounding_radius)
        ++n;
  return n;
}

// Pairs of bodies that got at least one contact (the response may make
// several contacts per pair) and the pair tests that should give contacts.
std::set<std::pair<EntityId, EntityId>> pairsWithContacts(const World& w) {
  std::set<std::pair<EntityId, EntityId>> out;
  for (const Contact& c : w.contacts()) out.emplace(c.a, c.b);
  return out;
}
std::set<std::pair<EntityId, EntityId>> pairsThatShouldTouch(const World& w, bool accept) {
  std::set<std::pair<EntityId, EntityId>> out;
  for (std::size_t i = 0; i < w.pairCount(); ++i) {
    const PairTest& t = pairTests(w)[i];
    if (t.status() == PairStatus::Colliding || (accept && t.status() == PairStatus::Unresolved))
      out.emplace(t.bodyA().id, t.bodyB().id);
  }
  return out;
}

void expectCountsAddUp(const TickReport& r, std::size_t static_pairs) {
  EXPECT_EQ(r.detection.colliding + r.detection.separate + r.detection.unresolved,
            r.detection.broad_pairs - static_pairs);
  EXPECT_LE(r.detection.unresolved_accepted, r.detection.unresolved);
  EXPECT_GE(r.phases.total_s, r.phases.narrow_s);
}

TEST(World, ZeroBudgetAcceptsEveryPairUnresolved) {
  World w = packedWorld(4, UnresolvedPolicy::Accept);
  const std::size_t static_pairs = staticStaticPairs(w);
  ASSERT_GT(static_pairs, 0u);
  const TickReport r = w.step(0.01, Budget::ofSphereTests(0));
  ASSERT_GT(r.detection.broad_pairs, static_pairs);
  expectCountsAddUp(r, static_pairs);
  EXPECT_EQ(r.detection.sphere_tests, 0);
  EXPECT_TRUE(r.detection.interrupted);
  EXPECT_EQ(r.detection.unresolved, r.detection.broad_pairs - static_pairs);
  EXPECT_EQ(r.detection.unresolved_accepted, r.detection.unresolved);
  EXPECT_EQ(r.response.contacts, w.contacts().size());
  EXPECT_EQ(pairsWithContacts(w), pairsThatShouldTouch(w, true));
  EXPECT_EQ(pairsWithContacts(w).size(), r.detection.unresolved);
  EXPECT_EQ(w.pairCount(), r.detection.unresolved);
  EXPECT_GT(r.accuracy.geometric_inaccuracy, 0.0);
  // Before any test the bound is |cA - cB| + h_A + h_B, never below the estimate.
  EXPECT_GE(r.accuracy.geometric_bound, r.accuracy.geometric_inaccuracy);
  EXPECT_FALSE(r.accuracy.perception_used);
  EXPECT_EQ(r.accuracy.perceived_inaccuracy, 0.0);
  for (const Contact& c : w.contacts()) {
    EXPECT_FALSE(c.resolved);
    EXPECT_TRUE(c.normal.allFinite());
    EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    EXPECT_GE(c.depth, 0.0);
    EXPECT_EQ(w.entityIds()[c.index_a], c.a);
    EXPECT_EQ(w.entityIds()[c.index_b], c.b);
  }
}

TEST(World, ZeroBudgetRejectsEveryPairUnresolved) {
  World w = packedWorld(4, UnresolvedPolicy::Reject);
  const std::size_t static_pairs = staticStaticPairs(w);
  const TickReport r = w.step(0.01, Budget::ofSphereTests(0));
  expectCountsAddUp(r, static_pairs);
  EXPECT_EQ(r.detection.unresolved, r.detection.broad_pairs - static_pairs);
  EXPECT_EQ(r.detection.unresolved_accepted, 0u);
  EXPECT_EQ(r.response.contacts, 0u);
  EXPECT_EQ(r.accuracy.geometric_inaccuracy, 0.0);
  EXPECT_EQ(r.accuracy.geometric_bound, 0.0);
}

TEST(World, UnlimitedBudgetResolvesEveryPair) {
  World w = packedWorld(4, UnresolvedPolicy::Accept);
  const std::size_t static_pairs = staticStaticPairs(w);
  for (int tick = 0; tick < 3; ++tick) {
    const TickReport r = w.step(0.01, Budget::unlimited());
    expectCountsAddUp(r, static_pairs);
    EXPECT_EQ(r.detection.unresolved, 0u);
    EXPECT_FALSE(r.detection.interrupted);
    EXPECT_GT(r.detection.colliding, 0u);
    EXPECT_GT(r.detection.separate, 0u);
    EXPECT_EQ(pairsWithContacts(w), pairsThatShouldTouch(w, true));
    EXPECT_EQ(pairsWithContacts(w).size(), r.detection.colliding);
    EXPECT_EQ(r.accuracy.geometric_inaccuracy, 0.0);
    std::int64_t tests = 0;
    for (std::size_t i = 0; i < w.pairCount(); ++i) tests += pairTests(w)[i].sphereTests();
    EXPECT_EQ(r.detection.sphere_tests, tests);
    for (const Contact& c : w.contacts()) {
      EXPECT_TRUE(c.resolved);
      const int levels = std::max(w.shape(w.bodyShapes()[c.index_a]).tree.levelCount(),
                                  w.shape(w.bodyShapes()[c.index_b]).tree.levelCount());
      EXPECT_EQ(c.level, levels - 1);  // found at the leaves
    }
  }
}

TEST(World, PartialBudgetSplitsPairsAndStaysWithinTheCount) {
  World w = packedWorld(4, UnresolvedPolicy::Accept);
  const std::size_t static_pairs = staticStaticPairs(w);
  const TickReport full = World(packedWorld(4, UnresolvedPolicy::Accept)).step(0.01, Budget::unlimited());
  const std::int64_t budget = full.detection.sphere_tests / 3;
  const TickReport r = w.step(0.01, Budget::ofSphereTests(budget));
  expectCountsAddUp(r, static_pairs);
  EXPECT_TRUE(r.detection.interrupted);
  EXPECT_GT(r.detection.unresolved, 0u);
  EXPECT_EQ(r.detection.unresolved_accepted, r.detection.unresolved);
  EXPECT_EQ(pairsWithContacts(w), pairsThatShouldTouch(w, true));
  EXPECT_EQ(pairsWithContacts(w).size(), r.detection.colliding + r.detection.unresolved);
  EXPECT_GE(r.accuracy.geometric_bound, 0.0);
  // The budget is checked before each step: at most one step past it.
  EXPECT_GE(r.detection.sphere_tests, budget);
}

TEST(World, ContactFollowsTheLineOfCentresFromAToB) {
  World w;
  const ShapeId cube = addPreset(w, "cube");
  const EntityId a = w.addEntity(specAt(cube, Vec3(0, 0, 0)));
  const EntityId b = w.addEntity(specAt(cube, Vec3(0.39, 0, 0)));  // 1 cm overlap along x
  const TickReport r = w.step(0.0, Budget::unlimited());
  ASSERT_EQ(r.detection.colliding, 1u);
  ASSERT_GE(w.contacts().size(), 1u);
  const Contact& c = w.contacts()[0];
  EXPECT_EQ(c.a, a);
  EXPECT_EQ(c.b, b);
  EXPECT_TRUE(c.resolved);
  EXPECT_GT(c.normal.x(), 0.999);  // from a towards b, face on
  EXPECT_GT(c.depth, 0.0);
  EXPECT_GT(c.point.x(), 0.0);
  EXPECT_LT(c.point.x(), 0.39);
  EXPECT_GT(c.gap_bound, 0.0);
}

TEST(World, CoincidentCentresGiveAFiniteContact) {
  World w;
  const ShapeId ball = addPreset(w, "sphere");
  w.addEntity(specAt(ball, Vec3(1, 1, 1)));
  w.addEntity(specAt(ball, Vec3(1, 1, 1)));
  w.step(0.0, Budget::unlimited());
  ASSERT_EQ(w.contacts().size(), 1u);  // one-level trees: root-root is the only leaf pair
  const Contact& c = w.contacts()[0];
  EXPECT_TRUE(c.normal.allFinite());
  EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
  // Each ball's centre lies in the other's solid: the contact is measured
  // from there (kInteriorNode), a diameter deep, at a point inside both balls.
  const double radius = 0.5 * w.shape(ball).voxels.extent().x();
  EXPECT_TRUE(c.node_a == kInteriorNode || c.node_b == kInteriorNode);
  EXPECT_LT(c.separation, -1.5 * radius);
  EXPECT_LT((c.point - Vec3(1, 1, 1)).norm(), radius);
}

TEST(World, PerceivedInaccuracyOnlyWithAFixation) {
  World w = packedWorld(3, UnresolvedPolicy::Accept);
  Camera cam;
  // Camera 3 m back along -y looking at the block (+y forward, z up -> optical y down).
  Mat3 r;
  r.col(0) = Vec3(1, 0, 0);   // optical x: right
  r.col(1) = Vec3(0, 0, -1);  // optical y: down
  r.col(2) = Vec3(0, 1, 0);   // optical z: forward
  cam.camera_to_world.orientation = Quat(r);
  cam.camera_to_world.position = Vec3(0.4, -3.0, 0.4);
  w.perception().setCamera(cam);
  TickReport r0 = w.step(0.0, Budget::ofSphereTests(0));
  EXPECT_FALSE(r0.accuracy.perception_used);
  EXPECT_EQ(r0.accuracy.perceived_inaccuracy, 0.0);
  w.perception().setFixation(Vec2(cam.width / 2.0, cam.height / 2.0));
  const TickReport r1 = w.step(0.0, Budget::ofSphereTests(0));
  EXPECT_TRUE(r1.accuracy.perception_used);
  EXPECT_GT(r1.accuracy.perceived_inaccuracy, 0.0);
  // P is the sum of f(e, g) over the accepted pairs; contacts carry their pair's f.
  double sum = 0.0;
  std::map<std::pair<EntityId, EntityId>, double> priority;
  for (std::size_t i = 0; i < w.pairCount(); ++i) {
    const PairTest& t = pairTests(w)[i];
    priority[{t.bodyA().id, t.bodyB().id}] = w.perception().measure(t).priority;
    sum += priority[{t.bodyA().id, t.bodyB().id}];
  }
  EXPECT_NEAR(sum, r1.accuracy.perceived_inaccuracy, 1e-9 * sum);
  ASSERT_FALSE(w.contacts().empty());
  for (const Contact& c : w.contacts()) EXPECT_DOUBLE_EQ(c.priority, (priority[{c.a, c.b}]));
}

TEST(World, AutoBoxModeUsesDynamicBoxesForElongatedShapes) {
  World w;
  const ShapeId rod = addPreset(w, "rod");
  // Two parallel rods 0.3 m apart along y: their fixed cubes (half-side ~0.21)
  // overlap, their dynamic boxes (0.1 m thick) do not.
  EntitySpec s = specAt(rod, Vec3(0, 0, 0));
  w.addEntity(s);
  s.pose.position = Vec3(0, 0.3, 0);
  w.addEntity(s);
  EXPECT_EQ(w.step(0.0, Budget::unlimited()).detection.broad_pairs, 0u);
  World fixed;
  const ShapeId rod2 = addPreset(fixed, "rod");
  s.shape = rod2;
  s.box_mode = BoxMode::FixedCube;
  s.pose.position = Vec3(0, 0, 0);
  fixed.addEntity(s);
  s.pose.position = Vec3(0, 0.3, 0);
  fixed.addEntity(s);
  EXPECT_EQ(fixed.step(0.0, Budget::unlimited()).detection.broad_pairs, 1u);
}

}  // namespace
}  // namespace stc
