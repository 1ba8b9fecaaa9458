// Steady frame rate of the whole tick (issue 9, item 2; issue 49, items 4
// and 5): integrate, broad phase, narrow phase and response under one tick
// budget (Budget::tick_seconds). Scenes (default): corner_drift 500 (the packed
// box with gravity into one corner: the paper's worst case, everything ends in
// one pile), rockfall 1,000 and 5,000, cube_box 10,000 and pyramid 5,050 (Box2D's
// large_pyramid); 60 s of simulated ticks at 60 Hz each, priority queues,
// saccadic gaze, policy accept. Each scene runs twice, side by side: under the
// budget, and unbudgeted (Budget::unlimited(), the reference).
//
// Per tick: whole-tick thread CPU time (clock_gettime(CLOCK_THREAD_CPUTIME_ID))
// and wall time; the phase split and what the narrow phase and the response got
// (TickReport); solver passes. Target: p99 whole tick <= 1.1 x budget. At the
// end, the plausibility figures of issue 49 item 4 (test/support/plausibility.hpp,
// the figures test_budget_plausibility asserts) for both runs: movers with a
// non-finite state, out of the scene's bounds (each named on stderr;
// --trace-escape names them at every tick they are outside, from the first,
// with what that tick did), the fastest mover against a fall from the scene's
// top, 0.5 s windows whose stored and real speeds differ by more than
// 10 % + 0.05 m/s, how deep the movers reach into static plates (p99 in
// voxels), movers asleep, their mean height against the unbudgeted run's. And
// movers that moved in the last second, how many contacts a tick came from
// unresolved pairs and from their root spheres, and how many unresolved pairs
// a tick kept a deeper frontier's contacts (TickReport::response.frontier_kept).
//
// The budget runs on the thread's CPU clock by default (World::setClock), so
// the other processes of a shared machine do not eat it; --wall-clock runs it
// on the steady clock, as the node does.
//
// Usage: bench_steady_frame_rate [--scene all|NAME[:N][,NAME[:N]...]] [--entities N]
//          [--tick-budget-ms 16.7] [--seconds 60] [--budget-off] [--no-reference] [--wall-clock]
//          [--trace-escape] [--trace-ticks FILE] [--sphere-tests N] [--solver-iterations N]
//          [--position-correction F] [--reuse-tolerance T] [--solver sequential|jacobi|soft]
//          [--markdown FILE] [--smoke]
//   --scene: a bare NAME picks that scene's default cases (rockfall: 1,000 and 5,000)
//   --entities N: every chosen scene at N movers instead
//   --budget-off: the unbudgeted run alone; --no-reference: the budgeted run alone
//   --reuse-tolerance T: ResponseOptions::reuse_tolerance in [0, 1] (0: every pair built
//     every tick; default: the World's), to measure contact recycling off and on
//   --trace-ticks FILE: a CSV line a tick of every run (its cost, contacts, the island levels)
//   --smoke: every scene at 100 entities for 0.05 s: that the bench runs, scripts/bench_smoke.sh
//   A budgeted tick's contacts without its clock: `--tick-budget-ms 1e9 --sphere-tests 0
//   --no-reference` (every pair cut at its root spheres, as a starved budget leaves it, but
//   nothing timed, so two builds give the same ticks): how solver changes were weighed for
//   the budgeted case (budgeted runs follow the clock and part after a few ticks).
#include "bench_args.hpp"
#include "plausibility.hpp"
#include "scene_cases.hpp"
#include "sphere_tree_collision/gaze_model.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"
#include "tick_clock.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace {

using namespace stc;
using stc_bench::maxOf;
using stc_bench::percentile;
// Thread CPU time beside the wall time: immune to the process being
// descheduled on a shared machine (the budget itself is wall time).
using stc_bench::threadCpuSeconds;
using Case = stc_bench::SceneCase;

const std::vector<Case> kDefaultCases{{SceneKind::CornerDrift, 500},
                                      {SceneKind::Rockfall, 1000},
                                      {SceneKind::Rockfall, 5000},
                                      {SceneKind::CubeBox, 10000},
                                      {SceneKind::Pyramid, 5050}};

