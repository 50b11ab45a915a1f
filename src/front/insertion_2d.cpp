// Bowyer–Watson insertion in 2D; see insertion.hpp. The 3D insertion's
// scheme (insertion.cpp) with triangles: one infinite vertex whose ghost
// triangles close the convex hull, conflicts decided by the perturbed
// in-circle test (kernels::in_sphere, the clip predicate in disguise), BRIO
// order with guided walks (insertion_order.hpp). Serial: a 2D insertion is
// a fraction of what the cells that need it would cost.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <tbb/parallel_sort.h>

#include "insertion.hpp"
#include "insertion_order.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::front {
namespace {

using kernels::ExactContext;

constexpr std::int32_t infinite = -1;  ///< the vertex every ghost triangle shares

/// A triangle: vertices, and for each k what lies across the edge opposite
/// v[k]: 4 u + m for the triangle u whose edge m it is. Finite ones are
/// counter-clockwise; a ghost (one vertex infinite) is oriented as if that
/// vertex were a point beyond its hull edge.
struct Tri {
  std::int32_t v[3];
  std::int32_t n[3];
};

inline std::int32_t across(std::int32_t u, int m) { return 4 * u + m; }
inline std::int32_t tri_of(std::int32_t a) { return a >> 2; }
inline int edge_of(std::int32_t a) { return a & 3; }

int infinite_slot(const Tri& t) {
  for (int k = 0; k < 3; ++k)
    if (t.v[k] == infinite) return k;
  return 3;
}

// The filters in front of kernels::orientation and kernels::in_sphere for
// points that are ids into one array (as insertion.cpp's 3D ones): the exact
// sign when the float evaluation is certain, 0 otherwise. The bounds are the
// kernels' (delaunay_predicates.hpp).

// Sign of det[b - a, c - a].
[[gnu::always_inline]] inline int orientation_filter(const double* a, const double* b, const double* c) {
  const double m0 = (b[0] - a[0]) * (c[1] - a[1]), m1 = (b[1] - a[1]) * (c[0] - a[0]);
  const double det = m0 - m1;
  const double bound = 16 * kernels::filter::u * (std::fabs(m0) + std::fabs(m1)) + kernels::filter::abs_eps;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

// For a counter-clockwise triangle abc: +1 when q is surely inside its
// circumcircle, -1 surely outside, 0 undecided. With rows r_k = p_k - a and
// s_k = |r_k|^2 (k = b, c, q), q is inside iff det[[r_k, s_k]] < 0.
[[gnu::always_inline]] inline int in_circle_filter(const double* a, const double* b, const double* c, const double* q) {
  double r[3][2], s[3];
  const double* p[3] = {b, c, q};
  for (int k = 0; k < 3; ++k) {
    r[k][0] = p[k][0] - a[0];
    r[k][1] = p[k][1] - a[1];
    s[k] = r[k][0] * r[k][0] + r[k][1] * r[k][1];
  }
  // The 2x2 minor of the rows other than k, and its permanent.
  auto minor = [&](int i, int j, double& perm) {
    const double u = r[i][0] * r[j][1], v = r[i][1] * r[j][0];
    perm = std::fabs(u) + std::fabs(v);
    return u - v;
  };
  double p0, p1, p2;
  const double d0 = minor(1, 2, p0), d1 = minor(0, 2, p1), d2 = minor(0, 1, p2);
  const double det = s[0] * d0 - s[1] * d1 + s[2] * d2;
  const double bound = 64 * kernels::filter::u * (s[0] * p0 + s[1] * p1 + s[2] * p2) + kernels::filter::abs_eps;
  return det < -bound ? 1 : (det > bound ? -1 : 0);
}

class Triangulation2 {
 public:
  /// Vertices are numbered by `global`, the insertion order (vertex k is
  /// point global[k] of ctx; its coordinates are copied in that order).
  Triangulation2(const ExactContext& ctx, std::vector<std::int32_t> global, std::vector<std::int32_t> guide)
      : ctx_(ctx), global_(std::move(global)), guide_(std::move(guide)) {
    const std::size_t n = global_.size();
    coords_.resize(2 * n);
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t e = 0; e < 2; ++e) coords_[2 * k + e] = ctx.points[static_cast<std::size_t>(global_[k]) * 2 + e];
    vtri_.resize(n);
    pending_.assign(n + 1, -1);
    // A Delaunay triangulation has about 2 triangles per point (and a ghost
    // per hull edge).
    tris_.reserve(2 * n + 64);
    mark_.reserve(2 * n + 64);
  }

  /// Start from the counter-clockwise triangle s and its three ghosts.
  void start(std::array<std::int32_t, 3> s) {
    Tri t0{{s[0], s[1], s[2]}, {-1, -1, -1}};
    tris_.push_back(t0);
    for (int k = 0; k < 3; ++k) {
      Tri g = t0;
      g.v[k] = infinite;
      // With the infinite vertex standing for a point beyond edge k (the
      // side away from v[k]) the order is clockwise: swap the other two.
      std::swap(g.v[(k + 1) % 3], g.v[(k + 2) % 3]);
      tris_.push_back(g);
    }
    // Link the four by their shared edges.
    for (int a = 0; a < 4; ++a)
      for (int ka = 0; ka < 3; ++ka)
        for (int b = 0; b < 4; ++b) {
          if (a == b) continue;
          for (int kb = 0; kb < 3; ++kb)
            if (same_edge(tris_[static_cast<std::size_t>(a)], ka, tris_[static_cast<std::size_t>(b)], kb))
              tris_[static_cast<std::size_t>(a)].n[ka] = across(b, kb);
        }
    mark_.assign(4, 0);
    last_ = 0;
    for (const std::int32_t v : s) vtri_[static_cast<std::size_t>(v)] = 0;
  }

  /// Insert vertex q (not in the triangulation yet, at no vertex's place).
  void insert(std::int32_t q) {
    const std::int32_t t0 = locate(q, walk_start(q));
    if (++epoch_ >= (1u << 30)) {
      std::fill(mark_.begin(), mark_.end(), 0u);
      epoch_ = 1;
    }
    const std::uint32_t mark_out = epoch_ << 1, mark_in = mark_out | 1;
    if (!conflicts(t0, q)) throw std::logic_error("tessera: 2D insertion: the located triangle is not in conflict");
    mark_[static_cast<std::size_t>(t0)] = mark_in;
    stack_.assign(1, t0);
    cavity_.clear();
    boundary_.clear();
    while (!stack_.empty()) {
      const std::int32_t t = stack_.back();
      stack_.pop_back();
      cavity_.push_back(t);
      for (int k = 0; k < 3; ++k) {
        const std::int32_t link = tris_[static_cast<std::size_t>(t)].n[k];
        const std::int32_t u = tri_of(link);
        std::uint32_t& m = mark_[static_cast<std::size_t>(u)];
        bool in;
        if ((m | 1) == mark_in) {
          in = m & 1;
        } else {
          in = conflicts(u, q);
          m = in ? mark_in : mark_out;
          if (in) stack_.push_back(u);
        }
        if (in) continue;
        // An edge of the cavity's boundary: the new triangle is t with q in
        // place of v[k] (q sees the edge from v[k]'s side).
        Edge e;
        for (int j = 0; j < 3; ++j) e.v[j] = tris_[static_cast<std::size_t>(t)].v[j];
        e.v[k] = q;
        e.k = k;
        e.outside = u;
        e.back = edge_of(link);
        boundary_.push_back(e);
      }
    }
    free_.insert(free_.end(), cavity_.begin(), cavity_.end());
    // The new triangles fan around q: the two through q and boundary vertex
    // v meet across the edge qv, found by v (pending_, by vertex + 1 so the
    // infinite vertex has a place; each boundary vertex is in two).
    for (const Edge& e : boundary_) {
      const std::int32_t nt = allocate();
      Tri& t = tris_[static_cast<std::size_t>(nt)];
      for (int j = 0; j < 3; ++j) {
        t.v[j] = e.v[j];
        // Every vertex of a removed triangle is on the cavity's boundary.
        if (e.v[j] != infinite) vtri_[static_cast<std::size_t>(e.v[j])] = nt;
      }
      t.n[e.k] = across(e.outside, e.back);
      tris_[static_cast<std::size_t>(e.outside)].n[e.back] = across(nt, e.k);
      for (int j = 0; j < 3; ++j) {
        if (j == e.k) continue;
        std::int32_t& p = pending_[static_cast<std::size_t>(e.v[3 - j - e.k] + 1)];
        if (p < 0) {
          p = across(nt, j);
        } else {
          t.n[j] = p;
          tris_[static_cast<std::size_t>(tri_of(p))].n[edge_of(p)] = across(nt, j);
          p = -1;
        }
      }
      last_ = nt;
    }
    prev_ = q;
  }

  /// The finite triangles, in the layout of insertion_delaunay_2d.
  Buffer<std::int32_t> take_rows() const;

 private:
  struct Edge {
    std::int32_t v[3];  // the new triangle's vertices (q at k)
    int k;
    std::int32_t outside;  // the triangle across the edge, not in conflict
    int back;              // its edge towards the cavity
  };

  /// Where q's walk starts: the last insertion's triangle, or the guide
  /// vertex's when the guide is nearer to q than the last inserted point
  /// (insertion.cpp, walk_start).
  std::int32_t walk_start(std::int32_t q) const {
    const std::int32_t g = guide_[static_cast<std::size_t>(q)];
    if (g < 0 || prev_ < 0) return last_;
    auto dist2 = [&](std::int32_t v) {
      const double dx = at(v)[0] - at(q)[0], dy = at(v)[1] - at(q)[1];
      return dx * dx + dy * dy;
    };
    return dist2(g) < dist2(prev_) ? vtri_[static_cast<std::size_t>(g)] : last_;
  }

  std::int32_t allocate() {
    if (!free_.empty()) {
      const std::int32_t t = free_.back();
      free_.pop_back();
      return t;
    }
    if (tris_.size() >= max_slots) throw std::length_error("tessera: 2D insertion: more triangles than Tri::n can number");
    tris_.emplace_back();
    mark_.push_back(0);
    return static_cast<std::int32_t>(tris_.size() - 1);
  }

  static bool same_edge(const Tri& a, int ka, const Tri& b, int kb) {
    std::int32_t ea[2], eb[2];
    for (int m = 0, i = 0, j = 0; m < 3; ++m) {
      if (m != ka) ea[i++] = a.v[m];
      if (m != kb) eb[j++] = b.v[m];
    }
    return std::minmax(ea[0], ea[1]) == std::minmax(eb[0], eb[1]);
  }

  /// Is q strictly inside t's (perturbed) circumcircle? For a ghost: is q
  /// beyond its edge, or on the edge's line strictly between its ends (the
  /// circumcircle of the triangle behind the edge meets the line there)?
  bool conflicts(std::int32_t ti, std::int32_t q) const {
    const Tri& t = tris_[static_cast<std::size_t>(ti)];
    const int inf = infinite_slot(t);
    if (inf == 3) return in_circle(t, q);
    std::int32_t ids[3] = {t.v[0], t.v[1], t.v[2]};
    ids[inf] = q;
    if (const int o = orientation(ids); o != 0) return o > 0;
    return in_circle(tris_[static_cast<std::size_t>(tri_of(t.n[inf]))], q);
  }

  const double* at(std::int32_t k) const { return coords_.data() + static_cast<std::size_t>(k) * 2; }
  std::int32_t global(std::int32_t k) const { return global_[static_cast<std::size_t>(k)]; }

  int orientation(const std::int32_t* ks) const {
    if (const int o = orientation_filter(at(ks[0]), at(ks[1]), at(ks[2]))) return o;
    const std::int32_t ids[3] = {global(ks[0]), global(ks[1]), global(ks[2])};
    return kernels::orientation(ctx_, ids);
  }

  bool in_circle(const Tri& t, std::int32_t q) const {
    if (const int s = in_circle_filter(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(q))) return s > 0;
    const std::int32_t planes[2] = {global(t.v[1]), global(t.v[2])};
    return kernels::in_sphere(ctx_, global(t.v[0]), planes, global(q));
  }

  /// A triangle whose closure holds q, or a ghost whose edge q lies strictly
  /// beyond: a stochastic visibility walk from `from` (insertion.cpp, locate).
  std::int32_t locate(std::int32_t q, std::int32_t from) {
    std::int32_t t = from, came_from = -1;
    if (const int inf = infinite_slot(tris_[static_cast<std::size_t>(t)]); inf != 3)
      t = tri_of(tris_[static_cast<std::size_t>(t)].n[inf]);
    for (;;) {
      const Tri& tt = tris_[static_cast<std::size_t>(t)];
      if (infinite_slot(tt) != 3) return t;
      rng_ = rng_ * 6364136223846793005ull + 1442695040888963407ull;
      const int first = static_cast<int>((rng_ >> 32) % 3);
      std::int32_t next = -1;
      for (int i = 0; i < 3; ++i) {
        const int k = (first + i) % 3;
        if (tri_of(tt.n[k]) == came_from) continue;  // q lies on this side of the edge just crossed
        std::int32_t ids[3] = {tt.v[0], tt.v[1], tt.v[2]};
        ids[k] = q;
        if (orientation(ids) < 0) {
          next = tri_of(tt.n[k]);
          break;
        }
      }
      if (next < 0) return t;
      came_from = t;
      t = next;
    }
  }

  static constexpr std::size_t max_slots = std::size_t{1} << 29;  // across() fits in int32

  const ExactContext& ctx_;
  std::vector<std::int32_t> global_;  // vertex -> input id
  std::vector<std::int32_t> guide_;   // vertex -> an earlier round's vertex near it, or -1
  std::vector<double> coords_;        // vertex -> coordinates (2 each)
  std::vector<std::int32_t> vtri_;    // inserted vertex -> a live triangle of it
  std::vector<Tri> tris_;
  std::vector<std::uint32_t> mark_;   // per slot: (epoch << 1) | in conflict
  std::vector<std::int32_t> free_;    // slots of removed triangles
  std::vector<std::int32_t> pending_; // vertex + 1 -> the new triangle's link awaiting its partner, or -1
  std::vector<std::int32_t> stack_, cavity_;
  std::vector<Edge> boundary_;
  std::uint32_t epoch_ = 0;
  std::int32_t last_ = 0;   // a triangle of the last insertion
  std::int32_t prev_ = -1;  // the vertex inserted last
  std::uint64_t rng_ = 0x2545F4914F6CDD1Dull;
};

Buffer<std::int32_t> Triangulation2::take_rows() const {
  using Row = std::array<std::int32_t, 3>;
  std::vector<std::uint8_t> is_free(tris_.size(), 0);
  for (const std::int32_t t : free_) is_free[static_cast<std::size_t>(t)] = 1;
  std::vector<Row> rows;
  rows.reserve(tris_.size());
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    if (is_free[i] || infinite_slot(tris_[i]) != 3) continue;
    Row r{global(tris_[i].v[0]), global(tris_[i].v[1]), global(tris_[i].v[2])};
    // Ascending, then the last two swapped where that order is clockwise (an
    // odd permutation of the counter-clockwise one).
    const int inversions = (r[0] > r[1]) + (r[0] > r[2]) + (r[1] > r[2]);
    std::sort(r.begin(), r.end());
    if (inversions & 1) std::swap(r[1], r[2]);
    rows.push_back(r);
  }
  tbb::parallel_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) {
    if (a[0] != b[0]) return a[0] < b[0];
    const std::int32_t a1 = std::min(a[1], a[2]), b1 = std::min(b[1], b[2]);
    if (a1 != b1) return a1 < b1;
    return std::max(a[1], a[2]) < std::max(b[1], b[2]);
  });
  Buffer<std::int32_t> out(3 * rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) std::copy(rows[i].begin(), rows[i].end(), out.data() + 3 * i);
  return out;
}

}  // namespace

