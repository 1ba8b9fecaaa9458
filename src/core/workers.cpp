// Workers on a oneTBB task arena (workers.hpp).
#include "workers.hpp"

#include "sphere_tree_collision/budget.hpp"
#include "sphere_tree_collision/types.hpp"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <string>
#include <thread>

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

// A short wait in a spin loop; after many, the core is offered to others
// (a loaded machine), at the cost of a later start.
class Spin {
 public:
  void wait() {
    if (++spins_ < kBeforeYield) {
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    } else {
      std::this_thread::yield();
    }
  }
  void reset() { spins_ = 0; }

 private:
  static constexpr int kBeforeYield = 1 << 14;
  int spins_ = 0;
};

}  // namespace

// A stage is published like a sequence lock: `sequence` is odd while the
// calling thread writes the stage's fields and even once they are out, so a
// member that read the same even value before and after reading the fields
// has one stage's fields. Each block keeps the sequence of the stage that
// took it; a member takes a block by raising that to its own stage's, so a
// member still reading an old stage takes nothing.
//
// A member task stays after a withTeam call for kLinger, spinning, so that
// the next call (the next tick) finds it awake; then it leaves. A member
// leaving clears `present` and then reads `open`; withTeam sets `open` and
// then reads `present`: one of the two sees the other, so a call never
// lacks a member that it thinks is there (at worst two tasks serve as one
// member, which claiming makes harmless).
struct Team::State {
  std::atomic<std::uint64_t> sequence{0};
  std::atomic<const RangeFn*> fn{nullptr};
  std::atomic<std::size_t> count{0};
  std::atomic<std::size_t> done{0};
  std::atomic<Team::Claim> claim{Team::Claim::OwnShareWhole};
  std::array<std::atomic<std::uint64_t>, kMaxBlocks> taken{};
  std::atomic<bool> open{false};      // a withTeam call is running
  std::atomic<bool> shutdown{false};  // the Workers are going
  std::array<std::atomic<bool>, kMaxThreads> present{};  // a task serves as member m
  bool timed = false;  // read and written by the calling thread only, as `times`
  LoopTimes times;
};

namespace {
constexpr std::chrono::microseconds kLinger{2000};
}  // namespace

struct Workers::Arena {
  explicit Arena(int threads) : arena(threads), team(&state, threads) {}
  ~Arena();
  tbb::task_arena arena;
  Team::State state;
  Team team;                // of the state above
  tbb::task_group members;  // the member tasks; they outlive a withTeam call by a linger
  bool running = false;     // in withTeam; set and read by the calling thread
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
  if (arena_->running) {  // pieces of at least `grain`, a few per member
    const std::size_t most = 4 * static_cast<std::size_t>(threads_);
    const std::size_t pieces = std::min({most, Team::kMaxBlocks, n / std::max<std::size_t>(grain, 1)});
    arena_->team.forBlocks(pieces, [&](std::size_t k, std::size_t) {
      const auto [begin, end] = chunkRange(n, k, pieces);
      fn(begin, end);
    });
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain > 0 ? grain : 1),
                      [&](const tbb::blocked_range<std::size_t>& r) { fn(r.begin(), r.end()); });
  });
}

