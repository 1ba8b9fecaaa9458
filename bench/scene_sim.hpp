// The simulation the scheduler benchmarks take their snapshots from: a scene
// stepped with unlimited budgets (round-robin: the reference scheduler), with
// the scene's camera, so a gaze that follows a rock lands where the
// evaluation Worlds (same camera) see it.
#pragma once

#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include <memory>

namespace stc_bench {

struct SceneSim {
  std::unique_ptr<stc::World> world;
  stc::SceneSpec spec;
};

inline SceneSim makeSceneSim(stc::SceneKind kind, const stc::SceneParams& params = stc::SceneParams{}) {
  stc::WorldConfig config;
  config.gravity = stc::sceneGravity(kind);
  config.scheduler.kind = stc::SchedulerKind::RoundRobin;
  SceneSim sim;
  sim.world = std::make_unique<stc::World>(config);
  sim.spec = stc::populateScene(*sim.world, kind, params);
  sim.world->perception().setCamera(sim.spec.camera);
  return sim;
}

}  // namespace stc_bench
