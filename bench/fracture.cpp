// Fracture cost (issue 14, item 3): the rockfall with breakable rocks. Per
// strength: bodies broken, pieces made, entities at the end, time per break
// (split + pieces' trees + entity bookkeeping) and its share of the ticks.
// Prints a markdown table (docs/fracture.md).
//
//   bench_fracture [rocks] [seconds]    defaults 200 rocks, 6 s of simulated time
#include "sphere_tree_collision/scenes.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

using namespace stc;

int main(int argc, char** argv) {
  const int rocks = argc > 1 ? std::atoi(argv[1]) : 200;
  const double seconds = argc > 2 ? std::atof(argv[2]) : 6.0;
  std::printf("rockfall, %d rocks (0.4 m, resolution 8), %.1f s simulated, "
              "min_piece_voxels 8 attach\n\n", rocks, seconds);
  std::printf("| strength (N s) | breaks | entities at end | shapes | time per break mean / max (ms) | "
              "fracture share of tick time |\n|---:|---:|---:|---:|---:|---:|\n");
  for (const double strength : {0.0, 200.0, 100.0, 50.0}) {
    WorldConfig config;
    config.gravity = sceneGravity(SceneKind::Rockfall);
    World world(config);
    SceneParams params;
    params.entities = rocks;
    const SceneSpec spec = populateScene(world, SceneKind::Rockfall, params);
    for (BodyState& body : world.bodies()) {
      if (!body.is_static) body.material.strength = strength;
    }
    const std::size_t shapes_before = world.shapeCount();
    std::size_t breaks = 0;
    double fracture_s = 0.0, total_s = 0.0, worst = 0.0;
    const int ticks = static_cast<int>(seconds / spec.dt);
    for (int i = 0; i < ticks; ++i) {
      const TickReport r = world.step(spec.dt, Budget::unlimited());
      breaks += r.fractures;
      fracture_s += r.fracture_s;
      total_s += r.total_s;
      if (r.fractures > 0) worst = std::max(worst, r.fracture_s / r.fractures);
    }
    std::printf("| %.0f | %zu | %zu | %zu new | %.3f / %.3f | %.1f%% |\n", strength, breaks, world.entityCount(),
                world.shapeCount() - shapes_before, breaks ? 1e3 * fracture_s / breaks : 0.0, 1e3 * worst,
                total_s > 0 ? 100.0 * fracture_s / total_s : 0.0);
    std::fflush(stdout);
  }
  return 0;
}
