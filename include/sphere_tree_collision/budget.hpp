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
// per `check_every` charged tests so the check stays cheap.
class BudgetTracker {
 public:
  using Clock = std::chrono::steady_clock;

  explicit BudgetTracker(const Budget& budget)
      : budget_(budget), start_(Clock::now()),
        timed_(budget.seconds < std::numeric_limits<double>::infinity()) {
    if (timed_) {
      deadline_ = start_ + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(budget.seconds > 0 ? budget.seconds : 0.0));
    }
  }

  void charge(std::int64_t sphere_tests) { spent_tests_ += sphere_tests; }
  std::int64_t spentTests() const { return spent_tests_; }

  // True once the test count or the deadline is reached.
  bool exhausted() {
    if (spent_tests_ >= budget_.sphere_tests) return true;
    if (!timed_) return false;
    if (budget_.seconds <= 0.0) return true;
    if (Clock::now() >= deadline_) { expired_at_ = Clock::now(); return true; }
    return false;
  }
  double elapsedSeconds() const {
    return std::chrono::duration<double>(Clock::now() - start_).count();
  }
  const Budget& budget() const { return budget_; }

 private:
  Budget budget_;
  Clock::time_point start_;
  Clock::time_point deadline_{};
  Clock::time_point expired_at_{};
  bool timed_ = false;
  std::int64_t spent_tests_ = 0;
};

}  // namespace stc
