// The convex hull of a point set as walls (tessera::hull_walls): cells
// bounded by the hull of their points instead of a box (freud #839 asks for
// a dilated hull; scipy's users clip unbounded cells to it by hand).
//
// The hull's facets are the facets of the Delaunay triangulation that one
// simplex holds (tessera::delaunay: exact, symbolically perturbed, so every
// input has one, lattices and duplicates included). Its cost is cut first:
// the extreme points along 26 directions (8 in 2D) span a polytope inside the
// hull, and a point strictly inside each of that polytope's facets (exact
// orientations) is no hull vertex; only the rest are triangulated (of a
// million uniform points in a cube, ~0.1%). (S. G. Akl and G. T. Toussaint,
// "A fast convex hull algorithm", Information Processing Letters 7(5), 1978.)
//
// Facets in one plane (lattices: a cube's face is hundreds of triangles)
// make one wall: adjacent hull facets are merged where the exact orientation
// of one with the other's far corner is zero. A wall's normal is its best
// conditioned facet's cross product in floats; its offset is set so that
// every point lies inside exactly: for a facet corner a and any point p,
// n . p = n . a + m . (p - a) + (n - m) . (p - a), with m the exact normal
// (m . (p - a) <= 0 on the hull), so the offset is the largest rounded-up
// n . a of the facet's corners plus a bound of |n - m|_1 times the points'
// largest extent. The wall then lies within ~1e-14 of the coordinates' size
// outside the facet's plane; where every operation is exact (lattices), on
// it. (No test input has needed the extent term: the offset over the
// group's corners, rounded up, held every point; it covers what a normal
// tilted by rounding may reach far along the facet.)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <span>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "tessera/cells.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/engine/thread_arena.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera {
namespace {

constexpr double unit = 0x1p-53;  // unit roundoff

/// The hull facets of a triangulation: each facet's D point ids, ordered so
/// that the simplex's remaining vertex lies on its negative side (the
/// outward orientation: det[a1 - a0, (a2 - a0,) p - a0] < 0 inside).
std::vector<std::int32_t> hull_facets(const Delaunay& dt) {
  const int D = dt.dim, w = D + 1;
  const std::vector<std::int32_t> nbr = simplex_neighbors(dt);
  std::vector<std::int32_t> facets;
  for (std::size_t r = 0; r < dt.n_simplices(); ++r)
    for (int k = 0; k < w; ++k) {
      if (nbr[r * static_cast<std::size_t>(w) + static_cast<std::size_t>(k)] != -1) continue;
      const std::size_t at = facets.size();
      for (int j = 0; j < w; ++j)
        if (j != k) facets.push_back(dt.simplices[r * static_cast<std::size_t>(w) + static_cast<std::size_t>(j)]);
      // Moving vertex k to the end of a positively oriented row takes D - k
      // transpositions: with D - k even the facet in row order has it on the
      // positive side, so two of its ids swap.
      if ((D - k) % 2 == 0) std::swap(facets[at], facets[at + 1]);
    }
  return facets;
}

/// a - b, and whether it is exact (Knuth's two-sum error term is zero).
double difference(double a, double b, bool& exact) {
  const double s = a - b, z = s - a;
  exact = exact && (a - (s - z)) + (-b - z) == 0;
  return s;
}

/// v scaled by a power of two to a largest component in [1, 2) (a normal's
/// direction does not change, and its products can then neither overflow
/// nor underflow: points at 1e-200 have normals of 1e-400 in 3D); `exact`
/// stays true only where no component lost a bit on the way.
void normalize(double* v, int n, bool& exact) {
  double m = 0;
  for (int k = 0; k < n; ++k) m = std::max(m, std::fabs(v[k]));
  if (!(m > 0) || !std::isfinite(m)) return;
  const int e = std::ilogb(m);
  for (int k = 0; k < n; ++k) {
    const double x = std::ldexp(v[k], -e);
    exact = exact && std::ldexp(x, e) == v[k];
    v[k] = x;
  }
}

/// a * b - c * d, and whether it is exact.
double cross_term(double a, double b, double c, double d, bool& exact) {
  const double p = a * b, q = c * d;
  exact = exact && std::fma(a, b, -p) == 0 && std::fma(c, d, -q) == 0;
  return difference(p, q, exact);
}

struct UnionFind {
  std::vector<std::int32_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::int32_t find(std::int32_t x) {
    while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
    return x;
  }
  void unite(std::int32_t a, std::int32_t b) {
    a = find(a), b = find(b);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace

std::vector<Wall> hull_walls(std::span<const double> points, int dim, double dilation, int threads) {
  if (dim != 2 && dim != 3) throw InputError("hull_walls: dim must be 2 or 3");
  if (points.size() % static_cast<std::size_t>(dim) != 0)
    throw InputError("hull_walls: the coordinates are not a whole number of points");
  if (!std::isfinite(dilation) || dilation < 0)
    throw InputError("hull_walls: the dilation must be a finite distance >= 0");
  const std::size_t n = points.size() / static_cast<std::size_t>(dim);
  if (n < static_cast<std::size_t>(dim + 1))
    throw InputError("hull_walls: a hull needs at least " + std::to_string(dim + 1) + " points");
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i]))
      throw InputError("hull_walls: point " + std::to_string(i / static_cast<std::size_t>(dim)) + " is not finite");
  auto at = [&](std::int32_t i) { return &points[static_cast<std::size_t>(i) * static_cast<std::size_t>(dim)]; };
  DelaunayOptions o;
  o.dim = dim;
  o.threads = threads;
  // The hull facets of some of the points (ids into `points`).
  auto hull_of = [&](const std::vector<std::int32_t>& ids) {
    std::vector<double> sub;
    sub.reserve(ids.size() * static_cast<std::size_t>(dim));
    for (const std::int32_t i : ids) sub.insert(sub.end(), at(i), at(i) + dim);
    std::vector<std::int32_t> facets = hull_facets(delaunay(sub, dim, {}, o));
    for (auto& v : facets) v = ids[static_cast<std::size_t>(v)];
    return facets;
  };

