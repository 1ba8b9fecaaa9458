// The narrow phase's chunks (narrow_chunks.hpp).
#include "narrow_chunks.hpp"

namespace stc {

std::vector<NarrowChunk> makeNarrowChunks(std::size_t chunks, const SchedulerOptions& options) {
  std::vector<NarrowChunk> out(chunks);
  for (NarrowChunk& chunk : out) chunk.scheduler = makeScheduler(options);
  return out;
}

ScheduleStats mergedStats(const std::vector<NarrowChunk>& chunks, std::size_t count) {
  ScheduleStats total;
  for (std::size_t k = 0; k < count; ++k) {
    const NarrowChunk& chunk = chunks[k];
    total.sphere_tests += chunk.stats.sphere_tests;
    total.interrupted = total.interrupted || chunk.stats.interrupted;
    total.overhead_seconds += chunk.stats.overhead_seconds;
    total.used_perception = total.used_perception || chunk.stats.used_perception;
  }
  return total;
}

}  // namespace stc
