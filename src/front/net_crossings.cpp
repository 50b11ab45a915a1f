// Crossing triangles of a smoothed surface net (see net_crossings.hpp).
//
// Broad phase: a uniform grid of cells about twice the mean triangle's size,
// each triangle listed in every cell its bounding box meets; a pair is tested
// once, in the cell holding the lower corner of their boxes' overlap. Narrow
// phase: float filters that settle most pairs apart with a bound far above
// their rounding, then exact orientation signs (in 3D, and in 2D projections
// for what lies in a plane): the interior of one triangle meets the other iff
// no line in its plane separates it from the other's section by that plane
// (interior_meets).
#include "net_crossings.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera::front {
namespace {

using Pair = std::pair<std::size_t, std::size_t>;

int orient(const double* a, const double* b, const double* c, const double* d) {
  const double* p[4] = {a, b, c, d};
  return kernels::orientation(3, p);
}

/// Whether the points q[0..m) lie certainly strictly on one side of the
/// plane of triangle t, by a float filter: each signed distance n . (q - t0),
/// n = u x w from t's edge vectors, kept only where it exceeds 1e-10 of
/// |u| |w| |q - t0|, far above its rounding (a few ulps of those products;
/// not of |n| |q - t0|: a nearly flat triangle's n is a difference of
/// products that may be mostly rounding). A point exactly at a corner of t is
/// passed over, as long as one other is certainly off the plane: then the
/// triangle of the q (and the corners it shares with t) meets t's plane in
/// the hull of at most two of t's corners, an edge of both or a corner.
/// Most candidate pairs end here, without an exact orientation; the
/// exception counts for the distinct vertices that coincide on exact
/// lattices (the unsmoothed net, where the untangling pins it).
bool surely_one_side(const double* const t[3], const double* const* q, int m) {
  const double u[3] = {t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
  const double w[3] = {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
  const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
  const double uw = (std::fabs(u[0]) + std::fabs(u[1]) + std::fabs(u[2])) *
                    (std::fabs(w[0]) + std::fabs(w[1]) + std::fabs(w[2]));
  int side = 0;
  for (int k = 0; k < m; ++k) {
    if (std::equal(q[k], q[k] + 3, t[0]) || std::equal(q[k], q[k] + 3, t[1]) || std::equal(q[k], q[k] + 3, t[2]))
      continue;
    const double d[3] = {q[k][0] - t[0][0], q[k][1] - t[0][1], q[k][2] - t[0][2]};
    const double s = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    const double bound = 1e-10 * uw * (std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]));
    const int sk = s > bound ? 1 : s < -bound ? -1 : 0;
    if (sk == 0 || (side != 0 && sk != side)) return false;
    side = sk;
  }
  return side != 0;
}

/// Float filter for triangles lying nearly in one plane (a flat stretch of a
/// net, where the plane test above cannot decide): projected on the
/// coordinate plane that both face (each normal's component along the
/// dropped axis at least 1e-3 of its largest, and certainly not zero: above
/// 1e-10 of the products it comes from, so the projection is one to one on
/// each), an edge of one separates them by a margin (1e-10 of the
/// products, far above rounding), the corners on that edge that both share
/// or that project exactly onto its ends excepted. Then a common point would
/// project onto the edge and onto the hull of the other's excepted corners,
/// so lie on the boundary of both: they do not cross.
bool surely_apart_in_plane(const double* const a[3], const std::int32_t* ca, const double* const b[3],
                           const std::int32_t* cb) {
  // n = u x w and the size of the products behind it, |u| |w|.
  auto normal = [](const double* const t[3], double* n) {
    const double u[3] = {t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
    const double w[3] = {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
    n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
    return (std::fabs(u[0]) + std::fabs(u[1]) + std::fabs(u[2])) * (std::fabs(w[0]) + std::fabs(w[1]) + std::fabs(w[2]));
  };
  double na[3], nb[3];
  const double uwa = normal(a, na), uwb = normal(b, nb);
  const int drop = std::fabs(na[0]) >= std::fabs(na[1]) && std::fabs(na[0]) >= std::fabs(na[2]) ? 0
                   : std::fabs(na[1]) >= std::fabs(na[2])                                       ? 1
                                                                                                : 2;
  auto faces = [&](const double* n, double uw) {
    return std::fabs(n[drop]) > 1e-3 * std::max({std::fabs(n[0]), std::fabs(n[1]), std::fabs(n[2])}) &&
           std::fabs(n[drop]) > 1e-10 * uw;
  };
  if (!faces(na, uwa) || !faces(nb, uwb)) return false;
  const int x = drop == 0 ? 1 : 0, y = drop == 2 ? 1 : 2;
  // Does the line through t's edge k separate u from t's third corner?
  auto separates = [&](const double* const t[3], const std::int32_t* ct, int k, const double* const u[3],
                       const std::int32_t* cu) {
    const double* p = t[k];
    const double* q = t[(k + 1) % 3];
    const double ex = q[x] - p[x], ey = q[y] - p[y], e1 = std::fabs(ex) + std::fabs(ey);
    auto side = [&](const double* r, double& margin) {
      const double dx = r[x] - p[x], dy = r[y] - p[y];
      margin = 1e-10 * e1 * (std::fabs(dx) + std::fabs(dy));
      return ex * dy - ey * dx;
    };
    double m = 0;
    const double inner = side(t[(k + 2) % 3], m);
    if (!(std::fabs(inner) > m)) return false;
    for (int j = 0; j < 3; ++j) {
      if (cu[j] == ct[k] || cu[j] == ct[(k + 1) % 3]) continue;  // on the edge itself, and in both
      if ((u[j][x] == p[x] && u[j][y] == p[y]) || (u[j][x] == q[x] && u[j][y] == q[y])) continue;
      const double s = side(u[j], m);
      if (!(std::fabs(s) > m) || (s > 0) == (inner > 0)) return false;
    }
    return true;
  };
  for (int k = 0; k < 3; ++k)
    if (separates(a, ca, k, b, cb) || separates(b, cb, k, a, ca)) return true;
  return false;
}

/// Exact 2D orientation of p, q, r projected on the coordinate plane that
/// leaves out axis `drop`.
int orient2(const double* p, const double* q, const double* r, int drop) {
  const int x = drop == 0 ? 1 : 0, y = drop == 2 ? 1 : 2;
  const double pp[2] = {p[x], p[y]}, qq[2] = {q[x], q[y]}, rr[2] = {r[x], r[y]};
  const double* pts[3] = {pp, qq, rr};
  return kernels::orientation(2, pts);
}

/// An axis to leave out so that triangle t (corners not collinear) projects
/// one to one: one along which its exact projected orientation is not zero,
/// its float normal's largest component tried first.
int projection_axis(const double* const t[3]) {
  const double u[3] = {t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
  const double w[3] = {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
  const double n[3] = {std::fabs(u[1] * w[2] - u[2] * w[1]), std::fabs(u[2] * w[0] - u[0] * w[2]),
                       std::fabs(u[0] * w[1] - u[1] * w[0])};
  const int first = n[0] >= n[1] && n[0] >= n[2] ? 0 : n[1] >= n[2] ? 1 : 2;
  for (int k = 0; k < 3; ++k) {
    const int drop = (first + k) % 3;
    if (orient2(t[0], t[1], t[2], drop) != 0) return drop;
  }
  return first;  // (not reached for a triangle that is not collinear)
}

/// Whether the interior of triangle t (corners not collinear) meets the
/// closed triangle u (of any shape). That set is the interior of t met with
/// K = u ∩ plane(t), a convex set in t's plane: the other triangle when both
/// lie in one plane, else a segment or a point whose ends are u's corners in
/// the plane and the points where u's edges cross it. An open triangle and a
/// closed convex polygon in one plane are apart iff a line along an edge of
/// either has the other on its closed outer side (the separating axis
/// theorem: the edges of t - K are those of t and of K), and for a segment
/// K, a side of K's line is a side of u's plane. Each side is an exact sign:
/// of a projection for points in t's plane, and for the point X where edge
/// pq of u crosses it, orient(p, q, t_i, t_j) = side(X, t_i t_j) * s(q),
/// s(q) the side of t's plane that q lies on (expand the determinant with
/// p = X - h (q - p)).
bool interior_meets(const double* const t[3], const double* const u[3]) {
  int s[3];
  for (int k = 0; k < 3; ++k) s[k] = orient(t[0], t[1], t[2], u[k]);
  if ((s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0)) return false;
  const int drop = projection_axis(t);
  const int turn = orient2(t[0], t[1], t[2], drop);
  const bool u_flat = kernels::collinear3(u[0], u[1], u[2]);
  if (s[0] == 0 && s[1] == 0 && s[2] == 0) {  // one plane: K = u
    // Has a line along an edge of triangle p (of orientation p_turn in the
    // projection) every corner of q on its closed outer side?
    auto edge_apart = [drop](const double* const p[3], int p_turn, const double* const q[3]) {
      for (int e = 0; e < 3; ++e) {
        const double* a = p[e];
        const double* b = p[(e + 1) % 3];
        if (orient2(a, b, q[0], drop) * p_turn <= 0 && orient2(a, b, q[1], drop) * p_turn <= 0 &&
            orient2(a, b, q[2], drop) * p_turn <= 0)
          return true;
      }
      return false;
    };
    if (edge_apart(t, turn, u)) return false;
    if (!u_flat) return !edge_apart(u, orient2(u[0], u[1], u[2], drop), t);
    // u a segment (or a point, which the edges above settled): t's corners
    // all on one closed side of its line?
    const double* p = u[0];
    const double* q = std::equal(u[1], u[1] + 3, p) ? u[2] : u[1];
    if (std::equal(q, q + 3, p)) return true;
    int lo = 0, hi = 0;
    for (int k = 0; k < 3; ++k) {
      const int o = orient2(p, q, t[k], drop);
      lo += o < 0, hi += o > 0;
    }
    return lo > 0 && hi > 0;
  }
  // The ends of K (at most two: not all of u's corners are on one side).
  int side[2][3];
  int ends = 0;
  for (int k = 0; k < 3 && ends < 2; ++k) {
    const int l = (k + 1) % 3;
    if (s[k] == 0) {
      for (int e = 0; e < 3; ++e) side[ends][e] = orient2(t[e], t[(e + 1) % 3], u[k], drop) * turn;
      ++ends;
    }
    if (s[k] * s[l] < 0 && ends < 2) {
      for (int e = 0; e < 3; ++e) side[ends][e] = orient(u[k], u[l], t[e], t[(e + 1) % 3]) * s[l];
      ++ends;
    }
  }
  for (int e = 0; e < 3; ++e)
    if (side[0][e] <= 0 && (ends == 1 || side[1][e] <= 0)) return false;
  // A segment K (u not flat: a flat u meets a plane it does not lie in at
  // one point): t's corners on one closed side of u's plane?
  if (ends == 2 && !u_flat) {
    int lo = 0, hi = 0;
    for (int k = 0; k < 3; ++k) {
      const int o = orient(u[0], u[1], u[2], t[k]);
      lo += o < 0, hi += o > 0;
    }
    return lo > 0 && hi > 0;
  }
  return true;
}

}  // namespace

bool triangle_pair_crosses(const double* const a[3], const std::int32_t* ca, const double* const b[3],
                           const std::int32_t* cb) {
  // The corners of each that the other lacks. If those of one lie strictly
  // on one side of the other's plane, the two meet at most at their shared
  // corners or edge (no exact sign needed): most candidate pairs end here.
  const double* only_a[3];
  const double* only_b[3];
  int na = 0, nb = 0;
  for (int k = 0; k < 3; ++k) {
    if (ca[k] != cb[0] && ca[k] != cb[1] && ca[k] != cb[2]) only_a[na++] = a[k];
    if (cb[k] != ca[0] && cb[k] != ca[1] && cb[k] != ca[2]) only_b[nb++] = b[k];
  }
  if (na == 0 || nb == 0) return false;  // (the same corners)
  if (surely_one_side(a, only_b, nb) || surely_one_side(b, only_a, na)) return false;
  if (surely_apart_in_plane(a, ca, b, cb)) return false;
  // A triangle with two corners at one place (the coincident vertices of
  // exact lattices) is flat, with no interior of its own: it crosses the
  // other only through the other's interior, and not if its corners are all
  // at the other's corners (then it lies on an edge of the other, or at a
  // corner).
  auto same = [](const double* p, const double* q) { return std::equal(p, p + 3, q); };
  auto pinched = [&](const double* const t[3]) { return same(t[0], t[1]) || same(t[1], t[2]) || same(t[2], t[0]); };
  auto on_corners = [&](const double* const t[3], const double* const u[3]) {
    for (int k = 0; k < 3; ++k)
      if (!same(t[k], u[0]) && !same(t[k], u[1]) && !same(t[k], u[2])) return false;
    return true;
  };
  const bool flat_a = pinched(a), flat_b = pinched(b);
  if ((flat_a && (flat_b || on_corners(a, b))) || (flat_b && on_corners(b, a))) return false;
  return triangle_pair_crosses_exactly(a, b, flat_a, flat_b);
}

bool triangle_pair_crosses_exactly(const double* const a[3], const double* const b[3], bool flat_a, bool flat_b) {
  flat_a = flat_a || kernels::collinear3(a[0], a[1], a[2]);
  flat_b = flat_b || kernels::collinear3(b[0], b[1], b[2]);
  return (!flat_a && interior_meets(a, b)) || (!flat_b && interior_meets(b, a));
}

std::vector<Pair> crossing_triangles(std::span<const double> xyz, std::span<const std::int32_t> corners,
                                     std::span<const std::uint8_t> changed, std::span<const std::uint8_t> settled) {
  return CrossingCheck()(xyz, corners, changed, settled);
}

// The grid over the triangles' boxes: cells about twice the mean triangle,
// at most ~4 per triangle in all. None when a box is not finite (positions
// are finite by construction).
template <class BoxOf>
std::optional<CrossingCheck::Grid> CrossingCheck::make_grid(std::size_t nt, BoxOf&& bounding_box) {
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, size = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    double b[6];
    bounding_box(t, b);
    double extent = 0;
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], b[d]);
      hi[d] = std::max(hi[d], b[d + 3]);
      extent = std::max(extent, b[d + 3] - b[d]);
    }
    size += extent;
  }
  for (int d = 0; d < 3; ++d)
    if (!std::isfinite(lo[d]) || !std::isfinite(hi[d])) return std::nullopt;
  double h = 2 * size / static_cast<double>(nt);
  auto cells_along = [&](double cell, int d) {
    return static_cast<std::int64_t>(std::floor((hi[d] - lo[d]) / cell)) + 1;
  };
  for (;;) {
    if (!(h > 0)) h = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], std::numeric_limits<double>::min()});
    const double cells = static_cast<double>(cells_along(h, 0)) * static_cast<double>(cells_along(h, 1)) *
                         static_cast<double>(cells_along(h, 2));
    if (cells <= 4.0 * static_cast<double>(nt) + 64) break;
    h *= 1.5;
  }
  return Grid{{lo[0], lo[1], lo[2]}, h, {cells_along(h, 0), cells_along(h, 1), cells_along(h, 2)}};
}

