// Formatting in parallel, writing in order: the writers' large per-cell
// records (a .vtu's connectivity and faces, a .csv's rows) are formatted by
// chunks of cells on the worker threads while the chunks already done are
// written, in cell order, to the stream (not installed).
//
// The file's bytes are those of a sequential loop over the cells: each chunk
// is the concatenation of its cells' records, and the chunks are written in
// order. On two threads, writing a 700 MB .vtu is then bounded by the
// kernel's copy into the page cache rather than by that copy plus the
// formatting.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <ostream>
#include <vector>

#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

namespace tessera::io::detail {

/// Write the records of items [0, n) to `emit`, in order. `format(i0, i1,
/// out)` appends the records of items [i0, i1) to `out` (a buffer reused
/// across chunks, cleared before each call) and may run on any worker
/// thread, concurrently with other chunks; `emit(data, size)` runs on one
/// thread at a time, in item order. `chunk` items go into one buffer.
template <class Format, class Emit>
void write_ordered_chunks(std::size_t n, std::size_t chunk, Format&& format, Emit&& emit) {
  if (n == 0) return;
  chunk = std::max<std::size_t>(chunk, 1);
  struct Piece {
    std::size_t begin = 0, end = 0;
    std::vector<char>* out = nullptr;
  };
  // One buffer per token in flight, handed round in a ring: a piece's buffer
  // is reused only once the piece `tokens` places before it has been written
  // (the pipeline never has more than `tokens` pieces in flight).
  const std::size_t tokens = 2 * static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  std::vector<std::vector<char>> buffers(tokens);
  std::size_t next = 0, issued = 0;
  tbb::parallel_pipeline(
      tokens,
      tbb::make_filter<void, Piece>(tbb::filter_mode::serial_in_order,
                                    [&](tbb::flow_control& fc) -> Piece {
                                      if (next >= n) {
                                        fc.stop();
                                        return {};
                                      }
                                      Piece p{next, std::min(n, next + chunk), &buffers[issued++ % tokens]};
                                      next = p.end;
                                      return p;
                                    }) &
          tbb::make_filter<Piece, Piece>(tbb::filter_mode::parallel,
                                         [&](Piece p) {
                                           p.out->clear();
                                           format(p.begin, p.end, *p.out);
                                           return p;
                                         }) &
          tbb::make_filter<Piece, void>(tbb::filter_mode::serial_in_order,
                                        [&](Piece p) { emit(p.out->data(), p.out->size()); }));
}

}  // namespace tessera::io::detail
