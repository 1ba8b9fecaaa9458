// Workers: the threads one World's tick may use, a oneTBB task arena of
// WorldConfig::threads threads (0: every core). With one thread every loop
// runs on the calling thread and the task library is not involved at all.
// The loops here only split work: each index must write its own slots, so
// the result does not depend on how the range was cut.
#pragma once

#include "sphere_tree_collision/phase_options.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>

namespace stc {

// Work done body by body (boxes, integration, the solver's store): a task
// takes at least this many bodies, so its hand-over costs little beside it.
constexpr std::size_t kBodiesPerTask = 256;
// The thread count `threads` stands for: 0 -> the cores the process may use.
int resolveThreads(int threads);

// A callable f(begin, end) seen through a pointer: no copy, no allocation.
// Valid while the callable lives (a loop's body, for the loop's call).
class RangeFn {
 public:
  template <typename F, typename = std::enable_if_t<!std::is_same_v<std::decay_t<F>, RangeFn>>>
  RangeFn(F&& f)  // NOLINT: implicit, so a lambda can be passed as is
      : object_(const_cast<void*>(static_cast<const void*>(&f))),
        call_([](void* o, std::size_t b, std::size_t e) { (*static_cast<std::remove_reference_t<F>*>(o))(b, e); }) {}
  void operator()(std::size_t begin, std::size_t end) const { call_(object_, begin, end); }

 private:
  void* object_;
  void (*call_)(void*, std::size_t, std::size_t);
};

// The calling thread's view of the team's parallel loops (Workers::timeLoops):
// how many there were, the wall time inside them, and of that the time it
// waited for the other members after its own blocks. The rest of a tick is
// the calling thread alone: the serial part, measured rather than fitted.
struct LoopTimes {
  std::uint64_t loops = 0;
  double loop_s = 0.0;
  double wait_s = 0.0;
};

// The threads of one Workers::withTeam call: the calling thread (member 0)
// and the arena's other threads, which stay awake between the stages it
// posts, so a stage starts within microseconds instead of after a worker's
// wake-up (0.3-8 ms on this 2-core VM: docs/parallel.md).
class Team {
 public:
  static constexpr std::size_t kMaxBlocks = 64;  // of one forBlocks round
  int members() const { return members_; }
  // How a member takes blocks besides its own share's (the k with
  // k * members / count == member).
  enum class Claim : std::uint8_t {
    // Its whole own share first, then runs it: the same bodies stage after
    // stage stay on one core (the solver's slabs, the loops that fill them).
    OwnShareWhole,
    // Its own share one block at a time, then the others' from their ends:
    // a member that finishes early takes over the rest of a slower one's
    // share (blocks of uneven cost: a pile bunches in the pair list).
    Balanced,
  };
  // fn(k, k + 1) once for each block k in [0, count), each by one member, who
  // takes its own share as `claim` says and then any block left; returns when
  // all are done. Only the thread that called withTeam may call it.
  void forBlocks(std::size_t count, RangeFn fn, Claim claim = Claim::OwnShareWhole);

 private:
  friend class Workers;
  struct State;
  explicit Team(State* state, int members) : state_(state), members_(members) {}
  void take(int member, std::uint64_t stage, const RangeFn* fn, std::size_t count, Claim claim);  // claim and run
  void serve(int member);  // a worker member: run stages until the team stops
  State* state_;           // null with one member
  int members_;
};

class Workers {
 public:
  // Throws InputError("threads") as validateThreads.
  explicit Workers(int threads = 1);
  ~Workers();
  Workers(Workers&&) noexcept;
  Workers& operator=(Workers&&) noexcept;

  int threads() const { return threads_; }
  // While on, each team loop reads the steady clock three times (about 20 ns
  // a read here) and adds to loopTimes(); off by default. With one thread
  // there are no team loops: loopTimes() stays zero.
  void timeLoops(bool on);
  LoopTimes loopTimes() const;  // summed since construction
  // fn over [0, n) in pieces of at least `grain` indices, on the arena's
  // threads (the caller among them); returns when all are done.
  void forEach(std::size_t n, std::size_t grain, RangeFn fn) const;
  // fn(k, k + 1) for each chunk k in [0, chunks), each one task; on the
  // team, taken as `claim` says.
  void forChunks(std::size_t chunks, RangeFn fn, Team::Claim claim = Team::Claim::OwnShareWhole) const;
  // body(team) on the calling thread while the arena's other threads serve
  // as team members, spinning between stages; returns when body has. Within
  // body, forEach and forChunks run on the team too, and a nested withTeam
  // gets the same team. (A task loop there would let a waiting thread take a
  // member's task, which never hears of the stages: so none is started.)
  template <typename Body>
  void withTeam(Body&& body) const {
    runTeam([](void* b, Team& team) { (*static_cast<std::remove_reference_t<Body>*>(b))(team); },
            const_cast<void*>(static_cast<const void*>(&body)));
  }

 private:
  void runTeam(void (*call)(void*, Team&), void* body) const;

  struct Arena;
  std::unique_ptr<Arena> arena_;  // null with one thread
  int threads_ = 1;
};

// Indices [first, second) of chunk k of `chunks` over [0, count): equal runs, in order.
inline std::pair<std::size_t, std::size_t> chunkRange(std::size_t count, std::size_t k, std::size_t chunks) {
  return {count * k / chunks, count * (k + 1) / chunks};
}

// workers->forEach, or fn(0, n) on the caller without workers.
inline void forEachIndex(const Workers* workers, std::size_t n, std::size_t grain, RangeFn fn) {
  if (workers != nullptr) {
    workers->forEach(n, grain, fn);
  } else if (n > 0) {
    fn(0, n);
  }
}

}  // namespace stc
