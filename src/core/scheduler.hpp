// Schedulers (paper 3.4.3): who gets the next step of the narrow phase until
// every PairTest resolves or the Budget ends.
#pragma once

#include "pair_test.hpp"
#include "deadline.hpp"
#include "sphere_tree_collision/perception.hpp"
#include "sphere_tree_collision/phase_options.hpp"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace stc {

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
