// Workers on a oneTBB task arena (workers.hpp).
#include "sphere_tree_collision/workers.hpp"

#include "sphere_tree_collision/types.hpp"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

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

namespace {

// Spins before a waiting thread yields its core: long enough to cover a
// stage of a few microseconds, short enough that on a loaded machine the
// thread it waits for gets the core back soon.
constexpr int kSpinsBeforeYield = 2000;
// Blocks a thread a loop in a session is cut into: claimed as threads come
// free, so uneven blocks even out.
constexpr std::size_t kBlocksPerThread = 4;

inline void relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Waits until done() holds, spinning, then yielding the core.
template <typename Done>
void waitUntil(Done&& done) {
  for (int spins = 0; !done(); ++spins) {
    if (spins < kSpinsBeforeYield) {
      relax();
    } else {
      std::this_thread::yield();
    }
  }
}

}  // namespace

struct Workers::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;

  // The stages of one session, numbered in the order they are published
  // (every runStages call of the session continues the count). A stage is
  // set up just before it is published and never reused within the
  // session, so a thread that is late for a stage only finds its blocks taken.
  struct Stage {
    std::atomic<std::uint64_t> claimed{0};  // a bit per block
    std::atomic<std::uint32_t> done{0};     // blocks finished
    std::uint32_t blocks = 0;
    std::size_t index = 0;                  // the stage's number in its runStages call
    const StageFns* fns = nullptr;
  };
  // In pages that never move: a helper may read a stage while the caller
  // adds pages. Allocated once, kept for later sessions.
  static constexpr std::size_t kPageStages = 1024;
  static constexpr std::size_t kMaxPages = 4096;
  std::unique_ptr<std::unique_ptr<Stage[]>[]> pages{new std::unique_ptr<Stage[]>[kMaxPages]};
  Stage& stage(std::size_t sequence) { return pages[sequence / kPageStages][sequence % kPageStages]; }

  std::atomic<std::int64_t> published{-1};  // the last stage published; -1: none yet
  std::atomic<bool> finished{false};
  std::atomic<int> joined{0};  // helpers that have started: each one's place
  std::size_t next_sequence = 0;  // the caller's: the next stage's number
  std::atomic<bool> in_session{false};  // written by the caller alone
  std::thread::id caller;               // the session's calling thread
  tbb::task_group helpers;

  // Runs the blocks of stage `sequence` this thread can claim: first its
  // own share (thread `self` of `threads`: the same run of blocks in every
  // stage, so it meets the same bodies stage after stage and they stay in
  // its cache), then any left.
  void work(std::size_t sequence, int self, int threads) {
    Stage& st = stage(sequence);
    const auto take = [&](std::uint32_t k) {
      const std::uint64_t bit = std::uint64_t{1} << k;
      if (st.claimed.fetch_or(bit, std::memory_order_relaxed) & bit) return;
      st.fns->run(st.index, k);
      st.done.fetch_add(1, std::memory_order_release);
    };
    const auto [own_first, own_end] =
        chunkRange(st.blocks, static_cast<std::size_t>(self), static_cast<std::size_t>(threads));
    for (std::size_t k = own_first; k < own_end; ++k) take(static_cast<std::uint32_t>(k));
    for (std::uint32_t k = 0; k < st.blocks; ++k) {
      if (st.claimed.load(std::memory_order_relaxed) == allBlocks(st.blocks)) return;
      take(k);
    }
  }
  static std::uint64_t allBlocks(std::uint32_t blocks) {
    return blocks >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << blocks) - 1;
  }

  // A helper's life: the session's stages as they are published, until it ends.
  void help(int threads) {
    const int self = 1 + joined.fetch_add(1, std::memory_order_relaxed);
    std::int64_t last = -1;
    for (int spins = 0;;) {
      if (finished.load(std::memory_order_acquire)) return;
      const std::int64_t s = published.load(std::memory_order_acquire);
      if (s != last) {
        work(static_cast<std::size_t>(s), self, threads);
        last = s;
        spins = 0;
      } else if (++spins < kSpinsBeforeYield) {
        relax();
      } else {
        std::this_thread::yield();
      }
    }
  }
};

Workers::Workers(int threads) : threads_(resolveThreads(threads)) {
  if (threads_ > 1) arena_ = std::make_unique<Arena>(threads_);
}
Workers::~Workers() = default;
Workers::Workers(Workers&&) noexcept = default;
Workers& Workers::operator=(Workers&&) noexcept = default;

bool Workers::inSessionOfThisThread() const {
  return arena_ && arena_->in_session.load(std::memory_order_relaxed) &&
         arena_->caller == std::this_thread::get_id();
}

bool Workers::inSessionOfAnotherThread() const {
  return arena_ && arena_->in_session.load(std::memory_order_relaxed) &&
         arena_->caller != std::this_thread::get_id();
}

