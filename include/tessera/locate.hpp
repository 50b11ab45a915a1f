// Point location in a Delaunay triangulation: which simplex holds a query
// point (scipy.spatial.Delaunay.find_simplex).
//
// Two methods, one answer: the lowest index of a simplex whose closed region
// holds the point (so the same for any thread count, and for points on
// shared facets, edges or vertices), decided by exact orientation tests.
// * walk: from a simplex of a point near the query (a grid of seeds), step
//   across a facet the query lies beyond until none is left; then gather
//   the simplices that share the query's face (those across facets through
//   it) and answer the lowest. Needs a convex triangulation: without labels
//   and with hull completion, a step out of the hull proves the query outside.
// * grid: a uniform grid over the simplices' bounding box lists, per bin,
//   every simplex whose bounding box meets it; a query tests its bin's
//   simplices. Needs no convexity, so it serves labelled (concave) regions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "tessera/delaunay.hpp"

namespace tessera {

enum class LocateMethod {
  automatic,  ///< walk on a hull-complete triangulation, else grid
  walk,       ///< InputError unless dt.hull_completed
  grid,
};

class SimplexLocator {
 public:
  /// The simplex adjacency a walk steps through: simplex_neighbors(dt).
  using Adjacency = std::shared_ptr<const std::vector<std::int32_t>>;

  /// Index the simplices of `dt`, whose vertex coordinates are `points`
  /// (dt.n_points * dt.dim, row-major: the triangulated points). Throws
  /// InputError when `points` does not match `dt`, or for a periodic
  /// triangulation (its simplices span images, not the points). A walk needs
  /// simplex_neighbors(dt): pass it as `neighbors` when the caller already
  /// has it (it is shared, not copied), else the walk computes it. An
  /// adjacency of the wrong size, or naming a simplex that does not exist,
  /// is an InputError; the grid ignores it.
  SimplexLocator(const Delaunay& dt, std::span<const double> points, int threads = 0,
                 LocateMethod method = LocateMethod::automatic, Adjacency neighbors = nullptr);

  /// For each query point (row-major, dt.dim coordinates each): the lowest
  /// index of a simplex whose closed region holds it, or -1 (outside every
  /// simplex, or a NaN coordinate). `dt` and `points` must be the ones the
  /// locator was built from. Threads as in VoronoiOptions (0: automatic).
  /// `progress`, as VoronoiOptions::progress: called between chunks of
  /// queries, it may throw Cancelled to stop.
  std::vector<std::int32_t> locate(const Delaunay& dt, std::span<const double> points,
                                   std::span<const double> queries, int threads = 0,
                                   const std::function<void(double)>& progress = {}) const;

  /// The method chosen (never automatic).
  LocateMethod method() const { return method_; }
  /// Grid bins per axis (1 on the unused z axis in 2D): the grid's, or the
  /// walk's seed grid. entries(): the grid's (bin, simplex) entries, its
  /// index's size (0 for a walk).
  const std::int64_t* bins() const { return bins_; }
  /// The walk's simplex adjacency (the one passed in, or computed); null
  /// for the grid.
  const Adjacency& neighbors() const { return neighbors_; }
  std::size_t entries() const { return ids_.size(); }

 private:
  // Bins near cubes holding `items_per_bin` of `items` (spread over the box), then scale_.
  void size_bins(double items_per_bin, double items);
  void build_grid(const Delaunay& dt, std::span<const double> points, int threads);
  void build_walk(const Delaunay& dt, std::span<const double> points, int threads);
  std::int32_t walk(const Delaunay& dt, std::span<const double> points, const double* x, std::uint64_t salt) const;
  std::int32_t scan_bin(const Delaunay& dt, std::span<const double> points, const double* x) const;

  // The bin of coordinate x on axis d, clamped to the grid (monotone in x).
  std::int64_t bin_of(int d, double x) const;
  // The bin at grid coordinates (x, y, z): x fastest.
  std::size_t bin_index(std::int64_t x, std::int64_t y, std::int64_t z) const;

  int dim_ = 3;
  std::size_t n_simplices_ = 0, n_points_ = 0;
  double lo_[3] = {}, hi_[3] = {}, scale_[3] = {};  // the vertices' box; bin = floor((x - lo) * scale)
  std::int64_t bins_[3] = {1, 1, 1};
  LocateMethod method_ = LocateMethod::grid;
  // grid
  std::vector<std::uint64_t> offsets_;  // per bin, CSR into ids_
  std::vector<std::int32_t> ids_;       // simplices per bin, ascending
  // walk
  Adjacency neighbors_;                  // simplex_neighbors(dt)
  std::vector<std::int32_t> seed_;       // per bin: a simplex to start from
};

}  // namespace tessera
