// TickReport: what one World::step did, in parts: the phases' times, what
// the budget gave each phase, the detection's pairs and tests, the accuracy
// given up (and whether perception weighed it), the response, fracture, and
// the bodies' count and health after the tick. The ROS layer copies it into
// ~tick_stats, the error-report CSV and diagnostics from one list of fields
// (src/ros/include/sphere_tree_collision/ros/tick_fields.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

namespace stc {

// The level of response a body's island got in the last tick
// (World::responseLevel; island levels: src/core/island_levels.hpp).
enum class ResponseLevel : std::uint8_t {
  Full,    // stepped fully (or no level applied: unlimited response)
  Held,    // held still for the tick, waiting for its turn
  Asleep,  // its island sleeps (islands.hpp)
  Static,  // a static body
};
const char* responseLevelName(ResponseLevel level);  // "full" | "held" | "asleep" | "static"

// What the island levels did in one tick (TickReport::response.levels).
struct IslandLevelReport {
  bool used = false;                // the response was limited: islands were ranked
  double allowance = 0.0;           // cost the full islands could bring (contacts; inf: any)
  double full_cost = 0.0;           // estimated cost of the islands stepped fully
  std::size_t islands_full = 0, bodies_full = 0;  // awake islands stepped fully (joined ones included)
  std::size_t islands_held = 0, bodies_held = 0;  // held still this tick
  std::size_t islands_joined = 0;   // chosen held, then stepped: a moving body reached them
  int most_ticks_held = 0;          // the longest wait of an island held now (ticks, this one included)
  std::size_t largest_island = 0;   // bodies of the largest awake island (one that always runs when first)
  double largest_cost = 0.0;        // its cost
  // Perceived cost of holding: the summed gaze priority (without aging) of
  // the islands held this tick. Summed over ticks it is the held ticks
  // weighted by how noticeable each island was.
  double held_priority = 0.0;
};

// Wall times of the phases, seconds, on the World's clock (World::setClock).
// Each phase starts where the one before ended, so with fracture_s
// (TickFracture) they add up to total_s.
struct TickPhases {
  double integrate_s = 0.0;  // island levels chosen, then integration
  double broad_s = 0.0;
  double sweep_s = 0.0;      // continuous collision of fast bodies, between broad and narrow phase
  double narrow_s = 0.0;
  double response_s = 0.0;
  double contacts_s = 0.0;   // of response_s: building the contacts (the rest is the solve)
  double total_s = 0.0;
  // With threads > 1 and World::timeTeamLoops on (else 0): the team's parallel
  // loops this tick, the calling thread's wall time inside them and, of that,
  // its wait for the other threads. total_s - team_loop_s ran on one thread.
  std::uint64_t team_loops = 0;
  double team_loop_s = 0.0, team_wait_s = 0.0;
};

// What each phase got of the budget. Integrate and the broad phase cannot be
// interrupted: they get what they use. The narrow phase gets Budget::seconds
// or what the tick budget leaves after them and the reserve, whichever is
// less; the response gets the rest of the tick (infinity: no limit).
struct TickBudgetShares {
  double tick_budget_s = std::numeric_limits<double>::infinity();
  double narrow_budget_s = std::numeric_limits<double>::infinity();
  double response_budget_s = std::numeric_limits<double>::infinity();
  // Kept back from the narrow phase (with a tick budget) for what cannot be
  // cut after it: its own accounting and the response's mandatory part (the
  // largest such cost of recent ticks, with a 25% margin: kReserveMargin in
  // world.cpp).
  double reserve_s = 0.0;
};

// The broad and narrow phases' pairs, and what the scheduler spent on them.
struct TickDetection {
  std::size_t broad_pairs = 0;
  std::size_t colliding = 0;            // resolved colliding at the leaves
  std::size_t reused = 0;               // of those, resumed with last tick's contacts (no sphere tested)
  std::size_t separate = 0;             // resolved separate
  std::size_t unresolved = 0;           // left unresolved at interruption
  std::size_t unresolved_accepted = 0;  // of those, accepted as colliding (policy accept)
  std::int64_t sphere_tests = 0;
  bool interrupted = false;
  double scheduling_overhead_s = 0.0;  // part of TickPhases::narrow_s spent deciding, not testing
};

// What the accepted unresolved pairs cost in accuracy, measured in 3D and as
// a viewer would perceive it (perception.hpp).
struct TickAccuracy {
  bool perception_used = false;       // false without a fixation: no projection work
  double geometric_inaccuracy = 0.0;  // nabla: sum of 3D gap estimates of accepted unresolved pairs
  double geometric_bound = 0.0;       // sum of rigorous bounds h_a + h_b over the same pairs
  double perceived_inaccuracy = 0.0;  // P: sum of f(e, g) over the same pairs
};

// The contacts and the solve.
struct TickResponse {
  std::size_t contacts = 0;
  // Of the accepted unresolved pairs, those that kept a deeper frontier's
  // contacts (Physics::kFrontierTolerance).
  std::size_t frontier_kept = 0;
  // Of the contacts, those measured against the other body's solid (node
  // kInteriorNode): a pair pressed deeper than its shells, or nested.
  std::size_t interior_contacts = 0;
  int velocity_passes = 0;             // solver iterations run (>= 1 with contacts)
  int position_passes = 0;             // split-impulse iterations run (>= 1 with penetration)
  double response_refinement_s = 0.0;  // of TickPhases::response_s: iterations the deadline could have cut
  // Under a limited response (a tick budget or Budget::response_contacts):
  // which awake islands were stepped fully and which were held still
  // (island_levels.hpp; World::responseLevel names each body's).
  IslandLevelReport levels;
};

// Bodies broken this tick (their pieces replace them; the tick's contacts
// are then dropped, as with any removal) and the time spent splitting them
// and building the pieces' trees, deferred splits included (at the tick's
// start and after the response).
struct TickFracture {
  std::size_t fractures = 0;
  std::size_t fractures_deferred = 0;  // waiting for time: broken from the next tick's start
  double fracture_s = 0.0;
  std::size_t piece_trees = 0;  // new pieces' sphere-trees built this tick
  double piece_tree_s = 0.0;    // of fracture_s: building them
};

// The bodies after the tick.
struct TickBodies {
  std::size_t entities = 0;
  std::size_t sleeping = 0;  // asleep after the tick (islands.hpp)
  // Removed at the end of the tick (World::quarantined() names them): state
  // non-finite or beyond the limits, and, apart, bodies that left the world.
  std::size_t quarantined = 0;
  std::size_t left_world = 0;
};

struct TickReport {
  TickPhases phases;
  TickBudgetShares budget;
  TickDetection detection;
  TickAccuracy accuracy;
  TickResponse response;
  TickFracture fracture;
  TickBodies bodies;
};

}  // namespace stc
