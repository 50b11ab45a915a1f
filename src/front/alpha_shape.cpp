// tessera::alpha_shape (include/tessera/alpha_shape.hpp): which simplices
// are small enough, which facets no kept simplex holds are singular faces
// of the alpha complex, and the boundary of the kept simplices' union.
//
// The tests. With corner a as origin, e_k = p_k - a and the lifted weights
// w_k = |e_k|^2 + r_a^2 - r_k^2 (all r = 0 without radii):
// * a simplex's circumcentre (orthocentre) is a + n / (2 D), D = det[e], and
//     3D: n = w_1 (e_2 x e_3) + w_2 (e_3 x e_1) + w_3 (e_1 x e_2),
//     2D: n = (w_1 e_2y - w_2 e_1y, w_2 e_1x - w_1 e_2x);
//   its squared radius |c - a|^2 - r_a^2 is at most alpha^2 iff
//     |n|^2 <= 4 D^2 (alpha^2 + r_a^2);
// * a facet's smallest orthosphere (centre in its affine hull) has centre
//   a + (u . E) / (2 g), G the Gram matrix of its edges E, g = det G,
//   u = adj(G) w; it is small enough iff w . u <= 4 g (alpha^2 + r_a^2), and
//   an apex d lies strictly inside iff u . (E e_d) > w_d g (the facet is
//   then attached; in a Delaunay triangulation the one or two apexes are
//   the only points to ask).
// Each margin is written once as a template over the number type. The float
// stage (Approx) evaluates it on the differences scaled by a power of two
// (the largest in [1, 2): nothing overflows or underflows but a far-off
// alpha or radius) beside its permanent (the same expression over absolute
// values): no term has more than ~30 rounded operations along it, so 64
// unit roundoffs of the permanent bound the error with room to spare. Where
// the value does not clear that bound, GMP rationals decide (every double is
// one). A simplex whose D is zero exactly (flat) is never kept. Without
// radii, an edge surely longer than 2 alpha ends both tests first (a chord
// is at most a diameter): most simplices of surface samples and of a
// shape's outside.
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include <gmpxx.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "compensated_sum.hpp"
#include "pass.hpp"
#include "point_buckets.hpp"
#include "tessera/alpha_shape.hpp"
#include "tessera/engine/thread_arena.hpp"

namespace tessera {
namespace {

constexpr double unit = 0x1p-53;  // unit roundoff

/// A row's entry: its point id and (periodic) its image's shift, ordered by
/// id, then shift (a translation keeps that order).
using Entry = std::pair<std::int32_t, std::array<int, 3>>;

/// Where a triangulation's entries lie: a row's slot k is its point, or in a
/// periodic triangulation that point (as wrapped, Delaunay::periodic_points)
/// moved by the entry's shift in lattice vectors, which the box's rounding
/// makes exact.
struct Geometry {
  const Delaunay& dt;
  std::span<const double> points;  ///< the input's, or the periodic points
  std::span<const double> radii;
  bool periodic;
  std::array<std::array<double, 3>, 3> lattice{};
  std::size_t w;

