// Bowyer–Watson insertion in 3D; see insertion.hpp.
#include "insertion.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <tbb/parallel_sort.h>

#include "id_hash.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::front {
namespace {

using kernels::ExactContext;

constexpr std::int32_t infinite = -1;  ///< the vertex every ghost tetrahedron shares

/// A tetrahedron: vertices, and for each k the tetrahedron across the face
/// opposite v[k]. Finite ones are positively oriented; a ghost (one vertex
/// infinite) is oriented as if that vertex were a point beyond its facet.
struct Tet {
  std::int32_t v[4];
  std::int32_t n[4];
};

int infinite_slot(const Tet& t) {
  for (int k = 0; k < 4; ++k)
    if (t.v[k] == infinite) return k;
  return 4;
}

// 21 bits of x spread to every third bit.
std::uint64_t spread3(std::uint64_t x) {
  x &= 0x1FFFFF;
  x = (x | x << 32) & 0x1F00000000FFFFull;
  x = (x | x << 16) & 0x1F0000FF0000FFull;
  x = (x | x << 8) & 0x100F00F00F00F00Full;
  x = (x | x << 4) & 0x10C30C30C30C30C3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}

// The insertion order: BRIO rounds (a point joins round r with probability
// 2^-(r+1), by its hash; the smallest rounds first), each in Morton order.
std::vector<std::int32_t> brio_order(const ExactContext& ctx, std::span<const std::int32_t> ids, const double* lo,
                                     const double* hi) {
  struct Key {
    std::uint64_t round;  // smallest rounds first
    std::uint64_t code;
    std::int32_t id;
  };
  constexpr int max_round = 24;
  std::vector<Key> keys(ids.size());
  double scale[3];
  for (int d = 0; d < 3; ++d) scale[d] = hi[d] > lo[d] ? 2097151.0 / (hi[d] - lo[d]) : 0.0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    const double* p = ctx.points + static_cast<std::size_t>(ids[i]) * 3;
    std::uint64_t code = 0;
    for (int d = 0; d < 3; ++d) {
      const double c = std::clamp((p[d] - lo[d]) * scale[d], 0.0, 2097151.0);
      code |= spread3(static_cast<std::uint64_t>(c)) << d;
    }
    const int round = std::min(std::countl_zero(id_hash(ids[i])), max_round);
    keys[i] = {static_cast<std::uint64_t>(max_round - round), code, ids[i]};
  }
  tbb::parallel_sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.round != b.round ? a.round < b.round
                                                : (a.code != b.code ? a.code < b.code : a.id < b.id);
  });
  std::vector<std::int32_t> order(ids.size());
  for (std::size_t i = 0; i < keys.size(); ++i) order[i] = keys[i].id;
  return order;
}

// The filters in front of kernels::orientation and kernels::in_sphere,
// written out for 3D and for points that are ids into one array: the walk and
// the cavity search ask tens of them per point. Each returns the exact sign
// when its float evaluation is certain, and 0 otherwise (then the kernels'
// predicates decide, with their exact arithmetic and perturbation). The
// quantities and bounds are those of the kernels' filters
// (delaunay_predicates.hpp), evaluated in another order: the bounds hold for
// any order of the sums.

