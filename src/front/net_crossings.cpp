// Crossing triangles of a smoothed surface net (see net_crossings.hpp).
//
// Broad phase: a bounding volume hierarchy over the triangles' boxes (in
// doubles), split at the median of the boxes' centres along their widest
// axis, walked as pairs of nodes whose boxes meet, from (root, root) down
// both at once, so each pair of triangles is met once. A uniform grid
// (stop 84) failed where the triangles' sizes or places spread over many
// orders of magnitude (a net of points with outliers: 800 triangles 1e277
// long among 32,000 of size 0.07): its cells, sized by the mean triangle,
// held the whole bulk in one, and its float boxes rounded the bulk's to one
// point, so every pair was a candidate (5e8). The hierarchy adapts to any
// spread. Narrow phase: float filters that settle most pairs apart with a
// bound far above their rounding, then exact orientation signs (in 3D, and
// in 2D projections for what lies in a plane): the interior of one triangle
// meets the other iff no line in its plane separates it from the other's
// section by that plane (interior_meets).
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
#include <tbb/parallel_invoke.h>

#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera::front {
namespace {

using Pair = std::pair<std::size_t, std::size_t>;

int orient(const double* a, const double* b, const double* c, const double* d) {
  const double* p[4] = {a, b, c, d};
  return kernels::orientation(3, p);
}

/// The float filters below bound their rounding relative to products of
/// the vectors they take (edges, differences), which holds while no product
/// overflows or underflows: while those products lie in [1/safe, safe].
/// Where they do not (nets of points no frame fits: coordinates from 1 to
/// 1e277, whose long triangles' normals overflow), each vector is scaled by
/// a power of two to its largest component's exponent first (`normalize`):
/// that changes no sign, and the products are then at least 1e-10 (a
/// component that underflows on the way errs by 2^-1074, far below). Without
/// it every such pair fell to the exact orientation: minutes for 1,800
/// points.
constexpr double safe = 1e250;
bool in_safe_range(double x) { return x >= 1 / safe && x <= safe; }

void normalize(double* v, int n) {
  double m = 0;
  for (int k = 0; k < n; ++k) m = std::max(m, std::fabs(v[k]));
  if (!(m > 0) || !std::isfinite(m)) return;  // (then nothing is decided)
  const int e = std::ilogb(m);
  for (int k = 0; k < n; ++k) v[k] = std::ldexp(v[k], -e);
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
  double u[3] = {t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
  double w[3] = {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
  for (const bool scaled : {false, true}) {
    if (scaled) normalize(u, 3), normalize(w, 3);
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    const double uw = (std::fabs(u[0]) + std::fabs(u[1]) + std::fabs(u[2])) *
                      (std::fabs(w[0]) + std::fabs(w[1]) + std::fabs(w[2]));
    int side = 0;
    bool out_of_range = false;
    for (int k = 0; k < m; ++k) {
      if (std::equal(q[k], q[k] + 3, t[0]) || std::equal(q[k], q[k] + 3, t[1]) || std::equal(q[k], q[k] + 3, t[2]))
        continue;
      double d[3] = {q[k][0] - t[0][0], q[k][1] - t[0][1], q[k][2] - t[0][2]};
      if (scaled) normalize(d, 3);
      const double s = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
      const double bound = 1e-10 * uw * (std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]));
      if (!scaled && !(in_safe_range(uw) && in_safe_range(bound))) {
        out_of_range = true;
        break;
      }
      const int sk = s > bound ? 1 : s < -bound ? -1 : 0;
      if (sk == 0 || (side != 0 && sk != side)) return false;
      side = sk;
    }
    if (!out_of_range) return side != 0;
  }
  return false;
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
  // Once unscaled, then (if a product left the safe range) scaled.
  for (const bool scaled : {false, true}) {
    bool out_of_range = false;
    auto check = [&](double product) {
      if (!scaled && !in_safe_range(product)) out_of_range = true;
    };
    // n = u x w and the size of the products behind it, |u| |w|.
    auto normal = [&](const double* const t[3], double* n) {
      double u[3] = {t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
      double w[3] = {t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
      if (scaled) normalize(u, 3), normalize(w, 3);
      n[0] = u[1] * w[2] - u[2] * w[1], n[1] = u[2] * w[0] - u[0] * w[2], n[2] = u[0] * w[1] - u[1] * w[0];
      const double uw =
          (std::fabs(u[0]) + std::fabs(u[1]) + std::fabs(u[2])) * (std::fabs(w[0]) + std::fabs(w[1]) + std::fabs(w[2]));
      check(uw);
      return uw;
    };
    double na[3], nb[3];
    const double uwa = normal(a, na), uwb = normal(b, nb);
    if (out_of_range) continue;
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
      double e[2] = {q[x] - p[x], q[y] - p[y]};
      if (scaled) normalize(e, 2);
      const double e1 = std::fabs(e[0]) + std::fabs(e[1]);
      auto side = [&](const double* r, double& margin) {
        double d[2] = {r[x] - p[x], r[y] - p[y]};
        if (scaled) normalize(d, 2);
        margin = 1e-10 * e1 * (std::fabs(d[0]) + std::fabs(d[1]));
        check(e1), check(margin);
        return e[0] * d[1] - e[1] * d[0];
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
      return !out_of_range;
    };
    for (int k = 0; k < 3 && !out_of_range; ++k)
      if (separates(a, ca, k, b, cb) || separates(b, cb, k, a, ca)) return true;
    if (!out_of_range) return false;
  }
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

namespace {
constexpr std::uint32_t leaf_size = 4;  // triangles per leaf, at most

bool boxes_meet(const double* a, const double* b) {
  return a[0] <= b[3] && b[0] <= a[3] && a[1] <= b[4] && b[1] <= a[4] && a[2] <= b[5] && b[2] <= a[5];
}
}  // namespace

// Splits items[b, e) (the subtree of `node`) at the median of the boxes'
// centres along the axis they spread most on. The left part gets ceil(L/2)
// of the subtree's L leaves (whole leaves), so a subtree of L leaves holds
// 2L - 1 nodes, depth first: the left child follows its parent and the right
// child comes 2 * (the left's leaves) after it, and subtrees build in
// parallel with no shared counter. Ties break by triangle index: the split
// is a function of the boxes (std::nth_element with a total order). The
// items are the centres with their triangle, contiguous: moved by
// nth_element rather than reached through indices (3x faster).
void CrossingCheck::build(std::size_t node, std::uint32_t b, std::uint32_t e, Item* items) {
  Node& nd = nodes_[node];
  nd.begin = b, nd.end = e, nd.right = 0;
  const std::uint32_t leaves = (e - b + leaf_size - 1) / leaf_size;
  if (leaves <= 1) return;
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::uint32_t i = b; i < e; ++i)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], items[i].centre[d]), hi[d] = std::max(hi[d], items[i].centre[d]);
  const int axis = hi[0] - lo[0] >= hi[1] - lo[1] && hi[0] - lo[0] >= hi[2] - lo[2] ? 0
                   : hi[1] - lo[1] >= hi[2] - lo[2]                                ? 1
                                                                                   : 2;
  const std::uint32_t left_leaves = (leaves + 1) / 2, mid = b + left_leaves * leaf_size;
  std::nth_element(items + b, items + mid, items + e, [axis](const Item& s, const Item& t) {
    return s.centre[axis] < t.centre[axis] || (s.centre[axis] == t.centre[axis] && s.t < t.t);
  });
  nd.right = static_cast<std::uint32_t>(node + 2 * left_leaves);
  const std::size_t right = nd.right;
  if (e - b >= 16384)
    tbb::parallel_invoke([&] { build(node + 1, b, mid, items); }, [&] { build(right, mid, e, items); });
  else {
    build(node + 1, b, mid, items);
    build(right, mid, e, items);
  }
}

// Every node's box, the union of its triangles', and whether it holds a
// changed one (children before parents: a child's index is above its
// parent's).
void CrossingCheck::fit(std::span<const std::uint8_t> changed) {
  for (std::size_t node = nodes_.size(); node-- > 0;) {
    Node& nd = nodes_[node];
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    auto unite = [&](const double* o) {
      for (int d = 0; d < 3; ++d) box[d] = std::min(box[d], o[d]), box[d + 3] = std::max(box[d + 3], o[d + 3]);
    };
    if (nd.right == 0) {
      nd.changed = changed.empty();
      for (std::uint32_t i = nd.begin; i < nd.end; ++i) {
        unite(box_[i].data());
        nd.changed = nd.changed || changed[order_[i]];
      }
    } else {
      unite(nodes_[node + 1].box), unite(nodes_[nd.right].box);
      nd.changed = nodes_[node + 1].changed || nodes_[nd.right].changed;
    }
    std::copy_n(box, 6, nd.box);
  }
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
  // Positions are finite by construction; a box that is not has no pairs
  // found (as the grid before it).
  auto finite = [](const Box& b) { return std::all_of(b.begin(), b.end(), [](double v) { return std::isfinite(v); }); };
  const bool filtered = !changed.empty();
  // With `changed` and the same number of triangles as last time, the tree
  // is kept: the changed triangles' boxes are replaced and the nodes' refit.
  const bool keep = filtered && nodes_.size() > 0 && box_.size() == nt;
  std::atomic<bool> all_finite{true};
  if (keep) {
    tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i)
        if (changed[order_[i]]) {
          bounding_box(order_[i], box_[i].data());
          if (!finite(box_[i])) all_finite.store(false, std::memory_order_relaxed);
        }
    });
  } else {
    Buffer<Item> items(nt);
    tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
      for (std::size_t t = r.begin(); t != r.end(); ++t) {
        Box box;
        bounding_box(t, box.data());
        if (!finite(box)) all_finite.store(false, std::memory_order_relaxed);
        for (int d = 0; d < 3; ++d) items[t].centre[d] = box[d] / 2 + box[d + 3] / 2;  // (no overflow)
        items[t].t = static_cast<std::uint32_t>(t);
      }
    });
    if (!all_finite) {
      nodes_.clear(), box_.clear();
      return out;
    }
    const std::size_t leaves = (nt + leaf_size - 1) / leaf_size;
    nodes_.resize(2 * leaves - 1);
    build(0, 0, static_cast<std::uint32_t>(nt), items.data());
    order_.resize(nt);
    box_.resize(nt);
    tbb::parallel_for(Range(0, nt, 4096), [&](const Range& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        order_[i] = items[i].t;
        bounding_box(order_[i], box_[i].data());
      }
    });
  }
  if (!all_finite) return out;
  fit(changed);

  // The pairs of nodes whose boxes meet, walked down both at once from
  // (root, root): each pair of triangles is met once, at the pair of leaves
  // holding them. With `changed`, a pair of nodes with no changed triangle
  // is passed over (fit marks them).
  tbb::enumerable_thread_specific<std::vector<Pair>> found;
  auto test = [&](std::uint32_t i, std::uint32_t j, std::vector<Pair>& mine) {
    const std::size_t s = order_[i], t = order_[j];
    if (filtered && !changed[s] && !changed[t]) return;
    if (!settled.empty() && settled[s] && settled[t]) return;
    if (!boxes_meet(box_[i].data(), box_[j].data())) return;
    const double* a[3] = {at(s, 0), at(s, 1), at(s, 2)};
    const double* b[3] = {at(t, 0), at(t, 1), at(t, 2)};
    if (triangle_pair_crosses(a, &corners[3 * s], b, &corners[3 * t])) mine.emplace_back(std::min(s, t), std::max(s, t));
  };
  auto walk = [&](auto&& self, std::uint32_t x, std::uint32_t y) -> void {
    const Node& a = nodes_[x];
    const Node& b = nodes_[y];
    if (filtered && !a.changed && !b.changed) return;
    const bool parallel = a.end - a.begin + b.end - b.begin >= 8192;
    if (x == y) {
      if (a.right == 0) {
        std::vector<Pair>& mine = found.local();
        for (std::uint32_t i = a.begin; i < a.end; ++i)
          for (std::uint32_t j = i + 1; j < a.end; ++j) test(i, j, mine);
        return;
      }
      const std::uint32_t l = x + 1, r = a.right;
      if (parallel)
        tbb::parallel_invoke([&] { self(self, l, l); }, [&] { self(self, r, r); }, [&] { self(self, l, r); });
      else
        self(self, l, l), self(self, r, r), self(self, l, r);
      return;
    }
    if (!boxes_meet(a.box, b.box)) return;
    if (a.right == 0 && b.right == 0) {
      std::vector<Pair>& mine = found.local();
      for (std::uint32_t i = a.begin; i < a.end; ++i)
        if (boxes_meet(box_[i].data(), b.box))
          for (std::uint32_t j = b.begin; j < b.end; ++j) test(i, j, mine);
      return;
    }
    // Down the larger (a leaf stays).
    if (b.right == 0 || (a.right != 0 && a.end - a.begin >= b.end - b.begin)) {
      if (parallel)
        tbb::parallel_invoke([&] { self(self, x + 1, y); }, [&] { self(self, a.right, y); });
      else
        self(self, x + 1, y), self(self, a.right, y);
    } else {
      if (parallel)
        tbb::parallel_invoke([&] { self(self, x, y + 1); }, [&] { self(self, x, b.right); });
      else
        self(self, x, y + 1), self(self, x, b.right);
    }
  };
  walk(walk, 0, 0);
  for (const auto& v : found) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace tessera::front