  Geometry(const Delaunay& d, std::span<const double> input_points, std::span<const double> r)
      : dt(d), points(d.is_periodic() ? std::span<const double>(d.periodic_points) : input_points), radii(r),
        periodic(d.is_periodic()), w(static_cast<std::size_t>(d.dim + 1)) {
    if (periodic) lattice = periodic_lattice(d.bounds, d.tilt);
  }
  std::int32_t id(std::size_t row, std::size_t k) const { return dt.simplices[row * w + k]; }
  const std::int8_t* shift(std::size_t row, std::size_t k) const {
    return dt.simplex_shifts.data() + (row * w + k) * static_cast<std::size_t>(dt.dim);
  }
  Entry entry(std::size_t row, std::size_t k) const {
    Entry e{id(row, k), {0, 0, 0}};
    if (periodic)
      for (int a = 0; a < dt.dim; ++a) e.second[static_cast<std::size_t>(a)] = shift(row, k)[a];
    return e;
  }
  /// The coordinates of point `id` moved by `shift` lattice vectors, in
  /// `buffer` (periodic), or a pointer into the points.
  const double* place(std::int32_t point, const std::array<int, 3>& s, double* buffer) const {
    const double* p = points.data() + static_cast<std::size_t>(point) * static_cast<std::size_t>(dt.dim);
    if (!periodic) return p;
    periodic_image(lattice, dt.dim, p, s, buffer);
    return buffer;
  }
  /// Entry (row, k)'s coordinates.
  const double* at(std::size_t row, std::size_t k, double* buffer) const {
    const Entry e = entry(row, k);
    return place(e.first, e.second, buffer);
  }
  double radius(std::size_t row, std::size_t k) const {
    return radii.empty() ? 0.0 : radii[static_cast<std::size_t>(id(row, k))];
  }
};

/// A simplex's corners (D + 1 pointers to dim doubles: into the points, or
/// into `xyz` for a periodic triangulation's images) and, with radii,
/// theirs. Filled in place (the pointers may point into the object).
struct Corners {
  int D = 3;
  std::array<const double*, 4> p{};
  std::array<double, 4> r{0, 0, 0, 0};
  double xyz[4][3] = {};
};

void corners(const Geometry& g, std::size_t row, Corners& c) {
  c.D = g.dt.dim;
  for (std::size_t k = 0; k < g.w; ++k) {
    c.p[k] = g.at(row, k, c.xyz[k]);
    c.r[k] = g.radius(row, k);
  }
}

/// A float value and its permanent (the same expression over the absolute
/// values of its inputs): the rounding error of the value is at most a few
/// dozen unit roundoffs of the permanent for the expressions below.
struct Approx {
  double v = 0, p = 0;
  Approx() = default;
  explicit Approx(double x) : v(x), p(std::fabs(x)) {}
  Approx(double value, double perm) : v(value), p(perm) {}
};
Approx operator+(Approx a, Approx b) { return {a.v + b.v, a.p + b.p}; }
Approx operator-(Approx a, Approx b) { return {a.v - b.v, a.p + b.p}; }
Approx operator*(Approx a, Approx b) { return {a.v * b.v, a.p * b.p}; }

/// A corner a and vectors to other points from it, with lifted weights
/// w = |e|^2 + r_a^2 - r^2, and rhs = alpha^2 + r_a^2: in T = Approx on
/// differences scaled by 2^scale (the largest in [1, 2)), in T = mpq_class
/// exactly.
template <class T>
struct Frame {
  int D = 3, m = 0;  ///< dimension; vectors
  int scale = 0;     ///< Approx: the vectors are the differences times 2^scale
  bool capped = false;  ///< Approx: alpha was capped (below)
  std::array<std::array<T, 3>, 5> e;
  std::array<T, 5> w;
  T rhs;
};

/// x 2^e, exactly where no result is subnormal (a power of two built from
/// its bits: ldexp's call cost a tenth of the keep test).
double times_pow2(double x, int e) {
  if (e < -1022 || e > 1023) return std::ldexp(x, e);
  return x * std::bit_cast<double>(static_cast<std::uint64_t>(e + 1023) << 52);
}

/// The s with the largest |difference| times 2^s in [1, 2) (big > 0, finite).
int scale_of(double big) {
  const int biased = static_cast<int>((std::bit_cast<std::uint64_t>(big) >> 52) & 0x7ff);
  if (biased != 0) return 1023 - biased;  // big = 1.f 2^(biased - 1023)
  int ex = 0;
  std::frexp(big, &ex);  // subnormal: big = f 2^ex, f in [0.5, 1)
  return 1 - ex;
}

/// a, its radius, the other points q[0..m) and theirs. Approx: false when
/// something is not finite (far radii, a huge spread): rationals then.
bool make_frame(Frame<Approx>& f, int D, const double* a, double ra, const double* const* q, const double* rq, int m,
                double alpha) {
  f.D = D;
  f.m = m;
  double x[5][3] = {};
  double big = 0;
  for (int k = 0; k < m; ++k)
    for (int d = 0; d < D; ++d) {
      x[k][d] = q[k][d] - a[d];
      big = std::max(big, std::fabs(x[k][d]));
    }
  if (!(big > 0) || !std::isfinite(big)) return false;
  const int scale = scale_of(big);
  f.scale = scale;
  const Approx ras(times_pow2(ra, scale));
  const Approx ra2 = ras * ras;
  for (int k = 0; k < m; ++k) {
    Approx sq;
    for (int d = 0; d < D; ++d) {
      f.e[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)] = Approx(times_pow2(x[k][d], scale));
      const Approx& c = f.e[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)];
      sq = sq + c * c;
    }
    const Approx rk(times_pow2(rq[k], scale));
    f.w[static_cast<std::size_t>(k)] = sq + ra2 - rk * rk;
  }
  // alpha capped at 2^100 (scaled; the vectors are below 2): a test the
  // capped alpha passes, the true one passes too (callers redo the others).
  const double scaled_alpha = times_pow2(alpha, scale);
  f.capped = scaled_alpha > 0x1p100;
  const Approx as(std::min(scaled_alpha, 0x1p100));
  f.rhs = as * as + ra2;
  return std::isfinite(f.rhs.p) && std::isfinite(f.w[0].p) && std::isfinite(f.w[static_cast<std::size_t>(m - 1)].p);
}

void make_frame(Frame<mpq_class>& f, int D, const double* a, double ra, const double* const* q, const double* rq,
                int m, double alpha) {
  f.D = D;
  f.m = m;
  const mpq_class ra2 = mpq_class(ra) * mpq_class(ra);
  for (int k = 0; k < m; ++k) {
    mpq_class sq = 0;
    for (int d = 0; d < D; ++d) {
      auto& c = f.e[static_cast<std::size_t>(k)][static_cast<std::size_t>(d)];
      c = mpq_class(q[k][d]) - mpq_class(a[d]);
      sq += c * c;
    }
    const mpq_class rk(rq[k]);
    f.w[static_cast<std::size_t>(k)] = sq + ra2 - rk * rk;
  }
  f.rhs = mpq_class(alpha) * mpq_class(alpha) + ra2;
}

