// engine::ThreadArena runs the thread count it is given (no more), beyond the machine's
// cores too (a plain tbb::task_arena ran on the cores alone there, and oneTBB
// warned on stderr); the cap it raises is back when it ends, and an
// application's lower cap still wins. resolve_threads bounds the request.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <set>
#include <thread>

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"

namespace {

using tessera::engine::ThreadArena;

std::size_t cap() { return tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism); }

// How many of `n` tasks, one per iteration, ran at once: each waits (up to a
// few seconds) until all n have started, so all n are counted only if n
// threads took part together.
int simultaneous(ThreadArena& arena, int n) {
  std::atomic<int> started{0}, together{0};
  arena.execute([&] {
    tbb::parallel_for(0, n, 1, [&](int) {
      started.fetch_add(1);
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
      while (started.load() < n && std::chrono::steady_clock::now() < until) std::this_thread::yield();
      if (started.load() >= n) together.fetch_add(1);
    });
  });
  return together.load();
}

TEST(ThreadArena, RunsMoreThreadsThanCoresAtOnce) {
  const int n = tbb::info::default_concurrency() + 2;  // above the default cap on any machine
  const std::size_t before = cap();
  {
    ThreadArena arena(n);
    EXPECT_EQ(arena.threads(), n);
    EXPECT_EQ(simultaneous(arena, n), n);
    EXPECT_GE(cap(), static_cast<std::size_t>(n));
  }
  EXPECT_EQ(cap(), before);  // raised only while the arena lives
}

TEST(ThreadArena, RunsNoMoreThanItsCount) {
  ThreadArena arena(2);
  std::set<std::thread::id> ids;
  std::mutex m;
  arena.execute([&] {
    tbb::parallel_for(0, 2000, 1, [&](int) {
      std::this_thread::sleep_for(std::chrono::microseconds(50));
      const std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
  });
  EXPECT_LE(ids.size(), 2u);
  EXPECT_EQ(ThreadArena(0).threads(), 1);
  EXPECT_EQ(ThreadArena(-3).threads(), 1);
}

TEST(ThreadArena, AnApplicationsLowerCapWins) {
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
  ThreadArena arena(4);
  EXPECT_EQ(cap(), 1u);
  std::set<std::thread::id> ids;
  std::mutex m;
  arena.execute([&] {
    tbb::parallel_for(0, 200, 1, [&](int) {
      const std::lock_guard<std::mutex> lock(m);
      ids.insert(std::this_thread::get_id());
    });
  });
  EXPECT_EQ(ids.size(), 1u);
}

TEST(ThreadArena, ResolveThreadsBoundsTheRequest) {
  EXPECT_EQ(tessera::resolve_threads(3), 3);
  EXPECT_EQ(tessera::resolve_threads(tessera::max_threads), tessera::max_threads);
  EXPECT_THROW(tessera::resolve_threads(tessera::max_threads + 1), tessera::InputError);
}

}  // namespace
