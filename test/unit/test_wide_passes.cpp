// The solver's passes four manifolds wide (ResponseOptions::wide_passes,
// contact_solver_wide.cpp) reorder the manifolds only where no movable body
// is shared, so every body meets its contacts in the one-at-a-time order:
// the worlds must agree bit for bit, tick by tick, on every built-in scene
// and with the options that change which passes run.
#include "physics.hpp"
#include "same_state.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "world_access.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <utility>

namespace stc {
namespace {

constexpr int kTicks = 300;

World sceneWorld(SceneKind kind, int entities, const WorldConfig& config) {
  SceneParams params;
  params.entities = entities;
  return std::move(makeSceneWorld(kind, params, config).world);
}

// Runs `kind` with the passes wide and one manifold at a time, under the
// same `tune`d options, and checks the two worlds after every tick.
void expectSameBits(SceneKind kind, int entities, const std::string& variant,
                    const std::function<void(WorldConfig&)>& tune) {
  WorldConfig config;
  tune(config);
  config.response.wide_passes = true;
  World wide = sceneWorld(kind, entities, config);
  config.response.wide_passes = false;
  World narrow = sceneWorld(kind, entities, config);
  std::size_t manifolds = 0, batches = 0;
  for (int t = 0; t < kTicks; ++t) {
    wide.step(1.0 / 60.0, Budget::unlimited());
    narrow.step(1.0 / 60.0, Budget::unlimited());
    ASSERT_TRUE(sameState(wide, narrow)) << toString(kind) << " " << variant << ", tick " << t;
    ASSERT_EQ(physicsReport(narrow).solve.wide_batches, 0u);
    manifolds += physicsReport(wide).solve.manifolds;
    batches += physicsReport(wide).solve.wide_batches;
  }
  // The wide passes did run, and mostly with more than one manifold a batch
  // (a stack's manifolds share bodies and must go one by one).
  ASSERT_GT(batches, 0u) << toString(kind) << " " << variant;
  EXPECT_GT(static_cast<double>(manifolds) / static_cast<double>(batches), 1.5) << toString(kind) << " " << variant;
}

TEST(WidePasses, GiveTheOneAtATimeBitsOnEveryBuiltInScene) {
  for (const SceneKind kind : {SceneKind::PackedBox, SceneKind::BouncingBox, SceneKind::Rockfall,
                               SceneKind::CornerDrift, SceneKind::CubeBox}) {
    expectSameBits(kind, 150, "defaults", [](WorldConfig&) {});
  }
}

TEST(WidePasses, GiveTheOneAtATimeBitsWithTheOptionsThatChangeThePasses) {
  // Without shock propagation (the impulses leave the wide rows after the
  // velocity passes), with a position pass that turns bodies (one at a
  // time, after wide velocity passes), with few iterations, and on two
  // threads (a stage's blocks at once).
  expectSameBits(SceneKind::CornerDrift, 150, "no shock", [](WorldConfig& c) { c.response.shock_propagation = false; });
  expectSameBits(SceneKind::CornerDrift, 150, "turning positions", [](WorldConfig& c) { c.response.position_turns = true; });
  expectSameBits(SceneKind::CubeBox, 150, "3 iterations", [](WorldConfig& c) { c.response.iterations = 3; });
  expectSameBits(SceneKind::CornerDrift, 150, "2 threads", [](WorldConfig& c) {
    c.threads = 2;
    c.response.solver_task_manifolds = 4;
  });
}

TEST(WidePasses, JacobiStaysOneAtATime) {
  WorldConfig config;
  config.response.solver = SolverKind::Jacobi;
  World w = sceneWorld(SceneKind::CornerDrift, 50, config);
  std::size_t manifolds = 0;
  for (int t = 0; t < 60; ++t) {
    w.step(1.0 / 60.0, Budget::unlimited());
    manifolds += physicsReport(w).solve.manifolds;
    ASSERT_EQ(physicsReport(w).solve.wide_batches, 0u) << "tick " << t;
  }
  EXPECT_GT(manifolds, 0u);
}

}  // namespace
}  // namespace stc
