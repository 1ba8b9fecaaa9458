// Error against run time (issues 6 and 11, paper 3.4.2-3.4.3): for each
// scheduler and a sweep of budgets, what the narrow phase leaves wrong,
// measured against FCL's exact collide/distance on the same poses.
//
// A simulation World (dynamics on, unlimited budget) runs the scene and
// snapshots its poses (the "ticks"). One evaluation World per scheduler (same
// scene, response off, its scheduler warm) takes each snapshot and runs
// step(dt = 0, budget): every scheduler sees the same poses, pairs and gaze.
// Accepted = colliding at the leaves, or unresolved at interruption (policy
// accept: the paper's repulsion case). For every accepted pair FCL gives the truth:
//   false positive  accepted, but FCL says the bodies do not touch
//   true gap        FCL distance (metres), summed
//   true P          sum of f(e, g_true), e from the centre of collision, and
//                   g_true = FCL distance in pixels at the centre's depth
// "unres" columns sum over accepted *unresolved* pairs only (the paper's P and
// nabla are defined over those); "acc" columns over all accepted pairs.
//
// Load: the machine may be shared. A tick during which the thread lost its
// core (wall time more than 50 us above the thread's CPU time) is run again
// (up to 20 times; the same poses give the same pairs), so every time and
// every wall-clock budget here is of code that ran undisturbed: its wall time
// is its thread CPU time. The count of such re-runs and the load average are
// reported.
//
// Repeats: every (snapshot, budget) is run `repeats` times, the schedulers
// interleaved (A B C D A B C D ...) so the load of a shared machine hits all
// alike. Repeat r of every scheduler sums its errors over the snapshots: one
// CSV row per scene x scheduler x budget x repeat. Ratios are of those sums,
// repeat by repeat; the headline gives their median and min-max.
//
// Usage: bench_error_vs_runtime [--quick] [--csv FILE] [--markdown FILE]
//          [--snapshots N] [--repeats R] [--scene packed_box|rockfall]
//          [--gaze entity|screen] [--queues K] [--ratio R] [--cost-exponent A]
//          [--smoke]  (--quick with 1 snapshot, 1 repeat and no CSV: that the bench runs, scripts/bench_smoke.sh)
#include "sphere_tree_collision/gaze_model.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include "bench_args.hpp"
#include "contact_builder.hpp"
#include "fcl_mesh.hpp"
#include "pair_test.hpp"
#include "tick_clock.hpp"
#include "world_access.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <tuple>
#include <unordered_map>
#include <vector>

