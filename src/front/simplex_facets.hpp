// The facets of a triangulation's simplices, grouped so the (one or two)
// simplices sharing a facet sit side by side. Used by simplex_neighbors() and
// by the Delaunay validator.
//
// Every facet record (simplex s, the slot k opposite the facet) is bucketed
// by the facet's lowest id, by a counting sort over the rows
// (bucket_by_point): the facets opposite the slots other than s's lowest
// vertex all hold that vertex, so they go to it; the facet opposite it goes
// to s's second-lowest id. Each point then sorts its few records (~27 in
// 3D). Laid out point after point, that is the global order by (facet,
// simplex): at 1M uniform 3D points, the 27M records took ~3 s through a
// parallel sort, and a search of each point's star (every simplex holding
// it) ~2 s.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "point_buckets.hpp"
#include "tessera/delaunay.hpp"

namespace tessera::front {

struct FacetRecord {
  std::array<std::int32_t, 3> facet;  ///< ascending ids; unused slots (2D) are -1
  std::int32_t simplex;               ///< row of the simplex
  std::int32_t k;                     ///< slot of the vertex opposite the facet
  bool same_facet(const FacetRecord& o) const {
    return facet[0] == o.facet[0] && facet[1] == o.facet[1] && facet[2] == o.facet[2];
  }
  /// By facet, then simplex; spelled out, as std::array's comparisons call memcmp.
  bool operator<(const FacetRecord& o) const {
    if (facet[0] != o.facet[0]) return facet[0] < o.facet[0];
    if (facet[1] != o.facet[1]) return facet[1] < o.facet[1];
    if (facet[2] != o.facet[2]) return facet[2] < o.facet[2];
    return simplex < o.simplex;
  }
};

/// The facet records of a triangulation bucketed by their facet's lowest id
/// (CSR over points), built in the calling arena. Throws as check_simplex_ids.
class FacetBuckets {
 public:
  explicit FacetBuckets(const Delaunay& dt) : dt_(dt), w_(static_cast<std::size_t>(dt.dim + 1)) {
    check_simplex_ids(dt);
    // The facet opposite slot k holds the row's lowest id unless k is that
    // id's slot; then its lowest is the row's second-lowest id.
    bucket_by_point(
        dt, w_,
        [&](std::size_t s, std::size_t k) {
          const Lowest l = lowest(s);
          return k == l.slot ? l.second : l.id;
        },
        [&](std::size_t s, std::size_t k) { return static_cast<std::uint64_t>(s * w_ + k); }, offsets_, slots_);
  }

  /// The records of point a's bucket (the facets whose lowest id is a) into
  /// `out` (cleared), ascending by (facet, simplex).
  void records(std::size_t a, std::vector<FacetRecord>& out) const;

  /// Where point a's records start in the global (facet, simplex) order.
  std::size_t first_record(std::size_t a) const { return static_cast<std::size_t>(offsets_[a]); }
  std::size_t total() const { return slots_.size(); }

 private:
  struct Lowest {
    std::int32_t id, second;  // the row's lowest id and its lowest id at another slot
    std::size_t slot;         // the first slot holding id
  };
  Lowest lowest(std::size_t s) const {
    const std::int32_t* row = dt_.simplices.data() + s * w_;
    std::size_t k0 = 0;
    for (std::size_t k = 1; k < w_; ++k)
      if (row[k] < row[k0]) k0 = k;
    std::int32_t second = INT32_MAX;
    for (std::size_t k = 0; k < w_; ++k)
      if (k != k0) second = std::min(second, row[k]);
    return {row[k0], second, k0};
  }

  const Delaunay& dt_;
  std::size_t w_;
  std::vector<std::int64_t> offsets_;  // n_points + 1
  std::vector<std::uint64_t> slots_;   // s * (dim + 1) + k, per bucket in simplex order
};

// GCC 12 warns about out-of-bounds accesses deep inside std::sort when the
// vector may hold a single record; they are false positives (GCC bug 107986).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
inline void FacetBuckets::records(std::size_t a, std::vector<FacetRecord>& out) const {
  out.clear();
  // The rows of the facets opposite a row's lowest vertex lie anywhere:
  // their loads are started together, so that their misses overlap.
  for (auto e = offsets_[a]; e != offsets_[a + 1]; ++e)
    __builtin_prefetch(dt_.simplices.data() + slots_[static_cast<std::size_t>(e)] / w_ * w_);
  for (auto e = offsets_[a]; e != offsets_[a + 1]; ++e) {
    const std::uint64_t slot = slots_[static_cast<std::size_t>(e)];
    const std::size_t s = static_cast<std::size_t>(slot / w_), k = static_cast<std::size_t>(slot % w_);
    const std::int32_t* row = dt_.simplices.data() + s * w_;
    FacetRecord& r = out.emplace_back();
    r.facet = {-1, -1, -1};
    r.simplex = static_cast<std::int32_t>(s);
    r.k = static_cast<std::int32_t>(k);
    for (std::size_t j = 0, c = 0; j < w_; ++j)
      if (j != k) r.facet[c++] = row[j];
    std::sort(r.facet.begin(), r.facet.begin() + dt_.dim);
  }
  std::sort(out.begin(), out.end());
}
#pragma GCC diagnostic pop

/// Every facet record of `dt`, ascending by (facet, simplex), built in the
/// calling arena.
inline std::vector<FacetRecord> sorted_facets(const Delaunay& dt) {
  const FacetBuckets buckets(dt);
  std::vector<FacetRecord> recs(buckets.total());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, dt.n_points, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<FacetRecord> local;
    for (std::size_t a = r.begin(); a != r.end(); ++a) {
      buckets.records(a, local);
      std::copy(local.begin(), local.end(), recs.begin() + static_cast<std::ptrdiff_t>(buckets.first_record(a)));
    }
  });
  return recs;
}

}  // namespace tessera::front
