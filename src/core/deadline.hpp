// Deadline and BudgetTracker: how the tick's phases keep to a Budget
// (budget.hpp) inside the core. Internal: World::step takes a Budget, and
// no public call names these.
#pragma once

#include "sphere_tree_collision/budget.hpp"

#include <cstdint>
#include <limits>

namespace stc {

// A time a phase must end by, on a clock (nullptr: the steady clock).
class Deadline {
 public:
  Deadline() = default;  // never
  Deadline(const SecondsClock* clock, double at) : clock_(clock), at_(at) {}

  bool isSet() const { return at_ < std::numeric_limits<double>::infinity(); }
  double at() const { return at_; }
  double now() const { return clock_ != nullptr ? (*clock_)() : steadySeconds(); }
  // Seconds left (negative once passed); infinity when not set (no clock read).
  double remaining() const { return isSet() ? at_ - now() : std::numeric_limits<double>::infinity(); }
  bool passed() const { return isSet() && now() >= at_; }

 private:
  const SecondsClock* clock_ = nullptr;
  double at_ = std::numeric_limits<double>::infinity();
};

// Tracks the narrow phase's spending against a sphere-test count and a
// deadline. The clock is read at most once per `check_every` charged tests so
// the check stays cheap (the steady clock's read costs tens of ns, as much as
// several sphere tests): a deadline is seen at most `check_every` tests (plus
// the step in progress) late. The first check always reads the clock.
class BudgetTracker {
 public:
  static constexpr std::int64_t kDefaultCheckEvery = 32;

  // The narrow phase alone: budget.seconds from now on the steady clock.
  explicit BudgetTracker(const Budget& budget, std::int64_t check_every = kDefaultCheckEvery);
  BudgetTracker(std::int64_t sphere_tests, const Deadline& deadline,
                std::int64_t check_every = kDefaultCheckEvery)
      : sphere_tests_(sphere_tests), deadline_(deadline), check_every_(check_every > 0 ? check_every : 1) {}

  void charge(std::int64_t sphere_tests) { spent_tests_ += sphere_tests; }
  std::int64_t spentTests() const { return spent_tests_; }

  // True once the test count or the deadline is reached. Once true, stays true.
  bool exhausted() {
    if (spent_tests_ >= sphere_tests_) return true;
    if (!deadline_.isSet()) return false;
    if (expired_) return true;
    if (spent_tests_ < next_clock_check_) return false;
    next_clock_check_ = spent_tests_ + check_every_;
    return expired_ = deadline_.passed();
  }

 private:
  std::int64_t sphere_tests_;
  Deadline deadline_;
  bool expired_ = false;
  std::int64_t check_every_;
  std::int64_t next_clock_check_ = 0;
  std::int64_t spent_tests_ = 0;
};

// The check interval for `clock`: BudgetTracker::kDefaultCheckEvery scaled by
// what a read of it costs against a read of the steady clock (each the least
// of a few timed batches, so a preempted batch does not count), between
// kDefaultCheckEvery and kMostCheckEvery (a clock within twice the steady
// clock's cost keeps the default). Reading it then costs the narrow
// phase the share the steady clock costs at the default: a thread CPU clock
// is a system call, about 20 times the steady clock's read, and read every 32
// tests it took 13 % of a budgeted rockfall's tick. Reads `clock` 64 times.
inline constexpr std::int64_t kMostCheckEvery = 4096;
std::int64_t checkEveryFor(const SecondsClock& clock);

}  // namespace stc
