// The narrow phase cut for the workers (World::step): the pair list in
// static chunks, in pair order: one per thread under a budget, so each
// thread's scheduler orders all the pairs it takes; a few per thread,
// balanced over the threads (Team::Claim::Balanced), when nothing limits the
// phase, since every pair is then tested to the end whatever the order and a
// pile bunches its costly pairs in one part of the list. Each chunk has its own
// scheduler (the same kind and options), its own arena for its tests' hits
// and its share of the sphere-test budget, so chunks share nothing but the
// deadline while they run, and a chunk's result depends only on its pairs
// and its share: the same thread count gives the same chunks and results.
#pragma once

#include "pair_test.hpp"
#include "scheduler.hpp"
#include "workers.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace stc {

// A cache line of its own: a chunk's step counters change with every
// step, and a neighbour's thread reads its own next to them.
struct alignas(64) NarrowChunk {
  std::unique_ptr<Scheduler> scheduler;
  PairArena arena;    // hits and pairs of this chunk's tests
  ScheduleStats stats;  // of this tick's run
};

// Chunk k's share of a sphere-test budget: equal parts, the remainder to the
// first chunks, so the shares sum to the budget.
inline std::int64_t chunkShare(std::int64_t budget, std::size_t k, std::size_t chunks) {
  const auto n = static_cast<std::int64_t>(chunks);
  return budget / n + (static_cast<std::int64_t>(k) < budget % n ? 1 : 0);
}

// Chunks a thread when nothing limits the narrow phase.
constexpr std::size_t kUnlimitedChunksPerThread = 4;

// Chunks the narrow phase is cut into on `threads` threads, `limited` by a
// sphere-test budget or a deadline, or not.
inline std::size_t narrowChunkCount(std::size_t threads, bool limited) {
  return threads > 1 && !limited ? kUnlimitedChunksPerThread * threads : threads;
}

// `chunks` chunks with a scheduler each (makeScheduler: validates the options).
std::vector<NarrowChunk> makeNarrowChunks(std::size_t chunks, const SchedulerOptions& options);

// The first `count` chunks' stats as one run's: tests and overhead summed, interrupted and
// used_perception when any chunk was.
ScheduleStats mergedStats(const std::vector<NarrowChunk>& chunks, std::size_t count);

}  // namespace stc