namespace {

using namespace stc;

struct Options {
  bool quick = false;
  bool smoke = false;
  std::string csv = "docs/error_vs_runtime.csv";  // empty: none
  std::string markdown;
  int snapshots = 12;
  int repeats = 7;
  std::string scene;            // empty: both
  std::string gaze = "entity";  // entity | screen
  // Priority-queue settings: the library's defaults unless given.
  int queues = SchedulerOptions{}.queue_count;
  double ratio = SchedulerOptions{}.queue_ratio;
  double cost_exponent = SchedulerOptions{}.cost_exponent;
  SchedulerOptions schedulerOptions(SchedulerKind kind) const {
    SchedulerOptions o;
    o.kind = kind;
    o.queue_count = queues;
    o.queue_ratio = ratio;
    o.cost_exponent = cost_exponent;
    return o;
  }
};

constexpr SchedulerKind kKinds[] = {SchedulerKind::RoundRobin, SchedulerKind::Sequential,
                                    SchedulerKind::PerceptualSequential,
                                    SchedulerKind::PriorityQueues};
constexpr std::size_t kKindCount = sizeof(kKinds) / sizeof(kKinds[0]);
// Budgets as fractions of the snapshot's unlimited cost: its sphere tests, or
// round-robin's unlimited narrow-phase time for wall-clock budgets. Negative: unlimited.
const std::vector<double> kTestFractions = {0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3,
                                            0.4,  0.5,  0.6,  0.8, -1.0};
const std::vector<double> kTimeFractions = {0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0};

struct Truth {
  bool collide = false;
  double distance = 0.0;
};

// What one step under one budget leaves wrong (one tick of one repeat).
struct TickErrors {
  double narrow_s = 0, overhead_s = 0, sphere_tests = 0, pairs = 0, unresolved = 0, accepted = 0;
  double false_pos = 0, true_gap_unres = 0, true_p_unres = 0, true_p_acc = 0, est_nabla = 0, est_p = 0;
  TickErrors& operator+=(const TickErrors& o) {
    for (double TickErrors::*f :
         {&TickErrors::narrow_s, &TickErrors::overhead_s, &TickErrors::sphere_tests, &TickErrors::pairs,
          &TickErrors::unresolved, &TickErrors::accepted, &TickErrors::false_pos, &TickErrors::true_gap_unres,
          &TickErrors::true_p_unres, &TickErrors::true_p_acc, &TickErrors::est_nabla, &TickErrors::est_p}) {
      this->*f += o.*f;
    }
    return *this;
  }
};

// One CSV row: a repeat's errors summed over the snapshots, with its ticks' narrow times.
struct Row {
  std::string scene, scheduler, budget_kind;  // tests | seconds | unlimited
  double fraction = 1.0;
  int repeat = 0;
  TickErrors sum;
  // Per tick: times are medians over the ticks, not sums (a tick the OS
  // descheduled on the shared machine would otherwise weigh on every figure).
  std::vector<double> narrow_s, overhead_share;
  void add(const TickErrors& t) {
    sum += t;
    narrow_s.push_back(t.narrow_s);
    overhead_share.push_back(t.narrow_s > 0 ? t.overhead_s / t.narrow_s : 0.0);
  }
  double overheadPercent() const { return 100.0 * stc_bench::percentile(overhead_share, 0.5); }
  double unresolvedShare() const { return sum.unresolved / std::max(1.0, sum.pairs); }
};

// (scene, scheduler, budget kind, fraction, repeat) -> row
using RowKey = std::tuple<std::string, std::string, std::string, double, int>;

class Evaluator {
 public:
  Evaluator(SceneKind kind, const SceneParams& params, const Options& opt) : opt_(opt) {
    WorldConfig sim_config;
    sim_config.gravity = sceneGravity(kind);
    sim_config.scheduler.kind = SchedulerKind::RoundRobin;
    sim_ = std::make_unique<World>(sim_config);
    spec_ = populateScene(*sim_, kind, params);
    sim_->perception().setCamera(spec_.camera);

    WorldConfig eval_config = sim_config;
    eval_config.response.enabled = false;
    eval_config.unresolved_policy = UnresolvedPolicy::Accept;
    for (SchedulerKind k : kKinds) {
      eval_config.scheduler = opt.schedulerOptions(k);
      evals_.push_back(std::make_unique<World>(eval_config));
      populateScene(*evals_.back(), kind, params);
      evals_.back()->perception().setCamera(spec_.camera);
    }
  }

  const SceneSpec& spec() const { return spec_; }
  World& sim() { return *sim_; }
  long reruns() const { return reruns_; }
  long ticks() const { return ticks_; }

  // One tick that kept its core throughout (see Load above).
  TickReport stepUndisturbed(World& world, const Budget& budget) {
    ++ticks_;
    for (int attempt = 0;; ++attempt) {
      const double cpu0 = stc_bench::threadCpuSeconds();
      const double wall0 = stc_bench::wallSeconds();
      const TickReport report = world.step(0.0, budget);
      const double lost = (stc_bench::wallSeconds() - wall0) - (stc_bench::threadCpuSeconds() - cpu0);
      if (lost <= kLostCoreS || attempt == kMaxReruns) return report;
      ++reruns_;
    }
  }

