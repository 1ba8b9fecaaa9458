// What any scheduling order could gain at equal sphere tests (issue 11): the
// perceived error left by ideal orders, with no bookkeeping cost at all,
// against round-robin's, on the snapshots bench_error_vs_runtime uses.
//
// Per snapshot (packed box after 36, 42, ... ticks; gaze on a random rock),
// each pair's FCL distance and its full cost C (sphere tests to resolve it).
// True P left is summed as bench_error_vs_runtime does (e from where each
// unresolved pair stopped); the oracle values a pair at its resolved state. Orders, each run under a sphere-test budget:
//   round_robin    Hubbard's, list order
//   greedy g=reach the pair of highest w s (r_a + r_b) / c steps next, exactly
//                  (w the gaze weight, s pixels per metre, c the next step's
//                  tests; a heap-free argmax per step: no bins, no cost)
//   greedy g=paper the same with g the centre distance of a frontier sphere pair
//   priority_queues the library's scheduler with its defaults
//   oracle         pairs resolved whole by v / C, highest first: knows each
//                  pair's outcome and cost in advance, so no scheduler can match it
//   last tick      pairs resolved whole by v / C of the tick before (the same
//                  entity pair's, measured as the oracle's; new pairs last):
//                  what a scheduler that remembered each pair's outcome could
//                  reach at best, if the tick before had been resolved whole
//   separate a tick before, then queues
//                  the tick before run by the priority queues under the same
//                  share of its sphere tests; the pairs they found separate
//                  go first, whole, by that tick's v / C; then the queues over
//                  the rest (pairs in contact are not put back): what a memory
//                  of one budgeted tick could buy
//   memory, explore X
//                  run on every tick, under the same share of each tick's
//                  tests, remembering what each pair was when last resolved:
//                  pairs remembered separate first, whole, by w s g / c (g the
//                  gap their test saw: roots apart, else the paper's); then X
//                  of the budget on the pairs resolved longest ago (never
//                  first), whole; then the queues over the rest
// Printed: true P left, summed over the snapshots, over round-robin's.
//
// Usage: bench_scheduler_order_bound [--scene packed_box|rockfall] [--snapshots N] [--smoke]
//   --smoke: 1 snapshot, that the bench runs, scripts/bench_smoke.sh
#include "sphere_tree_collision/gaze_model.hpp"
#include "sphere_tree_collision/scenes.hpp"
#include "sphere_tree_collision/world.hpp"

#include "bench_args.hpp"
#include "deadline.hpp"
#include "fcl_mesh.hpp"
#include "pair_test.hpp"
#include "scene_sim.hpp"
#include "scheduler.hpp"
#include "world_access.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using namespace stc;

struct PairFacts {
  PairBody a, b;
  std::array<std::uint32_t, 2> bodies{};  // dense indices
  double weight = 0, px_per_metre = 0;  // gaze weight and scale from the two bodies (as priority queues)
  double gap = 0;                       // FCL distance, metres
  double value = 0;                     // f(e, g_true) at the resolved state (for the oracle)
  double cost = 0;                      // sphere tests to resolve
};

using Priority = std::function<double(const PairTest&, const PairFacts&)>;

// True P of the pairs left unresolved, as bench_error_vs_runtime sums it: e
// from each pair's centre of collision where it stopped, g_true in pixels there.
double trueP(const std::vector<PairTest>& tests, const std::vector<PairFacts>& facts, const Perception& perception) {
  double sum = 0;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    if (tests[i].resolved()) continue;
    if (const auto depth = perception.depthOf(tests[i].centreOfCollision())) {
      sum += perceivedInaccuracy(perception.measure(tests[i]).eccentricity_px,
                                 facts[i].gap * perception.focalPx() / *depth);
    }
  }
  return sum;
}

