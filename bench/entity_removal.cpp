// Cost of removing entities (issue 48, item 1): a lattice of N cubes whose
// broad-phase boxes overlap all 26 neighbours' (about 13 pairs per cube, the
// cubes themselves apart, no gravity: nothing moves), stepped once so the
// broad phase holds its pairs; then K cubes, chosen at random (seeded), are
// removed in one batch, as the quarantine does, and the world is stepped
// again. Thread CPU time of the K World::removeEntity calls, per removal,
// and of the tick after them (the broad phase drops the removed boxes'
// endpoints and pairs there) beside the tick before them. Median of R runs.
//
//   bench_entity_removal [--entities N] [--remove K] [--runs R]   defaults 10000, 1000, 5
//   bench_entity_removal --smoke                                   1000, 100, 1 run: that it runs
#include "sphere_tree_collision/world.hpp"

#include "bench_args.hpp"
#include "sweep_and_prune.hpp"
#include "tick_clock.hpp"
#include "world_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

using namespace stc;
using stc_bench::percentile;
using stc_bench::threadCpuSeconds;

namespace {

struct Options {
  int entities = 10000;
  int remove = 1000;
  int runs = 5;
};

Options parse(int argc, char** argv) {
  Options o;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string& a = args.flag();
    if (a == "--entities") o.entities = std::stoi(args.required());
    else if (a == "--remove") o.remove = std::stoi(args.required());
    else if (a == "--runs") o.runs = std::stoi(args.required());
    else if (a == "--smoke") o = Options{1000, 100, 1};
    else throw InputError(a, "unknown argument");
  }
  if (o.entities < 1) throw InputError("--entities", "must be >= 1");
  if (o.remove < 0 || o.remove > o.entities) throw InputError("--remove", "must be in [0, --entities]");
  if (o.runs < 1) throw InputError("--runs", "must be >= 1");
  return o;
}

struct Run {
  std::size_t pairs_before = 0, pairs_after = 0;
  double tick_before_s = 0.0, remove_s = 0.0, tick_after_s = 0.0;
};

Run runOnce(const Options& o, std::uint32_t seed) {
  WorldConfig config;
  config.max_entities = static_cast<std::size_t>(o.entities);
  World world(config);
  const double side = 0.4;  // cube of 8 voxels of 5 cm
  const ShapeId cube = world.addShape("cube", makePreset("cube"));
  // Spacing 1.2 sides: the cubes are apart, their fixed-cube boxes (half
  // width sqrt(3)/2 side) overlap every neighbour's on the lattice.
  const double spacing = 1.2 * side;
  const int n = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(o.entities))));
  std::vector<EntityId> ids;
  for (int k = 0; static_cast<int>(ids.size()) < o.entities; ++k) {
    const int i = k % n, j = (k / n) % n, l = k / (n * n);
    EntitySpec spec;
    spec.shape = cube;
    spec.pose.position = Vec3(i, j, l) * spacing;
    ids.push_back(world.addEntity(spec));
  }
  Run run;
  const double dt = 1.0 / 60.0;
  world.step(dt, Budget::unlimited());  // the first sort of the broad phase
  double t = threadCpuSeconds();
  world.step(dt, Budget::unlimited());
  run.tick_before_s = threadCpuSeconds() - t;
  run.pairs_before = broadPhase(world).pairs().size();

  std::mt19937 rng(seed);
  std::shuffle(ids.begin(), ids.end(), rng);
  t = threadCpuSeconds();
  for (int r = 0; r < o.remove; ++r) world.removeEntity(ids[static_cast<std::size_t>(r)]);
  run.remove_s = threadCpuSeconds() - t;
  t = threadCpuSeconds();
  world.step(dt, Budget::unlimited());
  run.tick_after_s = threadCpuSeconds() - t;
  run.pairs_after = broadPhase(world).pairs().size();
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (!stc_bench::parseFlags("bench_entity_removal", parse, argc, argv, o)) return 2;
  std::vector<double> before, remove, after;
  Run last;
  for (int r = 0; r < o.runs; ++r) {
    last = runOnce(o, static_cast<std::uint32_t>(r + 1));
    before.push_back(last.tick_before_s);
    remove.push_back(last.remove_s);
    after.push_back(last.tick_after_s);
  }
  std::printf("entity removal: %d cubes on a lattice, %zu broad-phase pairs, %d removed at random in one batch "
              "(%zu pairs left), median of %d runs, thread CPU, load %.2f\n\n",
              o.entities, last.pairs_before, o.remove, last.pairs_after, o.runs, stc_bench::loadAverage());
  std::printf("| removals (ms) | per removal (us) | tick before (ms) | tick after the removals (ms) |\n"
              "|---:|---:|---:|---:|\n");
  const double removal_ms = 1e3 * percentile(remove, 0.5);
  std::printf("| %.2f | %.2f | %.2f | %.2f |\n", removal_ms, o.remove > 0 ? 1e3 * removal_ms / o.remove : 0.0,
              1e3 * percentile(before, 0.5), 1e3 * percentile(after, 0.5));
  return 0;
}