struct Run {
  std::string scene;
  int bodies = 0;
  bool budgeted = false;
  std::vector<double> cpu, wall;                           // whole tick, s
  std::vector<double> cpu_but_integrate;                   // whole tick less integrate, s
  std::vector<double> integrate, broad, narrow, response;  // TickReport (budget clock), s
  std::vector<double> narrow_got, reserve;                 // s, ticks with a tick budget
  std::vector<double> velocity_passes, position_passes, unresolved_share;
  int interrupted = 0;
  truth::Plausibility plausibility;  // issue 49, item 4
  // Movers that went more than kMovedMetres in the last second: whether the
  // scene came to rest, as a viewer would judge it at the end.
  std::size_t moving = 0;
  // Contacts a tick over the run (mean), of them those of accepted
  // unresolved pairs, and of those the ones built from the root spheres
  // (level 0). Per tick they swing with what the narrow phase got.
  double contacts = 0.0, unresolved_contacts = 0.0, root_contacts = 0.0;
  double frontier_kept = 0.0;  // pairs a tick (mean) that kept a deeper frontier's contacts
  // Island levels (TickReport::response.levels), means a tick: islands stepped fully
  // and held, of those held the ones a moving body joined to the tick, bodies
  // held; the longest wait (ticks); summed over the run, the held body-ticks
  // (each one tick of simulated time a body lags behind) and the held
  // islands' gaze priority (the perceived cost: ticks held weighted by how
  // noticeable each island was).
  double islands_full = 0.0, islands_held = 0.0, islands_joined = 0.0, bodies_held = 0.0;
  int most_ticks_held = 0;
  std::vector<double> largest_island;  // bodies, a tick
  double held_body_ticks = 0.0, held_priority = 0.0;
};


constexpr double kMovedMetres = 0.02;

// What every run of the bench shares, from the command line.
struct RunSettings {
  double seconds = 60.0;
  double position_correction = NAN;  // NaN: the World's default
  double reuse_tolerance = NAN;      // NaN: the World's default
  SolverKind solver = ResponseOptions{}.solver;
  bool wall_clock = false;
  bool trace_escape = false;
  std::FILE* trace_ticks = nullptr;  // --trace-ticks: a CSV line a tick, or none
};

// --trace-ticks: what each tick cost and what the island levels did, to see
// which ticks make p99 and why.
constexpr const char* kTraceHeader =
    "scene,bodies,run,tick,cpu_ms,response_ms,contacts_ms,narrow_ms,contacts,islands_full,bodies_full,"
    "islands_held,bodies_held,islands_joined,largest_island,most_ticks_held,full_cost,allowance,velocity_passes\n";