// True P left after stepping by `priority` (argmax each step; nullptr: round-robin) under `budget` tests.
double pLeft(const std::vector<PairFacts>& facts, const Priority& priority, std::int64_t budget,
             const Perception& perception) {
  const std::size_t n = facts.size();
  std::vector<PairTest> tests(n);
  for (std::size_t i = 0; i < n; ++i) tests[i].reset(facts[i].a, facts[i].b);
  std::int64_t spent = 0;
  if (!priority) {
    for (bool any = true; any && spent < budget;) {
      any = false;
      for (std::size_t i = 0; i < n && spent < budget; ++i) {
        if (!tests[i].resolved()) spent += tests[i].step(), any = true;
      }
    }
  } else {
    std::vector<double> p(n);
    for (std::size_t i = 0; i < n; ++i) {
      tests[i].trackFrontierGap();
      p[i] = priority(tests[i], facts[i]);
    }
    while (spent < budget) {
      std::size_t best = n;
      for (std::size_t i = 0; i < n; ++i) {
        if (!tests[i].resolved() && (best == n || p[i] > p[best])) best = i;
      }
      if (best == n) break;
      spent += tests[best].step();
      p[best] = priority(tests[best], facts[best]);
    }
  }
  return trueP(tests, facts, perception);
}

// The library's priority queues (defaults) over `tests` (parallel to `facts`,
// fresh or part stepped) under `budget` more sphere tests.
void runQueues(const std::vector<PairFacts>& facts, std::size_t body_count, const Perception& perception,
               std::int64_t budget, std::vector<PairTest>& tests) {
  std::vector<std::array<std::uint32_t, 2>> of_pair(facts.size());
  for (std::size_t i = 0; i < facts.size(); ++i) of_pair[i] = facts[i].bodies;
  BudgetTracker tracker(Budget::ofSphereTests(budget));
  makeScheduler(SchedulerOptions{})->run(tests, tests.size(), PairBodies{of_pair.data(), body_count}, &perception,
                                         tracker);
}

std::vector<PairTest> freshTests(const std::vector<PairFacts>& facts) {
  std::vector<PairTest> tests(facts.size());
  for (std::size_t i = 0; i < facts.size(); ++i) tests[i].reset(facts[i].a, facts[i].b);
  return tests;
}

// True P left by the library's priority queues (defaults) under `budget` tests.
double queuesLeft(const std::vector<PairFacts>& facts, std::size_t body_count, const Perception& perception,
                  std::int64_t budget) {
  std::vector<PairTest> tests = freshTests(facts);
  runQueues(facts, body_count, perception, budget, tests);
  return trueP(tests, facts, perception);
}

double oracleLeft(const std::vector<PairFacts>& facts, std::int64_t budget) {
  std::vector<const PairFacts*> order;
  for (const PairFacts& f : facts) order.push_back(&f);
  std::sort(order.begin(), order.end(),
            [](const PairFacts* x, const PairFacts* y) { return x->value * y->cost > y->value * x->cost; });
  double spent = 0, left = 0;
  for (const PairFacts* f : order) {
    if (spent + f->cost <= static_cast<double>(budget)) {
      spent += f->cost;
    } else {
      left += f->value;
    }
  }
  return left;
}

// A pair's entity ids: the same pair from one tick to the next.
using PairKey = std::pair<EntityId, EntityId>;
PairKey keyOf(const PairFacts& f) { return {f.a.id, f.b.id}; }
using FactsByPair = std::map<PairKey, const PairFacts*>;

// Each of `facts`' value and cost (at least 1) as `known` had them (value 0,
// cost 1: a pair it lacks).
void knownWorth(const FactsByPair& known, const std::vector<PairFacts>& facts, std::vector<double>& value,
                std::vector<double>& cost) {
  value.assign(facts.size(), 0.0);
  cost.assign(facts.size(), 1.0);
  for (std::size_t i = 0; i < facts.size(); ++i) {
    const auto found = known.find(keyOf(facts[i]));
    if (found == known.end()) continue;
    value[i] = found->second->value;
    cost[i] = std::max(found->second->cost, 1.0);
  }
}

// The pairs `order` names, each stepped until resolved, while `spent` is under `until`.
void resolveWhole(std::vector<PairTest>& tests, const std::vector<std::size_t>& order, std::int64_t until,
                  std::int64_t& spent) {
  for (std::size_t k = 0; k < order.size() && spent < until; ++k) {
    PairTest& test = tests[order[k]];
    while (!test.resolved() && spent < until) spent += test.step();
  }
}