template <class T>
T dot(const Frame<T>& f, int i, int j) {
  T s = f.e[static_cast<std::size_t>(i)][0] * f.e[static_cast<std::size_t>(j)][0];
  for (int d = 1; d < f.D; ++d)
    s = s + f.e[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)] *
                f.e[static_cast<std::size_t>(j)][static_cast<std::size_t>(d)];
  return s;
}

/// A simplex (vectors 0..D-1 its edges from a): 4 det^2 rhs - |n|^2, which
/// is >= 0 iff its circumsphere (orthosphere) is small enough; and det.
template <class T>
T simplex_margin(const Frame<T>& f, T& det) {
  const auto& e = f.e;
  const auto& w = f.w;
  T n2;
  if (f.D == 3) {
    std::array<std::array<T, 3>, 3> c;  // e_1 x e_2, e_2 x e_0, e_0 x e_1
    for (int i = 0; i < 3; ++i) {
      const auto j = static_cast<std::size_t>((i + 1) % 3), k = static_cast<std::size_t>((i + 2) % 3);
      for (int d = 0; d < 3; ++d) {
        const auto d1 = static_cast<std::size_t>((d + 1) % 3), d2 = static_cast<std::size_t>((d + 2) % 3);
        c[static_cast<std::size_t>(i)][static_cast<std::size_t>(d)] = e[j][d1] * e[k][d2] - e[j][d2] * e[k][d1];
      }
    }
    det = e[0][0] * c[0][0] + e[0][1] * c[0][1] + e[0][2] * c[0][2];
    for (std::size_t d = 0; d < 3; ++d) {
      const T n = w[0] * c[0][d] + w[1] * c[1][d] + w[2] * c[2][d];
      if (d == 0) n2 = n * n;
      else n2 = n2 + n * n;
    }
  } else {
    det = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    const T n0 = w[0] * e[1][1] - w[1] * e[0][1], n1 = w[1] * e[0][0] - w[0] * e[1][0];
    n2 = n0 * n0 + n1 * n1;
  }
  const T four(4);
  return four * det * det * f.rhs - n2;
}

/// A facet (vectors 0..D-2 its edges from a) with the Gram matrix G of its
/// edges, g = det G, and u = adj(G) w: its smallest orthosphere (centre in
/// its affine hull) has centre a + (u . E) / (2 g) and squared radius
/// w . u / (4 g) - r_a^2.
template <class T>
struct FacetTerms {
  T g;
  std::array<T, 2> u;
};

template <class T>
FacetTerms<T> facet_terms(const Frame<T>& f) {
  FacetTerms<T> t;
  if (f.D == 2) {
    t.g = dot(f, 0, 0);
    t.u[0] = f.w[0];
    return t;
  }
  const T g11 = dot(f, 0, 0), g12 = dot(f, 0, 1), g22 = dot(f, 1, 1);
  t.g = g11 * g22 - g12 * g12;
  t.u[0] = g22 * f.w[0] - g12 * f.w[1];
  t.u[1] = g11 * f.w[1] - g12 * f.w[0];
  return t;
}

/// 4 g rhs - w . u: >= 0 iff the facet's smallest orthosphere is small enough.
template <class T>
T facet_margin(const Frame<T>& f, const FacetTerms<T>& t) {
  const T four(4);
  T wu = f.w[0] * t.u[0];
  if (f.D == 3) wu = wu + f.w[1] * t.u[1];
  return four * t.g * f.rhs - wu;
}

/// For the apex at vector `k`: u . (E e_k) - w_k g, > 0 iff the apex lies
/// strictly inside the facet's smallest orthosphere (the facet is attached).
template <class T>
T apex_margin(const Frame<T>& f, const FacetTerms<T>& t, int k) {
  T s = t.u[0] * dot(f, 0, k);
  if (f.D == 3) s = s + t.u[1] * dot(f, 1, k);
  return s - f.w[static_cast<std::size_t>(k)] * t.g;
}

/// The sign of an Approx margin when its float value clears its error
/// bound, else 0.
int filtered_sign(const Approx& x) {
  constexpr double filter_ulps = 64;
  constexpr double tiny = 0x1p-1000;  // subnormal roundings: far below any scaled term that matters
  const double err = filter_ulps * unit * x.p + tiny;
  if (!std::isfinite(x.v) || !std::isfinite(err)) return 0;
  return x.v > err ? 1 : x.v < -err ? -1 : 0;
}