  void evaluateSnapshot(const std::string& scene, double t, GazeModel& gaze,
                        std::map<RowKey, Row>& rows) {
    const Vec2 fixation = gaze.fixationAt(t, *sim_);
    for (auto& eval : evals_) {  // same poses, same creation order
      for (std::size_t i = 0; i < sim_->entityCount(); ++i) eval->bodies()[i].pose = sim_->bodies()[i].pose;
      eval->perception().setFixation(fixation);
      eval->step(0.0, Budget::unlimited());  // warm
    }
    truth_.clear();

    // Unlimited cost of this snapshot: sphere tests (the same for every
    // scheduler) and round-robin's narrow-phase time (median of 5).
    std::vector<double> times;
    std::int64_t total_tests = 0;
    for (int r = 0; r < 5; ++r) {
      const TickReport rep = stepUndisturbed(*evals_[0], Budget::unlimited());
      times.push_back(rep.phases.narrow_s);
      total_tests = rep.detection.sphere_tests;
    }
    const double full_time = stc_bench::percentile(times, 0.5);

    auto sweep = [&](const char* budget_kind, double f, const Budget& budget) {
      for (int rep = 0; rep < opt_.repeats; ++rep) {
        for (std::size_t k = 0; k < kKindCount; ++k) {  // interleaved: A B C D, A B C D, ...
          const TickReport report = stepUndisturbed(*evals_[k], budget);
          Row& row = rows[RowKey{scene, toString(kKinds[k]), budget_kind, f, rep}];
          if (row.scene.empty()) {
            row.scene = scene;
            row.scheduler = toString(kKinds[k]);
            row.budget_kind = budget_kind;
            row.fraction = f;
            row.repeat = rep;
          }
          row.add(errorsOf(*evals_[k], report));
        }
      }
    };
    for (double f : kTestFractions) {
      if (f < 0.0) {
        sweep("unlimited", 1.0, Budget::unlimited());
      } else {
        sweep("tests", f, Budget::ofSphereTests(std::llround(f * static_cast<double>(total_tests))));
      }
    }
    for (double f : kTimeFractions) sweep("seconds", f, Budget::ofSeconds(f * full_time));
  }

 private:
  // One FCL mesh per shape, in the same body frame as the tree; built on first use.
  const truth::FclMesh& meshOf(const World& world, ShapeId id) {
    if (meshes_.size() <= id) meshes_.resize(id + 1);
    if (!meshes_[id]) meshes_[id] = truth::makeFclMesh(world.shape(id).voxels, world.shape(id).body_origin);
    return *meshes_[id];
  }

  const Truth& truthOf(const World& world, const PairTest& test) {
    const std::uint64_t key = (static_cast<std::uint64_t>(test.bodyA().id) << 32) | test.bodyB().id;
    const auto found = truth_.find(key);
    if (found != truth_.end()) return found->second;
    const std::size_t ia = *world.indexOf(test.bodyA().id);
    const std::size_t ib = *world.indexOf(test.bodyB().id);
    const truth::FclMesh& ma = meshOf(world, world.bodyShapes()[ia]);
    const truth::FclMesh& mb = meshOf(world, world.bodyShapes()[ib]);
    Truth t;
    t.collide = truth::exactCollide(ma, *test.bodyA().pose, mb, *test.bodyB().pose);
    t.distance = t.collide ? 0.0 : truth::exactDistance(ma, *test.bodyA().pose, mb, *test.bodyB().pose);
    return truth_.emplace(key, t).first->second;
  }

  TickErrors errorsOf(const World& world, const TickReport& rep) {
    TickErrors e;
    e.narrow_s = rep.phases.narrow_s;
    e.overhead_s = rep.detection.scheduling_overhead_s;
    e.sphere_tests = static_cast<double>(rep.detection.sphere_tests);
    e.pairs = static_cast<double>(world.pairCount());
    e.unresolved = static_cast<double>(rep.detection.unresolved);
    e.est_nabla = rep.accuracy.geometric_inaccuracy;
    e.est_p = rep.accuracy.perceived_inaccuracy;
    const Perception& perception = world.perception();
    for (std::size_t i = 0; i < world.pairCount(); ++i) {
      const PairTest& test = pairTests(world)[i];
      const bool unresolved = test.status() == PairStatus::Unresolved;
      if (!unresolved && test.status() != PairStatus::Colliding) continue;  // separate: rejected
      e.accepted += 1;
      const Truth& truth = truthOf(world, test);
      double f = 0.0;
      if (const auto depth = perception.depthOf(test.centreOfCollision())) {
        const double g_true_px = truth.distance * perception.focalPx() / *depth;
        f = perceivedInaccuracy(perception.measure(test).eccentricity_px, g_true_px);
      }
      if (!truth.collide) e.false_pos += 1;
      e.true_p_acc += f;
      if (unresolved) {
        e.true_gap_unres += truth.distance;
        e.true_p_unres += f;
      }
    }
    return e;
  }