std::vector<Pair> CrossingCheck::operator()(std::span<const double> xyz, std::span<const std::int32_t> corners,
                                            std::span<const std::uint8_t> changed,
                                            std::span<const std::uint8_t> settled) {
  const std::size_t nt = corners.size() / 3;
  std::vector<Pair> out;
  if (nt < 2) return out;
  auto at = [&](std::size_t t, int k) { return &xyz[3 * static_cast<std::size_t>(corners[3 * t + static_cast<std::size_t>(k)])]; };
  using Range = tbb::blocked_range<std::size_t>;

  auto bounding_box = [&](std::size_t t, double* b) {
    for (int d = 0; d < 3; ++d) {
      b[d] = std::min({at(t, 0)[d], at(t, 1)[d], at(t, 2)[d]});
      b[d + 3] = std::max({at(t, 0)[d], at(t, 1)[d], at(t, 2)[d]});
    }
  };
  const bool filtered = !changed.empty();
  // With `changed` and the same number of triangles as last time, the grid
  // and the boxes of the triangles not changed are kept (a changed one that
  // left the grid lies in its border cells).
  const bool keep = filtered && grid_ && box_.size() == nt;
  if (!keep) grid_ = make_grid(nt, bounding_box);
  if (!grid_) return out;
  const double* lo = grid_->lo;
  const double h = grid_->h;
  const std::int64_t* n = grid_->n;
  auto index = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::size_t>((k * n[1] + j) * n[0] + i);
  };
  // Each box in floats, rounded outwards (half the memory; a box that
  // grew only makes a candidate more), and its cells: the lowest and highest
  // along each axis, from the box in doubles. A pair whose boxes meet in
  // floats but not in doubles may be tested in no cell: it cannot cross.
  box_.resize(nt);
  span_.resize(nt);
  const auto& box = box_;
  const auto& span = span_;
  tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t) {
      if (keep && !changed[t]) continue;
      double b[6];
      bounding_box(t, b);
      for (int d = 0; d < 6; ++d) {
        const auto f = static_cast<float>(b[d]);
        box_[t][d] = d < 3 ? (f > b[d] ? std::nextafter(f, -INFINITY) : f) : (f < b[d] ? std::nextafter(f, INFINITY) : f);
        span_[t][d] = static_cast<std::int32_t>(std::clamp<std::int64_t>(
            static_cast<std::int64_t>(std::floor((b[d] - lo[d % 3]) / h)), 0, n[d % 3] - 1));
      }
    }
  });
  auto for_cells = [&](std::size_t t, auto&& body) {
    const auto& c = span[t];
    for (std::int64_t k = c[2]; k <= c[5]; ++k)
      for (std::int64_t j = c[1]; j <= c[4]; ++j)
        for (std::int64_t i = c[0]; i <= c[3]; ++i) body(index(i, j, k));
  };
  // With `changed`, only the cells a changed triangle meets can hold a pair
  // to test: only those are filled.
  const auto ncell = static_cast<std::size_t>(n[0] * n[1] * n[2]);
  auto zero = [](auto& buffer, std::size_t n) {  // in parallel: the buffers are large
    buffer.resize(n);
    tbb::parallel_for(Range(0, n, std::size_t{1} << 16), [&](const Range& r) {
      std::fill(buffer.begin() + static_cast<std::ptrdiff_t>(r.begin()), buffer.begin() + static_cast<std::ptrdiff_t>(r.end()), 0);
    });
  };
  auto& wanted = wanted_;
  if (filtered) {
    zero(wanted, ncell);
    tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t)
        if (changed[t])
          for_cells(t, [&](std::size_t c) { std::atomic_ref<std::uint8_t>(wanted[c]).store(1, std::memory_order_relaxed); });
    });
  }
  // The cells' triangle lists (CSR; within a cell in no fixed order, which
  // only orders the tests: the result is sorted).
  auto& offset = offset_;
  zero(offset, ncell + 1);
  tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t)
      for_cells(t, [&](std::size_t c) {
        if (!filtered || wanted[c]) std::atomic_ref<std::int64_t>(offset[c + 1]).fetch_add(1, std::memory_order_relaxed);
      });
  });
  for (std::size_t c = 0; c < ncell; ++c) offset[c + 1] += offset[c];
  auto& members = members_;
  members.resize(static_cast<std::size_t>(offset[ncell]));
  // Filled through offset[c] as the cursor of cell c, which ends at c's end,
  // the next cell's start: shifted back by one place afterwards.
  tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
    for (std::size_t t = r.begin(); t != r.end(); ++t)
      for_cells(t, [&](std::size_t c) {
        if (filtered && !wanted[c]) return;
        const auto slot = std::atomic_ref<std::int64_t>(offset[c]).fetch_add(1, std::memory_order_relaxed);
        members[static_cast<std::size_t>(slot)] = static_cast<std::uint32_t>(t);
      });
  });
  std::copy_backward(offset.begin(), offset.end() - 1, offset.end());
  offset[0] = 0;

  // Each cell's pairs by a sweep along x over its boxes, copied out and
  // sorted by their lower x: a box meets only the boxes after it that start
  // before it ends.
  struct Item {
    std::array<float, 6> box;
    std::array<std::int32_t, 3> low;  // its lowest cell along each axis
    std::uint32_t t;
  };
  tbb::enumerable_thread_specific<std::vector<Pair>> found;
  tbb::enumerable_thread_specific<std::vector<Item>> items;
  tbb::parallel_for(Range(0, ncell, 256), [&](const Range& r) {
    std::vector<Pair>& mine = found.local();
    std::vector<Item>& local = items.local();
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      const auto b0 = static_cast<std::size_t>(offset[c]), b1 = static_cast<std::size_t>(offset[c + 1]);
      if (b1 - b0 < 2) continue;
      local.clear();
      for (std::size_t x = b0; x < b1; ++x) {
        const std::uint32_t t = members[x];
        local.push_back({box[t], {span[t][0], span[t][1], span[t][2]}, t});
      }
      std::sort(local.begin(), local.end(), [](const Item& p, const Item& q) {
        return p.box[0] < q.box[0] || (p.box[0] == q.box[0] && p.t < q.t);
      });
      for (std::size_t x = 0; x < local.size(); ++x) {
        const Item& is = local[x];
        for (std::size_t y = x + 1; y < local.size() && local[y].box[0] <= is.box[3]; ++y) {
          const Item& it = local[y];
          const std::size_t s = is.t, t = it.t;
          if (filtered && !changed[s] && !changed[t]) continue;
          if (!settled.empty() && settled[s] && settled[t]) continue;
          if (!(is.box[1] <= it.box[4] && it.box[1] <= is.box[4] && is.box[2] <= it.box[5] && it.box[2] <= is.box[5]))
            continue;
          // Tested in one cell only: the one holding the overlap's lower corner.
          if (index(std::max(is.low[0], it.low[0]), std::max(is.low[1], it.low[1]), std::max(is.low[2], it.low[2])) != c)
            continue;
          const double* a[3] = {at(s, 0), at(s, 1), at(s, 2)};
          const double* b[3] = {at(t, 0), at(t, 1), at(t, 2)};
          if (triangle_pair_crosses(a, &corners[3 * s], b, &corners[3 * t]))
            mine.emplace_back(std::min(s, t), std::max(s, t));
        }
      }
    }
  });
  for (const auto& v : found) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace tessera::front
