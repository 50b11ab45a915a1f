// Point location in a Delaunay triangulation: which simplex holds a query
// point (scipy.spatial.Delaunay.find_simplex).
//
// A uniform grid over the simplices' bounding box lists, per bin, every
// simplex whose bounding box meets it. A query tests the simplices of its
// bin with the exact orientation predicate and answers the lowest index whose
// closed simplex holds it: the same answer for any thread count, and for
// points on shared facets, edges or vertices. Unlike a walk, the grid needs
// no convexity, so triangulations of labelled (concave) regions work too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tessera/delaunay.hpp"

namespace tessera {

class SimplexLocator {
 public:
  /// Index the simplices of `dt`, whose vertex coordinates are `points`
  /// (dt.n_points * dt.dim, row-major: the triangulated points). Throws
  /// InputError when `points` does not match `dt`.
  SimplexLocator(const Delaunay& dt, std::span<const double> points, int threads = 0);

  /// For each query point (row-major, dt.dim coordinates each): the lowest
  /// index of a simplex whose closed region holds it, or -1 (outside every
  /// simplex, or a NaN coordinate). `dt` and `points` must be the ones the
  /// locator was built from. Threads as in VoronoiOptions (0: automatic).
  std::vector<std::int32_t> locate(const Delaunay& dt, std::span<const double> points,
                                   std::span<const double> queries, int threads = 0) const;

  /// Grid bins per axis (1 on the unused z axis in 2D), and the total number of
  /// (bin, simplex) entries: the index's size.
  const std::int64_t* bins() const { return bins_; }
  std::size_t entries() const { return ids_.size(); }

 private:
  // The bin of coordinate x on axis d, clamped to the grid (monotone in x).
  std::int64_t bin_of(int d, double x) const;
  // The bin at grid coordinates (x, y, z): x fastest.
  std::size_t bin_index(std::int64_t x, std::int64_t y, std::int64_t z) const;

  int dim_ = 3;
  std::size_t n_simplices_ = 0, n_points_ = 0;
  double lo_[3] = {}, hi_[3] = {}, scale_[3] = {};  // the vertices' box; bin = floor((x - lo) * scale)
  std::int64_t bins_[3] = {1, 1, 1};
  std::vector<std::uint64_t> offsets_;  // per bin, CSR into ids_
  std::vector<std::int32_t> ids_;       // simplices per bin, ascending
};

}  // namespace tessera
