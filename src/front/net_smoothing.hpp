// Private: the pieces of surface-net smoothing (src/front/net_smoothing.cpp)
// that surface_nets.cpp also needs.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "tessera/faces.hpp"
#include "tessera/surface_nets.hpp"

namespace tessera::front {

/// InputError unless iterations >= 0, relaxation in (0, 1] and constraint a
/// finite number >= 0.
void check_smoothing_options(const SmoothingOptions& options);

/// Vertex kinds and smoothing stencils (CSR over the mesh vertices: the
/// neighbours each vertex averages over, ascending).
struct NetStencils {
  std::vector<NetVertexKind> kind;
  std::vector<std::int64_t> offsets;  ///< n_vertices + 1
  std::vector<std::int32_t> neighbors;
};

/// Classifies the vertices (box planes count as regions of their own) and
/// builds their stencils from the polygon edges: a surface vertex takes all
/// its edge neighbours, a junction vertex only those across junction edges
/// (edges whose D shared generators span three regions: its curve), a
/// corner none. Runs in the caller's task arena.
/// Is (u, w) a junction edge: do the D generators the keys of u and w share
/// span three distinct regions (3D; always false in 2D)?
bool is_junction_edge(const FaceSet& mesh, std::span<const std::int32_t> labels, std::size_t u, std::size_t w);

NetStencils build_stencils(const FaceSet& mesh, std::span<const std::int32_t> labels);

/// Newell's area vector (twice the area times the unit normal) of the 3D
/// polygon `loop` (n corners) over coordinates xyz.
inline void newell(const double* xyz, const std::int32_t* loop, std::size_t n, double* out) {
  out[0] = out[1] = out[2] = 0;
  for (std::size_t q = 0; q < n; ++q) {
    const double* u = &xyz[3 * static_cast<std::size_t>(loop[q])];
    const double* w = &xyz[3 * static_cast<std::size_t>(loop[q + 1 == n ? 0 : q + 1])];
    out[0] += (u[1] - w[1]) * (u[2] + w[2]);
    out[1] += (u[2] - w[2]) * (u[0] + w[0]);
    out[2] += (u[0] - w[0]) * (u[1] + w[1]);
  }
}

/// Per mesh vertex at `positions` (mesh.vertices' layout: the vertices
/// where the cells left them), its distance to its generators (a Voronoi
/// vertex is equidistant from all of them; box planes in its key are
/// skipped): the radius of its petal, the local spacing there. In a periodic
/// face set `points` are the points as the cells took them (wrapped into the
/// box, Cells::periodic_points) and the generator is the image the key names,
/// the lattice vectors scaled by 2^k as the points are. Runs in the caller's
/// task arena.
std::vector<double> petal_radii(const FaceSet& mesh, std::span<const double> positions, std::span<const double> points,
                                int k = 0);

/// The net's computation frame: smoothing and triangulation square lengths
/// and multiply them (constraints, normals, areas), which overflowed for
/// points at 1e200 and underflowed at 1e-200 in the input's units (vertices
/// moved without their constraint, polygons were cut along other diagonals).
/// They run on positions scaled by 2^k, the cells' own frame
/// (choose_scaling over the points and the vertices' extent): exact, and
/// k = 0 for input of ordinary range.
int net_frame_shift(std::span<const double> vertices, std::span<const double> points, int dim);
/// A periodic face set's lattice vectors in the net's frame (scaled by 2^k,
/// exactly), for periodic_image.
std::array<std::array<double, 3>, 3> net_lattice(const FaceSet& mesh, int k);
/// x scaled by 2^k, in place (exact while nothing becomes subnormal).
inline void scale_pow2(std::vector<double>& x, int k) {
  for (double& v : x) v = std::ldexp(v, k);
}

/// A polygon counts as degenerate, with no orientation to keep, when its
/// area vector's length is at most this fraction of the square of its local
/// spacing (2D: the segment's length, of the spacing itself).
inline constexpr double degenerate_fraction = 1e-10;

/// The orientation the smoothing guard keeps for polygon `loop` (n corners)
/// at positions x: in 3D Newell's vector, in 2D the segment's direction —
/// zero where the polygon is degenerate (degenerate_fraction, the local
/// spacing being its corners' largest petal radius). Exact ties on a lattice
/// (8 cospherical voxel centres) split a Voronoi vertex into coincident ones,
/// and the faces among them have zero area. With a spacing such as 0.7 the
/// voxel centres round off the lattice and those faces keep an area of
/// ~1e-13 of the spacing squared, whose normal is rounding noise: kept as an
/// orientation, the first smoothing step "flipped" it and froze its corners,
/// and the freeze spread in rounds (a 256^3 volume: 84 rounds instead of 20,
/// smoothing 3x slower, its corners held back where the binary lattice's
/// moved). Lengths are compared, not their squares, which would overflow or
/// underflow first.
inline void reference_orientation(int dim, const double* x, const double* petal, const std::int32_t* loop,
                                  std::size_t n, double* out) {
  double spacing = 0;
  for (std::size_t q = 0; q < n; ++q) spacing = std::max(spacing, petal[static_cast<std::size_t>(loop[q])]);
  double norm2 = 0, limit = 0;
  if (dim == 2) {
    const double* a = &x[2 * static_cast<std::size_t>(loop[0])];
    const double* b = &x[2 * static_cast<std::size_t>(loop[1])];
    out[0] = b[0] - a[0];
    out[1] = b[1] - a[1];
    norm2 = out[0] * out[0] + out[1] * out[1];
    limit = degenerate_fraction * spacing;
  } else {
    newell(x, loop, n, out);
    norm2 = out[0] * out[0] + out[1] * out[1] + out[2] * out[2];
    limit = degenerate_fraction * spacing * spacing;
  }
  if (std::sqrt(norm2) <= limit)
    for (int a = 0; a < dim; ++a) out[a] = 0;
}

/// The "ladder" of a loop of n corners starting at corner `start`: a strip
/// zig-zagging between the two ends of the loop instead of a fan, so no
/// vertex collects many thin triangles: (p0,p1,p(n-1)), (p1,p(n-2),p(n-1)),
/// (p1,p2,p(n-2)), ... (indices relative to `start`). Every triangle keeps
/// the loop's orientation (its corners are in loop order). emit(i, j, k)
/// gets loop positions.
template <class Emit>
void ladder(std::size_t n, std::size_t start, Emit&& emit) {
  std::size_t lo = 0, hi = n - 1;
  auto at = [&](std::size_t i) { return (start + i) % n; };
  for (bool left = true; hi - lo >= 2; left = !left) {
    if (left) {
      emit(at(lo), at(lo + 1), at(hi));
      ++lo;
    } else {
      emit(at(lo), at(hi - 1), at(hi));
      --hi;
    }
  }
}

/// Score of a ladder rotation of a 3D polygon whose corners are at pos(v)
/// (a callable returning const double*), against its original normal `ref`
/// (Newell's vector at the original positions x0): the smallest, over its
/// triangles, of dot(triangle area vector, ref) / (|ref| * sum of the
/// triangle's squared edges) — positive iff every triangle faces the
/// polygon's original way, larger when they are well shaped. Triangles of
/// (relative) zero area at x0 — coincident corners, as exact lattices make
/// — have no shape to score, but must not turn over: one whose area vector
/// now points against ref by more than 1e-9 of the polygon's (twice its
/// area, |ref|) makes the score negative (a fuzz found such triangles folded
/// over by up to 3% of the spacing squared when they were left out). Rounding
/// noise on a triangle that stays degenerate is far below that. +infinity
/// when every triangle is degenerate and none turned over.
template <class Pos>
double ladder_score(Pos&& pos, const double* x0, const std::int32_t* loop, std::size_t n, std::size_t start,
                    const double* ref) {
  const double rr = ref[0] * ref[0] + ref[1] * ref[1] + ref[2] * ref[2];
  double worst = std::numeric_limits<double>::infinity();
  if (!(rr > 0)) return worst;
  auto area_dot = [&](const double* a, const double* b, const double* c, double* edges) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    if (edges)
      *edges = u[0] * u[0] + u[1] * u[1] + u[2] * u[2] + w[0] * w[0] + w[1] * w[1] + w[2] * w[2] +
               (w[0] - u[0]) * (w[0] - u[0]) + (w[1] - u[1]) * (w[1] - u[1]) + (w[2] - u[2]) * (w[2] - u[2]);
    return ref[0] * (u[1] * w[2] - u[2] * w[1]) + ref[1] * (u[2] * w[0] - u[0] * w[2]) +
           ref[2] * (u[0] * w[1] - u[1] * w[0]);
  };
  auto orig = [&](std::size_t i) { return &x0[3 * static_cast<std::size_t>(loop[i])]; };
  bool turned_over = false;
  ladder(n, start, [&](std::size_t i, std::size_t j, std::size_t k) {
    double edges = 0;
    const double d = area_dot(pos(loop[i]), pos(loop[j]), pos(loop[k]), &edges);
    // |ref| is twice the polygon's area: triangles below 1e-10 of it at x0
    // are degenerate (ref · area vector is |ref| times twice the area).
    if (area_dot(orig(i), orig(j), orig(k), nullptr) <= 1e-10 * rr) {
      turned_over = turned_over || d < -1e-9 * rr;
      return;
    }
    worst = std::min(worst, d / (std::sqrt(rr) * (edges > 0 ? edges : 1.0)));
  });
  return turned_over ? -std::numeric_limits<double>::infinity() : worst;
}