  static constexpr double kLostCoreS = 50e-6;
  static constexpr int kMaxReruns = 20;
  Options opt_;
  long reruns_ = 0, ticks_ = 0;
  std::unique_ptr<World> sim_;
  std::vector<std::unique_ptr<World>> evals_;  // one per scheduler, kKinds order
  SceneSpec spec_;
  std::vector<std::shared_ptr<truth::FclMesh>> meshes_;
  std::unordered_map<std::uint64_t, Truth> truth_;
};

struct LoadStats {
  long ticks = 0, reruns = 0;
};

// The 1-minute load average (/proc/loadavg); NaN if unreadable.
double loadAverage() {
  double load = NAN;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1) load = NAN;
    std::fclose(f);
  }
  return load;
}

void runScene(SceneKind kind, const Options& opt, std::map<RowKey, Row>& rows, LoadStats& load) {
  SceneParams params;
  int warmup = 30, every = 6;
  if (kind == SceneKind::Rockfall) warmup = 75;  // rocks are falling and piling by then
  if (opt.quick) params.entities = kind == SceneKind::Rockfall ? 80 : 125;
  Evaluator ev(kind, params, opt);
  // Gaze: "entity" (default) jumps every snapshot (0.1 s) to a seeded random
  // mover and follows it: a viewer fixates objects. "screen": saccades to
  // seeded random screen points every 0.3 s (may land on empty background).
  GazeParams screen;
  screen.mode = GazeMode::Saccades;
  screen.seed = 11;
  GazeModel screen_gaze(screen);
  std::mt19937 pick(11);
  const double dt = ev.spec().dt;
  double t = 0.0;
  for (int i = 0; i < warmup; ++i, t += dt) ev.sim().step(dt, Budget::unlimited());
  const int snapshots = opt.smoke ? 1 : opt.quick ? 3 : opt.snapshots;
  for (int s = 0; s < snapshots; ++s) {
    for (int i = 0; i < every; ++i, t += dt) ev.sim().step(dt, Budget::unlimited());
    GazeParams follow;
    follow.mode = GazeMode::Follow;
    follow.target = ev.spec().movers[pick() % ev.spec().movers.size()];
    GazeModel entity_gaze(follow);
    ev.evaluateSnapshot(toString(kind), t, opt.gaze == "screen" ? screen_gaze : entity_gaze, rows);
    std::fprintf(stderr, "  %s snapshot %d/%d (t = %.2f s, %zu pairs)\n", toString(kind), s + 1,
                 snapshots, t, ev.sim().pairCount());
  }
  load.ticks += ev.ticks();
  load.reruns += ev.reruns();
}

// ---------------------------------------------------------------------------
// CSV and tables.

