// The object behind tessera._core.Delaunay (bind_delaunay.cpp; saved by bind_io.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "tessera/delaunay.hpp"
#include "tessera/locate.hpp"

namespace tessera::python {

/// The triangulation plus what is derived from it on first use (not every
/// caller wants it) and then kept: the simplex adjacency and the Delaunay
/// edges, which every view shares, and the point locator, which every
/// find_simplex call reuses. None is resized once set: numpy views point into
/// them (arrays.hpp). The simplex adjacency is shared with a walking
/// locator, which steps through it: whichever needs it first computes it.
struct DelaunayResult {
  Delaunay dt;
  SimplexLocator::Adjacency neighbors;
  std::optional<VertexNeighbors> vertex_neighbors;
  std::shared_ptr<const SimplexLocator> locator;
};

}  // namespace tessera::python