/// The ladder rotation a 3D polygon is triangulated by, its corners at
/// xyz: the best ladder_score of its n rotations (0 for a triangle) against
/// `ref`, its unsmoothed orientation (reference_orientation), or, for a
/// polygon degenerate before smoothing (ref zero), its Newell normal at xyz.
/// A rotation replaces an earlier one only if it scores better by more than
/// rounding (1e-9 relative): rotations that tie exactly on a lattice differ
/// by noise off it, which must not choose the triangles. One function for
/// triangulate_ladder and the smoothing's crossing check, which must see the
/// triangles that are output.
inline std::size_t output_ladder_rotation(const double* xyz, const double* x0, const std::int32_t* loop,
                                          std::size_t n, const double* ref_given) {
  std::size_t best = 0;
  if (n <= 3) return best;
  double ref[3] = {ref_given[0], ref_given[1], ref_given[2]};
  if (ref[0] == 0 && ref[1] == 0 && ref[2] == 0) newell(xyz, loop, n, ref);
  auto pos = [&](std::int32_t v) { return xyz + 3 * static_cast<std::size_t>(v); };
  // (best = -inf makes the bound NaN: then any larger score is better)
  auto better = [](double score, double best_score) {
    return score > best_score && !(score <= best_score + 1e-9 * std::fabs(best_score));
  };
  double best_score = -std::numeric_limits<double>::infinity();
  for (std::size_t start = 0; start < n; ++start) {
    const double score = ladder_score(pos, x0, loop, n, start, ref);
    if (better(score, best_score)) {
      best_score = score;
      best = start;
    }
  }
  return best;
}

}  // namespace tessera::front
