// What the response phase does and how (paper 3.5, 4): the options of the
// contacts, the impulse solver and the swept test, checked in one place.
#pragma once

#include <cstdint>
#include <string>

namespace stc {

// How the impulses of one tick are iterated (docs/response.md has the measurements).
enum class SolverKind : std::uint8_t {
  Sequential,  // projected Gauss-Seidel (sequential impulses): each contact sees the last one's impulse
  Jacobi,      // the paper's simultaneous scheme: every iteration computes all impulses from
               // one state, then applies them together (mass splitting keeps it convergent)
  Soft,        // soft step (after Box2D v3): `substeps` substeps inside the tick, each one
               // biased pass with soft contacts, positions moved, one relaxing pass
               // (contact_solver_soft.cpp; docs/response.md: the soft step)
};
// "sequential" | "jacobi" | "soft"; throws InputError("solver") otherwise.
SolverKind parseSolverKind(const std::string& name);
const char* toString(SolverKind kind);

struct ResponseOptions {
  bool enabled = true;
  int iterations = 15;                  // velocity (and position) iterations per tick, >= 1
  // m/s: slower approach is treated as resting. The World raises it to at
  // least 4 |g| dt: a body resting under gravity falls that fast within a
  // speculative gap in one or two ticks, and bouncing on that would never settle.
  double restitution_threshold = 0.2;
  double position_correction = 0.2;     // fraction of penetration removed per tick, [0, 1]
  // The split-impulse position pass moves bodies out of penetration by
  // translation alone (false), or by translation and rotation (true: the
  // pass before; a pile's rocks then kept rocking in place, turned by
  // pseudo-velocities the velocity solve never sees; docs/sleeping.md).
  bool position_turns = false;
  double allowed_penetration = 0.0;     // metres kept as slop (0: 2% of the contact's gap bound h_a + h_b)
  SolverKind solver = SolverKind::Sequential;
  // The soft step (solver = Soft) only: substeps a tick (>= 1; more when a
  // contact is small for the tick: h <= 0.07 sqrt(its sphere bound / |g|), at
  // most 64; `iterations`, position_correction and shock_propagation are not
  // used), and its soft
  // contacts: a penetration beyond the slop is pushed out as a spring of
  // `contact_hertz` (Hz, >= 0; 0: a quarter of the substep rate, the most it
  // may be; twice that against an immovable body) with `contact_damping_ratio`
  // (> 0), at most `max_push_speed` m/s (> 0).
  int substeps = 4;
  double contact_hertz = 0.0;
  double contact_damping_ratio = 10.0;
  double max_push_speed = 3.0;
  // Sequential passes take four manifolds that share no movable body at a
  // time, side by side in vector registers (contact_solver_wide.cpp): the
  // same result bit for bit as one at a time (false), in less time. A
  // position pass that turns bodies runs one at a time.
  bool wide_passes = true;
  bool warm_starting = true;            // start from last tick's impulses of matching contacts
  // After the iterations, one sweep up the contact graph from the static
  // bodies in which each supporting body counts as immovable for what rests
  // on it (shock propagation, Guendelman et al. 2003): stacks and heavy-on-light
  // hold; only approach towards the support is removed, never added.
  bool shock_propagation = true;
  int max_contacts_per_pair = 4;        // spread-out representatives of the sphere pairs, 1..16
  bool face_normals = true;             // voxel-box face axis when it separates more (ContactBuilder)
  bool continuous = true;               // sweep fast bodies back to their first contact
  // A body is fast when it moves (incl. rotation at its farthest sphere) more
  // than this fraction of its smallest leaf radius in one tick.
  double sweep_threshold = 0.5;
  bool gyroscopic = true;               // implicit-midpoint w x Iw (see dynamics.hpp)
  // A colliding pair's contacts are kept from tick to tick, and the pair
  // skips the narrow phase and contact building, while no point of either
  // body moves relative to the other by more than this fraction of the
  // smaller leaf radius of the two since they were built
  // (pair_contact_cache.hpp). 0: every pair is tested and built every tick.
  // In [0, 1]; only with the response enabled. A carried contact is measured
  // again from anchors fixed in each body at this tick's poses, so its
  // separation follows the bodies; piles settle as with every contact built
  // (docs/response.md: reusing a pair's contacts, where 0.05 is measured).
  double reuse_tolerance = 0.05;
  // With threads > 1: a solver stage (contact_partition.hpp) of fewer
  // manifolds than this runs on the calling thread, a bigger one's blocks on
  // the workers (each hand-off may wake a worker; docs/parallel.md). >= 1.
  int solver_task_manifolds = 32;
};
// Throws InputError naming the field ("response.iterations", ...).
void validateResponseOptions(const ResponseOptions& options);

}  // namespace stc