  // The extreme points along 26 (8) directions, the first at a tie.
  std::vector<std::int32_t> extremes;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = dim == 3 ? -1 : 0; dz <= (dim == 3 ? 1 : 0); ++dz) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const double dir[3] = {double(dx), double(dy), double(dz)};
        std::int32_t best = 0;
        double best_value = -INFINITY;
        for (std::size_t i = 0; i < n; ++i) {
          double v = 0;
          for (int d = 0; d < dim; ++d) v += dir[d] * points[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)];
          if (v > best_value) best_value = v, best = static_cast<std::int32_t>(i);
        }
        extremes.push_back(best);
      }
  std::sort(extremes.begin(), extremes.end());
  extremes.erase(std::unique(extremes.begin(), extremes.end()), extremes.end());

  // The points not strictly inside the extremes' hull (all of them where
  // the extremes span no volume: a flat or thin set).
  std::vector<std::int32_t> candidates;
  std::vector<std::int32_t> inner;
  if (extremes.size() > static_cast<std::size_t>(dim)) {
    try {
      inner = hull_of(extremes);
    } catch (const InputError&) {
      inner.clear();  // (flat extremes: the prefilter is skipped)
    }
  }
  if (inner.empty()) {
    candidates.resize(n);
    std::iota(candidates.begin(), candidates.end(), 0);
  } else {
    std::vector<std::uint8_t> keep(n);
    engine::ThreadArena(resolve_threads(threads)).execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const auto id = static_cast<std::int32_t>(i);
          bool inside = true;
          for (std::size_t f = 0; f < inner.size() && inside; f += static_cast<std::size_t>(dim)) {
            const double* p[4] = {at(inner[f]), at(inner[f + 1]), dim == 3 ? at(inner[f + 2]) : at(id), at(id)};
            inside = kernels::orientation(dim, p) < 0;
          }
          keep[i] = !inside;
        }
      });
    });
    for (std::size_t i = 0; i < n; ++i)
      if (keep[i]) candidates.push_back(static_cast<std::int32_t>(i));
  }
  std::vector<std::int32_t> facets;
  try {
    facets = hull_of(candidates);
  } catch (const InputError& e) {
    throw InputError(std::string("hull_walls: ") + e.what());
  }
  const std::size_t nf = facets.size() / static_cast<std::size_t>(dim);
  if (nf == 0) throw InputError("hull_walls: the points span no area (volume): they have no hull to bound cells by");
  auto facet = [&](std::size_t f) { return &facets[f * static_cast<std::size_t>(dim)]; };

  // Facets in one plane (on one line) merge: across each ridge (a 3D hull
  // edge, a 2D hull vertex) the two facets holding it, one plane where the
  // second's far corner lies in the first's.
  UnionFind groups(nf);
  std::map<std::array<std::int32_t, 2>, std::size_t> first_at;  // ridge (ascending; 2D: one id, -1) -> a facet
  for (std::size_t f = 0; f < nf; ++f)
    for (int k = 0; k < dim; ++k) {
      std::array<std::int32_t, 2> ridge{-1, -1};
      for (int j = 0, r = 0; j < dim; ++j)
        if (j != k) ridge[static_cast<std::size_t>(r++)] = facet(f)[j];
      if (dim == 3 && ridge[0] > ridge[1]) std::swap(ridge[0], ridge[1]);
      const auto [it, fresh] = first_at.emplace(ridge, f);
      if (fresh) continue;
      const std::size_t g = it->second;
      const std::int32_t far = facet(f)[k];  // f's corner off the ridge
      const double* p[4] = {at(facet(g)[0]), at(facet(g)[1]), dim == 3 ? at(facet(g)[2]) : at(far), at(far)};
      if (kernels::orientation(dim, p) == 0)
        groups.unite(static_cast<std::int32_t>(f), static_cast<std::int32_t>(g));
    }

  // The points' largest extent, bounding |p - a| along any axis.
  double extent = 0;
  for (int d = 0; d < dim; ++d) {
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = 0; i < n; ++i) {
      lo = std::min(lo, points[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)]);
      hi = std::max(hi, points[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)]);
    }
    extent = std::max(extent, (hi - lo) * (1 + 2 * unit));
  }

  // Per group: the facet whose normal is best conditioned (largest |n|
  // against the product of its edges), then the offset over every corner
  // of the group's facets.
  struct Normal {
    double n[3] = {0, 0, 0};
    double error = 0;    // bound of |n - m|_1, m the exact normal
    double quality = -1; // |n| / (|u| |w|)
  };
  // (Where every operation behind n is exact, as on lattices, the error is
  // 0 and the wall passes through the facet exactly.)
  auto normal_of = [&](std::size_t f) {
    Normal r;
    const double* a = at(facet(f)[0]);
    bool exact = true;
    double u[3] = {0, 0, 0}, w[3] = {0, 0, 0};
    for (int d = 0; d < dim; ++d) u[d] = difference(at(facet(f)[1])[d], a[d], exact);
    normalize(u, dim, exact);
    if (dim == 2) {
      // Outward: the far vertex lies to the right of a -> b.
      r.n[0] = -u[1], r.n[1] = u[0];
      r.error = exact ? 0 : 2 * unit * (std::fabs(u[0]) + std::fabs(u[1]));
      r.quality = 1;
    } else {
      for (int d = 0; d < 3; ++d) w[d] = difference(at(facet(f)[2])[d], a[d], exact);
      normalize(w, 3, exact);
      r.n[0] = cross_term(u[1], w[2], u[2], w[1], exact);
      r.n[1] = cross_term(u[2], w[0], u[0], w[2], exact);
      r.n[2] = cross_term(u[0], w[1], u[1], w[0], exact);
      const double uw = (std::fabs(u[0]) + std::fabs(u[1]) + std::fabs(u[2])) * (std::fabs(w[0]) + std::fabs(w[1]) + std::fabs(w[2]));
      // The differences err by a unit each, the products and their
      // difference by two more: 8 units of |u|_1 |w|_1 bound it with room.
      r.error = exact ? 0 : 8 * unit * uw;
      r.quality = uw > 0 ? std::hypot(r.n[0], r.n[1], r.n[2]) / uw : 0;
    }
    return r;
  };
  std::vector<std::size_t> best(nf, nf);
  std::vector<Normal> normals(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    normals[f] = normal_of(f);
    const auto g = static_cast<std::size_t>(groups.find(static_cast<std::int32_t>(f)));
    if (best[g] == nf || normals[f].quality > normals[best[g]].quality) best[g] = f;
  }
  // n . a rounded up: exact where each product and sum is, else plus a
  // bound of its rounding (3 units of the terms' magnitudes; 4 for room).
  std::vector<double> offset(nf, -INFINITY);
  std::vector<std::uint8_t> offset_exact(nf, 1);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto g = static_cast<std::size_t>(groups.find(static_cast<std::int32_t>(f)));
    const Normal& nm = normals[best[g]];
    for (int k = 0; k < dim; ++k) {
      const double* a = at(facet(f)[k]);
      bool exact = true;
      double s = 0, size = 0;
      for (int d = 0; d < dim; ++d) {
        const double t = nm.n[d] * a[d];
        exact = exact && std::fma(nm.n[d], a[d], -t) == 0;
        s = difference(s, -t, exact);
        size += std::fabs(t);
      }
      const double up = exact ? s : s + 4 * unit * size;
      if (up > offset[g]) offset[g] = up, offset_exact[g] = exact;
    }
  }
  std::vector<Wall> walls;
  for (std::size_t g = 0; g < nf; ++g) {
    if (best[g] == nf) continue;
    const Normal& nm = normals[best[g]];
    const double norm = std::hypot(nm.n[0], nm.n[1], nm.n[2]);
    if (!(norm > 0) || !std::isfinite(norm))
      throw InputError("hull_walls: a hull facet's normal under- or overflows (coordinates too small or too large)");
    const double terms[3] = {offset[g], nm.error * extent, dilation * norm};
    double d = offset[g];
    if (!offset_exact[g] || terms[1] != 0 || terms[2] != 0) {
      d = terms[0] + terms[1] + terms[2];
      d += 8 * unit * (std::fabs(terms[0]) + terms[1] + terms[2]);  // (the sums' rounding, with room)
      d = std::nextafter(d, INFINITY);
    }
    if (!std::isfinite(d)) throw InputError("hull_walls: a wall's offset overflows (coordinates too large)");
    Wall wall;
    for (int k = 0; k < dim; ++k) wall.normal[static_cast<std::size_t>(k)] = nm.n[k];
    wall.offset = d;
    walls.push_back(wall);
  }
  return walls;
}

}  // namespace tessera
