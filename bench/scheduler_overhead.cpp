// Scheduling overhead at unlimited budget (issue 11 item 1): one snapshot of
// a scene (packed box after 36 ticks, rockfall after 80, the gaze on one
// rock), stepped `ticks` times by one World per scheduler with the response
// off. At unlimited budget every scheduler does identical work (same pairs,
// same states, same sphere tests), so what one costs beyond round-robin is its
// bookkeeping.
//
// Prints per scheduler: the median tick's narrow phase (ms) and the
// scheduler's own overhead figure (ScheduleStats::overhead_seconds) as a share
// of it. The schedulers' worlds take their ticks in turn. Ticks during which the thread lost its core (wall time more than
// 20 us over thread CPU time) are run again, so the load of a shared machine
// does not enter the figures.
//
// Instruction counts (stable under load): all the work of the timed ticks is
// inside measureTicks(), so
//   valgrind --tool=callgrind --toggle-collect='*measureTicks*' bench_scheduler_overhead
//     --scheduler priority_queues --ticks 5 --no-retry
//   callgrind_annotate --inclusive=yes callgrind.out.PID | grep -E 'narrowPhase|::run|PairTest::step'
// gives the narrow phase, the scheduler's run() and the sphere-tree steps inside
// it; run() less step() is the scheduler's own work.
//
// Usage: bench_scheduler_overhead [--scene packed_box|rockfall] [--scheduler NAME|all] [--ticks N]
//          [--no-retry] [--queues K --ratio R --cost-exponent A] [--smoke]
//   --smoke: 3 ticks, no retry: that the bench runs, scripts/bench_smoke.sh
#include "sphere_tree_collision/gaze_model.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include "bench_args.hpp"
#include "scene_sim.hpp"
#include "tick_clock.hpp"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace {

using namespace stc;

struct TickTimes {
  std::vector<double> narrow_s, overhead_share;
};

// Everything timed happens in here (the callgrind toggle above). The worlds
// take their ticks in turn, so a change of the machine's speed or load during
// the run hits every scheduler alike.
__attribute__((noinline)) std::vector<TickTimes> measureTicks(const std::vector<World*>& worlds, int ticks,
                                                              double retry_s) {
  std::vector<TickTimes> out(worlds.size());
  for (int t = 0; t < ticks; ++t) {
    for (std::size_t w = 0; w < worlds.size(); ++w) {
      for (int attempt = 0;; ++attempt) {
        const double cpu0 = stc_bench::threadCpuSeconds();
        const double wall0 = stc_bench::wallSeconds();
        const TickReport report = worlds[w]->step(0.0, Budget::unlimited());
        const double lost = (stc_bench::wallSeconds() - wall0) - (stc_bench::threadCpuSeconds() - cpu0);
        if (lost > retry_s && attempt < 20) continue;  // descheduled: not this code's time
        out[w].narrow_s.push_back(report.phases.narrow_s);
        out[w].overhead_share.push_back(report.detection.scheduling_overhead_s / report.phases.narrow_s);
        break;
      }
    }
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene = "packed_box", only = "all";
  int ticks = 60;
  SchedulerOptions queues;  // priority queues' options (defaults)
  double retry_s = 20e-6;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string& a = args.flag();
    if (a == "--scene") scene = args.value();
    else if (a == "--scheduler") only = args.value();
    else if (a == "--ticks") ticks = std::stoi(args.value());
    else if (a == "--no-retry") retry_s = 1e9;
    else if (a == "--smoke") ticks = 3, retry_s = 1e9;
    else if (a == "--queues") queues.queue_count = std::stoi(args.value());
    else if (a == "--ratio") queues.queue_ratio = std::stod(args.value());
    else if (a == "--cost-exponent") queues.cost_exponent = std::stod(args.value());
    else return args.unknown();
  }
  const SceneKind kind = parseScene(scene);
  SceneWorld scene_sim = stc_bench::makeSceneSim(kind);
  World& sim = scene_sim.world;
  const SceneSpec& spec = scene_sim.spec;
  const WorldConfig config = sim.config();
  const int warmup = kind == SceneKind::Rockfall ? 80 : 36;
  for (int i = 0; i < warmup; ++i) sim.step(spec.dt, Budget::unlimited());
  GazeParams follow;
  follow.mode = GazeMode::Follow;
  follow.target = spec.movers[spec.movers.size() / 2];
  GazeModel gaze(follow);
  const Vec2 fixation = gaze.fixationAt(warmup * spec.dt, sim);

  std::printf("%s, %zu pairs, gaze (%.0f, %.0f) px, %d ticks\n", scene.c_str(), sim.pairCount(),
              fixation.x(), fixation.y(), ticks);
  std::printf("| scheduler | narrow ms (median tick) | overhead / narrow %% (median tick) |\n|---|---|---|\n");
  std::vector<const char*> names;
  std::vector<std::unique_ptr<World>> worlds;
  for (const char* name : {"round_robin", "sequential", "perceptual_sequential", "priority_queues"}) {
    if (only != "all" && only != name) continue;
    WorldConfig eval_config = config;
    eval_config.response.enabled = false;
    eval_config.unresolved_policy = UnresolvedPolicy::Accept;
    eval_config.scheduler = queues;
    eval_config.scheduler.kind = parseScheduler(name);
    auto eval = std::make_unique<World>(eval_config);
    populateScene(*eval, kind);
    eval->perception().setCamera(spec.camera);
    for (std::size_t i = 0; i < sim.entityCount(); ++i) eval->bodies()[i].pose = sim.bodies()[i].pose;
    eval->perception().setFixation(fixation);
    eval->step(0.0, Budget::unlimited());  // warm
    names.push_back(name);
    worlds.push_back(std::move(eval));
  }
  std::vector<World*> stepped;
  for (auto& w : worlds) stepped.push_back(w.get());
  const std::vector<TickTimes> times = measureTicks(stepped, ticks, retry_s);
  for (std::size_t w = 0; w < names.size(); ++w) {
    std::printf("| %s | %.3f | %.1f |\n", names[w], 1e3 * stc_bench::percentile(times[w].narrow_s, 0.5),
                100.0 * stc_bench::percentile(times[w].overhead_share, 0.5));
  }
  return 0;
}