void Workers::forChunks(std::size_t chunks, RangeFn fn, Team::Claim claim) const {
  if (chunks == 0) return;
  if (!arena_ || chunks == 1) {
    for (std::size_t k = 0; k < chunks; ++k) fn(k, k + 1);
    return;
  }
  if (arena_->running) {
    arena_->team.forBlocks(chunks, fn, claim);
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

void Team::take(int member, std::uint64_t stage, const RangeFn* fn, std::size_t count, Claim claim_mode) {
  const auto claim = [&](std::size_t k) {
    std::uint64_t was = state_->taken[k].load(std::memory_order_relaxed);
    while (was < stage) {
      if (state_->taken[k].compare_exchange_weak(was, stage, std::memory_order_acq_rel)) return true;
    }
    return false;
  };
  const auto run = [&](std::size_t k) {
    (*fn)(k, k + 1);
    state_->done.fetch_add(1, std::memory_order_release);
  };
  const std::size_t first = (static_cast<std::size_t>(member) * count + members_ - 1) / members_;
  const std::size_t last = (static_cast<std::size_t>(member + 1) * count + members_ - 1) / members_;
  if (claim_mode == Claim::Balanced) {
    for (std::size_t k = first; k < last; ++k) {
      if (claim(k)) run(k);
    }
    // The others' shares from their ends, where their members get to last.
    for (std::size_t i = 1; i <= count - (last - first); ++i) {
      const std::size_t k = (first + count - i) % count;
      if (claim(k)) run(k);
    }
    return;
  }
  // The own share is claimed whole before any of it runs: a busy member's
  // next block stays its own (taking it would move its data between cores).
  std::uint64_t own = 0;  // bit k - first: claimed (at most kMaxBlocks)
  for (std::size_t k = first; k < last; ++k) {
    if (claim(k)) own |= std::uint64_t{1} << (k - first);
  }
  for (std::size_t k = first; k < last; ++k) {
    if ((own >> (k - first)) & 1u) run(k);
  }
  for (std::size_t i = last - first; i < count; ++i) {  // then what the others have not claimed
    const std::size_t k = (first + i) % count;
    if (claim(k)) run(k);
  }
}

void Team::forBlocks(std::size_t count, RangeFn fn, Claim claim) {
  if (state_ == nullptr || count < 2) {
    for (std::size_t k = 0; k < count; ++k) fn(k, k + 1);
    return;
  }
  for (std::size_t base = 0; base < count; base += kMaxBlocks) {
    const double start = state_->timed ? steadySeconds() : 0.0;
    const std::size_t round = std::min(kMaxBlocks, count - base);
    const auto shifted = [&](std::size_t k, std::size_t) { fn(base + k, base + k + 1); };
    const RangeFn round_fn(shifted);
    const std::uint64_t odd = state_->sequence.load(std::memory_order_relaxed) + 1;
    state_->sequence.store(odd, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    state_->fn.store(&round_fn, std::memory_order_relaxed);
    state_->count.store(round, std::memory_order_relaxed);
    state_->claim.store(claim, std::memory_order_relaxed);
    state_->done.store(0, std::memory_order_relaxed);
    state_->sequence.store(odd + 1, std::memory_order_release);
    take(0, odd + 1, &round_fn, round, claim);
    const double own_done = state_->timed ? steadySeconds() : 0.0;
    Spin spin;
    while (state_->done.load(std::memory_order_acquire) < round) spin.wait();
    if (state_->timed) {
      const double end = steadySeconds();
      ++state_->times.loops;
      state_->times.loop_s += end - start;
      state_->times.wait_s += end - own_done;
    }
  }
}

void Team::serve(int member) {
  std::uint64_t served = 0;
  Spin spin;
  auto idle_since = std::chrono::steady_clock::now();
  for (unsigned idle = 0;; ++idle) {
    const std::uint64_t stage = state_->sequence.load(std::memory_order_acquire);
    if (stage != served && (stage & 1u) == 0) {
      const RangeFn* fn = state_->fn.load(std::memory_order_relaxed);
      const std::size_t count = state_->count.load(std::memory_order_relaxed);
      const Claim claim = state_->claim.load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (state_->sequence.load(std::memory_order_relaxed) != stage) continue;  // rewritten meanwhile
      served = stage;
      take(member, stage, fn, count, claim);  // fn is called only for a block taken: the stage is live
      spin.reset();
      idle = 0;
      idle_since = std::chrono::steady_clock::now();
      continue;
    }
    if (state_->shutdown.load(std::memory_order_acquire)) break;
    if (idle % 256 == 255) {
      const auto now = std::chrono::steady_clock::now();
      if (state_->open.load(std::memory_order_acquire)) {
        idle_since = now;
      } else if (now - idle_since > kLinger) {
        state_->present[static_cast<std::size_t>(member)].store(false);
        if (!state_->open.load()) return;
        state_->present[static_cast<std::size_t>(member)].store(true);  // a call began: stay
      }
    }
    spin.wait();
  }
  state_->present[static_cast<std::size_t>(member)].store(false);
}

Workers::Arena::~Arena() {
  state.shutdown.store(true, std::memory_order_release);
  arena.execute([&] { members.wait(); });
}

void Workers::timeLoops(bool on) {
  if (arena_) arena_->state.timed = on;
}

LoopTimes Workers::loopTimes() const { return arena_ ? arena_->state.times : LoopTimes{}; }

void Workers::runTeam(void (*call)(void*, Team&), void* body) const {
  if (!arena_) {
    Team alone(nullptr, 1);
    call(body, alone);
    return;
  }
  if (arena_->running) {  // within withTeam: the same team
    call(body, arena_->team);
    return;
  }
  Arena& a = *arena_;
  Team::State& state = a.state;
  a.running = true;
  state.open.store(true);
  for (int m = 1; m < threads_; ++m) {
    if (state.present[static_cast<std::size_t>(m)].load()) continue;  // still there from the last call
    state.present[static_cast<std::size_t>(m)].store(true);
    a.arena.execute([&a, m] { a.members.run([&a, m] { a.team.serve(m); }); });
  }
  const auto close = [&] {
    state.open.store(false, std::memory_order_release);
    a.running = false;
  };
  try {
    call(body, a.team);
  } catch (...) {
    close();
    throw;
  }
  close();
}

}  // namespace stc