std::optional<Buffer<std::int32_t>> insertion_delaunay_2d(const ExactContext& ctx, std::span<const std::int32_t> ids,
                                                          const double* lo, const double* hi,
                                                          const std::function<void(double)>& progress) {
  if (ctx.dim != 2) throw std::logic_error("tessera: insertion_delaunay_2d is 2D only");
  BrioOrder order = brio_order(ctx, ids, lo, hi);
  // The first triangle: the first two points and the first point off their
  // line (in insertion order).
  const std::size_t m = order.ids.size();
  if (m < 3) return std::nullopt;
  std::size_t c = 2;
  std::array<std::int32_t, 3> s{order.ids[0], order.ids[1], -1};
  int o = 0;
  for (; c < m; ++c) {
    s[2] = order.ids[c];
    if ((o = kernels::orientation(ctx, s.data())) != 0) break;
  }
  if (c == m) return std::nullopt;
  std::array<std::int32_t, 3> local{0, 1, static_cast<std::int32_t>(c)};
  if (o < 0) std::swap(local[1], local[2]);
  std::vector<std::int32_t> guide = brio_guides(ctx, order);
  order.codes = {};
  Triangulation2 tri(ctx, std::move(order.ids), std::move(guide));
  tri.start(local);
  for (std::size_t i = 2; i < m; ++i) {
    if (i == c) continue;
    tri.insert(static_cast<std::int32_t>(i));
    if (progress && (i & 16383) == 16383) progress(static_cast<double>(i + 1) / static_cast<double>(m));
  }
  if (progress) progress(1.0);
  return tri.take_rows();
}

}  // namespace tessera::front
