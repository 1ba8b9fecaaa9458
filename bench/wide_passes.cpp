// What the solver's four-wide passes (ResponseOptions::wide_passes,
// contact_solver_wide.cpp) save: the same scene stepped with the passes four
// manifolds at a time and one at a time, on one thread, unlimited budget.
// Both compute the same bits tick for tick (test_wide_passes; checked here
// on every tick too), so they do the same work and only the time differs.
// The two worlds tick in turns of 30 ticks, so a shared machine's load falls
// on both alike.
//
// Per run: thread-CPU ms of the whole tick (p50, mean) and the response's
// wall ms (p50, mean; the response is where the passes are), with the
// one-at-a-time / four-wide ratios.
//
// Usage: bench_wide_passes [--scenes corner_drift:500,rockfall:1000,packed_box:500,cube_box:10000]
//          [--seconds 3] [--cube-seconds 1.5] [--settle 1] [--smoke]
//   --seconds: simulated time timed per scene (cube_box: --cube-seconds);
//   --settle: simulated time run first, untimed (both worlds).
// Last lines: WIDE scene=<name> tick_x=<ratio of tick CPU p50> response_x=<ratio of response p50>.
#include "bench_args.hpp"
#include "same_bits.hpp"
#include "scene_cases.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "tick_clock.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using namespace stc;
using stc_bench::loadAverage;
using stc_bench::meanOf;
using stc_bench::percentile;
using stc_bench::threadCpuSeconds;

using Case = stc_bench::SceneCase;
using stc_bench::caseName;

using Options = stc_bench::SceneTiming;  // its defaults: 3 s a scene, cube_box 1.5 s, 1 s settling

struct Run {
  std::vector<double> tick_cpu, response;  // seconds per tick
};

SceneWorld makeWorld(const Case& c, bool wide) {
  WorldConfig config;
  config.response.wide_passes = wide;
  SceneParams params;
  params.entities = c.bodies;
  return makeSceneWorld(c.kind, params, config);
}

void timedTicks(World& world, double dt, int ticks, Run& run) {
  for (int t = 0; t < ticks; ++t) {
    const double cpu0 = threadCpuSeconds();
    const TickReport r = world.step(dt, Budget::unlimited());
    run.tick_cpu.push_back(threadCpuSeconds() - cpu0);
    run.response.push_back(r.phases.response_s);
  }
}

bool sameBodies(const World& x, const World& y) {
  if (x.entityCount() != y.entityCount()) return false;
  for (std::size_t i = 0; i < x.entityCount(); ++i) {
    if (!sameBits(x.bodies()[i], y.bodies()[i])) return false;
  }
  return true;
}

double ms(double s) { return 1e3 * s; }
double ratio(double a, double b) { return b > 0.0 ? a / b : NAN; }

Options parseOptions(int argc, char** argv) {
  Options o;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string a = args.flag();
    if (!o.take(a, args)) {
      throw InputError(a, "unknown option (see the comment at the top of bench/wide_passes.cpp)");
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (!stc_bench::parseFlags("bench_wide_passes", parseOptions, argc, argv, options)) return 2;
  constexpr int kTurn = 30;  // ticks per turn
  std::printf("# solver passes four manifolds wide against one at a time: one thread, unlimited budget\n");
  std::printf("| scene | ticks | tick CPU p50 / mean ms, one at a time | four wide | response p50 / mean ms, one at a time "
              "| four wide | tick x | response x | same bits |\n|---|---|---|---|---|---|---|---|---|\n");
  std::vector<std::string> summary;
  for (const Case& c : options.cases) {
    SceneWorld one = makeWorld(c, false);
    SceneWorld wide = makeWorld(c, true);
    const double dt = one.spec.dt;
    const double seconds = options.secondsOf(c);
    const int ticks = std::max(1, static_cast<int>(std::lround(seconds / dt)));
    const int settle = static_cast<int>(std::lround(options.settle / dt));
    bool same = true;
    for (int t = 0; t < settle; ++t) {
      one.world.step(dt, Budget::unlimited());
      wide.world.step(dt, Budget::unlimited());
      same = same && sameBodies(one.world, wide.world);
    }
    Run run_one, run_wide;
    for (int done = 0; done < ticks; done += kTurn) {
      const int n = std::min(kTurn, ticks - done);
      timedTicks(one.world, dt, n, run_one);
      timedTicks(wide.world, dt, n, run_wide);
      same = same && sameBodies(one.world, wide.world);
    }
    const double tick_one = percentile(run_one.tick_cpu, 0.5), tick_wide = percentile(run_wide.tick_cpu, 0.5);
    const double resp_one = percentile(run_one.response, 0.5), resp_wide = percentile(run_wide.response, 0.5);
    std::printf("| %s | %d | %.1f / %.1f | %.1f / %.1f | %.1f / %.1f | %.1f / %.1f | %.2f | %.2f | %s |\n",
                caseName(c).c_str(), ticks, ms(tick_one), ms(meanOf(run_one.tick_cpu)), ms(tick_wide),
                ms(meanOf(run_wide.tick_cpu)), ms(resp_one), ms(meanOf(run_one.response)), ms(resp_wide),
                ms(meanOf(run_wide.response)), ratio(tick_one, tick_wide), ratio(resp_one, resp_wide),
                same ? "yes" : "NO");
    std::fflush(stdout);
    char line[256];
    std::snprintf(line, sizeof line, "WIDE scene=%s tick_x=%.2f response_x=%.2f", caseName(c).c_str(),
                  ratio(tick_one, tick_wide), ratio(resp_one, resp_wide));
    summary.emplace_back(line);
  }
  std::printf("# load average %.2f\n", loadAverage());
  for (const std::string& line : summary) std::printf("%s\n", line.c_str());
  return 0;
}