/// Without radii, whether some edge among the points p[0..m) is surely
/// longer than 2 alpha: then every sphere through them is larger than
/// alpha (a chord is at most a diameter), and neither a simplex nor a facet
/// of them can be small. Most simplices of surface samples (long, through
/// the object) and of the outside of a shape end here. The squares of
/// rounded differences are within 5 unit roundoffs, alpha^2 within one;
/// alpha^2 near underflow asks nothing.
bool surely_too_long(const double* const* p, int m, int D, double alpha) {
  const double a2 = alpha * alpha;
  if (!(a2 >= 0x1p-1000)) return false;  // also inf: nothing is too long
  const double limit = 4 * a2 * (1 + 16 * unit);
  for (int i = 0; i < m; ++i)
    for (int j = i + 1; j < m; ++j) {
      double d2 = 0;
      for (int d = 0; d < D; ++d) {
        const double x = p[i][d] - p[j][d];
        d2 += x * x;
      }
      if (d2 > limit) return true;
    }
  return false;
}

/// Whether a simplex is kept: its circumsphere (orthosphere) has a squared
/// radius at most alpha^2.
bool keep_simplex(const Corners& s, double alpha, bool weighted, std::size_t& exact) {
  if (!weighted && surely_too_long(s.p.data(), s.D + 1, s.D, alpha)) return false;
  const double* q[3] = {s.p[1], s.p[2], s.p[3]};
  const double rq[3] = {s.r[1], s.r[2], s.r[3]};
  Frame<Approx> f;
  if (make_frame(f, s.D, s.p[0], s.r[0], q, rq, s.D, alpha)) {
    Approx det;
    const int sign = filtered_sign(simplex_margin(f, det));
    if (sign > 0) return true;
    if (sign < 0 && !f.capped) return false;
  }
  ++exact;
  thread_local Frame<mpq_class> g;
  make_frame(g, s.D, s.p[0], s.r[0], q, rq, s.D, alpha);
  mpq_class det;
  const mpq_class margin = simplex_margin(g, det);
  return sgn(det) != 0 && sgn(margin) >= 0;
}

/// Whether a facet (D corners) that no kept simplex holds is a singular face
/// of the alpha complex: its smallest orthosphere has a squared radius at
/// most alpha^2 and holds neither apex (the opposite vertices of its one or
/// two simplices) strictly inside.
bool singular_facet(int D, const double* const* p, const double* r, int apexes, double alpha, std::size_t& exact) {
  // Vectors from p[0]: the facet's other corners, then the apexes.
  const int m = D - 1 + apexes;
  const double* q[4];
  double rq[4];
  for (int k = 0; k < m; ++k) {
    q[k] = p[k + 1];
    rq[k] = r[k + 1];
  }
  Frame<Approx> f;
  if (make_frame(f, D, p[0], r[0], q, rq, m, alpha)) {
    const FacetTerms<Approx> t = facet_terms(f);
    const int small = filtered_sign(facet_margin(f, t));
    if (small < 0 && !f.capped) return false;
    if (small > 0) {
      bool decided = true;
      for (int k = D - 1; k < m && decided; ++k) {
        const int in = filtered_sign(apex_margin(f, t, k));
        if (in > 0) return false;  // attached
        decided = in < 0;
      }
      if (decided) return true;
    }
  }
  ++exact;
  thread_local Frame<mpq_class> g;
  make_frame(g, D, p[0], r[0], q, rq, m, alpha);
  const FacetTerms<mpq_class> t = facet_terms(g);
  if (sgn(t.g) == 0 || sgn(facet_margin(g, t)) < 0) return false;
  for (int k = D - 1; k < m; ++k)
    if (sgn(apex_margin(g, t, k)) > 0) return false;
  return true;
}

void check_arguments(const Delaunay& dt, std::span<const double> points, std::span<const double> radii,
                     const char* who) {
  front::check_simplex_ids(dt);
  if (dt.is_periodic() && (dt.simplex_shifts.size() != dt.simplices.size() * static_cast<std::size_t>(dt.dim) ||
                           dt.periodic_points.size() != dt.n_points * static_cast<std::size_t>(dt.dim)))
    throw InputError(std::string(who) + ": a periodic triangulation without its shifts or points");
  if (!dt.is_periodic() && points.size() != dt.n_points * static_cast<std::size_t>(dt.dim))
    throw InputError(std::string(who) + ": " + std::to_string(points.size()) + " coordinates for a triangulation of " +
                     std::to_string(dt.n_points) + " points in " + std::to_string(dt.dim) + "D");
  if (dt.power && radii.size() != dt.n_points)
    throw InputError(std::string(who) + ": a regular triangulation of " + std::to_string(dt.n_points) +
                     " points needs their " + std::to_string(dt.n_points) + " radii, got " +
                     std::to_string(radii.size()));
  if (!dt.power && !radii.empty())
    throw InputError(std::string(who) + ": radii given for a triangulation computed without them");
  if (!radii.empty()) front::check_radii(radii, dt.n_points);
}

