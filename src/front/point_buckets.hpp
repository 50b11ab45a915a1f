// Per-point buckets of a triangulation's simplex entries: a counting sort
// that everything pairing simplices by a shared facet or edge starts from
// (simplex_neighbors and the validator's facets, simplex_facets.hpp; the
// Delaunay edges, vertex_neighbors, and its transpose of them, by
// bucket_rows directly). Two simplices sharing a facet both list
// it under its lowest vertex, so each point matches a few entries of its own
// instead of a global sort of all of them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "tessera/delaunay.hpp"

namespace tessera::front {

/// A periodic triangulation's rows name images (Delaunay::simplex_shifts):
/// what matches facets or edges by ids alone refuses it.
inline void refuse_periodic(const Delaunay& dt, const char* who) {
  if (dt.is_periodic())
    throw InputError(std::string(who) + ": not available for a periodic triangulation (its simplices meet images)");
}

/// Throws InputError unless every id in dt's rows names one of its points
/// (a Delaunay put together by hand may not), and when the simplices
/// outnumber 32-bit indices. Whatever indexes points by a row's ids checks first.
inline void check_simplex_ids(const Delaunay& dt) {
  const std::size_t n = dt.n_points, w = static_cast<std::size_t>(dt.dim + 1), m = dt.n_simplices();
  if (m > static_cast<std::size_t>(INT32_MAX))
    throw InputError("triangulation has more than 2^31 - 1 simplices (simplex indices are 32-bit)");
  const std::int32_t* const rows = dt.simplices.data();
  for (std::size_t e = 0; e < m * w; ++e)
    if (rows[e] < 0 || static_cast<std::size_t>(rows[e]) >= n)
      throw InputError("simplex " + std::to_string(e / w) + " has point id " + std::to_string(rows[e]) +
                       ", outside [0, " + std::to_string(n) + ")");
}

/// A counting sort of the entries (r, k), k < length(r), of rows r < rows
/// into `targets` buckets: entry (r, k) goes to bucket route(r, k) as
/// value(r, k). Built in the calling arena, with one histogram per chunk of
/// rows (as many chunks as the arena has threads, at most 8: each costs 8
/// bytes per target), so no two threads touch one counter; chunks scatter
/// in row order, so each bucket lists its entries by ascending (r, k)
/// whatever the thread count. (One atomic counter per target instead was
/// several times slower: locked increments on random cache lines do not
/// overlap their misses.) `offsets` gets targets + 1 entries, `out` one
/// value per entry.
template <class T, class Length, class Route, class Value>
void bucket_rows(std::size_t targets, std::size_t rows, Length&& length, Route&& route, Value&& value,
                 std::vector<std::int64_t>& offsets, std::vector<T>& out) {
  const std::size_t n = targets, m = rows;
  const std::size_t chunks = std::clamp<std::size_t>(static_cast<std::size_t>(tbb::this_task_arena::max_concurrency()), 1,
                                                     std::clamp<std::size_t>(m / 4096, 1, 8));
  auto first = [&](std::size_t c) { return c * m / chunks; };
  // count[c][v]: bucket v's entries in chunk c; then the slot of chunk c's first.
  std::vector<std::vector<std::int64_t>> count(chunks);
  tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
    count[c].assign(n, 0);
    for (std::size_t r = first(c); r < first(c + 1); ++r)
      for (std::size_t k = 0, e = static_cast<std::size_t>(length(r)); k < e; ++k) ++count[c][static_cast<std::size_t>(route(r, k))];
  });
  offsets.resize(n + 1);
  std::int64_t at = 0;
  for (std::size_t v = 0; v < n; ++v) {
    offsets[v] = at;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::int64_t k = count[c][v];
      count[c][v] = at;
      at += k;
    }
  }
  offsets[n] = at;
  out.resize(static_cast<std::size_t>(at));
  tbb::parallel_for(std::size_t(0), chunks, [&](std::size_t c) {
    std::int64_t* const slot = count[c].data();
    for (std::size_t r = first(c); r < first(c + 1); ++r)
      for (std::size_t k = 0, e = static_cast<std::size_t>(length(r)); k < e; ++k)
        out[static_cast<std::size_t>(slot[route(r, k)]++)] = value(r, k);
  });
}

/// bucket_rows over a triangulation: `per_simplex` entries (s, k) of each
/// simplex s go to point route(s, k) as value(s, k).
template <class T, class Route, class Value>
void bucket_by_point(const Delaunay& dt, std::size_t per_simplex, Route&& route, Value&& value,
                     std::vector<std::int64_t>& offsets, std::vector<T>& out) {
  bucket_rows(dt.n_points, dt.n_simplices(), [per_simplex](std::size_t) { return per_simplex; }, route, value, offsets, out);
}

}  // namespace tessera::front