// Pairs resolved whole in order of `first_value` / `first_cost` (parallel to
// `facts`; value 0: not among them) while the budget lasts; then, with
// `then_queues`, the priority queues over the rest with what is left.
double promotedLeft(const std::vector<PairFacts>& facts, const std::vector<double>& first_value,
                    const std::vector<double>& first_cost, bool then_queues, std::size_t body_count,
                    std::int64_t budget, const Perception& perception) {
  const std::size_t n = facts.size();
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < n; ++i) {
    if (first_value[i] > 0.0 || !then_queues) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return first_value[x] * first_cost[y] > first_value[y] * first_cost[x];
  });
  std::vector<PairTest> tests = freshTests(facts);
  std::int64_t spent = 0;
  resolveWhole(tests, order, budget, spent);
  if (then_queues && spent < budget) runQueues(facts, body_count, perception, budget - spent, tests);
  return trueP(tests, facts, perception);
}

// What a pair was when last resolved.
struct Remembered {
  int tick = -1;
  bool separate = false;
  double cost = 1.0;  // sphere tests it took
  double gap = 0.0;   // separate: its gap as the test saw it (metres)
};
using Memory = std::map<PairKey, Remembered>;

// A separate pair's gap as its own test saw it: its roots' gap when they do
// not touch, else the last frontier's (the paper's estimate).
double seenGap(const PairTest& test) {
  const SphereNode& ra = test.bodyA().tree->node(0);
  const SphereNode& rb = test.bodyB().tree->node(0);
  const double roots = (test.bodyA().pose->apply(ra.centre) - test.bodyB().pose->apply(rb.centre)).norm() -
                       ra.radius - rb.radius;
  return roots > 0.0 ? roots : test.frontierGap();
}