/// A triangulation's facet adjacency: nb[s w + k] the simplex across the
/// facet opposite slot k of s (-1: none); periodic, nbk its slot opposite
/// that facet (a plain one's is found in its row: slot_across).
/// simplex_neighbors() for a plain triangulation; a periodic one's facets
/// match by ids and shifts up to a translation: each facet's entries in
/// (id, shift) order, translated so that the first is at shift 0, are its
/// key (a translation keeps that order, so the same corner comes first in
/// both simplices).
struct Adjacency {
  std::vector<std::int32_t> nb;
  std::vector<std::int8_t> nbk;
};

Adjacency adjacency(const Geometry& g) {
  const Delaunay& dt = g.dt;
  const std::size_t m = dt.n_simplices(), w = g.w, D = static_cast<std::size_t>(dt.dim);
  Adjacency a;
  if (m == 0) return a;
  if (!g.periodic) a.nb = simplex_neighbors(dt);
  if (g.periodic) {
    struct Record {
      std::array<Entry, 3> key;
      std::size_t s, k;
      bool operator<(const Record& o) const { return key != o.key ? key < o.key : (s != o.s ? s < o.s : k < o.k); }
    };
    std::vector<Record> recs(m * w);
    engine::ThreadArena(dt.threads_used).execute([&] {
      tbb::parallel_for(std::size_t{0}, m, [&](std::size_t s) {
        for (std::size_t k = 0; k < w; ++k) {
          Record& rec = recs[s * w + k];
          rec.s = s;
          rec.k = k;
          rec.key.fill({-1, {0, 0, 0}});
          std::size_t c = 0;
          for (std::size_t j = 0; j < w; ++j)
            if (j != k) rec.key[c++] = g.entry(s, j);
          std::sort(rec.key.begin(), rec.key.begin() + static_cast<std::ptrdiff_t>(D));
          const std::array<int, 3> base = rec.key[0].second;
          for (std::size_t c2 = 0; c2 < D; ++c2)
            for (std::size_t x = 0; x < 3; ++x) rec.key[c2].second[x] -= base[x];
        }
      });
      tbb::parallel_sort(recs.begin(), recs.end());
    });
    a.nb.assign(m * w, -1);
    a.nbk.assign(m * w, -1);
    for (std::size_t i = 0; i + 1 < recs.size(); ++i) {
      if (recs[i].key != recs[i + 1].key) continue;
      const Record &x = recs[i], &y = recs[i + 1];
      a.nb[x.s * w + x.k] = static_cast<std::int32_t>(y.s);
      a.nbk[x.s * w + x.k] = static_cast<std::int8_t>(y.k);
      a.nb[y.s * w + y.k] = static_cast<std::int32_t>(x.s);
      a.nbk[y.s * w + y.k] = static_cast<std::int8_t>(x.k);
      ++i;
    }
    return a;
  }
  return a;
}

/// The slot of simplex o = nb[r w + k] opposite the facet it shares with r.
std::size_t slot_across(const Adjacency& a, std::size_t w, std::size_t r, std::size_t k) {
  if (!a.nbk.empty()) return static_cast<std::size_t>(a.nbk[r * w + k]);
  const auto o = static_cast<std::size_t>(a.nb[r * w + k]);
  for (std::size_t j = 0; j < w; ++j)
    if (a.nb[o * w + j] == static_cast<std::int32_t>(r)) return j;
  return w;  // (not a conforming triangulation)
}

/// The apex of simplex o across the facet opposite slot k of row r (o's slot
/// ok), in r's frame: in a periodic triangulation o's entries are moved by
/// the translation that takes the facet's first (id, shift) entry in o to
/// the same entry in r.
const double* neighbour_apex(const Geometry& g, std::size_t r, std::size_t k, std::size_t o, std::size_t ok,
                             double* buffer) {
  if (!g.periodic) return g.at(o, ok, buffer);
  auto first_entry = [&](std::size_t s, std::size_t skip) {
    Entry best{INT32_MAX, {0, 0, 0}};
    for (std::size_t j = 0; j < g.w; ++j)
      if (j != skip) best = std::min(best, g.entry(s, j));
    return best.second;
  };
  const std::array<int, 3> in_r = first_entry(r, k), in_o = first_entry(o, ok);
  Entry apex = g.entry(o, ok);
  for (std::size_t x = 0; x < 3; ++x) apex.second[x] += in_r[x] - in_o[x];
  return g.place(apex.first, apex.second, buffer);
}

/// How many keys occur more than twice (sorts `keys`, in the calling arena).
template <class Key>
std::size_t keys_in_more_than_two(std::vector<Key>& keys) {
  tbb::parallel_sort(keys.begin(), keys.end());
  std::size_t count = 0;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j] == keys[i]) ++j;
    count += j - i > 2;
    i = j;
  }
  return count;
}

/// The facet of a row opposite its slot k, oriented outward (3D) or with the
/// simplex on its left (2D). Taking slot k out of a positively oriented row
/// leaves its vertex on the facet's outer side when k is even (3D: det of
/// the facet's edges with the far vertex is then negative; 2D: the segment
/// has the triangle on its left); for odd k two ids swap.
void outward_facet(const std::int32_t* row, int D, int k, std::int32_t* out) {
  int m = 0;
  for (int j = 0; j <= D; ++j)
    if (j != k) out[m++] = row[j];
  if (k % 2 == 1) std::swap(out[0], out[1]);
}

