// Steady frame rate (issue 6, item 7): the paper's reason for interrupting.
// Worst case: the packed box with gravity into one corner (scene corner_drift),
// so every body ends up in one pile and the narrow phase keeps growing.
// 60 s of simulated ticks at 60 Hz, once with the budget off and once with a
// wall-clock budget on the narrow phase, same scene, scheduler and gaze.
//
// Per tick: total tick time; non-interruptible part = integrate + broad +
// response (total - narrow); overshoot = narrow-phase time - budget (how late
// the narrow phase ends past its deadline: the last step, plus the
// non-interruptible set-up and accounting around the scheduler).
// Frame deadline D = budget + p99 of the non-interruptible part (this run).
// Target: p99 tick <= 1.1 x D.
//
// Usage: bench_steady_frame_rate [--quick] [--budget-ms B] [--seconds S]
//                                [--markdown FILE]
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "tick_clock.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace stc;
using stc_bench::percentile;
// Thread CPU time beside the wall time: immune to the process being
// descheduled on a shared machine (the budget itself is wall time).
using stc_bench::threadCpuSeconds;

struct Run {
  std::vector<double> total, narrow, nonint, overshoot, cpu;
  std::vector<double> unresolved_share;
  int interrupted = 0;
  double final_spread = 0;  // mean distance of the movers from the corner at the end
};

Run simulate(const SceneParams& params, double seconds, const Budget& budget) {
  WorldConfig config;
  config.gravity = sceneGravity(SceneKind::CornerDrift);
  config.scheduler.kind = SchedulerKind::PriorityQueues;
  World world(config);
  const SceneSpec spec = populateScene(world, SceneKind::CornerDrift, params);
  world.perception().setCamera(spec.camera);
  GazeParams gp;
  gp.mode = GazeMode::Saccades;
  gp.seed = 3;
  GazeModel gaze(gp);
  Run run;
  const int ticks = static_cast<int>(std::lround(seconds / spec.dt));
  const bool timed = std::isfinite(budget.seconds);
  for (int i = 0; i < ticks; ++i) {
    world.perception().setFixation(gaze.fixationAt(i * spec.dt, world));
    const double c0 = threadCpuSeconds();
    const TickReport r = world.step(spec.dt, budget);
    run.cpu.push_back(threadCpuSeconds() - c0);
    run.total.push_back(r.total_s);
    run.narrow.push_back(r.narrow_s);
    run.nonint.push_back(r.total_s - r.narrow_s);
    run.unresolved_share.push_back(r.broad_pairs ? double(r.unresolved) / double(r.broad_pairs) : 0.0);
    if (r.interrupted) {
      ++run.interrupted;
      if (timed) run.overshoot.push_back(r.narrow_s - budget.seconds);
    }
  }
  double spread = 0;
  for (EntityId id : spec.movers) spread += world.bodies()[*world.indexOf(id)].pose.position.norm();
  run.final_spread = spread / static_cast<double>(spec.movers.size());
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  double budget_ms = 2.0;
  double seconds = 60.0;
  std::string markdown;
  SceneParams params;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string { return i + 1 < argc ? argv[++i] : ""; };
    if (a == "--quick") {
      seconds = 5.0;
      params.entities = 125;
    } else if (a == "--budget-ms") {
      budget_ms = std::stod(next());
    } else if (a == "--seconds") {
      seconds = std::stod(next());
    } else if (a == "--markdown") {
      markdown = next();
    } else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  const double budget = budget_ms * 1e-3;
  std::fprintf(stderr, "corner_drift: %.0f s simulated, budget off ...\n", seconds);
  const Run off = simulate(params, seconds, Budget::unlimited());
  std::fprintf(stderr, "corner_drift: %.0f s simulated, budget %.2f ms ...\n", seconds, budget_ms);
  const Run on = simulate(params, seconds, Budget::ofSeconds(budget));

  std::string md;
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "Scene corner_drift (%d entities, gravity into one corner), %.0f s at 60 Hz "
                "(%zu ticks per run), priority queues, saccadic gaze, policy accept.\n"
                "Budget on: %.2f ms of narrow phase. D = budget + p99 of the non-interruptible "
                "phases (integrate + broad + response) of that run. Times in ms.\n\n",
                params.entities > 0 ? params.entities : 500, seconds, on.total.size(), budget_ms);
  md += buf;
  md += "| run | p50 tick | p99 tick | max tick | p99 non-interr. | D | p99 / D | ticks > D | "
        "ticks interrupted | p50 narrow | p99 narrow | CPU p50 | CPU p99 | CPU max |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  const double d = budget + percentile(on.nonint, 0.99);
  for (const auto& [name, r] : {std::pair<const char*, const Run&>{"budget off", off},
                                std::pair<const char*, const Run&>{"budget on", on}}) {
    const double over = static_cast<double>(
        std::count_if(r.total.begin(), r.total.end(), [&](double t) { return t > d; }));
    std::snprintf(buf, sizeof buf,
                  "| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | %.1f%% | %.1f%% | %.3f | %.3f | "
                  "%.3f | %.3f | %.3f |\n",
                  name, 1e3 * percentile(r.total, 0.5), 1e3 * percentile(r.total, 0.99),
                  1e3 * *std::max_element(r.total.begin(), r.total.end()),
                  1e3 * percentile(r.nonint, 0.99), 1e3 * d, percentile(r.total, 0.99) / d,
                  100.0 * over / static_cast<double>(r.total.size()),
                  100.0 * r.interrupted / static_cast<double>(r.total.size()),
                  1e3 * percentile(r.narrow, 0.5), 1e3 * percentile(r.narrow, 0.99),
                  1e3 * percentile(r.cpu, 0.5), 1e3 * percentile(r.cpu, 0.99),
                  1e3 * *std::max_element(r.cpu.begin(), r.cpu.end()));
    md += buf;
  }
  std::snprintf(buf, sizeof buf,
                "\nOvershoot past the deadline (narrow-phase time - budget, interrupted ticks): "
                "p50 %.3f ms, p99 %.3f ms, max %.3f ms.\n"
                "Unresolved share of broad pairs with the budget on: p50 %.1f%%, p99 %.1f%%.\n"
                "Mean distance of the movers from the corner at the end: %.2f m (off), %.2f m (on).\n",
                1e3 * percentile(on.overshoot, 0.5), 1e3 * percentile(on.overshoot, 0.99),
                on.overshoot.empty() ? NAN : 1e3 * *std::max_element(on.overshoot.begin(), on.overshoot.end()),
                100 * percentile(on.unresolved_share, 0.5), 100 * percentile(on.unresolved_share, 0.99),
                off.final_spread, on.final_spread);
  md += buf;
  std::printf("%s", md.c_str());
  if (!markdown.empty()) std::ofstream(markdown) << md;
  return 0;
}
