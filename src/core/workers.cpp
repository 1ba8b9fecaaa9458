// Workers on a oneTBB task arena (workers.hpp).
#include "sphere_tree_collision/workers.hpp"

#include "sphere_tree_collision/types.hpp"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <string>

namespace stc {

void validateThreads(int threads) {
  if (threads < 0 || threads > kMaxThreads) {
    throw InputError("threads", "must be in [0, " + std::to_string(kMaxThreads) + "] (0: all cores), got " +
                                    std::to_string(threads));
  }
}

int resolveThreads(int threads) {
  validateThreads(threads);
  if (threads > 0) return threads;
  const int cores = tbb::info::default_concurrency();  // honours the process's CPU mask
  return cores > 0 ? std::min(cores, kMaxThreads) : 1;
}

struct Workers::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

Workers::Workers(int threads) : threads_(resolveThreads(threads)) {
  if (threads_ > 1) arena_ = std::make_unique<Arena>(threads_);
}
Workers::~Workers() = default;
Workers::Workers(Workers&&) noexcept = default;
Workers& Workers::operator=(Workers&&) noexcept = default;

void Workers::forEach(std::size_t n, std::size_t grain, RangeFn fn) const {
  if (n == 0) return;
  if (!arena_ || n <= grain) {
    fn(0, n);
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain > 0 ? grain : 1),
                      [&](const tbb::blocked_range<std::size_t>& r) { fn(r.begin(), r.end()); });
  });
}

void Workers::forChunks(std::size_t chunks, RangeFn fn) const {
  if (chunks == 0) return;
  if (!arena_ || chunks == 1) {
    for (std::size_t k = 0; k < chunks; ++k) fn(k, k + 1);
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k < r.end(); ++k) fn(k, k + 1);
                      },
                      tbb::simple_partitioner());
  });
}

}  // namespace stc
