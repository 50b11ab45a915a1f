// tessera::boundary_polygons (include/tessera/alpha_shape.hpp): a 2D alpha
// shape's boundary segments chained into rings, grouped into one polygon per
// piece.
//
// Each boundary segment a -> b has its kept triangle on its left. Leaving b,
// the ring takes b's one outgoing segment; where b has several (the shape
// touches itself there), it keeps to the sector it came through: from the
// triangle t = (a, b, c) it crosses the edge (b, c) into the kept triangle
// beyond, again and again, until that edge is a boundary segment b -> c,
// which is the next one. No angles are compared, so the choice is exact,
// and rings never cross. A ring is outer (counter-clockwise) or a hole by
// the exact orientation of its corner at its lowest vertex (lowest x, then
// y): there every neighbour along the ring lies to the right or above, so
// the corner is convex and never flat (edges of a triangulation do not
// overlap). Each piece has one outer ring; its holes follow it.
#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "point_buckets.hpp"
#include "tessera/alpha_shape.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera {

BoundaryPolygons boundary_polygons(const Delaunay& dt, std::span<const double> points, const AlphaShape& shape) {
  if (shape.dim != 2 || dt.dim != 2) throw InputError("boundary_polygons: only for a 2D alpha shape");
  front::refuse_periodic(dt, "boundary_polygons");  // (rings of images: ids alone would cross the box)
  if (points.size() != 2 * dt.n_points) throw InputError("boundary_polygons: points are not the triangulation's");
  const std::size_t m = dt.n_simplices(), nf = shape.n_boundary();
  if (shape.piece.size() != shape.simplex_rows.size() || shape.boundary_simplex.size() != nf ||
      std::any_of(shape.simplex_rows.begin(), shape.simplex_rows.end(),
                  [&](std::int32_t r) { return r < 0 || static_cast<std::size_t>(r) >= m; }))
    throw InputError("boundary_polygons: the alpha shape is not one of this triangulation");
  const std::int32_t* const rows = dt.simplices.data();
  const std::int32_t* const seg = shape.boundary.data();
  // Outgoing segments per start vertex (CSR), in segment order.
  std::vector<std::int64_t> first(dt.n_points + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) ++first[static_cast<std::size_t>(seg[2 * f]) + 1];
  for (std::size_t v = 0; v < dt.n_points; ++v) first[v + 1] += first[v];
  std::vector<std::int32_t> out(nf);
  {
    std::vector<std::int64_t> at(first.begin(), first.end() - 1);
    for (std::size_t f = 0; f < nf; ++f) out[static_cast<std::size_t>(at[static_cast<std::size_t>(seg[2 * f])]++)] = static_cast<std::int32_t>(f);
  }
  // The sector walks need the triangles' neighbours and which are kept;
  // only where some vertex has more than one outgoing segment.
  std::vector<std::int32_t> nb;
  std::vector<std::uint8_t> kept;
  for (std::size_t v = 0; v < dt.n_points && nb.empty(); ++v)
    if (first[v + 1] - first[v] > 1) {
      nb = simplex_neighbors(dt);
      kept.assign(m, 0);
      for (const std::int32_t r : shape.simplex_rows) kept[static_cast<std::size_t>(r)] = 1;
    }
  auto slot = [&](std::size_t t, std::int32_t v) {
    for (std::size_t k = 0; k < 3; ++k)
      if (rows[3 * t + k] == v) return k;
    return std::size_t{3};
  };
  // The segment after f.
  auto next = [&](std::size_t f) -> std::size_t {
    const std::int32_t b = seg[2 * f + 1];
    const auto bu = static_cast<std::size_t>(b);
    if (first[bu + 1] - first[bu] == 1) return static_cast<std::size_t>(out[static_cast<std::size_t>(first[bu])]);
    std::size_t t = static_cast<std::size_t>(shape.boundary_simplex[f]);
    std::int32_t a = seg[2 * f];
    for (;;) {
      // t holds a -> b counter-clockwise; c is its third corner.
      std::int32_t c = -1;
      for (std::size_t k = 0; k < 3; ++k)
        if (rows[3 * t + k] != a && rows[3 * t + k] != b) c = rows[3 * t + k];
      const std::int32_t o = nb[3 * t + slot(t, a)];  // across (b, c)
      if (o < 0 || !kept[static_cast<std::size_t>(o)]) {
        for (auto e = first[bu]; e != first[bu + 1]; ++e) {
          const auto g = static_cast<std::size_t>(out[static_cast<std::size_t>(e)]);
          if (seg[2 * g + 1] == c && static_cast<std::size_t>(shape.boundary_simplex[g]) == t) return g;
        }
        throw InputError("boundary_polygons: the boundary is not the alpha shape's (no segment " + std::to_string(b) +
                         " -> " + std::to_string(c) + ")");
      }
      t = static_cast<std::size_t>(o);
      a = c;
    }
  };
  // Rings, traced from each unvisited segment in order; each with its piece
  // and orientation.
  struct Ring {
    std::int64_t begin, end;
    std::int32_t piece;
    bool outer;
  };
  std::vector<Ring> rings;
  std::vector<std::int32_t> ring_ids;
  std::vector<std::uint8_t> seen(nf, 0);
  auto piece_of = [&](std::size_t f) {
    const auto it = std::lower_bound(shape.simplex_rows.begin(), shape.simplex_rows.end(), shape.boundary_simplex[f]);
    return shape.piece[static_cast<std::size_t>(it - shape.simplex_rows.begin())];
  };
  for (std::size_t f0 = 0; f0 < nf; ++f0) {
    if (seen[f0]) continue;
    Ring ring{static_cast<std::int64_t>(ring_ids.size()), 0, piece_of(f0), false};
    std::size_t f = f0;
    do {
      if (seen[f]) throw InputError("boundary_polygons: the boundary does not close into rings");
      seen[f] = 1;
      ring_ids.push_back(seg[2 * f]);
      f = next(f);
    } while (f != f0);
    ring.end = static_cast<std::int64_t>(ring_ids.size());
    // The corner at the lowest vertex (its first occurrence).
    std::int64_t low = ring.begin;
    auto at = [&](std::int64_t i) { return points.data() + 2 * static_cast<std::size_t>(ring_ids[static_cast<std::size_t>(i)]); };
    for (std::int64_t i = ring.begin + 1; i < ring.end; ++i) {
      const double *p = at(i), *q = at(low);
      if (p[0] < q[0] || (p[0] == q[0] && p[1] < q[1])) low = i;
    }
    const std::int64_t n = ring.end - ring.begin;
    const double* corner[3] = {at(ring.begin + (low - ring.begin + n - 1) % n), at(low),
                               at(ring.begin + (low - ring.begin + 1) % n)};
    ring.outer = kernels::orientation(2, corner) > 0;
    rings.push_back(ring);
  }
  // Polygons in piece order: the outer ring, then the holes.
  std::stable_sort(rings.begin(), rings.end(), [](const Ring& x, const Ring& y) {
    return x.piece != y.piece ? x.piece < y.piece : x.outer > y.outer;
  });
  BoundaryPolygons poly;
  poly.points.reserve(ring_ids.size());
  for (std::size_t i = 0; i < rings.size(); ++i) {
    const Ring& r = rings[i];
    const bool starts = i == 0 || r.piece != rings[i - 1].piece;
    if (starts != r.outer)  // (sorted: a piece's outer ring first)
      throw InputError("boundary_polygons: piece " + std::to_string(r.piece) + " has " +
                       (r.outer ? "two outer rings" : "no outer ring"));
    if (i > 0 && r.piece != rings[i - 1].piece) poly.polygon_rings.push_back(static_cast<std::int64_t>(i));
    poly.points.insert(poly.points.end(), ring_ids.begin() + r.begin, ring_ids.begin() + r.end);
    poly.ring_points.push_back(static_cast<std::int64_t>(poly.points.size()));
  }
  if (!rings.empty()) poly.polygon_rings.push_back(static_cast<std::int64_t>(rings.size()));
  return poly;
}

}  // namespace tessera