/// A union-find that threads share: roots link under lower roots by a
/// compare-and-swap (no cycles), finds halve paths as they go. The sets
/// (and so their count) do not depend on the order of the unions.
class ConcurrentUnionFind {
 public:
  explicit ConcurrentUnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  std::int32_t find(std::int32_t x) {
    for (;;) {
      std::int32_t p = at(x).load(std::memory_order_acquire);
      if (p == x) return x;
      const std::int32_t g = at(p).load(std::memory_order_acquire);
      if (g != p) at(x).compare_exchange_weak(p, g, std::memory_order_acq_rel);
      x = g;
    }
  }
  void unite(std::int32_t a, std::int32_t b) {
    for (;;) {
      a = find(a);
      b = find(b);
      if (a == b) return;
      if (a < b) std::swap(a, b);
      std::int32_t expected = a;
      if (at(a).compare_exchange_strong(expected, b, std::memory_order_acq_rel)) return;
    }
  }
  bool is_root(std::int32_t x) { return at(x).load(std::memory_order_acquire) == x; }

 private:
  std::atomic_ref<std::int32_t> at(std::int32_t x) { return std::atomic_ref<std::int32_t>(parent_[static_cast<std::size_t>(x)]); }
  std::vector<std::int32_t> parent_;
};

}  // namespace

std::vector<double> simplex_squared_radii(const Delaunay& dt, std::span<const double> points,
                                          std::span<const double> radii) {
  check_arguments(dt, points, radii, "simplex_squared_radii");
  const Geometry g(dt, points, radii);
  std::vector<double> out(dt.n_simplices());
  engine::ThreadArena(dt.threads_used).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, out.size(), 4096), [&](const tbb::blocked_range<std::size_t>& rg) {
      Corners s;
      for (std::size_t r = rg.begin(); r != rg.end(); ++r) {
        corners(g, r, s);
        const double* q[3] = {s.p[1], s.p[2], s.p[3]};
        const double rq[3] = {s.r[1], s.r[2], s.r[3]};
        Frame<Approx> f;
        out[r] = std::numeric_limits<double>::infinity();
        if (!make_frame(f, s.D, s.p[0], s.r[0], q, rq, s.D, 0.0)) continue;
        Approx det;
        const Approx margin = simplex_margin(f, det);  // 4 det^2 r_a^2 - |n|^2
        const double rho2 = -margin.v / (4 * det.v * det.v);
        if (det.v != 0 && std::isfinite(rho2)) out[r] = std::ldexp(rho2, -2 * f.scale);
      }
    });
  });
  return out;
}

