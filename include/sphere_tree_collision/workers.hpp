// Workers: the threads one World's tick may use, a oneTBB task arena of
// WorldConfig::threads threads (0: every core). With one thread every loop
// runs on the calling thread and the task library is not involved at all.
// The loops here only split work: each index must write its own slots, so
// the result does not depend on how the range was cut.
#pragma once

#include <cstddef>
#include <memory>
#include <type_traits>
#include <utility>

namespace stc {

// WorldConfig::threads and ~threads: 0 (all cores) .. kMaxThreads.
constexpr int kMaxThreads = 256;
// Throws InputError("threads") outside [0, kMaxThreads].
void validateThreads(int threads);
// The thread count `threads` stands for: 0 -> the cores the process may use.
int resolveThreads(int threads);

// A callable seen through a pointer: no copy, no allocation. Valid while
// the callable lives (a loop's body, for the loop's call).
template <typename Signature>
class FunctionRef;
template <typename R, typename... Args>
class FunctionRef<R(Args...)> {
 public:
  template <typename F, typename = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef>>>
  FunctionRef(F&& f)  // NOLINT: implicit, so a lambda can be passed as is
      : object_(const_cast<void*>(static_cast<const void*>(&f))),
        call_([](void* o, Args... args) -> R {
          return (*static_cast<std::remove_reference_t<F>*>(o))(std::forward<Args>(args)...);
        }) {}
  R operator()(Args... args) const { return call_(object_, std::forward<Args>(args)...); }

 private:
  void* object_;
  R (*call_)(void*, Args...);
};
// f(begin, end) over a range of indices.
using RangeFn = FunctionRef<void(std::size_t, std::size_t)>;

// Stages that run one after the other, each of blocks that may run at once
// (Workers::runStages); a stage has at most this many blocks.
constexpr std::size_t kMaxStageBlocks = 64;
struct StageFns {
  FunctionRef<std::size_t(std::size_t)> blocks;          // blocks(stage): how many (>= 1)
  FunctionRef<void(std::size_t, std::size_t)> run;       // run(stage, block)
  FunctionRef<bool(std::size_t)> go_on;                  // asked before each stage; false: stop there
};

class Workers {
 public:
  // Throws InputError("threads") as validateThreads.
  explicit Workers(int threads = 1);
  ~Workers();
  Workers(Workers&&) noexcept;
  Workers& operator=(Workers&&) noexcept;

  int threads() const { return threads_; }
  // fn over [0, n) in pieces of at least `grain` indices, on the arena's
  // threads (the caller among them); returns when all are done. In a
  // session (below) the loop is one stage on the session's threads.
  void forEach(std::size_t n, std::size_t grain, RangeFn fn) const;
  // fn(k, k + 1) for each chunk k in [0, chunks), each one task.
  void forChunks(std::size_t chunks, RangeFn fn) const;
  // Stages [0, stages) in order, stage s's blocks at once, until go_on
  // says stop; returns the stages run. The calling thread drives the stages
  // and claims blocks; the arena's other threads join while the call lasts,
  // claim blocks of the current stage and spin between stages, so a run of
  // small stages costs no task hand-offs, and nothing waits on a particular
  // thread (a busy or late worker only leaves the caller more blocks).
  std::size_t runStages(std::size_t stages, const StageFns& fns) const;
  // Runs body on the calling thread with the arena's other threads joined
  // for its runStages calls: they spin (then yield) through whatever else
  // body does, so the calls do not pay a worker's wake-up each (on this
  // 2-core VM 0.3-8 ms: a sleeping thread's core is halted). A session
  // inside a session is the outer one. Only runStages may use the threads
  // in body; other loops there run on the calling thread alone.
  void session(FunctionRef<void()> body) const;

 private:
  bool inSessionOfThisThread() const;
  bool inSessionOfAnotherThread() const;  // a helper of a session: its loops run alone
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

// workers->runStages, or the stages one block after the other on the
// caller without workers (the same order a single thread takes).
std::size_t runStages(const Workers* workers, std::size_t stages, const StageFns& fns);

}  // namespace stc
