// Budget: what ends the narrow phase of one tick. A wall-clock deadline, a
// count of sphere-sphere tests (deterministic: tests and benchmarks), or both.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>

namespace stc {

struct Budget {
  double seconds = std::numeric_limits<double>::infinity();
  std::int64_t sphere_tests = std::numeric_limits<std::int64_t>::max();

  static Budget unlimited() { return Budget{}; }
  static Budget ofSeconds(double s) { Budget b; b.seconds = s; return b; }
  static Budget ofSphereTests(std::int64_t n) { Budget b; b.sphere_tests = n; return b; }
};

// Tracks one tick's spending against a Budget. The clock is read at most once
// per `check_every` charged tests so the check stays cheap (a clock read costs
// tens of ns, as much as several sphere tests): a wall-clock deadline is seen
// at most `check_every` tests (plus the step in progress) late. The first
// check always reads the clock.
class BudgetTracker {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::int64_t kDefaultCheckEvery = 32;

  explicit BudgetTracker(const Budget& budget, std::int64_t check_every = kDefaultCheckEvery)
      : budget_(budget), start_(Clock::now()),
        timed_(budget.seconds < std::numeric_limits<double>::infinity()),
        check_every_(check_every > 0 ? check_every : 1) {
    if (timed_) {
      deadline_ = start_ + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(budget.seconds > 0 ? budget.seconds : 0.0));
    }
  }

  void charge(std::int64_t sphere_tests) { spent_tests_ += sphere_tests; }
  std::int64_t spentTests() const { return spent_tests_; }

  // True once the test count or the deadline is reached. Once true, stays true.
  bool exhausted() {
    if (spent_tests_ >= budget_.sphere_tests) return true;
    if (!timed_) return false;
    if (expired_) return true;
    if (budget_.seconds <= 0.0) return expired_ = true;
    if (spent_tests_ < next_clock_check_) return false;
    next_clock_check_ = spent_tests_ + check_every_;
    return expired_ = Clock::now() >= deadline_;
  }
  double elapsedSeconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }
  const Budget& budget() const { return budget_; }

 private:
  Budget budget_;
  Clock::time_point start_;
  Clock::time_point deadline_{};
  bool timed_ = false;
  bool expired_ = false;
  std::int64_t check_every_ = kDefaultCheckEvery;
  std::int64_t next_clock_check_ = 0;
  std::int64_t spent_tests_ = 0;
};

}  // namespace stc
