// Bowyer–Watson insertion in 3D; see insertion.hpp.
#include "insertion.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <tbb/parallel_sort.h>

#include "tessera/kernels/delaunay_predicates.hpp"

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

// splitmix64's finaliser (as delaunay.cpp's id_hash): the BRIO round of a point.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
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
    const int round = std::min(std::countl_zero(mix(static_cast<std::uint64_t>(ids[i]))), max_round);
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

class Triangulation {
 public:
  explicit Triangulation(const ExactContext& ctx) : ctx_(ctx) {}

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
          if (e.key == key && e.tet != nt) {
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
    std::vector<std::array<std::int32_t, 4>> out;
    out.reserve(tets_.size() / 2);
    std::vector<std::uint8_t> is_free(tets_.size(), 0);
    for (const std::int32_t t : free_) is_free[static_cast<std::size_t>(t)] = 1;
    for (std::size_t i = 0; i < tets_.size(); ++i) {
      if (is_free[i] || infinite_slot(tets_[i]) != 4) continue;
      std::array<std::int32_t, 4> r{tets_[i].v[0], tets_[i].v[1], tets_[i].v[2], tets_[i].v[3]};
      // Sort, counting the swaps: an odd permutation of a positive order is
      // negative, which the layout writes with its last two swapped.
      bool odd = false;
      for (int a = 1; a < 4; ++a)
        for (int b = a; b > 0 && r[b - 1] > r[b]; --b) {
          std::swap(r[b - 1], r[b]);
          odd = !odd;
        }
      if (odd) std::swap(r[2], r[3]);
      out.push_back(r);
    }
    tbb::parallel_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
      for (int k = 0; k < 2; ++k)
        if (a[k] != b[k]) return a[k] < b[k];
      const std::int32_t a2 = std::min(a[2], a[3]), b2 = std::min(b[2], b[3]);
      if (a2 != b2) return a2 < b2;
      return std::max(a[2], a[3]) < std::max(b[2], b[3]);
    });
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
    if (inf == 4) return kernels::in_sphere(ctx_, t.v[0], t.v + 1, q);
    std::int32_t ids[4] = {t.v[0], t.v[1], t.v[2], t.v[3]};
    ids[inf] = q;
    if (const int o = kernels::orientation(ctx_, ids); o != 0) return o > 0;
    const Tet& f = tets_[static_cast<std::size_t>(t.n[inf])];
    return kernels::in_sphere(ctx_, f.v[0], f.v + 1, q);
  }

  /// A tetrahedron whose closure holds q, or a ghost whose facet q lies
  /// strictly beyond: a visibility walk from `from`, which tries the faces
  /// from a varying first one (a stochastic walk terminates; Devillers,
  /// Pion & Teillaud, "Walking in a triangulation", 2002).
  std::int32_t locate(std::int32_t q, std::int32_t from) {
    std::int32_t t = from;
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
        std::int32_t ids[4] = {tt.v[0], tt.v[1], tt.v[2], tt.v[3]};
        ids[k] = q;
        if (kernels::orientation(ctx_, ids) < 0) {
          next = tt.n[k];
          break;
        }
      }
      if (next < 0) return t;
      t = next;
    }
  }

  const ExactContext& ctx_;
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

// Three points on one line? (Their projections on all three coordinate planes are.)
bool collinear(const ExactContext& ctx, std::int32_t a, std::int32_t b, std::int32_t c) {
  const double* p[3] = {ctx.points + static_cast<std::size_t>(a) * 3, ctx.points + static_cast<std::size_t>(b) * 3,
                        ctx.points + static_cast<std::size_t>(c) * 3};
  for (int d = 0; d < 3; ++d) {
    const int e = (d + 1) % 3;
    const double x[2] = {p[0][d], p[0][e]}, y[2] = {p[1][d], p[1][e]}, z[2] = {p[2][d], p[2][e]};
    const double* tri[3] = {x, y, z};
    if (kernels::orientation(2, tri) != 0) return false;
  }
  return true;
}

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
  while (c < order.size() && collinear(ctx, order[0], order[1], order[c])) ++c;
  if (c == order.size()) return std::nullopt;
  std::size_t d = c + 1;
  std::array<std::int32_t, 4> s{order[0], order[1], order[c], -1};
  int o = 0;
  for (; d < order.size(); ++d) {
    s[3] = order[d];
    if ((o = kernels::orientation(ctx, s.data())) != 0) break;
  }
  if (d == order.size()) return std::nullopt;
  if (o < 0) std::swap(s[2], s[3]);
  Triangulation tri(ctx);
  tri.start(s);
  for (std::size_t i = 2; i < order.size(); ++i)
    if (i != c && i != d) tri.insert(order[i]);
  return tri.rows();
}

}  // namespace tessera::front
