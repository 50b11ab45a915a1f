// The 2D and 3D Delaunay triangulation by incremental insertion
// (Bowyer–Watson), for the inputs whose cells cost far more than they find:
// points sampled on surfaces, whose Voronoi cells are needles reaching across
// the object, and in 2D points on circles or along curves (docs/design.md,
// "Insertion for costly inputs", "2D insertion"). Described here for 3D; 2D
// is the same with triangles, edges for facets and circles for spheres.
//
// The triangulation is kept with one infinite vertex: each convex hull facet
// has a "ghost" tetrahedron (facet + infinite vertex), so a point outside the
// hull is located and inserted as any other (the ghosts whose facet it sees
// are in its cavity). Conflicts are decided by the same perturbed in-sphere
// predicate as gift wrapping (kernels::in_sphere, the clip predicate in
// disguise), so the result is the triangulation the cells pass and hull
// completion produce, row for row, on any input — lattices and co-spherical
// points included. A point on the plane of a hull facet is in that ghost's
// conflict when it lies in the facet's circumcircle: the circumsphere of the
// finite tetrahedron behind the facet meets the plane in that circle, and the
// perturbation of the in-sphere test restricted to the plane depends only on
// the facet's points, so asking that tetrahedron gives the perturbed answer.
// Every finite tetrahedron is therefore strictly positively oriented.
//
// The order (BRIO, Amenta, Choi & Rote, "Incremental constructions con
// BRIO", 2003: rounds of doubling size, each in Morton order;
// insertion_order.hpp) keeps the walk from the last inserted point short;
// where the Morton curve jumps, a walk starts instead from a nearby point of
// the previous round (insertion.cpp, walk_start). Large rounds are inserted in parallel
// phases, one slab of space per worker (insertion.cpp, Triangulation::phase);
// the result does not depend on the order, so neither on the thread count.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "tessera/buffer.hpp"
#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::front {

/// What the parallel phases did (for tests and tuning).
struct InsertionStats {
  std::size_t phases = 0;        ///< parallel phases run
  std::size_t phase_points = 0;  ///< points they were given
  std::size_t deferred = 0;      ///< of those, points they left for later
  std::size_t stopped = 0;       ///< phases that deferred so many that later rounds went serially
  std::size_t resumed = 0;       ///< rounds that tried phases again after that (at most one)
  std::size_t guided = 0;        ///< walks started from a guide vertex rather than the last insertion
  /// Times the store of simplices grew past its first reservation (each
  /// growth copies it).
  std::size_t store_growths = 0;
  /// Steps the walks took from one simplex to the next: the work of point
  /// location, which an order without locality inflates.
  std::size_t steps = 0;
};

struct InsertionOptions {
  int threads = 1;  ///< workers of the parallel phases (1: serial; at most 255)
  /// Rounds with fewer points than this per thread are inserted serially.
  std::size_t parallel_min = 1024;
  InsertionStats* stats = nullptr;  ///< filled when given
  /// Called from the calling thread with the fraction of the points
  /// inserted, after each round, each parallel phase and every 16,384
  /// serial insertions; may throw (tessera::Cancelled) to stop the run.
  std::function<void(double)> progress;
};

/// The Delaunay tetrahedra (ctx.dim == 3) or triangles (ctx.dim == 2) of the
/// points `ids` (distinct coordinates: no exact duplicates; ids into
/// ctx.points). Each row lists its ids ascending, except that the last two
/// are swapped where that order is negatively oriented (2D: clockwise); rows
/// are in ascending order of their sorted ids (the layout of
/// tessera::Delaunay::simplices: D + 1 ids per row, flat). nullopt when the
/// points are all on one plane (2D: line), so no simplex exists. `coords`,
/// when not null, holds the points of `ids` in that order (ctx.dim each; the
/// same values as ctx.points): read in place of ctx.points by id, which
/// misses the cache per point where ids are not in space order. `lo`/`hi`
/// bound the points (for the insertion order only).
std::optional<Buffer<std::int32_t>> insertion_delaunay(const kernels::ExactContext& ctx,
                                                       std::span<const std::int32_t> ids, const double* coords,
                                                       const double* lo, const double* hi,
                                                       const InsertionOptions& options = {});

template <int D>
struct Pass;

/// insertion_delaunay of a pass's located points (distinct: the pass left
/// exact duplicates out, and of each set of coincident points the lowest id
/// is the vertex, as the cells decide). For tessera::delaunay (its rows) and
/// tessera::voronoi (the cells' neighbours). Call it in the pass's arena.
struct LocatedInsertion {
  std::optional<Buffer<std::int32_t>> rows;  ///< nullopt when the points are all on one plane (2D: line)
};
/// `progress`, when set, as InsertionOptions::progress. D = 2 or 3.
template <int D>
LocatedInsertion insert_located(const Pass<D>& pass, const std::function<void(double)>& progress = {});

}  // namespace tessera::front