// Sign of det[b - a, c - a, d - a].
inline int orientation_filter(const double* a, const double* b, const double* c, const double* d) {
  const double r0[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double r1[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double r2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  const double m0 = r1[1] * r2[2], m1 = r1[2] * r2[1];
  const double m2 = r1[2] * r2[0], m3 = r1[0] * r2[2];
  const double m4 = r1[0] * r2[1], m5 = r1[1] * r2[0];
  const double det = r0[0] * (m0 - m1) + r0[1] * (m2 - m3) + r0[2] * (m4 - m5);
  const double perm = std::fabs(r0[0]) * (std::fabs(m0) + std::fabs(m1)) +
                      std::fabs(r0[1]) * (std::fabs(m2) + std::fabs(m3)) +
                      std::fabs(r0[2]) * (std::fabs(m4) + std::fabs(m5));
  const double bound = 16 * kernels::filter::u * perm + kernels::filter::abs_eps;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

// For a positively oriented tetrahedron abcd: +1 when q is surely inside its
// circumsphere, -1 surely outside, 0 undecided. With rows r_k = p_k - a and
// s_k = |r_k|^2 (k = b, c, d, q), q is inside iff det[[r_k, s_k]] < 0
// (kernels::in_sphere; det R > 0 here).
inline int in_sphere_filter(const double* a, const double* b, const double* c, const double* d, const double* q) {
  double r[4][3], s[4];
  const double* p[4] = {b, c, d, q};
  for (int k = 0; k < 4; ++k) {
    for (int e = 0; e < 3; ++e) r[k][e] = p[k][e] - a[e];
    s[k] = r[k][0] * r[k][0] + r[k][1] * r[k][1] + r[k][2] * r[k][2];
  }
  // 2x2 minors of the x, y columns for each pair of rows, and their permanents.
  double xy[4][4], axy[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      const double u = r[i][0] * r[j][1], v = r[i][1] * r[j][0];
      xy[i][j] = u - v;
      axy[i][j] = std::fabs(u) + std::fabs(v);
    }
  // The 3x3 minor of rows i < j < k (columns x, y, z), expanded along z.
  auto minor = [&](int i, int j, int k, double& perm) {
    perm = std::fabs(r[i][2]) * axy[j][k] + std::fabs(r[j][2]) * axy[i][k] + std::fabs(r[k][2]) * axy[i][j];
    return r[i][2] * xy[j][k] - r[j][2] * xy[i][k] + r[k][2] * xy[i][j];
  };
  double p0, p1, p2, p3;
  const double d0 = minor(1, 2, 3, p0), d1 = minor(0, 2, 3, p1), d2 = minor(0, 1, 3, p2), d3 = minor(0, 1, 2, p3);
  const double det = -s[0] * d0 + s[1] * d1 - s[2] * d2 + s[3] * d3;
  const double perm = s[0] * p0 + s[1] * p1 + s[2] * p2 + s[3] * p3;
  const double bound = 64 * kernels::filter::u * perm + kernels::filter::abs_eps;
  return det < -bound ? 1 : (det > bound ? -1 : 0);
}

class Triangulation {
 public:
  /// Vertices are numbered by `global`, the insertion order: vertex k is
  /// point global[k] of ctx, and its coordinates are copied in that order, so
  /// the points a walk and a cavity meet lie close in memory too.
  Triangulation(const ExactContext& ctx, std::vector<std::int32_t> global) : ctx_(ctx), global_(std::move(global)) {
    coords_.resize(3 * global_.size());
    for (std::size_t k = 0; k < global_.size(); ++k)
      for (int e = 0; e < 3; ++e) coords_[3 * k + static_cast<std::size_t>(e)] = ctx.points[static_cast<std::size_t>(global_[k]) * 3 + static_cast<std::size_t>(e)];
  }

  /// Start from the positively oriented tetrahedron s and its four ghosts.
  void start(std::array<std::int32_t, 4> s) {
    tets_.clear();
    Tet t0{{s[0], s[1], s[2], s[3]}, {-1, -1, -1, -1}};
    tets_.push_back(t0);
    for (int k = 0; k < 4; ++k) {
      Tet g = t0;
      g.v[k] = infinite;
      // With the infinite vertex standing for a point beyond face k (the
      // side away from v[k]) the order is negative: swap two others.
      std::swap(g.v[(k + 1) % 4], g.v[(k + 2) % 4]);
      tets_.push_back(g);
    }
    // Link the five by their shared faces.
    for (std::size_t a = 0; a < tets_.size(); ++a)
      for (int ka = 0; ka < 4; ++ka)
        for (std::size_t b = 0; b < tets_.size(); ++b) {
          if (a == b) continue;
          for (int kb = 0; kb < 4; ++kb)
            if (same_face(tets_[a], ka, tets_[b], kb)) tets_[a].n[ka] = static_cast<std::int32_t>(b);
        }
    state_.assign(tets_.size(), 0);
    last_ = 0;
  }

  /// Insert point q (not yet in the triangulation, at no vertex's place).
  void insert(std::int32_t q) {
    const std::int32_t t0 = locate(q, last_);
    if (++epoch_ == (1u << 31)) {  // stale marks could read as this insertion's
      std::fill(state_.begin(), state_.end(), 0);
      epoch_ = 1;
    }
    if (!conflicts(t0, q)) throw std::logic_error("tessera: insertion: the located tetrahedron is not in conflict");
    mark(t0, true);
    stack_.assign(1, t0);
    cavity_.clear();
    boundary_.clear();
    while (!stack_.empty()) {
      const std::int32_t t = stack_.back();
      stack_.pop_back();
      cavity_.push_back(t);
      for (int k = 0; k < 4; ++k) {
        const std::int32_t u = tets_[static_cast<std::size_t>(t)].n[k];
        bool in;
        if (tested(u)) {
          in = in_conflict(u);
        } else {
          in = conflicts(u, q);
          mark(u, in);
          if (in) stack_.push_back(u);
        }
        if (in) continue;
        // A face of the cavity's boundary: the new tetrahedron is t with q
        // in place of v[k] (q sees the face from v[k]'s side).
        Face f;
        const Tet& tt = tets_[static_cast<std::size_t>(t)];
        for (int m = 0; m < 4; ++m) f.v[m] = tt.v[m];
        f.v[k] = q;
        f.k = k;
        f.outside = u;
        f.back = back_slot(u, t);
        boundary_.push_back(f);
      }
    }
    for (const std::int32_t t : cavity_) free_.push_back(t);
    // Each boundary edge bounds two of the new tetrahedra: they meet across
    // the face through it and q.
    const std::size_t need = std::bit_ceil(4 * boundary_.size() + 16);
    if (edges_.size() < need) edges_.assign(need, Edge{});
    const std::uint64_t mask = edges_.size() - 1;
    const int shift = 64 - std::countr_zero(edges_.size());
    used_.clear();
    for (const Face& f : boundary_) {
      const std::int32_t nt = allocate();
      Tet& t = tets_[static_cast<std::size_t>(nt)];
      for (int m = 0; m < 4; ++m) t.v[m] = f.v[m];
      t.n[f.k] = f.outside;
      tets_[static_cast<std::size_t>(f.outside)].n[f.back] = nt;
      for (int j = 0; j < 4; ++j) {
        if (j == f.k) continue;
        std::int32_t a = infinite, b = infinite;
        bool first = true;
        for (int m = 0; m < 4; ++m) {
          if (m == j || m == f.k) continue;
          (first ? a : b) = f.v[m];
          first = false;
        }
        if (a > b) std::swap(a, b);
        const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
                                  static_cast<std::uint32_t>(b);
        std::uint64_t h = (key * 0x9E3779B97F4A7C15ull) >> shift;
        for (;; h = (h + 1) & mask) {
          Edge& e = edges_[h];
          if (e.tet < 0) {
            e = {key, nt, j};
            used_.push_back(h);
            break;
          }
          if (e.key == key) {
            t.n[j] = e.tet;
            tets_[static_cast<std::size_t>(e.tet)].n[e.slot] = nt;
            e.key = ~std::uint64_t{0};  // matched: keep the probe chain, never match again
            break;
          }
        }
      }
      last_ = nt;
    }
    for (const std::uint64_t h : used_) edges_[h] = Edge{};
  }

  /// The finite tetrahedra, in the layout of insertion_delaunay.
  std::vector<std::array<std::int32_t, 4>> rows() const {
    using Row = std::array<std::int32_t, 4>;
    std::vector<std::uint8_t> is_free(tets_.size(), 0);
    for (const std::int32_t t : free_) is_free[static_cast<std::size_t>(t)] = 1;
    // Rows by their lowest id (a counting sort), then each point's few sorted.
    std::size_t n_ids = 0;
    for (const std::int32_t g : global_) n_ids = std::max(n_ids, static_cast<std::size_t>(g) + 1);
    std::vector<std::size_t> start(n_ids + 1, 0);
    std::vector<Row> rows;
    rows.reserve(tets_.size());
    for (std::size_t i = 0; i < tets_.size(); ++i) {
      if (is_free[i] || infinite_slot(tets_[i]) != 4) continue;
      Row r{global(tets_[i].v[0]), global(tets_[i].v[1]), global(tets_[i].v[2]), global(tets_[i].v[3])};
      // Sort, counting the swaps: an odd permutation of a positive order is
      // negative, which the layout writes with its last two swapped.
      bool odd = false;
      for (int a = 1; a < 4; ++a)
        for (int b = a; b > 0 && r[b - 1] > r[b]; --b) {
          std::swap(r[b - 1], r[b]);
          odd = !odd;
        }
      if (odd) std::swap(r[2], r[3]);
      rows.push_back(r);
      ++start[static_cast<std::size_t>(r[0]) + 1];
    }
    for (std::size_t g = 0; g < n_ids; ++g) start[g + 1] += start[g];
    std::vector<Row> out(rows.size());
    {
      std::vector<std::size_t> next(start.begin(), start.end() - 1);
      for (const Row& r : rows) out[next[static_cast<std::size_t>(r[0])]++] = r;
    }
    auto key_less = [](const Row& a, const Row& b) {  // row[0] is shared
      if (a[1] != b[1]) return a[1] < b[1];
      const std::int32_t a2 = std::min(a[2], a[3]), b2 = std::min(b[2], b[3]);
      if (a2 != b2) return a2 < b2;
      return std::max(a[2], a[3]) < std::max(b[2], b[3]);
    };
    for (std::size_t g = 0; g < n_ids; ++g)
      if (start[g + 1] - start[g] > 1)
        std::sort(out.begin() + static_cast<std::ptrdiff_t>(start[g]), out.begin() + static_cast<std::ptrdiff_t>(start[g + 1]),
                  key_less);
    return out;
  }

 private:
  struct Face {
    std::int32_t v[4];  // the new tetrahedron's vertices (q at k)
    int k;
    std::int32_t outside;  // the tetrahedron across the face, not in conflict
    int back;              // its slot pointing at the cavity
  };
  struct Edge {
    std::uint64_t key = 0;
    std::int32_t tet = -1;
    int slot = 0;
  };

  static bool same_face(const Tet& a, int ka, const Tet& b, int kb) {
    std::int32_t fa[3], fb[3];
    for (int m = 0, i = 0, j = 0; m < 4; ++m) {
      if (m != ka) fa[i++] = a.v[m];
      if (m != kb) fb[j++] = b.v[m];
    }
    std::sort(fa, fa + 3);
    std::sort(fb, fb + 3);
    return std::equal(fa, fa + 3, fb);
  }

  int back_slot(std::int32_t u, std::int32_t t) const {
    const Tet& tu = tets_[static_cast<std::size_t>(u)];
    for (int m = 0; m < 4; ++m)
      if (tu.n[m] == t) return m;
    throw std::logic_error("tessera: insertion: one-sided adjacency");
  }

  std::int32_t allocate() {
    if (!free_.empty()) {
      const std::int32_t t = free_.back();
      free_.pop_back();
      return t;
    }
    tets_.emplace_back();
    state_.push_back(0);
    return static_cast<std::int32_t>(tets_.size() - 1);
  }

  bool tested(std::int32_t t) const { return (state_[static_cast<std::size_t>(t)] >> 1) == epoch_; }
  bool in_conflict(std::int32_t t) const { return state_[static_cast<std::size_t>(t)] & 1; }
  void mark(std::int32_t t, bool in) { state_[static_cast<std::size_t>(t)] = (epoch_ << 1) | (in ? 1u : 0u); }

  /// Is q strictly inside t's (perturbed) circumsphere? For a ghost: is q
  /// beyond its facet, or on the facet's plane within its circumcircle?
  bool conflicts(std::int32_t ti, std::int32_t q) const {
    const Tet& t = tets_[static_cast<std::size_t>(ti)];
    const int inf = infinite_slot(t);
    if (inf == 4) return in_sphere(t, q);
    std::int32_t ids[4] = {t.v[0], t.v[1], t.v[2], t.v[3]};
    ids[inf] = q;
    if (const int o = orientation(ids); o != 0) return o > 0;
    return in_sphere(tets_[static_cast<std::size_t>(t.n[inf])], q);
  }

  const double* at(std::int32_t k) const { return coords_.data() + static_cast<std::size_t>(k) * 3; }
  std::int32_t global(std::int32_t k) const { return global_[static_cast<std::size_t>(k)]; }

  // kernels::orientation, its filter inline. The exact stages (and the
  // perturbation, by point id) are asked with the input's ids.
  int orientation(const std::int32_t* ks) const {
    if (const int o = orientation_filter(at(ks[0]), at(ks[1]), at(ks[2]), at(ks[3]))) return o;
    const std::int32_t ids[4] = {global(ks[0]), global(ks[1]), global(ks[2]), global(ks[3])};
    return kernels::orientation(ctx_, ids);
  }

  // kernels::in_sphere for a finite tetrahedron, its filter inline.
  bool in_sphere(const Tet& t, std::int32_t q) const {
    if (const int s = in_sphere_filter(at(t.v[0]), at(t.v[1]), at(t.v[2]), at(t.v[3]), at(q))) return s > 0;
    const std::int32_t planes[3] = {global(t.v[1]), global(t.v[2]), global(t.v[3])};
    return kernels::in_sphere(ctx_, global(t.v[0]), planes, global(q));
  }

  /// A tetrahedron whose closure holds q, or a ghost whose facet q lies
  /// strictly beyond: a visibility walk from `from`, which tries the faces
  /// from a varying first one (a stochastic walk terminates; Devillers,
  /// Pion & Teillaud, "Walking in a triangulation", 2002).
  std::int32_t locate(std::int32_t q, std::int32_t from) {
    std::int32_t t = from, came_from = -1;
    if (const int inf = infinite_slot(tets_[static_cast<std::size_t>(t)]); inf != 4)
      t = tets_[static_cast<std::size_t>(t)].n[inf];
    for (;;) {
      const Tet& tt = tets_[static_cast<std::size_t>(t)];
      if (infinite_slot(tt) != 4) return t;
      rng_ = rng_ * 6364136223846793005ull + 1442695040888963407ull;
      const int first = static_cast<int>(rng_ >> 62);
      std::int32_t next = -1;
      for (int i = 0; i < 4; ++i) {
        const int k = (first + i) & 3;
        if (tt.n[k] == came_from) continue;  // q lies on this side of the face just crossed
        std::int32_t ids[4] = {tt.v[0], tt.v[1], tt.v[2], tt.v[3]};
        ids[k] = q;
        if (orientation(ids) < 0) {
          next = tt.n[k];
          break;
        }
      }
      if (next < 0) return t;
      came_from = t;
      t = next;
    }
  }

  const ExactContext& ctx_;
  std::vector<std::int32_t> global_;  // vertex -> input id
  std::vector<double> coords_;        // vertex -> coordinates (3 each)
  std::vector<Tet> tets_;
  std::vector<std::uint32_t> state_;  // (epoch << 1) | in conflict, per tetrahedron
  std::uint32_t epoch_ = 0;
  std::vector<std::int32_t> free_;  // slots of removed tetrahedra
  std::int32_t last_ = 0;           // a tetrahedron of the last insertion: the next walk's start
  std::uint64_t rng_ = 0x2545F4914F6CDD1Dull;
  std::vector<std::int32_t> stack_, cavity_;
  std::vector<Face> boundary_;
  std::vector<Edge> edges_;
  std::vector<std::uint64_t> used_;
};

}  // namespace

std::optional<std::vector<std::array<std::int32_t, 4>>> insertion_delaunay(const ExactContext& ctx,
                                                                            std::span<const std::int32_t> ids,
                                                                            const double* lo, const double* hi) {
  if (ctx.dim != 3) throw std::logic_error("tessera: insertion_delaunay is 3D only");
  std::vector<std::int32_t> order = brio_order(ctx, ids, lo, hi);
  // The first tetrahedron: the first two points, the first point off their
  // line, the first off their plane (in insertion order).
  if (order.size() < 4) return std::nullopt;
  std::size_t c = 2;
  auto at = [&](std::size_t k) { return ctx.points + static_cast<std::size_t>(order[k]) * 3; };
  while (c < order.size() && kernels::collinear3(at(0), at(1), at(c))) ++c;
  if (c == order.size()) return std::nullopt;
  std::size_t d = c + 1;
  std::array<std::int32_t, 4> s{order[0], order[1], order[c], -1};
  int o = 0;
  for (; d < order.size(); ++d) {
    s[3] = order[d];
    if ((o = kernels::orientation(ctx, s.data())) != 0) break;
  }
  if (d == order.size()) return std::nullopt;
  std::array<std::int32_t, 4> local{0, 1, static_cast<std::int32_t>(c), static_cast<std::int32_t>(d)};
  if (o < 0) std::swap(local[2], local[3]);
  const std::size_t m = order.size();
  Triangulation tri(ctx, std::move(order));
  tri.start(local);
  for (std::size_t i = 2; i < m; ++i)
    if (i != c && i != d) tri.insert(static_cast<std::int32_t>(i));
  return tri.rows();
}

}  // namespace tessera::front