void Workers::forEach(std::size_t n, std::size_t grain, RangeFn fn) const {
  if (n == 0) return;
  if (!arena_ || n <= grain || inSessionOfAnotherThread()) {
    fn(0, n);
    return;
  }
  if (inSessionOfThisThread()) {
    // The session's threads are awake: one stage, in blocks of at least `grain`.
    const std::size_t blocks = std::min({n / std::max<std::size_t>(grain, 1),
                                         static_cast<std::size_t>(threads_) * kBlocksPerThread, kMaxStageBlocks});
    const auto block_count = [&](std::size_t) { return blocks; };
    const auto run = [&](std::size_t, std::size_t k) {
      const auto [begin, end] = chunkRange(n, k, blocks);
      fn(begin, end);
    };
    const auto go_on = [](std::size_t) { return true; };
    runStages(1, StageFns{block_count, run, go_on});
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain > 0 ? grain : 1),
                      [&](const tbb::blocked_range<std::size_t>& r) { fn(r.begin(), r.end()); });
  });
}

void Workers::forChunks(std::size_t chunks, RangeFn fn) const {
  if (chunks == 0) return;
  if (!arena_ || chunks == 1 || inSessionOfAnotherThread()) {
    for (std::size_t k = 0; k < chunks; ++k) fn(k, k + 1);
    return;
  }
  if (inSessionOfThisThread() && chunks <= kMaxStageBlocks) {
    const auto block_count = [&](std::size_t) { return chunks; };
    const auto run = [&](std::size_t, std::size_t k) { fn(k, k + 1); };
    const auto go_on = [](std::size_t) { return true; };
    runStages(1, StageFns{block_count, run, go_on});
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

void Workers::session(FunctionRef<void()> body) const {
  if (!arena_ || arena_->in_session.load(std::memory_order_relaxed)) {
    body();  // no threads, or inside a session (this thread's: the same one; another's: alone)
    return;
  }
  Arena& a = *arena_;
  a.caller = std::this_thread::get_id();
  a.published.store(-1, std::memory_order_relaxed);
  a.finished.store(false, std::memory_order_relaxed);
  a.joined.store(0, std::memory_order_relaxed);
  a.next_sequence = 0;
  a.in_session.store(true, std::memory_order_relaxed);
  a.arena.execute([&] {
    const int threads = threads_;
    for (int t = 1; t < threads; ++t) a.helpers.run([&a, threads] { a.help(threads); });
    // The helpers are released however body ends.
    struct Release {
      Arena& a;
      ~Release() {
        a.finished.store(true, std::memory_order_release);
        a.helpers.wait();
        a.in_session.store(false, std::memory_order_relaxed);
      }
    } release{a};
    body();
  });
}

std::size_t Workers::runStages(std::size_t stages, const StageFns& fns) const {
  if (!arena_ || inSessionOfAnotherThread()) return stc::runStages(nullptr, stages, fns);
  Arena& a = *arena_;
  if (!a.in_session.load(std::memory_order_relaxed)) {
    std::size_t run = 0;
    session([&] { run = runStages(stages, fns); });
    return run;
  }
  std::size_t run = 0;
  for (; run < stages; ++run) {
    if (!fns.go_on(run)) break;
    if (a.next_sequence == Arena::kPageStages * Arena::kMaxPages) {  // 4 M stages in one session
      for (std::size_t k = 0; k < fns.blocks(run); ++k) fns.run(run, k);  // the caller alone
      continue;
    }
    const std::size_t sequence = a.next_sequence++;
    std::unique_ptr<Arena::Stage[]>& page = a.pages[sequence / Arena::kPageStages];
    if (!page) page.reset(new Arena::Stage[Arena::kPageStages]);
    Arena::Stage& stage = a.stage(sequence);
    stage.claimed.store(0, std::memory_order_relaxed);
    stage.done.store(0, std::memory_order_relaxed);
    stage.blocks = static_cast<std::uint32_t>(fns.blocks(run));
    assert(stage.blocks >= 1 && stage.blocks <= kMaxStageBlocks);
    stage.index = run;
    stage.fns = &fns;
    a.published.store(static_cast<std::int64_t>(sequence), std::memory_order_release);
    a.work(sequence, 0, threads_);
    waitUntil([&] { return stage.done.load(std::memory_order_acquire) >= stage.blocks; });
  }
  return run;
}

std::size_t runStages(const Workers* workers, std::size_t stages, const StageFns& fns) {
  if (workers != nullptr) return workers->runStages(stages, fns);
  std::size_t run = 0;
  for (; run < stages && fns.go_on(run); ++run) {
    const std::size_t blocks = fns.blocks(run);
    for (std::size_t k = 0; k < blocks; ++k) fns.run(run, k);
  }
  return run;
}

}  // namespace stc
