// front::insertion_delaunay called directly (its parallel phases' knobs and
// statistics), on the distinct points of p (the lowest id of each set of
// coincident ones), dim coordinates per point. Rows of dim + 1 ids.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "front/insertion.hpp"

/// The exact context of p (dim coordinates per point), its box the points' bounding box.
inline tessera::kernels::ExactContext exact_context(const std::vector<double>& p, int dim) {
  const std::size_t d = static_cast<std::size_t>(dim), n = p.size() / d;
  tessera::kernels::ExactContext ctx;
  ctx.points = p.data();
  ctx.dim = dim;
  for (std::size_t a = 0; a < d; ++a) {
    ctx.lo[a] = ctx.hi[a] = p[a];
    for (std::size_t i = 0; i < n; ++i) {
      ctx.lo[a] = std::min(ctx.lo[a], p[d * i + a]);
      ctx.hi[a] = std::max(ctx.hi[a], p[d * i + a]);
    }
  }
  return ctx;
}

/// The ids of p's distinct points (the lowest id of each set of coincident
/// ones), ascending.
inline std::vector<std::int32_t> distinct_ids(const std::vector<double>& p, int dim) {
  const std::size_t d = static_cast<std::size_t>(dim), n = p.size() / d;
  std::vector<std::int32_t> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<std::int32_t>(i);
  auto at = [&](std::int32_t i) {
    return std::vector<double>(p.begin() + static_cast<std::ptrdiff_t>(d * static_cast<std::size_t>(i)),
                               p.begin() + static_cast<std::ptrdiff_t>(d * static_cast<std::size_t>(i) + d));
  };
  std::stable_sort(ids.begin(), ids.end(), [&](std::int32_t a, std::int32_t b) { return at(a) < at(b); });
  ids.erase(std::unique(ids.begin(), ids.end(), [&](std::int32_t a, std::int32_t b) { return at(a) == at(b); }), ids.end());
  std::sort(ids.begin(), ids.end());
  return ids;
}

inline std::vector<std::vector<std::int32_t>> insert_points(const std::vector<double>& p, int dim, int threads,
                                                            std::size_t parallel_min,
                                                            tessera::front::InsertionStats* stats = nullptr) {
  const std::size_t d = static_cast<std::size_t>(dim);
  const tessera::kernels::ExactContext ctx = exact_context(p, dim);
  const std::vector<std::int32_t> ids = distinct_ids(p, dim);
  tessera::front::InsertionOptions o;
  o.threads = threads;
  o.parallel_min = parallel_min;
  o.stats = stats;
  const auto flat = tessera::front::insertion_delaunay(ctx, ids, nullptr, ctx.lo.data(), ctx.hi.data(), o);
  const std::size_t k = d + 1;
  std::vector<std::vector<std::int32_t>> rows(flat ? flat->size() / k : 0);
  for (std::size_t r = 0; r < rows.size(); ++r) rows[r].assign(flat->data() + k * r, flat->data() + k * (r + 1));
  return rows;
}

/// Each input's rows on 2, 3 and 4 workers, with phases from 8 points per
/// thread, equal its serial rows.
inline void expect_phases_give_the_serial_rows(const std::vector<std::pair<std::string, std::vector<double>>>& inputs,
                                               int dim) {
  for (const auto& [what, p] : inputs) {
    const auto serial = insert_points(p, dim, 1, 8);
    EXPECT_FALSE(serial.empty()) << what;
    for (const int threads : {2, 3, 4}) EXPECT_EQ(insert_points(p, dim, threads, 8), serial) << what << ", threads " << threads;
  }
}

/// Phases ran on p, 2 workers, and deferred under a quarter of their points.
inline tessera::front::InsertionStats expect_phases_insert_most(const std::vector<double>& p, int dim) {
  tessera::front::InsertionStats stats;
  insert_points(p, dim, 2, 8, &stats);
  EXPECT_GE(stats.phases, 8u);
  EXPECT_LT(4 * stats.deferred, stats.phase_points) << stats.deferred << " of " << stats.phase_points;
  return stats;
}
