// A triangulation's simplices as a set of sorted id tuples: what the
// Delaunay tests compare against their oracles (CGAL), whatever the rows'
// order and orientation.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <set>
#include <vector>

#include "tessera/delaunay.hpp"

using SimplexSet = std::set<std::vector<std::int32_t>>;

inline SimplexSet as_set(const tessera::Delaunay& dt) {
  SimplexSet out;
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  for (std::size_t s = 0; s < dt.n_simplices(); ++s) {
    std::vector<std::int32_t> v(dt.simplices.begin() + static_cast<std::ptrdiff_t>(s * w),
                                dt.simplices.begin() + static_cast<std::ptrdiff_t>((s + 1) * w));
    std::sort(v.begin(), v.end());
    out.insert(v);
  }
  return out;
}