void writeCsv(const std::string& path, const std::map<RowKey, Row>& rows) {
  std::ofstream out(path);
  out << "scene,scheduler,budget_kind,fraction,repeat,ticks,narrow_ms_median,narrow_ms_mean,"
         "overhead_share_median,sphere_tests,pairs,unresolved,accepted,false_pos,true_gap_unres,"
         "true_p_unres,true_p_acc,est_nabla,est_p\n";
  char buf[1024];
  for (const auto& [key, r] : rows) {
    const double n = static_cast<double>(r.narrow_s.size());
    std::snprintf(buf, sizeof buf,
                  "%s,%s,%s,%.4g,%d,%zu,%.6g,%.6g,%.5f,%.0f,%.0f,%.0f,%.0f,%.0f,%.6g,%.6g,%.6g,%.6g,%.6g\n",
                  r.scene.c_str(), r.scheduler.c_str(), r.budget_kind.c_str(), r.fraction, r.repeat,
                  r.narrow_s.size(), 1e3 * stc_bench::percentile(r.narrow_s, 0.5), 1e3 * r.sum.narrow_s / n,
                  r.overheadPercent() / 100.0, r.sum.sphere_tests,
                  r.sum.pairs, r.sum.unresolved, r.sum.accepted, r.sum.false_pos, r.sum.true_gap_unres,
                  r.sum.true_p_unres, r.sum.true_p_acc, r.sum.est_nabla, r.sum.est_p);
    out << buf;
  }
}

struct Spread {
  double median = NAN, min = NAN, max = NAN;
};
Spread spreadOf(const std::vector<double>& v) {
  if (v.empty()) return {};
  return {stc_bench::percentile(v, 0.5), *std::min_element(v.begin(), v.end()),
          *std::max_element(v.begin(), v.end())};
}

std::string fmtSpread(const Spread& s) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.2f (%.2f-%.2f)", s.median, s.min, s.max);
  return buf;
}

