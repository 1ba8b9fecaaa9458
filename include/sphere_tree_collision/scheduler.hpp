// Schedulers (paper 3.4.3): who gets the next step of the narrow phase until
// every PairTest resolves or the Budget ends.
#pragma once

#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/pair_test.hpp"
#include "sphere_tree_collision/perception.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace stc {

enum class SchedulerKind : std::uint8_t {
  RoundRobin,            // Hubbard: every pair one level, then again
  Sequential,            // pairs resolved fully one by one, in list order
  PerceptualSequential,  // sorted by perceptual priority, then sequential
  PriorityQueues,        // model picks one of K queues; round-robin inside; highest first
};
// "round_robin" | "sequential" | "perceptual_sequential" | "priority_queues";
// throws InputError("scheduler") otherwise.
SchedulerKind parseScheduler(const std::string& name);
const char* toString(SchedulerKind kind);

enum class UnresolvedPolicy : std::uint8_t { Accept, Reject };
// "accept" | "reject"; throws InputError("unresolved_policy") otherwise.
UnresolvedPolicy parseUnresolvedPolicy(const std::string& name);
const char* toString(UnresolvedPolicy policy);

// Defaults: priority queues with 16 queues a factor 2 apart and the priority
// per sphere test (cost_exponent 1), the best measured here
// (docs/error_vs_runtime.md). The paper's variant: queue_count 4,
// queue_ratio 4, cost_exponent 0.
struct SchedulerOptions {
  SchedulerKind kind = SchedulerKind::PriorityQueues;
  int queue_count = 16;  // priority queues only; 1..64
  // Priority queues only; > 1. Log-scale bins relative to the largest priority
  // at the start of the run: the top queue holds f >= fmax / ratio, the next
  // f >= fmax / ratio^2, ..., the bottom queue the rest (and f = 0).
  double queue_ratio = 2.0;
  // Priority queues only: the priority is f(e, g) / c^cost_exponent, c the
  // sphere tests the pair's next step will take (1 at the roots, about 8 per
  // intersecting sphere pair below). 0: the paper's f(e, g). 1: expected
  // error removed per unit of budget, so cheap steps that may resolve a pair go first.
  double cost_exponent = 1.0;
};
// Throws InputError("queue_count"), ("queue_ratio") or ("cost_exponent").
void validateSchedulerOptions(const SchedulerOptions& options);

struct ScheduleStats {
  std::int64_t sphere_tests = 0;
  bool interrupted = false;       // budget ended with unresolved pairs left
  double overhead_seconds = 0.0;  // time spent deciding (perception, sorting, queues), not testing
  bool used_perception = false;   // false when there is no fixation: no projection work done
};

// The two bodies of each pair test as dense indices in [0, body_count): a
// perceptual scheduler projects each body once per run, not once per pair.
// Without them (of_pair null) priority queues run as round-robin.
struct PairBodies {
  const std::array<std::uint32_t, 2>* of_pair = nullptr;  // [count], parallel to the tests
  std::size_t body_count = 0;
};

// One call per tick. Steps tests[0..count) under the budget. Without a
// perception (nullptr or no fixation) the perceptual schedulers fall back to
// their non-perceptual order and say so in ScheduleStats::used_perception.
class Scheduler {
 public:
  virtual ~Scheduler() = default;
  // tests[0..count) may be any run of a longer array (the World's parallel
  // narrow phase gives each chunk of its pairs its own scheduler).
  virtual ScheduleStats run(PairTest* tests, std::size_t count, const PairBodies& bodies,
                            const Perception* perception, BudgetTracker& budget) = 0;
  ScheduleStats run(std::vector<PairTest>& tests, std::size_t count, const PairBodies& bodies,
                    const Perception* perception, BudgetTracker& budget) {
    return run(tests.data(), count, bodies, perception, budget);
  }
};
// Validates the options (see validateSchedulerOptions).
std::unique_ptr<Scheduler> makeScheduler(const SchedulerOptions& options);

}  // namespace stc
