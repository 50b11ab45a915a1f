// Point preparation: Lloyd relaxation — points moved towards a centroidal
// Voronoi tessellation (CVT), for meshing, granular packings and sampling
// patterns that want evenly spread points.
//
// Lloyd's method (S. P. Lloyd, "Least squares quantization in PCM", IEEE
// Trans. Inf. Theory 28(2), 1982; Q. Du, V. Faber, M. Gunzburger,
// "Centroidal Voronoi tessellations: applications and algorithms", SIAM
// Review 41(4), 1999): repeat { the cells of the points; move each point
// that owns a cell to its cell's centroid }. Each step lowers the CVT energy
// E = sum over cells of the integral of |x - p|^2 over the cell, within one
// domain: the centroid minimises the integral over a fixed cell, and the
// Voronoi partition minimises it for fixed points (Du, Faber, Gunzburger,
// §2). One iteration costs one cells pass (tessera::voronoi without the
// mesh) plus O(n).
//
// Choices, as built:
// * The domain is fixed across iterations. Given bounds (or a periodic
//   box) are kept; the default domain, the input's padded bounding box,
//   would shrink as the outer points move inwards, so the first
//   iteration's Cells::bounds, as computed, is given explicitly to every
//   later one. A lattice of cell centres in its box is then a fixed point,
//   and the points converge to a CVT of one domain.
// * Points that own no cell stay where they are, bit for bit: outside
//   points (label < 0: they clip their neighbours, as everywhere; a user's
//   fixed boundary samples), the copies of exact duplicates that do not own
//   the cell (the owner moves, so the next iteration separates them), points
//   set aside by ignore_outside_points (outside given bounds, or not
//   finite), and, of power cells, points whose cell is empty. Labels stay
//   with their points (the order never changes).
// * A moved point is its cell's centroid, held within the domain's walls
//   (a centroid of a cell on a wall may round an ulp past it, which the
//   next iteration's explicit bounds would refuse).
// * Periodic boxes (orthogonal and triclinic): the centroid is that of the
//   cell about the point as the cells took it (Cells::periodic_points), and
//   may lie outside the box; the moved point is wrapped back into the box as
//   the cells wrap points (front::periodic_input: by whole lattice vectors,
//   and rounded to the box's grid, where every image is exact), so a result
//   lies in the box. Its displacement is measured from the point as the
//   cells took it, not from where it was given (which may be a few periods
//   away).
// * Power cells (VoronoiOptions::radii): the weighted step, each point to
//   its power cell's centroid; the radii stay with their points (they are
//   the caller's array, unchanged). This lowers the power energy
//   sum of the integral of |x - p|^2 - r^2 over each cell.
// * Determinism: the cells are byte-identical for any thread count, each
//   point's move is its own, and the displacement statistics are summed in
//   point order: the result is byte-identical for any thread count.
// * Early stop: with tolerance > 0 the iterations stop after the first
//   whose largest displacement is at most tolerance times the mean spacing
//   (the domain's volume per generator of the first iteration, to the power
//   1 / dim).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera {

struct LloydOptions {
  /// How each iteration's cells are computed: bounds (or the default
  /// domain's padding), periodic axes and tilts, radii (power cells),
  /// ignore_outside_points, threads, points_per_bin and the cell method.
  /// The mesh is never built (build_mesh is ignored: only the centroids are
  /// needed); `only` must be empty (every cell moves its point). `progress`
  /// is called with the fraction of all iterations done,
  /// (iteration + the fraction of its cells pass) / iterations, and may
  /// throw Cancelled, which stops the run inside or between iterations.
  VoronoiOptions voronoi;
  int iterations = 10;   ///< >= 0; 0 returns the points unchanged (no cells are computed)
  /// Stop after the first iteration whose largest displacement is at most
  /// tolerance * LloydResult::spacing; 0: run every iteration. Finite, >= 0.
  double tolerance = 0;
};

struct LloydResult {
  std::vector<double> points;  ///< n * dim: the moved points, in input order
  int iterations = 0;          ///< iterations done (fewer than asked where the tolerance stopped them)
  /// Per iteration done: the largest and the root-mean-square displacement
  /// over the points that moved (those that owned a cell), and how many
  /// moved.
  std::vector<double> largest_displacement;
  std::vector<double> rms_displacement;
  std::vector<std::size_t> moved;
  /// The domain of every iteration: the first iteration's Cells::bounds (a
  /// periodic box as rounded to its grid). Empty when no iteration ran.
  std::optional<Bounds> domain;
  /// The mean spacing the tolerance is relative to: (domain volume /
  /// generators of the first iteration)^(1 / dim); 0 when no iteration ran.
  double spacing = 0;
  int threads_used = 1;  ///< the cells' (Cells::threads_used)
};

/// Lloyd relaxation of `points` (n * dim doubles, dim 2 or 3), `labels`
/// empty or n values (label < 0: an outside point, which stays). Throws
/// InputError for iterations < 0, a tolerance that is negative or not
/// finite, a non-empty `only`, a shape voronoi() refuses (also with 0
/// iterations), and whatever voronoi() refuses on the first iteration's
/// input.
LloydResult lloyd(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                  const LloydOptions& options = {});

}  // namespace tessera