std::string report(const std::map<RowKey, Row>& rows, const Options& opt) {
  auto rowOf = [&](const std::string& scene, const std::string& sched, const std::string& kind,
                   double f, int rep) -> const Row* {
    const auto it = rows.find(RowKey{scene, sched, kind, f, rep});
    return it == rows.end() ? nullptr : &it->second;
  };
  // Per repeat: a field's sum for `sched` over round-robin's; and a row field per repeat.
  auto ratios = [&](const std::string& scene, const std::string& sched, const std::string& kind, double f) {
    std::vector<double> out;
    for (int rep = 0; rep < opt.repeats; ++rep) {
      const Row* a = rowOf(scene, sched, kind, f, rep);
      const Row* rr = rowOf(scene, "round_robin", kind, f, rep);
      if (a && rr && rr->sum.true_p_unres > 0) out.push_back(a->sum.true_p_unres / rr->sum.true_p_unres);
    }
    return spreadOf(out);
  };
  auto perRepeat = [&](const std::string& scene, const std::string& sched, const std::string& kind,
                       double f, auto field) {
    std::vector<double> out;
    for (int rep = 0; rep < opt.repeats; ++rep) {
      if (const Row* r = rowOf(scene, sched, kind, f, rep)) out.push_back(field(*r));
    }
    return spreadOf(out);
  };
  const auto narrowMs = [](const Row& r) { return 1e3 * stc_bench::percentile(r.narrow_s, 0.5); };

  std::string md;
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "Settings: priority queues K = %d, bin ratio %.3g, priority f(e,g) / next-step cost^%.2g; "
                "gaze %s; policy accept; %d snapshots per scene; %d repeats, schedulers interleaved. "
                "Ratios: true P (sum over the snapshots, accepted unresolved pairs) of the scheduler over "
                "round-robin's, repeat by repeat: median (min-max).\n",
                opt.queues, opt.ratio, opt.cost_exponent,
                opt.gaze == "screen" ? "saccades to random screen points every 0.3 s"
                                     : "on a random moving entity, a new one every snapshot",
                opt.smoke ? 1 : opt.quick ? 3 : opt.snapshots, opt.repeats);
  md += buf;
  for (const char* scene : {"packed_box", "rockfall"}) {
    if (!rowOf(scene, "round_robin", "unlimited", 1.0, 0)) continue;
    // Overhead at unlimited budget (identical work for every scheduler).
    std::snprintf(buf, sizeof buf,
                  "\n### %s: scheduling overhead, unlimited budget (identical work)\n\n| scheduler | narrow ms "
                  "(median tick) | narrow / round-robin's | bookkeeping: 1 - RR's narrow / its narrow %% | "
                  "timed set-up / narrow %% (median tick) |\n|---|---|---|---|---|\n",
                  scene);
    md += buf;
    const Spread rr_ms = perRepeat(scene, "round_robin", "unlimited", 1.0, narrowMs);
    for (SchedulerKind k : kKinds) {
      const Spread ms = perRepeat(scene, toString(k), "unlimited", 1.0, narrowMs);
      const Spread share =
          perRepeat(scene, toString(k), "unlimited", 1.0, [](const Row& r) { return r.overheadPercent(); });
      std::snprintf(buf, sizeof buf, "| %s | %s | %.3f | %.1f | %s |\n", toString(k), fmtSpread(ms).c_str(),
                    ms.median / rr_ms.median, 100.0 * (1.0 - rr_ms.median / ms.median),
                    fmtSpread(share).c_str());
      md += buf;
    }
    for (const char* kind : {"seconds", "tests"}) {
      std::snprintf(buf, sizeof buf,
                    "\n### %s: equal %s, budgets where round-robin leaves >= 20%% unresolved\n\n"
                    "| budget | RR narrow ms | PQ narrow ms | RR unresolved %% | "
                    "**PQ / RR** | PSeq / RR | Seq / RR |\n|---|---|---|---|---|---|---|\n",
                    scene, std::strcmp(kind, "seconds") == 0 ? "wall time" : "sphere-test budget");
      md += buf;
      const auto& fractions = std::strcmp(kind, "seconds") == 0 ? kTimeFractions : kTestFractions;
      for (double f : fractions) {
        if (f < 0.0) continue;
        const Spread unres = perRepeat(scene, "round_robin", kind, f,
                                       [](const Row& r) { return 100.0 * r.unresolvedShare(); });
        if (!(unres.median >= 20.0)) continue;
        std::snprintf(buf, sizeof buf, "| %.0f%% | %.3f | %.3f | %.0f | **%s** | %s | %s |\n", 100 * f,
                      perRepeat(scene, "round_robin", kind, f, narrowMs).median,
                      perRepeat(scene, "priority_queues", kind, f, narrowMs).median, unres.median,
                      fmtSpread(ratios(scene, "priority_queues", kind, f)).c_str(),
                      fmtSpread(ratios(scene, "perceptual_sequential", kind, f)).c_str(),
                      fmtSpread(ratios(scene, "sequential", kind, f)).c_str());
        md += buf;
      }
    }
  }
  return md;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string& a = args.flag();
    if (a == "--quick") opt.quick = true;
    else if (a == "--smoke") opt.quick = true, opt.smoke = true, opt.repeats = 1, opt.csv.clear();
    else if (a == "--csv") opt.csv = args.value();
    else if (a == "--markdown") opt.markdown = args.value();
    else if (a == "--snapshots") opt.snapshots = std::stoi(args.value());
    else if (a == "--repeats") opt.repeats = std::max(1, std::stoi(args.value()));
    else if (a == "--scene") opt.scene = args.value();
    else if (a == "--gaze") opt.gaze = args.value();
    else if (a == "--queues") opt.queues = std::stoi(args.value());
    else if (a == "--ratio") opt.ratio = std::stod(args.value());
    else if (a == "--cost-exponent") opt.cost_exponent = std::stod(args.value());
    else return args.unknown();
  }
  std::map<RowKey, Row> rows;
  LoadStats load;
  const double load_before = loadAverage();
  for (SceneKind kind : {SceneKind::PackedBox, SceneKind::Rockfall}) {
    if (opt.scene.empty() || opt.scene == toString(kind)) runScene(kind, opt, rows, load);
  }
  if (!opt.csv.empty()) writeCsv(opt.csv, rows);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "Load: 1-minute load average %.1f before and %.1f after, on %u cores; %ld of %ld ticks lost "
                "their core and were run again.\n",
                load_before, loadAverage(), std::thread::hardware_concurrency(), load.reruns, load.ticks);
  const std::string md = buf + report(rows, opt);
  std::printf("%s", md.c_str());
  if (!opt.markdown.empty()) std::ofstream(opt.markdown) << md;
  return 0;
}