Run simulate(const Case& c, const RunSettings& settings, const Budget& budget, bool budgeted) {
  const double seconds = settings.seconds;
  WorldConfig config;
  config.scheduler.kind = SchedulerKind::PriorityQueues;
  config.response.solver = settings.solver;
  if (std::isfinite(settings.position_correction)) config.response.position_correction = settings.position_correction;
  if (std::isfinite(settings.reuse_tolerance)) config.response.reuse_tolerance = settings.reuse_tolerance;
  SceneParams params;
  params.entities = c.bodies;
  SceneWorld scene = makeSceneWorld(c.kind, params, config);
  World& world = scene.world;
  const SceneSpec& spec = scene.spec;
  if (!settings.wall_clock) world.setClock(threadCpuSeconds);
  GazeParams gp;
  gp.mode = GazeMode::Saccades;
  gp.seed = 3;
  GazeModel gaze(gp);
  Run run;
  run.scene = toString(c.kind);
  run.bodies = static_cast<int>(spec.movers.size());
  run.budgeted = budgeted;
  truth::PlausibilityCheck check(world, spec);
  const int ticks = static_cast<int>(std::lround(seconds / spec.dt));
  const int last_second = std::max(0, ticks - static_cast<int>(std::lround(1.0 / spec.dt)));
  std::vector<Vec3> second_before_end;  // the movers' positions a second before the end
  for (int i = 0; i < ticks; ++i) {
    if (i == last_second) {
      for (EntityId id : spec.movers) second_before_end.push_back(world.bodies()[*world.indexOf(id)].pose.position);
    }
    world.perception().setFixation(gaze.fixationAt(i * spec.dt, world));
    const double c0 = threadCpuSeconds();
    const auto w0 = std::chrono::steady_clock::now();
    const TickReport r = world.step(spec.dt, budget);
    run.wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());
    run.cpu.push_back(threadCpuSeconds() - c0);
    check.tick(world, spec.dt);  // outside the timed part
    run.cpu_but_integrate.push_back(run.cpu.back() - r.phases.integrate_s);
    run.integrate.push_back(r.phases.integrate_s);
    run.broad.push_back(r.phases.broad_s);
    run.narrow.push_back(r.phases.narrow_s);
    run.response.push_back(r.phases.response_s);
    if (std::isfinite(r.budget.tick_budget_s)) {
      run.narrow_got.push_back(r.budget.narrow_budget_s);
      run.reserve.push_back(r.budget.reserve_s);
    }
    run.velocity_passes.push_back(r.response.velocity_passes);
    run.position_passes.push_back(r.response.position_passes);
    run.unresolved_share.push_back(
        r.detection.broad_pairs ? double(r.detection.unresolved) / double(r.detection.broad_pairs) : 0.0);
    run.interrupted += r.detection.interrupted ? 1 : 0;
    run.frontier_kept += static_cast<double>(r.response.frontier_kept);
    run.islands_full += static_cast<double>(r.response.levels.islands_full);
    run.islands_held += static_cast<double>(r.response.levels.islands_held);
    run.islands_joined += static_cast<double>(r.response.levels.islands_joined);
    run.bodies_held += static_cast<double>(r.response.levels.bodies_held);
    run.held_body_ticks += static_cast<double>(r.response.levels.bodies_held);
    run.held_priority += r.response.levels.held_priority;
    run.most_ticks_held = std::max(run.most_ticks_held, r.response.levels.most_ticks_held);
    if (r.response.levels.used) run.largest_island.push_back(static_cast<double>(r.response.levels.largest_island));
    for (const Contact& contact : world.contacts()) {
      run.contacts += 1.0;
      if (contact.resolved) continue;
      run.unresolved_contacts += 1.0;
      run.root_contacts += contact.level == 0 ? 1.0 : 0.0;
    }
    if (i % 600 == 599) std::fprintf(stderr, "  %s: %d / %d ticks\n", run.scene.c_str(), i + 1, ticks);
    if (settings.trace_ticks != nullptr) {
      const IslandLevelReport& l = r.response.levels;
      std::fprintf(settings.trace_ticks, "%s,%d,%s,%d,%.3f,%.3f,%.3f,%.3f,%zu,%zu,%zu,%zu,%zu,%zu,%zu,%d,%.0f,%.0f,%d\n",
                   run.scene.c_str(), run.bodies, budgeted ? "budgeted" : "unbudgeted", i, run.cpu.back() * 1e3,
                   r.phases.response_s * 1e3, r.phases.contacts_s * 1e3, r.phases.narrow_s * 1e3, r.response.contacts,
                   l.islands_full, l.bodies_full, l.islands_held, l.bodies_held, l.islands_joined, l.largest_island,
                   l.most_ticks_held, l.full_cost, l.allowance, r.response.velocity_passes);
    }
    if (settings.trace_escape) {  // every tick a mover is outside: where, how fast, what the tick did
      for (EntityId id : spec.movers) {
        const BodyState& b = world.bodies()[*world.indexOf(id)];
        if (!spec.bounds.contains(b.pose.position)) {
          std::fprintf(stderr,
                       "  ESCAPE tick %d entity %u at (%.3f, %.3f, %.3f) v (%.3f, %.3f, %.3f) passes %d/%d unresolved "
                       "%zu contacts %zu\n",
                       i, static_cast<unsigned>(id), b.pose.position.x(), b.pose.position.y(), b.pose.position.z(),
                       b.linear_velocity.x(), b.linear_velocity.y(), b.linear_velocity.z(), r.response.velocity_passes,
                       r.response.position_passes, static_cast<std::size_t>(r.detection.unresolved),
                       static_cast<std::size_t>(r.response.contacts));
        }
      }
    }
  }
  if (ticks > 0) {
    run.contacts /= ticks;
    run.unresolved_contacts /= ticks;
    run.root_contacts /= ticks;
    run.frontier_kept /= ticks;
    run.islands_full /= ticks;
    run.islands_held /= ticks;
    run.islands_joined /= ticks;
    run.bodies_held /= ticks;
  }
  run.plausibility = check.finish(world);
  // Whether the movers went anywhere in the last second (a NaN pose counts as
  // moved), and which are out of the bounds.
  for (std::size_t k = 0; k < spec.movers.size(); ++k) {
    const EntityId id = spec.movers[k];
    const auto index = world.indexOf(id);
    if (!index) continue;
    const BodyState& b = world.bodies()[*index];
    if (k < second_before_end.size() && !((b.pose.position - second_before_end[k]).norm() <= kMovedMetres)) ++run.moving;
    if (!spec.bounds.contains(b.pose.position)) {
      std::fprintf(stderr, "  %s: entity %u outside the bounds at (%.3f, %.3f, %.3f), |v| %.3f m/s\n",
                   run.scene.c_str(), static_cast<unsigned>(id), b.pose.position.x(), b.pose.position.y(),
                   b.pose.position.z(), b.linear_velocity.norm());
    }
  }
  return run;
}

