// The options of the World's phases that WorldConfig gathers (world.hpp),
// apart from the phases themselves (internal, src/core): the narrow phase's
// scheduler (scheduler.hpp), sleeping islands (islands.hpp) and fracture
// (fracture.hpp), and the tick's threads (workers.hpp). The response's are
// response_options.hpp, the limits limits.hpp.
#pragma once

#include <cstdint>
#include <string>

namespace stc {

// --- The scheduler of the narrow phase (paper 3.4.3)

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

// --- Sleeping islands

struct SleepOptions {
  bool enabled = true;
  // m/s: a body whose centre and surface points moved on average slower than
  // this over time_to_sleep is resting (a spin counts by the surface speed it
  // gives, reach * |w|): each point stays in a ball of radius
  // linear_speed * time_to_sleep / 2 (5 mm), whatever its speed of the moment.
  double linear_speed = 0.02;
  double time_to_sleep = 0.5;  // s: an island whose bodies all rested this long sleeps
};
// Throws InputError naming the field ("sleeping.linear_speed",
// "sleeping.time_to_sleep"): each finite and >= 0.
void validateSleepOptions(const SleepOptions& options);

// --- The tick's threads (WorldConfig::threads and ~threads; docs/parallel.md)

// 0 (all cores) .. kMaxThreads.
constexpr int kMaxThreads = 256;
// Throws InputError("threads") outside [0, kMaxThreads].
void validateThreads(int threads);

// --- Fracture

// What happens to the components smaller than FractureOptions::min_piece_voxels.
enum class SmallPieces : std::uint8_t {
  Attach,  // they stay with the largest piece (mass and momentum kept)
  Vanish,  // they are dropped, as dust (their mass and momentum leave the world)
};
// "attach" | "vanish"; throws InputError("fracture.small_pieces").
SmallPieces parseSmallPieces(const std::string& name);

struct FractureOptions {
  int min_piece_voxels = 8;  // >= 1; the largest piece is kept whatever its size
  SmallPieces small_pieces = SmallPieces::Attach;
  // A piece's strength is the parent's times (piece volume / parent volume)
  // to this power (pieceStrength). 5/6: the energy balance of a crack
  // (docs/fracture.md); 0: pieces keep the parent's strength; >= 0.
  double strength_exponent = 5.0 / 6.0;
};
// Throws InputError("fracture.min_piece_voxels") (< 1),
// InputError("fracture.small_pieces") (not a known value) or
// InputError("fracture.strength_exponent") (not finite and >= 0).
void validateFractureOptions(const FractureOptions& options);

}  // namespace stc
