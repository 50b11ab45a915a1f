// ThreadArena: a oneTBB task arena that runs the thread count it was asked for.
//
// oneTBB caps its worker threads at the machine's cores (its default
// max_allowed_parallelism). A plain tbb::task_arena of more threads than
// that ran on the cores alone, and oneTBB printed "TBB Warning: The number of
// workers is currently limited ..." on stderr, while the run reported the
// count it was given. This arena raises the cap to its own thread count for
// its lifetime (a tbb::global_control), so `--threads 8` on a 2-core machine
// runs 8 threads, as asked: oversubscribed, but what the determinism tests
// need to exercise more threads than a small CI machine has. The cap is
// process-wide while it lasts, but it only lets arenas that ask for more
// threads have them; the implicit arena keeps the machine's concurrency. A
// lower cap set by the application (its own global_control) still wins:
// oneTBB applies the smallest active value.
#pragma once

#include <cstddef>
#include <optional>
#include <utility>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

namespace tessera::engine {

class ThreadArena {
 public:
  /// An arena of `threads` threads (values below 1 give 1). Callers resolve
  /// the user's option first (resolve_threads, which bounds it).
  explicit ThreadArena(int threads) : threads_(threads < 1 ? 1 : threads), arena_(threads_) {
    // The arena reserves its workers at its first execute(), so raising the
    // cap here, before that, is in time.
    const std::size_t cap = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
    if (static_cast<std::size_t>(threads_) > cap)
      allow_.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads_));
  }
  ThreadArena(const ThreadArena&) = delete;
  ThreadArena& operator=(const ThreadArena&) = delete;

  template <class F>
  decltype(auto) execute(F&& f) {
    return arena_.execute(std::forward<F>(f));
  }
  int threads() const { return threads_; }

 private:
  int threads_;
  std::optional<tbb::global_control> allow_;  // declared before the arena: outlives it
  tbb::task_arena arena_;
};

}  // namespace tessera::engine