std::string ms3(double lo, double mid, double hi) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.1f / %.1f / %.1f", 1e3 * lo, 1e3 * mid, 1e3 * hi);
  return buf;
}

std::string pct(const std::vector<double>& v) {
  return ms3(percentile(v, 0.5), percentile(v, 0.99), maxOf(v));
}

std::string budgetLabel(const Run& r) { return r.budgeted ? "budgeted" : "unbudgeted"; }

// The plausibility row of `r`; `reference`: the unbudgeted run of the same
// scene, whose mean height the budgeted one is held to (within 10 %).
std::string plausibilityRow(const Run& r, const Run* reference) {
  const truth::Plausibility& f = r.plausibility;
  char height[64] = "";
  if (reference != nullptr) {
    const double ref = reference->plausibility.mean_height;
    std::snprintf(height, sizeof height, "%+.1f%%", 100.0 * (f.mean_height - ref) / ref);
  }
  char worst[32] = "-";
  if (f.windows > 0) std::snprintf(worst, sizeof worst, "%+.3f", f.worst_window_excess);
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "| %s | %d | %s | %zu | %zu | %.2f / %.2f | %zu | %zu of %zu (worst %s) | %.2f / %.2f | %zu "
                "| %zu of %zu | %.2f | %s |\n",
                r.scene.c_str(), r.bodies, budgetLabel(r).c_str(), f.non_finite, f.outside, f.max_speed,
                f.fall_speed, f.too_fast, f.bad_windows, f.windows, worst, f.sink_p99_voxels,
                f.max_sink_voxels, f.sunk, f.asleep, f.movers, f.mean_height, height);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene = "all";
  int entities = 0;
  double budget_ms = 16.7;
  RunSettings settings;
  double& seconds = settings.seconds;
  bool budget_off = false, reference = true, smoke = false;
  std::int64_t sphere_tests = std::numeric_limits<std::int64_t>::max();
  int solver_iterations = std::numeric_limits<int>::max();
  bool reuse_set = false;
  std::string markdown, trace_ticks;
  std::vector<Case> cases;
  try {
    for (stc_bench::Args args(argc, argv); args.more();) {
      const std::string& a = args.flag();
      if (a == "--scene") scene = args.required();
      else if (a == "--entities") entities = std::stoi(args.required());
      else if (a == "--tick-budget-ms") budget_ms = std::stod(args.required());
      else if (a == "--seconds") seconds = std::stod(args.required());
      else if (a == "--budget-off") budget_off = true;
      else if (a == "--no-reference") reference = false;
      else if (a == "--sphere-tests") sphere_tests = std::stoll(args.required());
      else if (a == "--solver-iterations") solver_iterations = std::stoi(args.required());
      else if (a == "--position-correction") settings.position_correction = std::stod(args.required());
      else if (a == "--reuse-tolerance") {
        settings.reuse_tolerance = std::stod(args.required());
        reuse_set = true;
      }
      else if (a == "--solver") settings.solver = parseSolverKind(args.required());
      else if (a == "--wall-clock") settings.wall_clock = true;
      else if (a == "--trace-escape") settings.trace_escape = true;
      else if (a == "--trace-ticks") trace_ticks = args.required();
      else if (a == "--markdown") markdown = args.required();
      else if (a == "--smoke") smoke = true;
      else return args.unknown();
    }
    if (entities < 0) throw InputError("--entities", "must be >= 0 (0: each scene's default cases)");
    if (reuse_set && !(settings.reuse_tolerance >= 0.0 && settings.reuse_tolerance <= 1.0)) {
      throw InputError("--reuse-tolerance", "must be in [0, 1]");
    }
    if (budget_off && !reference) throw InputError("--no-reference", "with --budget-off nothing would run");
    cases = scene == "all" ? kDefaultCases : stc_bench::parseSceneCases(scene, kDefaultCases);
    if (cases.empty()) throw InputError("--scene", "names no scene");
    if (!trace_ticks.empty()) {
      settings.trace_ticks = std::fopen(trace_ticks.c_str(), "w");
      if (settings.trace_ticks == nullptr) throw InputError("--trace-ticks", "cannot write '" + trace_ticks + "'");
      std::fputs(kTraceHeader, settings.trace_ticks);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_steady_frame_rate: %s\n", e.what());
    return 2;
  }
  if (entities > 0 || smoke) {  // one case a scene, at that count
    std::vector<Case> one;
    for (Case c : cases) {
      c.bodies = smoke ? std::min(100, entities > 0 ? entities : c.bodies) : entities;
      if (std::none_of(one.begin(), one.end(), [&](const Case& o) { return o.kind == c.kind; })) one.push_back(c);
    }
    cases = one;
  }
  if (smoke) seconds = 0.05;
  Budget budget = Budget::ofTickSeconds(budget_ms * 1e-3);
  // The budget's two deterministic forms, alone or beside the tick's: what a
  // pile does with pairs left unresolved, or with few solver passes.
  budget.sphere_tests = sphere_tests;
  budget.solver_iterations = solver_iterations;

  std::vector<Run> runs;  // per case: the budgeted run, then the unbudgeted one
  for (const Case& c : cases) {
    if (!budget_off) {
      std::fprintf(stderr, "%s %d under the budget: %.0f s simulated ...\n", toString(c.kind), c.bodies, seconds);
      runs.push_back(simulate(c, settings, budget, true));
    }
    if (reference) {
      std::fprintf(stderr, "%s %d unbudgeted: %.0f s simulated ...\n", toString(c.kind), c.bodies, seconds);
      runs.push_back(simulate(c, settings, Budget::unlimited(), false));
    }
  }

  if (settings.trace_ticks != nullptr) std::fclose(settings.trace_ticks);
  std::string md;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "%.0f s at 60 Hz per scene and run; tick budget %.1f ms (%s clock)%s; priority queues, "
                "saccadic gaze, policy accept. ms as p50 / p99 / max.",
                seconds, budget_ms, settings.wall_clock ? "steady" : "thread-CPU",
                budget_off ? ", unbudgeted runs only" : reference ? ", each scene also unbudgeted" : "");
  md += buf;
  if (sphere_tests < std::numeric_limits<std::int64_t>::max()) {
    md += " Sphere tests a budgeted tick: " + std::to_string(sphere_tests) + ".";
  }
  if (solver_iterations < std::numeric_limits<int>::max()) {
    md += " Solver iterations a budgeted tick: " + std::to_string(solver_iterations) + ".";
  }
  if (std::isfinite(settings.position_correction)) {
    std::snprintf(buf, sizeof buf, " Position correction: %.2f.", settings.position_correction);
    md += buf;
  }
  if (std::isfinite(settings.reuse_tolerance)) {
    std::snprintf(buf, sizeof buf, " Reuse tolerance: %.3g.", settings.reuse_tolerance);
    md += buf;
  }
  if (settings.solver != ResponseOptions{}.solver) md += std::string(" Solver: ") + toString(settings.solver) + ".";
  md += "\n\n";
  md += "| scene | bodies | run | whole tick CPU | whole tick wall | p99 CPU / budget | ticks > 1.1 budget "
        "| CPU less integrate | integrate | broad | narrow "
        "| narrow got | response | reserve | velocity passes p50 / min | position passes p50 / min "
        "| interrupted | unresolved p50 | moved > 2 cm in the last s "
        "| contacts a tick (mean): all / unresolved / at the roots "
        "| pairs a tick that kept a deeper frontier (mean) |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Run& r : runs) {
    const auto min_of = [](const std::vector<double>& v) { return v.empty() ? NAN : *std::min_element(v.begin(), v.end()); };
    std::snprintf(buf, sizeof buf,
                  "| %s | %d | %s | %s | %s | %.2f | %.1f%% | %s | %s | %s | %s | %s | %s | %s | %.0f / %.0f | %.0f / %.0f "
                  "| %.1f%% | %.1f%% | %zu | %.0f / %.0f / %.0f | %.1f |\n",
                  r.scene.c_str(), r.bodies, budgetLabel(r).c_str(), pct(r.cpu).c_str(), pct(r.wall).c_str(),
                  percentile(r.cpu, 0.99) / (budget_ms * 1e-3),
                  100.0 * static_cast<double>(std::count_if(r.cpu.begin(), r.cpu.end(),
                                                            [&](double t) { return t > 1.1e-3 * budget_ms; })) /
                      static_cast<double>(std::max<std::size_t>(r.cpu.size(), 1)),
                  pct(r.cpu_but_integrate).c_str(), pct(r.integrate).c_str(),
                  pct(r.broad).c_str(), pct(r.narrow).c_str(), r.narrow_got.empty() ? "-" : pct(r.narrow_got).c_str(),
                  pct(r.response).c_str(), r.reserve.empty() ? "-" : pct(r.reserve).c_str(),
                  percentile(r.velocity_passes, 0.5), min_of(r.velocity_passes),
                  percentile(r.position_passes, 0.5), min_of(r.position_passes),
                  100.0 * r.interrupted / static_cast<double>(std::max<std::size_t>(r.cpu.size(), 1)),
                  100.0 * percentile(r.unresolved_share, 0.5), r.moving,
                  r.contacts, r.unresolved_contacts, r.root_contacts, r.frontier_kept);
    md += buf;
  }
  md += "\nPlausibility at the end (issue 49, item 4; test/support/plausibility.hpp): movers with a NaN state, "
        "out of the scene's bounds; the fastest mover against a fall from the scene's top (m/s); 0.5 s windows "
        "whose stored and real speeds differ by more than 10 % + 0.05 m/s (worst excess, m/s); how deep the "
        "movers reach into static plates, voxels (p99 / deepest) and how many more than one voxel; asleep; "
        "mean height of the movers (m) and against the unbudgeted run.\n\n"
        "| scene | bodies | run | NaN | outside | fastest / a fall allows | too fast | windows off "
        "| into plates p99 / max | > 1 voxel | asleep | mean height | height vs unbudgeted |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const Run* ref = nullptr;
    if (runs[i].budgeted && i + 1 < runs.size() && !runs[i + 1].budgeted && runs[i + 1].scene == runs[i].scene &&
        runs[i + 1].bodies == runs[i].bodies) {
      ref = &runs[i + 1];
    }
    md += plausibilityRow(runs[i], ref);
  }
  md +=
      "\nIsland levels of the budgeted runs (TickReport::response.levels, island_levels.hpp): islands a tick stepped "
      "fully / held still (mean), of the held ones joined to the tick by a moving body, bodies held a tick; "
      "the longest wait, ticks; the lag: simulated time a mover lost by the end, mean over the movers, s; "
      "the perceived cost: held island-ticks weighted by their gaze priority (exp(-e / 100)), a tick; "
      "the largest island's bodies, p50 / max.\n\n"
      "| scene | bodies | islands full / held | joined | bodies held | longest wait | mean lag | perceived cost "
      "| largest island |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  for (const Run& r : runs) {
    if (!r.budgeted) continue;
    const double ticks = static_cast<double>(std::max<std::size_t>(r.cpu.size(), 1));
    std::snprintf(buf, sizeof buf, "| %s | %d | %.1f / %.1f | %.1f | %.0f | %d | %.3f | %.3f | %.0f / %.0f |\n",
                  r.scene.c_str(), r.bodies, r.islands_full, r.islands_held, r.islands_joined, r.bodies_held,
                  r.most_ticks_held, r.held_body_ticks / std::max(r.bodies, 1) / 60.0, r.held_priority / ticks,
                  percentile(r.largest_island, 0.5), maxOf(r.largest_island));
    md += buf;
  }
  std::printf("%s", md.c_str());
  if (!markdown.empty()) std::ofstream(markdown) << md;
  return 0;
}
