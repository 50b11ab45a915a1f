// Long loops outside the cells' engine, cancellable between chunks.
//
// The engine calls VoronoiOptions::progress between batches of generators,
// and a callback that throws Cancelled stops it (Python's Ctrl-C). The other
// long calls (locating queries, probing, sampling images, fill, joggle, the
// adjacency graph) take the same callback and run their parallel loops in
// chunks, calling it from the calling thread between them: Python can only
// see a signal from the main thread, and a throw from inside a TBB loop would
// cancel it mid-chunk anyway. Without a callback a loop runs whole, as before.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "tessera/engine/thread_arena.hpp"

namespace tessera::detail {

/// Items per chunk: a few milliseconds of the cheapest per-item work on two
/// threads, so that Ctrl-C is seen within a fraction of a second and the
/// chunking (one callback and one loop launch per chunk) costs nothing.
inline constexpr std::size_t kProgressChunk = std::size_t{1} << 16;

/// Runs `body(begin, end)` over [0, n) in chunks of `chunk` items, calling
/// `progress(fraction done)` before each and once at the end; with no
/// callback, `body(0, n)` once. A callback's exception (Cancelled) leaves the
/// chunks after it undone and propagates.
template <class Body>
void in_progress_chunks(std::size_t n, const std::function<void(double)>& progress, Body&& body,
                        std::size_t chunk = kProgressChunk) {
  if (!progress) {
    body(std::size_t{0}, n);
    return;
  }
  for (std::size_t begin = 0; begin < n; begin += chunk) {
    progress(static_cast<double>(begin) / static_cast<double>(n));
    body(begin, std::min(n, begin + chunk));
  }
  progress(1.0);
}

/// `body(tbb::blocked_range<std::size_t>)` over [0, n) in parallel on
/// `threads` threads (resolved), in chunks of `chunk` items with `progress`
/// between them (in_progress_chunks); ranges of `grain` items. A chunk of
/// at most `grain` items, or one thread, runs on the caller alone.
template <class Body>
void parallel_in_progress_chunks(int threads, std::size_t n, std::size_t grain,
                                 const std::function<void(double)>& progress, Body&& body,
                                 std::size_t chunk = kProgressChunk) {
  engine::ThreadArena arena(threads);
  in_progress_chunks(n, progress, [&](std::size_t begin, std::size_t end) {
    if (threads <= 1 || end - begin <= grain) {
      body(tbb::blocked_range<std::size_t>(begin, end));
      return;
    }
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, grain), body); });
  }, chunk);
}

}  // namespace tessera::detail
