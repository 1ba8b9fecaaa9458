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
#include <array>
#include <atomic>
#include <cassert>
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

// Members copy a round out of the State (below), never through a pointer to
// the caller's: the caller returns once the last block is done, while a
// member may still be reading. `fn` and `after` are read only for a block
// claimed, while the round is live.
struct Team::Round {
  std::uint64_t sequence = 0;  // the value of State::sequence it was published under
  const RangeFn* fn = nullptr;
  std::size_t count = 0;
  const std::uint64_t* after = nullptr;  // null: no block waits for another
  std::size_t stages = 1;
  std::array<std::uint32_t, kMaxStages + 1> stage_first{};  // stage s: [stage_first[s], stage_first[s + 1])
};

// A round is published like a sequence lock: `sequence` is odd while the
// calling thread writes the round's fields and even once they are out, so a
// member that read the same even value before and after reading the fields
// has one round's fields. Each block keeps the sequence of the round that
// took it; a member takes a block by raising that to its own round's, so a
// member still reading an old round takes nothing. In a forBlocksAfter round
// a block also records the round that finished it, for the blocks waiting.
//
// A member task stays after a withTeam call for kLinger, spinning, so that
// the next call (the next tick) finds it awake; then it leaves. A member
// leaving clears `present` and then reads `open`; withTeam sets `open` and
// then reads `present`: one of the two sees the other, so a call never
// lacks a member that it thinks is there (at worst two tasks serve as one
// member, which claiming makes harmless).
struct Team::State {
  std::atomic<std::uint64_t> sequence{0};
  // The live round's fields (Round), written while `sequence` is odd.
  std::atomic<const RangeFn*> fn{nullptr};
  std::atomic<std::size_t> count{0};
  std::atomic<const std::uint64_t*> after{nullptr};
  std::atomic<std::size_t> stages{1};
  std::array<std::atomic<std::uint32_t>, kMaxStages + 1> stage_first{};
  std::atomic<std::size_t> done{0};
  std::array<std::atomic<std::uint64_t>, kMaxBlocks> taken{};
  std::array<std::atomic<std::uint64_t>, kMaxBlocks> finished{};  // the round that last finished it
  std::atomic<bool> open{false};      // a withTeam call is running
  std::atomic<bool> shutdown{false};  // the Workers are going
  std::array<std::atomic<bool>, kMaxThreads> present{};  // a task serves as member m
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

void Workers::forChunks(std::size_t chunks, RangeFn fn) const {
  if (chunks == 0) return;
  if (!arena_ || chunks == 1) {
    for (std::size_t k = 0; k < chunks; ++k) fn(k, k + 1);
    return;
  }
  if (arena_->running) {
    arena_->team.forBlocks(chunks, fn);
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

namespace {

// Claims block k for the round published as `sequence`; false when a member did first.
bool claimBlock(std::array<std::atomic<std::uint64_t>, Team::kMaxBlocks>& taken, std::size_t k,
                std::uint64_t sequence) {
  std::uint64_t was = taken[k].load(std::memory_order_relaxed);
  while (was < sequence) {
    if (taken[k].compare_exchange_weak(was, sequence, std::memory_order_acq_rel)) return true;
  }
  return false;
}

}  // namespace

void Team::runAfter(std::size_t k, const Round& round) {
  if (round.after != nullptr) {
    for (std::uint64_t wait = round.after[k]; wait != 0; wait &= wait - 1) {
      const auto j = static_cast<std::size_t>(__builtin_ctzll(wait));
      Spin spin;
      while (state_->finished[j].load(std::memory_order_acquire) < round.sequence) {
        if (claimBlock(state_->taken, j, round.sequence)) {  // nobody has it: run it here
          runAfter(j, round);
          break;
        }
        spin.wait();
      }
    }
  }
  (*round.fn)(k, k + 1);
  if (round.after != nullptr) state_->finished[k].store(round.sequence, std::memory_order_release);
  state_->done.fetch_add(1, std::memory_order_release);
}

void Team::take(int member, const Round& round) {
  // The own share of each stage is claimed whole before any of it runs: a
  // busy member's next block stays its own (taking it would move its data
  // between cores).
  const std::size_t members = static_cast<std::size_t>(members_);
  const auto m = static_cast<std::size_t>(member);
  std::uint64_t own = 0;  // bit k: claimed here
  for (std::size_t s = 0; s < round.stages; ++s) {
    const std::size_t begin = round.stage_first[s];
    const std::size_t size = round.stage_first[s + 1] - begin;
    const std::size_t first = begin + (m * size + members - 1) / members;
    const std::size_t last = begin + ((m + 1) * size + members - 1) / members;
    for (std::size_t k = first; k < last; ++k) {
      if (claimBlock(state_->taken, k, round.sequence)) own |= std::uint64_t{1} << k;
    }
  }
  for (std::uint64_t left = own; left != 0; left &= left - 1) {
    runAfter(static_cast<std::size_t>(__builtin_ctzll(left)), round);
  }
  for (std::size_t k = 0; k < round.count; ++k) {  // then what the others have not claimed
    if (claimBlock(state_->taken, k, round.sequence)) runAfter(k, round);
  }
}

void Team::publish(Round& round) {
  const std::uint64_t odd = state_->sequence.load(std::memory_order_relaxed) + 1;
  state_->sequence.store(odd, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
  state_->fn.store(round.fn, std::memory_order_relaxed);
  state_->count.store(round.count, std::memory_order_relaxed);
  state_->after.store(round.after, std::memory_order_relaxed);
  state_->stages.store(round.stages, std::memory_order_relaxed);
  for (std::size_t s = 0; s <= round.stages; ++s) state_->stage_first[s].store(round.stage_first[s], std::memory_order_relaxed);
  state_->done.store(0, std::memory_order_relaxed);
  round.sequence = odd + 1;
  state_->sequence.store(round.sequence, std::memory_order_release);
  take(0, round);
  Spin spin;
  while (state_->done.load(std::memory_order_acquire) < round.count) spin.wait();
}

void Team::forBlocks(std::size_t count, RangeFn fn) {
  if (state_ == nullptr || count < 2) {
    for (std::size_t k = 0; k < count; ++k) fn(k, k + 1);
    return;
  }
  for (std::size_t base = 0; base < count; base += kMaxBlocks) {
    const auto shifted = [&](std::size_t k, std::size_t) { fn(base + k, base + k + 1); };
    const RangeFn round_fn(shifted);
    Round round;
    round.fn = &round_fn;
    round.count = std::min(kMaxBlocks, count - base);
    round.stage_first[1] = static_cast<std::uint32_t>(round.count);
    publish(round);
  }
}

void Team::forBlocksAfter(std::size_t count, const std::uint64_t* after, const std::uint32_t* stage_first,
                          std::size_t stages, RangeFn fn) {
  assert(count <= kMaxBlocks && stages <= kMaxStages && stage_first[0] == 0 && stage_first[stages] == count);
  if (state_ == nullptr || count < 2) {  // in order: every block's `after` comes before it
    for (std::size_t k = 0; k < count; ++k) fn(k, k + 1);
    return;
  }
  Round round;
  round.fn = &fn;
  round.count = count;
  round.after = after;
  round.stages = stages;
  std::copy(stage_first, stage_first + stages + 1, round.stage_first.begin());
  publish(round);
}

void Team::serve(int member) {
  std::uint64_t served = 0;
  Spin spin;
  auto idle_since = std::chrono::steady_clock::now();
  for (unsigned idle = 0;; ++idle) {
    const std::uint64_t sequence = state_->sequence.load(std::memory_order_acquire);
    if (sequence != served && (sequence & 1u) == 0) {
      Round round;
      round.sequence = sequence;
      round.fn = state_->fn.load(std::memory_order_relaxed);
      round.count = state_->count.load(std::memory_order_relaxed);
      round.after = state_->after.load(std::memory_order_relaxed);
      round.stages = std::min(state_->stages.load(std::memory_order_relaxed), kMaxStages);
      for (std::size_t s = 0; s <= round.stages; ++s) {
        round.stage_first[s] = state_->stage_first[s].load(std::memory_order_relaxed);
      }
      std::atomic_thread_fence(std::memory_order_acquire);
      if (state_->sequence.load(std::memory_order_relaxed) != sequence) continue;  // rewritten meanwhile
      served = sequence;
      take(member, round);  // fn and after are read only for a block taken: the round is live
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
