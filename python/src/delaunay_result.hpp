// The object behind tessera._core.Delaunay (bind_delaunay.cpp; saved by bind_io.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "tessera/delaunay.hpp"

namespace tessera::python {

/// The triangulation plus its simplex adjacency, which is computed on first
/// use (not every caller wants it) and then kept, so every view shares it.
/// Neither is resized once set: numpy views point into both (arrays.hpp).
struct DelaunayResult {
  Delaunay dt;
  std::optional<std::vector<std::int32_t>> neighbors;
};

}  // namespace tessera::python
