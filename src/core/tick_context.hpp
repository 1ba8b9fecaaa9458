// TickContext: what World::step's phases share for one tick, made once at
// its start (as Box2D v3's step context): the tick's parameters, its report,
// its clock and the physics phases' view of the World. PhaseTimer times a
// phase into the report.
#pragma once

#include "physics.hpp"
#include "deadline.hpp"
#include "sphere_tree_collision/tick_report.hpp"

namespace stc {

// The tick's time on the World's clock: when it began and when its last
// timed phase ended (where the next one begins).
struct TickTime {
  const SecondsClock* clock = nullptr;
  double start = 0.0;
  double now = 0.0;
};

// Times one phase, from the end of the phase before to when the timer leaves
// scope, into `seconds`. A phase boundary is one clock read, so a stepping
// test clock sees the reads it always saw, and the phases add up to the tick.
class PhaseTimer {
 public:
  PhaseTimer(TickTime& time, double& seconds) : time_(time), seconds_(seconds), start_(time.now) {}
  ~PhaseTimer() {
    time_.now = (*time_.clock)();
    seconds_ = time_.now - start_;
  }
  PhaseTimer(const PhaseTimer&) = delete;
  PhaseTimer& operator=(const PhaseTimer&) = delete;

  double start() const { return start_; }

 private:
  TickTime& time_;
  double& seconds_;
  double start_;
};

struct TickContext {
  explicit TickContext(TickReport& tick_report) : report(tick_report) {}

  TickReport& report;
  double dt = 0.0;
  Budget budget;
  Deadline tick_end;      // set with a tick budget
  bool timed = false;     // a tick budget
  bool levelled = false;  // a limited response: islands ranked, some held (island_levels.hpp)
  TickTime time;
  // The part of the tick the budget can cut runs from the narrow phase's
  // start to the response's end; the scheduler stopped at `scheduled`, and
  // what follows it cannot be cut (the reserve and the level costs learn it).
  double narrow_start = 0.0, scheduled = 0.0, response_end = 0.0;
  // What the physics phases read and write (physics.hpp). The response sets
  // held_asleep when islands are held; the rest holds for the whole tick.
  StepContext physics;
};

}  // namespace stc
