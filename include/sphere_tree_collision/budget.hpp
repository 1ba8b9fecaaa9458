// Budget: what one tick may spend. The narrow phase is interruptible by a
// wall-clock limit or a count of sphere-sphere tests (deterministic: tests and
// benchmarks); the whole tick (integrate, broad phase, narrow phase, response)
// by a tick deadline; the response's solver by a count of iterations. Any
// combination; the first limit reached wins.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>

namespace stc {

struct Budget {
  double seconds = std::numeric_limits<double>::infinity();       // narrow phase alone
  std::int64_t sphere_tests = std::numeric_limits<std::int64_t>::max();
  // Whole tick. The narrow phase gets what integrate and the broad phase
  // leave, less a reserve for the response's mandatory part; the solver
  // refines while time remains (World::step).
  double tick_seconds = std::numeric_limits<double>::infinity();
  // Velocity (and as many position) iterations of the solver; at least one
  // of each always runs. The deterministic form of the response's share.
  int solver_iterations = std::numeric_limits<int>::max();
  // Island levels (island_levels.hpp): the most response cost, in last
  // tick's contacts (and one per body), the islands stepped fully may bring;
  // the others are held still for the tick, momentum kept. The deterministic
  // form of what a tick budget does with the time it leaves the response.
  std::int64_t response_contacts = std::numeric_limits<std::int64_t>::max();

  static Budget unlimited() { return Budget{}; }
  static Budget ofSeconds(double s) { Budget b; b.seconds = s; return b; }
  static Budget ofSphereTests(std::int64_t n) { Budget b; b.sphere_tests = n; return b; }
  static Budget ofTickSeconds(double s) { Budget b; b.tick_seconds = s; return b; }
  static Budget ofSolverIterations(int n) { Budget b; b.solver_iterations = n; return b; }
  static Budget ofResponseContacts(std::int64_t n) { Budget b; b.response_contacts = n; return b; }
};

// Monotonic seconds. The World reads time only through one of these, so a
// test can replace it with a fake clock and make a time budget deterministic.
using SecondsClock = std::function<double()>;
double steadySeconds();  // std::chrono::steady_clock

}  // namespace stc
