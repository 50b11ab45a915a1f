// The facets of a triangulation's simplices, sorted so the (one or two)
// simplices sharing a facet sit side by side. Used by simplex_neighbors() and
// by the Delaunay validator.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "tessera/delaunay.hpp"

namespace tessera::front {

struct FacetRecord {
  std::array<std::int32_t, 3> facet;  ///< ascending ids; unused slots (2D) are -1
  std::int32_t simplex;               ///< row of the simplex
  std::int32_t k;                     ///< slot of the vertex opposite the facet
  bool operator<(const FacetRecord& o) const { return facet != o.facet ? facet < o.facet : simplex < o.simplex; }
};

// GCC 12 warns about out-of-bounds accesses deep inside parallel_sort's
// small-range insertion sort here; they are false positives (GCC bug 107986).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Warray-bounds"
inline std::vector<FacetRecord> sorted_facets(const Delaunay& dt) {
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  const std::size_t m = dt.n_simplices();
  std::vector<FacetRecord> recs(m * w);
  tbb::parallel_for(std::size_t(0), m, [&](std::size_t s) {
    const std::int32_t* row = dt.simplices.data() + s * w;
    for (std::size_t k = 0; k < w; ++k) {
      FacetRecord r{{-1, -1, -1}, static_cast<std::int32_t>(s), static_cast<std::int32_t>(k)};
      for (std::size_t j = 0, c = 0; j < w; ++j)
        if (j != k) r.facet[c++] = row[j];
      std::sort(r.facet.begin(), r.facet.begin() + dt.dim);
      recs[s * w + k] = r;
    }
  });
  tbb::parallel_sort(recs.begin(), recs.end());
  return recs;
}
#pragma GCC diagnostic pop

}  // namespace tessera::front
