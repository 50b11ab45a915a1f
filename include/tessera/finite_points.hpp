// Points with a NaN or infinite coordinate (organized point clouds mark their
// missing returns so): one test, shared by the computations' set-aside, the
// periodic driver, the point tools and the command line.
#pragma once

#include <cmath>
#include <cstddef>
#include <span>

namespace tessera {

/// Whether point i of `coords` (n * dim values, row-major) has only finite
/// coordinates.
inline bool finite_point(std::span<const double> coords, std::size_t i, int dim) {
  const std::size_t d = static_cast<std::size_t>(dim);
  for (std::size_t a = 0; a < d; ++a)
    if (!std::isfinite(coords[i * d + a])) return false;
  return true;
}

/// How many points of `coords` have a NaN or infinite coordinate.
inline std::size_t count_non_finite(std::span<const double> coords, int dim) {
  const std::size_t n = coords.size() / static_cast<std::size_t>(dim);
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) count += !finite_point(coords, i, dim);
  return count;
}

}  // namespace tessera
