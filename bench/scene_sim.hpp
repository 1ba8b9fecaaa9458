// The simulation the scheduler benchmarks take their snapshots from: a scene
// stepped with unlimited budgets (round-robin: the reference scheduler), with
// the scene's camera, so a gaze that follows a rock lands where the
// evaluation Worlds (same camera) see it.
#pragma once

#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

namespace stc_bench {

inline stc::SceneWorld makeSceneSim(stc::SceneKind kind, const stc::SceneParams& params = stc::SceneParams{}) {
  stc::WorldConfig config;
  config.scheduler.kind = stc::SchedulerKind::RoundRobin;
  return stc::makeSceneWorld(kind, params, config);
}

}  // namespace stc_bench