// One budgeted tick of the memory order over this tick's pairs; `memory` learns what it resolved.
std::vector<PairTest> memoryTick(const std::vector<PairFacts>& facts, Memory& memory, int tick, double explore,
                                 std::size_t body_count, std::int64_t budget, const Perception& perception) {
  const std::size_t n = facts.size();
  std::vector<PairTest> tests = freshTests(facts);
  for (PairTest& test : tests) test.trackFrontierGap();
  std::vector<Remembered> known(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto found = memory.find(keyOf(facts[i]));
    if (found != memory.end()) known[i] = found->second;
  }
  std::vector<std::size_t> separate, stale(n);
  for (std::size_t i = 0; i < n; ++i) {
    stale[i] = i;
    if (known[i].separate) separate.push_back(i);
  }
  const auto worth = [&](std::size_t i) {
    return facts[i].weight * facts[i].px_per_metre * known[i].gap / known[i].cost;
  };
  std::stable_sort(separate.begin(), separate.end(), [&](std::size_t x, std::size_t y) { return worth(x) > worth(y); });
  std::stable_sort(stale.begin(), stale.end(), [&](std::size_t x, std::size_t y) { return known[x].tick < known[y].tick; });
  std::int64_t spent = 0;
  const auto exploring = std::llround(explore * static_cast<double>(budget));
  resolveWhole(tests, separate, budget - exploring, spent);
  resolveWhole(tests, stale, std::min<std::int64_t>(budget, spent + exploring), spent);
  if (spent < budget) runQueues(facts, body_count, perception, budget - spent, tests);
  for (std::size_t i = 0; i < n; ++i) {
    if (!tests[i].resolved()) continue;
    const bool separate = tests[i].status() == PairStatus::Separate;
    memory[keyOf(facts[i])] = Remembered{tick, separate, std::max<double>(1.0, tests[i].sphereTests()),
                                         separate ? seenGap(tests[i]) : 0.0};
  }
  return tests;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene = "packed_box";
  int snapshots = 6;
  for (stc_bench::Args args(argc, argv); args.more();) {
    const std::string& a = args.flag();
    if (a == "--scene") scene = args.value();
    else if (a == "--snapshots") snapshots = std::stoi(args.value());
    else if (a == "--smoke") snapshots = 1;
    else return args.unknown();
  }
  const SceneKind kind = parseScene(scene);
  SceneWorld scene_sim = stc_bench::makeSceneSim(kind);
  World& sim = scene_sim.world;
  const SceneSpec& spec = scene_sim.spec;
  WorldConfig config = sim.config();
  config.response.enabled = false;
  World eval(config);
  populateScene(eval, kind);
  eval.perception().setCamera(spec.camera);
  std::vector<std::shared_ptr<truth::FclMesh>> meshes;
  auto meshOf = [&](std::size_t body) -> const truth::FclMesh& {
    const ShapeId id = eval.bodyShapes()[body];
    if (meshes.size() <= id) meshes.resize(id + 1);
    if (!meshes[id]) meshes[id] = truth::makeFclMesh(eval.shape(id).voxels, eval.shape(id).body_origin);
    return *meshes[id];
  };

  const std::vector<double> shares = {0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.4};
  const Priority by_reach = [](const PairTest& t, const PairFacts& f) {
    // Before any step, and after a step that found no sphere pair (separate at
    // the roots: resolved, its priority unused), a constant (the root test costs 1).
    double g = 0.5;
    if (t.hasLastPair()) {
      const SpherePair first = t.lastPairs()[0];
      g = t.bodyA().tree->node(first.a).radius + t.bodyB().tree->node(first.b).radius;
    }
    return f.weight * f.px_per_metre * g / t.nextStepTests();
  };
  const Priority by_gap = [](const PairTest& t, const PairFacts& f) {
    return f.weight * f.px_per_metre * (t.stepsDone() > 0 ? t.frontierGap() : 0.5) / t.nextStepTests();
  };
  const std::vector<double> explores = {0.0, 0.2};
  const int kOrders = 7 + static_cast<int>(explores.size());
  std::vector<std::vector<double>> left(kOrders, std::vector<double>(shares.size(), 0.0));
  std::mt19937 pick(11);  // the gaze targets of bench_error_vs_runtime
  double t = 0.0;
  const int warmup = kind == SceneKind::Rockfall ? 75 : 30;
  for (int i = 0; i < warmup; ++i, t += spec.dt) sim.step(spec.dt, Budget::unlimited());
  // The simulation's poses under a fresh `gaze` at time t: each pair's facts, and the full run's report.
  // Without `truth` no FCL work (gap and value 0): a tick only run through.
  const auto measure = [&](GazeModel gaze, std::vector<PairFacts>& facts, bool truth) {
    for (std::size_t i = 0; i < sim.entityCount(); ++i) eval.bodies()[i].pose = sim.bodies()[i].pose;
    eval.perception().setFixation(gaze.fixationAt(t, sim));
    const TickReport full = eval.step(0.0, Budget::unlimited());
    const Perception& perception = eval.perception();
    facts.assign(eval.pairCount(), PairFacts{});
    for (std::size_t i = 0; i < facts.size(); ++i) {
      const PairTest& test = pairTests(eval)[i];
      PairFacts& f = facts[i];
      f.a = test.bodyA();
      f.b = test.bodyB();
      const auto ga = perception.gazeWeight(f.a.pose->position);
      const auto gb = perception.gazeWeight(f.b.pose->position);
      f.weight = std::sqrt(ga.weight * gb.weight);
      f.px_per_metre = std::sqrt(ga.px_per_metre * gb.px_per_metre);
      f.cost = static_cast<double>(test.sphereTests());
      f.bodies = {static_cast<std::uint32_t>(*eval.indexOf(f.a.id)), static_cast<std::uint32_t>(*eval.indexOf(f.b.id))};
      if (!truth) continue;
      const truth::FclMesh& ma = meshOf(*eval.indexOf(f.a.id));
      const truth::FclMesh& mb = meshOf(*eval.indexOf(f.b.id));
      const bool touching = truth::exactCollide(ma, *f.a.pose, mb, *f.b.pose);
      f.gap = touching ? 0.0 : truth::exactDistance(ma, *f.a.pose, mb, *f.b.pose);
      if (const auto depth = perception.depthOf(test.centreOfCollision())) {
        f.value = perceivedInaccuracy(perception.measure(test).eccentricity_px, f.gap * perception.focalPx() / *depth);
      }
    }
    return full;
  };
  std::vector<PairFacts> facts, before, passing;
  FactsByPair last_tick;
  std::vector<std::vector<Memory>> memories(explores.size(), std::vector<Memory>(shares.size()));
  int tick = 0;
  // Each memory order's budgeted tick on `tick_facts` (a tick of `report`'s full cost).
  const auto rememberTick = [&](const std::vector<PairFacts>& tick_facts, const TickReport& report) {
    for (std::size_t x = 0; x < explores.size(); ++x) {
      for (std::size_t b = 0; b < shares.size(); ++b) {
        memoryTick(tick_facts, memories[x][b], tick, explores[x], eval.bodies().size(),
                   std::llround(shares[b] * static_cast<double>(report.detection.sphere_tests)), eval.perception());
      }
    }
    ++tick;
  };
  for (int s = 0; s < snapshots; ++s) {
    GazeParams follow;
    follow.mode = GazeMode::Follow;
    follow.target = spec.movers[pick() % spec.movers.size()];
    const GazeModel gaze(follow);  // copied fresh into each measure, as one per snapshot before
    for (int i = 0; i < 4; ++i) {
      sim.step(spec.dt, Budget::unlimited());
      t += spec.dt;
      rememberTick(passing, measure(gaze, passing, false));
    }
    sim.step(spec.dt, Budget::unlimited());
    t += spec.dt;
    const TickReport full_before = measure(gaze, before, true);  // the tick before the snapshot
    rememberTick(before, full_before);
    last_tick.clear();
    for (const PairFacts& f : before) last_tick[keyOf(f)] = &f;
    // What the queues, under each share of that tick's tests, found separate.
    std::vector<FactsByPair> separate_before(shares.size());
    for (std::size_t b = 0; b < shares.size(); ++b) {
      std::vector<PairTest> tests = freshTests(before);
      runQueues(before, eval.bodies().size(), eval.perception(),
                std::llround(shares[b] * static_cast<double>(full_before.detection.sphere_tests)), tests);
      for (std::size_t i = 0; i < before.size(); ++i) {
        if (tests[i].status() == PairStatus::Separate) separate_before[b][keyOf(before[i])] = &before[i];
      }
    }
    sim.step(spec.dt, Budget::unlimited());
    t += spec.dt;
    const TickReport full = measure(gaze, facts, true);
    const Perception& perception = eval.perception();
    std::vector<double> last_value, last_cost, sep_value, sep_cost;
    knownWorth(last_tick, facts, last_value, last_cost);
    for (std::size_t b = 0; b < shares.size(); ++b) {
      const auto budget = std::llround(shares[b] * static_cast<double>(full.detection.sphere_tests));
      left[0][b] += pLeft(facts, nullptr, budget, perception);
      left[1][b] += pLeft(facts, by_reach, budget, perception);
      left[2][b] += pLeft(facts, by_gap, budget, perception);
      left[3][b] += queuesLeft(facts, eval.bodies().size(), perception, budget);
      left[4][b] += oracleLeft(facts, budget);
      left[5][b] += promotedLeft(facts, last_value, last_cost, false, eval.bodies().size(), budget, perception);
      knownWorth(separate_before[b], facts, sep_value, sep_cost);
      left[6][b] += promotedLeft(facts, sep_value, sep_cost, true, eval.bodies().size(), budget, perception);
      for (std::size_t x = 0; x < explores.size(); ++x) {
        const std::vector<PairTest> tests =
            memoryTick(facts, memories[x][b], tick, explores[x], eval.bodies().size(), budget, perception);
        left[7 + x][b] += trueP(tests, facts, perception);
      }
    }
    ++tick;
    std::fprintf(stderr, "  snapshot %d/%d\n", s + 1, snapshots);
  }
  std::printf("%s, %d snapshots: true P left / round-robin's, at a share of the full sphere tests\n\n| order |",
              scene.c_str(), snapshots);
  for (double share : shares) std::printf(" %.1f %% |", 100 * share);
  std::printf("\n|---|");
  for (std::size_t b = 0; b < shares.size(); ++b) std::printf("---|");
  std::vector<std::string> names = {"round_robin", "greedy, g = reach", "greedy, g = paper's estimate",
                                    "priority_queues (defaults)", "oracle", "last tick's v / C, known exactly",
                                    "separate a tick before (queues, same share) first, then queues"};
  for (double x : explores) names.push_back("memory of every budgeted tick, explore " + std::to_string(x).substr(0, 4));
  for (int o = 0; o < kOrders; ++o) {
    std::printf("\n| %s |", names[o].c_str());
    for (std::size_t b = 0; b < shares.size(); ++b) std::printf(" %.2f |", left[o][b] / left[0][b]);
  }
  std::printf("\n");
  return 0;
}
