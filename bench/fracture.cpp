// Fracture cost (issue 14, item 3): the rockfall with breakable rocks. Per
// strength, first with no budget (every break made in its tick), then under
// a tick budget of one frame (the scene's dt) on the thread's CPU clock
// (World::setClock: immune to the process being descheduled): bodies broken,
// pieces' trees built and their time, the breaks waiting, and the whole
// tick's time on the ticks that made pieces against the budget.
// Prints markdown tables (docs/fracture.md).
//
//   bench_fracture [rocks] [seconds]    defaults 200 rocks, 6 s of simulated time
//   bench_fracture --smoke              20 rocks, 0.5 s: that the bench runs (scripts/bench_smoke.sh)
#include "sphere_tree_collision/scenes.hpp"

#include "tick_clock.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

using namespace stc;
using stc_bench::maxOf;
using stc_bench::meanOf;
using stc_bench::percentile;

namespace {

struct Run {
  std::size_t breaks = 0, trees = 0, entities = 0, shapes = 0, most_waiting = 0;
  double fracture_s = 0.0, total_s = 0.0, budget_s = 0.0;
  std::vector<double> tree_s;         // per tick that built trees: its mean seconds per tree
  std::vector<double> piece_ticks_s;  // whole tick, ticks that built trees or made breaks
  std::vector<double> other_ticks_s;  // whole tick, the others
};

Run simulate(int rocks, double seconds, double strength, bool budgeted) {
  SceneParams params;
  params.entities = rocks;
  SceneWorld scene = makeSceneWorld(SceneKind::Rockfall, params);
  World& world = scene.world;
  const SceneSpec& spec = scene.spec;
  for (BodyState& body : world.bodies()) {
    if (!body.is_static) body.material.strength = strength;
  }
  world.setClock(stc_bench::threadCpuSeconds);
  const Budget budget = budgeted ? Budget::ofTickSeconds(spec.dt) : Budget::unlimited();
  Run run;
  run.budget_s = spec.dt;
  const std::size_t shapes_before = world.shapeCount();
  const int ticks = static_cast<int>(seconds / spec.dt);
  for (int i = 0; i < ticks; ++i) {
    const TickReport r = world.step(spec.dt, budget);
    run.breaks += r.fracture.fractures;
    run.trees += r.fracture.piece_trees;
    run.fracture_s += r.fracture.fracture_s;
    run.total_s += r.phases.total_s;
    run.most_waiting = std::max(run.most_waiting, r.fracture.fractures_deferred);
    if (r.fracture.piece_trees > 0)
      run.tree_s.push_back(r.fracture.piece_tree_s / static_cast<double>(r.fracture.piece_trees));
    (r.fracture.piece_trees > 0 || r.fracture.fractures > 0 ? run.piece_ticks_s : run.other_ticks_s)
        .push_back(r.phases.total_s);
  }
  run.entities = world.entityCount();
  run.shapes = world.shapeCount() - shapes_before;
  return run;
}

std::size_t countOver(const std::vector<double>& v, double limit) {
  return static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [limit](double x) { return x > limit; }));
}

}  // namespace

int main(int argc, char** argv) {
  const bool smoke = argc > 1 && std::strcmp(argv[1], "--smoke") == 0;
  const int rocks = smoke ? 20 : argc > 1 ? std::atoi(argv[1]) : 200;
  const double seconds = smoke ? 0.5 : argc > 2 ? std::atof(argv[2]) : 6.0;
  const std::vector<double> strengths = {0.0, 200.0, 100.0, 50.0};
  std::printf("rockfall, %d rocks (0.4 m, resolution 8), %.1f s simulated, min_piece_voxels 8 attach, "
              "thread CPU clock\n\n", rocks, seconds);

  std::printf("No budget:\n\n| strength (N s) | breaks | entities at end | new shapes | trees | "
              "time per tree mean / p99 (ms) | time per break (ms) | fracture share of tick time |\n"
              "|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const double strength : strengths) {
    const Run r = simulate(rocks, seconds, strength, false);
    std::printf("| %.0f | %zu | %zu | %zu | %zu | %.2f / %.2f | %.2f | %.1f%% |\n", strength, r.breaks, r.entities,
                r.shapes, r.trees, 1e3 * meanOf(r.tree_s), 1e3 * percentile(r.tree_s, 0.99),
                r.breaks ? 1e3 * r.fracture_s / static_cast<double>(r.breaks) : 0.0,
                r.total_s > 0 ? 100.0 * r.fracture_s / r.total_s : 0.0);
    std::fflush(stdout);
  }

  std::printf("\nTick budget of one frame:\n\n| strength (N s) | budget (ms) | breaks | trees | most waiting | "
              "ticks making pieces | their tick p50 / p99 / max (x budget) | over budget | "
              "other ticks p99 (x budget) | over budget |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const double strength : strengths) {
    const Run r = simulate(rocks, seconds, strength, true);
    const double b = r.budget_s;
    std::printf("| %.0f | %.1f | %zu | %zu | %zu | %zu | %.2f / %.2f / %.2f | %zu | %.2f | %zu of %zu |\n", strength,
                1e3 * b, r.breaks, r.trees, r.most_waiting, r.piece_ticks_s.size(),
                percentile(r.piece_ticks_s, 0.5) / b, percentile(r.piece_ticks_s, 0.99) / b,
                maxOf(r.piece_ticks_s) / b, countOver(r.piece_ticks_s, b), percentile(r.other_ticks_s, 0.99) / b,
                countOver(r.other_ticks_s, b), r.other_ticks_s.size());
    std::fflush(stdout);
  }
  return 0;
}