AlphaShape alpha_shape(const Delaunay& dt, std::span<const double> points, double alpha,
                       std::span<const double> radii) {
  check_arguments(dt, points, radii, "alpha_shape");
  if (std::isnan(alpha) || alpha < 0)
    throw InputError("alpha_shape: alpha must be a radius >= 0 (or +inf for the whole triangulation), got " +
                     std::to_string(alpha));
  const int D = dt.dim;
  const std::size_t w = static_cast<std::size_t>(D + 1), m = dt.n_simplices(), du = static_cast<std::size_t>(D);
  const Geometry g(dt, points, radii);
  AlphaShape shape;
  shape.dim = D;
  shape.alpha = alpha;

  // Which simplices are kept.
  std::vector<std::uint8_t> kept(m, 1);
  std::atomic<std::size_t> exact{0};
  engine::ThreadArena arena(dt.threads_used);
  if (!std::isinf(alpha)) {
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, 4096), [&](const tbb::blocked_range<std::size_t>& rg) {
        std::size_t here = 0;
        Corners s;
        for (std::size_t r = rg.begin(); r != rg.end(); ++r) {
          corners(g, r, s);
          kept[r] = keep_simplex(s, alpha, !radii.empty(), here);
        }
        exact += here;
      });
    });
  }
  for (std::size_t r = 0; r < m; ++r)
    if (kept[r]) shape.simplex_rows.push_back(static_cast<std::int32_t>(r));

  // Per row, which of its facets are on the boundary (bits 0..D: the
  // simplex is kept, the other side not) and which are singular faces of the
  // alpha complex (bits 4..4+D: neither side kept, and the facet small and
  // unattached; a shared facet is decided at its lower row). Then each
  // kind's facets are counted per block of rows and filled at each block's
  // offset: row order on any thread count.
  const Adjacency adj = adjacency(g);
  const std::vector<std::int32_t>& nb = adj.nb;
  std::vector<std::uint8_t> open(m, 0);
  const bool finite_alpha = !std::isinf(alpha);
  constexpr std::size_t block = 1 << 14;
  const std::size_t blocks = (m + block - 1) / block;
  arena.execute([&] {
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
      std::size_t here = 0;
      for (std::size_t r = b * block; r < std::min(m, (b + 1) * block); ++r) {
        std::uint8_t bits = 0;
        for (std::size_t k = 0; k < w; ++k) {
          const std::int32_t o = nb[r * w + k];
          const bool other_kept = o >= 0 && kept[static_cast<std::size_t>(o)];
          if (kept[r]) {
            if (!other_kept) bits |= static_cast<std::uint8_t>(1u << k);
            continue;
          }
          // Each shared facet once: at its lower row (in a small periodic
          // box a simplex may meet itself: at its lower slot).
          if (!finite_alpha || other_kept || (o >= 0 && static_cast<std::size_t>(o) < r)) continue;
          if (o >= 0 && static_cast<std::size_t>(o) == r && adj.nbk[r * w + k] < static_cast<std::int8_t>(k)) continue;
          // The facet's corners, then its apexes: this row's vertex k and
          // the neighbour's vertex across it (moved into this row's frame).
          const double* p[5];
          double rr[5] = {0, 0, 0, 0, 0}, xyz[5][3];
          int c = 0;
          for (std::size_t j = 0; j < w; ++j)
            if (j != k) {
              p[c] = g.at(r, j, xyz[c]);
              rr[c++] = g.radius(r, j);
            }
          // (Before the neighbour's row is read: most facets end here.)
          if (radii.empty() && surely_too_long(p, D, D, alpha)) continue;
          p[c] = g.at(r, k, xyz[c]);
          rr[c++] = g.radius(r, k);
          if (o >= 0) {
            const auto ou = static_cast<std::size_t>(o);
            const std::size_t ok = slot_across(adj, w, r, k);
            if (ok == w)
              throw InputError("alpha_shape: the triangulation does not conform (simplex " + std::to_string(o) +
                               " is simplex " + std::to_string(r) + "'s neighbour, not the reverse)");
            p[c] = neighbour_apex(g, r, k, ou, ok, xyz[c]);
            rr[c++] = g.radius(ou, ok);
          }
          if (singular_facet(D, p, rr, c - D, alpha, here)) bits |= static_cast<std::uint8_t>(16u << k);
        }
        open[r] = bits;
      }
      exact += here;
    });
  });
  shape.exact_tests = exact;
  // (Periodic: each facet's entries' shifts too, in its simplex's frame.)
  static constexpr std::int32_t slots[4] = {0, 1, 2, 3};
  auto gather = [&](unsigned shift, std::vector<std::int32_t>& facets, std::vector<std::int32_t>* simplex,
                    std::vector<std::int8_t>& shifts) {
    std::vector<std::size_t> at(blocks + 1, 0);
    arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
        std::size_t c = 0;
        for (std::size_t r = b * block; r < std::min(m, (b + 1) * block); ++r)
          c += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(open[r] >> shift) & 15u));
        at[b + 1] = c;
      });
    });
    std::partial_sum(at.begin(), at.end(), at.begin());
    facets.resize(at[blocks] * du);
    if (simplex) simplex->resize(at[blocks]);
    if (g.periodic) shifts.resize(at[blocks] * du * du);
    arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t b) {
        std::size_t f = at[b];
        for (std::size_t r = b * block; r < std::min(m, (b + 1) * block); ++r)
          for (std::size_t k = 0; k < w; ++k) {
            if (!((open[r] >> shift) & (1u << k))) continue;
            std::int32_t sl[3];
            outward_facet(slots, D, static_cast<int>(k), sl);
            for (std::size_t i = 0; i < du; ++i) {
              const auto j = static_cast<std::size_t>(sl[i]);
              facets[f * du + i] = g.id(r, j);
              if (g.periodic) std::copy_n(g.shift(r, j), du, shifts.data() + (f * du + i) * du);
            }
            if (simplex) (*simplex)[f] = static_cast<std::int32_t>(r);
            ++f;
          }
      });
    });
  };
  gather(0, shape.boundary, &shape.boundary_simplex, shape.boundary_shifts);
  gather(4, shape.singular, nullptr, shape.singular_shifts);

  // Pieces: union-find over the kept simplices through their shared facets.
  {
    ConcurrentUnionFind sets(m);
    const std::size_t nk = shape.simplex_rows.size();
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nk, 4096), [&](const tbb::blocked_range<std::size_t>& rg) {
        for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
          const std::int32_t r = shape.simplex_rows[i];
          for (std::size_t k = 0; k < w; ++k) {
            const std::int32_t o = nb[static_cast<std::size_t>(r) * w + k];
            if (o > r && kept[static_cast<std::size_t>(o)]) sets.unite(r, o);  // each shared facet once
          }
        }
      });
    });
    // Roots are their sets' lowest rows (unions link under the lower root),
    // so the roots in row order number the pieces by their lowest rows; a
    // piece's number is its root's place among them (few: a binary search).
    std::vector<std::int32_t> roots;
    for (std::size_t i = 0; i < nk; ++i)
      if (sets.is_root(shape.simplex_rows[i])) roots.push_back(shape.simplex_rows[i]);
    shape.components = roots.size();
    shape.piece.resize(nk);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nk, 4096), [&](const tbb::blocked_range<std::size_t>& rg) {
        for (std::size_t i = rg.begin(); i != rg.end(); ++i)
          shape.piece[i] = static_cast<std::int32_t>(
              std::lower_bound(roots.begin(), roots.end(), sets.find(shape.simplex_rows[i])) - roots.begin());
      });
    });
  }

  // Where the boundary is not a manifold: 3D edges in more than two
  // boundary triangles (a closed boundary has each edge an even number of
  // times), 2D vertices in more than two segments.
  const std::size_t nf = shape.n_boundary();
  if (D == 3 && g.periodic) {
    // Edges match by ids and the shift between their ends (up to a translation).
    using Edge = std::pair<std::array<std::int32_t, 2>, std::array<int, 3>>;
    std::vector<Edge> edges;
    edges.reserve(3 * nf);
    for (std::size_t f = 0; f < nf; ++f)
      for (std::size_t j = 0; j < 3; ++j) {
        std::size_t ia = 3 * f + j, ib = 3 * f + (j + 1) % 3;
        auto entry = [&](std::size_t i) {
          Entry e{shape.boundary[i], {0, 0, 0}};
          for (std::size_t x = 0; x < 3; ++x) e.second[x] = shape.boundary_shifts[i * 3 + x];
          return e;
        };
        auto a = entry(ia), b = entry(ib);
        if (b < a) std::swap(a, b);
        Edge e{{a.first, b.first}, {0, 0, 0}};
        for (std::size_t x = 0; x < 3; ++x) e.second[x] = b.second[x] - a.second[x];
        edges.push_back(e);
      }
    shape.nonmanifold_ridges = arena.execute([&] { return keys_in_more_than_two(edges); });
  } else if (D == 3) {
    std::vector<std::uint64_t> edges;
    edges.reserve(3 * nf);
    for (std::size_t f = 0; f < nf; ++f)
      for (int j = 0; j < 3; ++j) {
        auto a = static_cast<std::uint32_t>(shape.boundary[3 * f + static_cast<std::size_t>(j)]);
        auto b = static_cast<std::uint32_t>(shape.boundary[3 * f + static_cast<std::size_t>((j + 1) % 3)]);
        if (a > b) std::swap(a, b);
        edges.push_back(std::uint64_t{a} << 32 | b);
      }
    shape.nonmanifold_ridges = arena.execute([&] { return keys_in_more_than_two(edges); });
  } else {
    std::vector<std::uint32_t> uses(dt.n_points, 0);
    for (const std::int32_t v : shape.boundary) ++uses[static_cast<std::size_t>(v)];
    for (const std::uint32_t u : uses) shape.nonmanifold_ridges += u > 2;
  }

  // Measures: compensated sums over fixed blocks, added up in block order
  // (the same on any thread count).
  auto block_sums = [&](std::size_t count, auto&& term) {
    const std::size_t nb_blocks = (count + block - 1) / block;
    std::vector<front::CompensatedSum> part(nb_blocks);
    arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, nb_blocks, [&](std::size_t b) {
        for (std::size_t i = b * block; i < std::min(count, (b + 1) * block); ++i) part[b].add(term(i));
      });
    });
    front::CompensatedSum total;
    for (const front::CompensatedSum& c : part) {
      total.add(c.sum);
      total.add(c.carry);
    }
    return total.value();
  };
  shape.volume = block_sums(shape.simplex_rows.size(), [&](std::size_t i) {
    const auto r = static_cast<std::size_t>(shape.simplex_rows[i]);
    double xyz[4][3];
    const double* a = g.at(r, 0, xyz[0]);
    double e[3][3] = {};
    for (int k = 0; k < D; ++k) {
      const double* q = g.at(r, static_cast<std::size_t>(k) + 1, xyz[k + 1]);
      for (int d = 0; d < D; ++d) e[k][d] = q[d] - a[d];
    }
    return D == 3 ? (e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6
                  : (e[0][0] * e[1][1] - e[0][1] * e[1][0]) / 2;
  });
  shape.boundary_measure = block_sums(nf, [&](std::size_t f) {
    double xyz[3][3];
    auto corner = [&](std::size_t i) {
      const std::size_t e = f * du + i;
      std::array<int, 3> sh{0, 0, 0};
      if (g.periodic)
        for (std::size_t x = 0; x < du; ++x) sh[x] = shape.boundary_shifts[e * du + x];
      return g.place(shape.boundary[e], sh, xyz[i]);
    };
    const double *a = corner(0), *b = corner(1);
    if (D == 2) return std::hypot(b[0] - a[0], b[1] - a[1]);
    const double* c = corner(2);
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, x[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    return std::hypot(u[1] * x[2] - u[2] * x[1], u[2] * x[0] - u[0] * x[2], u[0] * x[1] - u[1] * x[0]) / 2;
  });
  return shape;
}

}  // namespace tessera
