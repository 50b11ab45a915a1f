// Vertices solved exactly, and the exact measure of a cell (volume or area,
// and centroid) for cells whose float measure cancels. See
// exact_predicates.hpp for the contracts.
#include <gmp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "exact_rows.hpp"
#include "nearest_double.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/wide_int.hpp"

namespace tessera::kernels {

using exact_rows::build_rows;
using exact_rows::det_rows;
using exact_rows::Scratch;

// ---- Rounding to nearest (nearest_double.hpp) ----

// Every measure of exact_cell_measure is rounded so, whichever tier
// computes it: to nearest rather than truncated (mpq_get_d's way, until
// stop 73), so that a measure that is exactly a double (the centroid of a
// prism spanning the box lies halfway between two box planes; its volume is
// often a short binary fraction) lies inside its rounding interval, where
// an error bound can certify it, not on that interval's edge.
double nearest_double(mpz_srcptr m, bool sticky, long k, int sign, mpz_ptr q, mpz_ptr r) {
  const long length = static_cast<long>(mpz_sizeinbase(m, 2));
  const long e = length - 1 - k;  // 2^e <= (m + f) 2^-k < 2^(e + 1)
  if (e >= 1024) return sign > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  // Bits of m below the result's last place: 53 significant bits, fewer
  // below DBL_MIN (the last place is then 2^-1074).
  long below = length - 53;
  if (e < -1022) below += -1022 - e;
  if (below > length) return sign > 0 ? 0.0 : -0.0;  // under half the smallest subnormal
  mpz_tdiv_q_2exp(q, m, static_cast<mp_bitcnt_t>(below));
  mpz_tdiv_r_2exp(r, m, static_cast<mp_bitcnt_t>(below));
  // Compare the dropped bits (and f) with half a last place.
  const long top = below - 1;  // the half's bit
  const bool half_set = mpz_tstbit(r, static_cast<mp_bitcnt_t>(top)) != 0;
  bool up = false;
  if (half_set) {
    mpz_clrbit(r, static_cast<mp_bitcnt_t>(top));
    up = mpz_sgn(r) != 0 || sticky || mpz_odd_p(q);  // above half, or a tie to an odd mantissa
  }
  if (up) mpz_add_ui(q, q, 1);
  // q <= 2^53 is exact as a double, and so is the scaled result unless it
  // overflows to the infinity IEEE rounding gives.
  const double v = std::ldexp(mpz_get_d(q), static_cast<int>(below - k));
  return sign > 0 ? v : -v;
}

// Beyond 2^1026 an infinity, below 2^-2000 a zero, without dividing.
double rational_to_double(mpq_ptr q) {
  const int sign = mpq_sgn(q);
  if (sign == 0) return 0.0;
  // 2^(e - 1) < |q| < 2^(e + 1)
  const long e = static_cast<long>(mpz_sizeinbase(mpq_numref(q), 2)) -
                 static_cast<long>(mpz_sizeinbase(mpq_denref(q), 2));
  if (e >= 1026) return sign > 0 ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  if (e <= -2000) return sign > 0 ? 0.0 : -0.0;
  // m = floor(|q| 2^k) with at least 56 bits, and whether a remainder is left.
  const long k = 57 - e;
  mpz_t m, rem, t0, t1;
  mpz_inits(m, rem, t0, t1, nullptr);
  mpz_abs(t0, mpq_numref(q));
  if (k >= 0) mpz_mul_2exp(t0, t0, static_cast<mp_bitcnt_t>(k));
  mpz_set(t1, mpq_denref(q));
  if (k < 0) mpz_mul_2exp(t1, t1, static_cast<mp_bitcnt_t>(-k));
  mpz_tdiv_qr(m, rem, t0, t1);
  const double v = nearest_double(m, mpz_sgn(rem) != 0, k, sign, t0, t1);
  mpz_clears(m, rem, t0, t1, nullptr);
  return v;
}

// ---- Vertices ----

namespace {

// A signed fixed-width integer into GMP (two's complement limbs, least
// significant first).
template <int N>
void set_wide(mpz_ptr out, WideInt<N> x) {
  const bool negative = x.negative();
  if (negative) x = WideInt<N>::from_int64(0) - x;
  mpz_import(out, N, -1, sizeof(std::uint64_t), 0, 0, x.limb);
  if (negative) mpz_neg(out, out);
}

// A vertex's Cramer numerators and determinant in fixed-width integers:
// y[d] = num[d] / det * 2^shift relative to p_i (vertex_numerators).
struct GridNumerators {
  WideInt<8> num[3];
  WideInt<6> det;
  int shift = 0;
};

// vertex_numerators in 64- to 256-bit integers, where p_i and the planes'
// points and bounds lie on one grid of at most 60 bits (every input whose
// coordinates share a scale): the rows relative to p_i, a = 2 q with
// |q| < 2^61 and b = |q|^2 < 2^124 (a box row: the unit axis, b its
// bound less p_i), so the cofactors (a x a) stay below 2^125, det A below
// 2^189 and the numerators (b times cofactors) below 2^251. The same
// rationals as in GMP throughout (build_rows, det_rows), which cost 40% of a
// chain of near copies' cells (4 determinants, each a few dozen GMP calls).
// pv: the rows' doubles as row_parts leaves them, on the grid of step
// 2^shift.
void vertex_numerators_narrow(const DoubleParts (*pv)[Scratch::kMaxDim], const std::int32_t* planes, int dim,
                              int shift, GridNumerators& g) {
  using I = __int128;
  std::int64_t ci[3], a[3][3];
  I b[3], cof[3][3];
  exact_rows::relative_rows(pv, planes, dim, shift, ci, a, b);
  exact_rows::cofactors(a, dim, cof);
  WideInt<3> det = WideInt<3>::from(0);
  for (int d = 0; d < dim; ++d) det = det + multiply(WideInt<1>::from_int64(a[0][d]), WideInt<2>::from(cof[0][d]));
  if (det.sign() == 0) throw std::logic_error("exact_vertex: vertex planes are dependent (corrupt cell)");
  g.det = det.widen<6>();
  for (int d = 0; d < dim; ++d) {
    WideInt<4> n = WideInt<4>::from(0);
    for (int r = 0; r < dim; ++r) n = n + multiply(WideInt<2>::from(b[r]), WideInt<2>::from(cof[r][d]));
    g.num[d] = n.widen<8>();
  }
}

// x / 2^shift for x = pt on a grid of step 2^shift, below 2^124 (as
// exact_rows::on_grid, in 128 bits).
__int128 on_wide_grid(const DoubleParts& pt, int shift) {
  if (pt.mant == 0) return 0;
  const int k = pt.e2 - shift;
  return k >= 0 ? static_cast<__int128>(pt.mant) * (static_cast<__int128>(1) << k) : pt.mant >> -k;
}

// vertex_numerators_narrow for a grid of 61 to 124 bits: random doubles in
// [0, 1) whose smallest coordinate is ~1e-3 already need 64 (points on a
// thin cylindrical band solve ~40 vertices of each cell exactly, with
// grids of 60 to 76 bits). Rows relative to p_i, in L limbs for b and the
// cofactors:
// * L = 4, grids of up to 124 bits: |q| < 2^125, a = 2 q below 2^126,
//   b = |q|^2 below 3 2^250 (a box row's b below 2^125); the cofactors
//   (differences of products of a) below 2^253, det A below
//   3 2^126 2^253 < 2^381 and the numerators below 3 (3 2^250) 2^253 <
//   2^507: 2, 4, 4, 6 and 8 limbs;
// * L = 3, grids of up to 92 bits (the band's): |q| < 2^93, a below 2^94,
//   b below 3 2^186 < 2^188, the cofactors below 2^189, det A below
//   3 2^94 2^189 < 2^285 and the numerators below 3 2^188 2^189 < 2^379:
//   2, 3, 3, 5 and 6 limbs. The products of 3 limbs by 3 take 9 word
//   products where 4 by 4 take 16: the band's cells (50k, one thread) 2.38-2.46
//   -> 2.31-2.33 s, the same doubles.
// Each value is signed within its width.
template <int L>
void vertex_numerators_wide(const DoubleParts (*pv)[Scratch::kMaxDim], const std::int32_t* planes, int dim,
                            int shift, GridNumerators& g) {
  using I = __int128;
  using W2 = WideInt<2>;
  using WL = WideInt<L>;
  I ci[3] = {0, 0, 0}, a[3][3] = {};
  WL b[3];
  for (int d = 0; d < dim; ++d) ci[d] = on_wide_grid(pv[dim][d], shift);
  for (int r = 0; r < dim; ++r) {
    if (planes[r] >= 0) {
      WideInt<4> sq = WideInt<4>::from(0);
      for (int d = 0; d < dim; ++d) {
        const I q = on_wide_grid(pv[r][d], shift) - ci[d];
        a[r][d] = 2 * q;
        sq = sq + multiply(W2::from(q), W2::from(q));
      }
      b[r] = sq.template narrow<L>();
    } else {
      const int axis = box_plane_axis(planes[r]);
      a[r][axis] = 1;
      b[r] = WL::from(on_wide_grid(pv[r][0], shift) - ci[axis]);
    }
  }
  // cof[r][d]: the cofactor of a[r][d] (exact_rows::cofactors, wider).
  WL cof[3][3];
  if (dim == 2) {
    cof[0][0] = WL::from(a[1][1]), cof[0][1] = WL::from(-a[1][0]);
    cof[1][0] = WL::from(-a[0][1]), cof[1][1] = WL::from(a[0][0]);
  } else {
    for (int r = 0; r < 3; ++r) {
      const I* u = a[(r + 1) % 3];
      const I* w = a[(r + 2) % 3];
      for (int d = 0; d < 3; ++d) {
        const int x = (d + 1) % 3, y = (d + 2) % 3;
        cof[r][d] = (multiply(W2::from(u[x]), W2::from(w[y])) - multiply(W2::from(u[y]), W2::from(w[x])))
                        .template narrow<L>();
      }
    }
  }
  WideInt<2 + L> det = WideInt<2 + L>::from(0);
  for (int d = 0; d < dim; ++d) det = det + multiply(W2::from(a[0][d]), cof[0][d]);
  if (det.sign() == 0) throw std::logic_error("exact_vertex: vertex planes are dependent (corrupt cell)");
  g.det = det.template widen<6>();
  for (int d = 0; d < dim; ++d) {
    WideInt<2 * L> n = WideInt<2 * L>::from(0);
    for (int r = 0; r < dim; ++r) n = n + multiply(b[r], cof[r][d]);
    g.num[d] = n.template widen<8>();
  }
}

// The numerators on the input's grid where it spans at most 124 bits
// (narrow up to 60, wide in 3 limbs up to 92, else in 4); false otherwise
// (GMP's turn).
bool grid_numerators(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, GridNumerators& g) {
  const int dim = ctx.dim;
  if ((dim != 2 && dim != 3) || ctx.radii != nullptr) return false;  // the integer rows know no radii
  for (int r = 0; r < dim; ++r)
    if (is_wall_plane(planes[r])) return false;  // nor walls
  DoubleParts pv[Scratch::kRows][Scratch::kMaxDim];
  GridScale span;
  exact_rows::row_parts(ctx, i, planes, dim, pv, span);
  if (span.all_zero() || !span.fits(124)) return false;
  g.shift = span.scale();
  if (span.fits(60)) vertex_numerators_narrow(pv, planes, dim, g.shift, g);
  else if (span.fits(92)) vertex_numerators_wide<3>(pv, planes, dim, g.shift, g);
  else vertex_numerators_wide<4>(pv, planes, dim, g.shift, g);
  return true;
}

// The bit length of m >= 0.
template <int N>
int bit_length(const WideInt<N>& m) {
  for (int k = N - 1; k >= 0; --k)
    if (m.limb[k] != 0) return 64 * k + 64 - std::countl_zero(m.limb[k]);
  return 0;
}

// The top `want` <= 128 bits of m >= 0 of bit length len: floor(m /
// 2^(len - want)), or m * 2^(want - len) when shorter.
template <int N>
unsigned __int128 top_bits(const WideInt<N>& m, int len, int want) {
  const int s = std::max(len - want, 0);
  const int w = s / 64, b = s % 64;
  auto limb = [&m](int k) { return k < N ? m.limb[k] : std::uint64_t{0}; };
  std::uint64_t lo = limb(w), mid = limb(w + 1);
  if (b != 0) {
    lo = (lo >> b) | (mid << (64 - b));
    mid = (mid >> b) | (limb(w + 2) << (64 - b));
  }
  const unsigned __int128 t = (static_cast<unsigned __int128>(mid) << 64) | lo;
  return len >= want ? t : t << (want - len);
}

// num / den * 2^shift as a double within 0.51 ulp (den != 0), with no GMP:
// the top 128 bits of |num| over the top 64 of |den| (each truncated,
// relatively by under 2^-63) give a 64- or 65-bit quotient q >= 2^63 (its
// truncation: under 2^-63 more), so q times its power of two lies within
// 2^-61 of the exact value, and the conversion to double rounds once
// (twice for a subnormal result: under 2 ulp either way, as the GMP
// path's).
double grid_quotient(WideInt<8> num, WideInt<6> den, int shift) {
  const bool negative = num.negative() != den.negative();
  if (num.negative()) num = WideInt<8>::from_int64(0) - num;
  if (den.negative()) den = WideInt<6>::from_int64(0) - den;
  const int ln = bit_length(num), ld = bit_length(den);
  if (ln == 0) return 0.0;
  const unsigned __int128 n = top_bits(num, ln, 128);
  const auto d = static_cast<std::uint64_t>(top_bits(den, ld, 64));
  const double q = static_cast<double>(n / d);
  // |num| / |den| ~ (n 2^(ln - 128)) / (d 2^(ld - 64)).
  const double r = std::ldexp(q, ln - ld - 64 + shift);
  return negative ? -r : r;
}

// Cramer's rule on the rows in s.a / s.b (build_rows' frame): det A into
// s.minor[dim], and into s.minor[d] the numerator of coordinate d less det A
// times p_i's (the vertex relative to p_i). Throws where the rows are
// dependent (a corrupt cell).
void cramer_numerators(int dim, Scratch& s) {
  int sel[Scratch::kMaxDim] = {0, 1, 2};
  det_rows(s.minor[dim], s.a, sel, dim, s);
  if (mpz_sgn(s.minor[dim]) == 0) throw std::logic_error("exact_vertex: vertex planes are dependent (corrupt cell)");
  for (int d = 0; d < dim; ++d) {
    // Swap column d with b, take the determinant, swap back.
    for (int r = 0; r < dim; ++r) mpz_swap(s.a[r][d], s.b[r]);
    det_rows(s.minor[d], s.a, sel, dim, s);
    for (int r = 0; r < dim; ++r) mpz_swap(s.a[r][d], s.b[r]);
    mpz_submul(s.minor[d], s.minor[dim], s.coord[Scratch::kRows][d]);
  }
}

// The vertex of cell i where planes[0..dim) meet, relative to p_i, as
// integers: y[d] = minor[d] / minor[dim] * 2^shift (returned), for d < dim.
// Cramer's rule on the integer rows (build_rows): det A, then numerator
// d = det(A with column d replaced by b), less det times p_i. Weights are
// infinitesimal and do not move the vertex in the limit. On 64-bit rows
// where the input allows (vertex_numerators_narrow), else on 128-bit ones
// (vertex_numerators_wide), else in GMP.
int vertex_numerators(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, Scratch& s) {
  const int dim = ctx.dim;
  GridNumerators g;
  if (grid_numerators(ctx, i, planes, g)) {
    set_wide(s.minor[dim], g.det);
    for (int d = 0; d < dim; ++d) set_wide(s.minor[d], g.num[d]);
    return g.shift;
  }
  const int shift = build_rows(ctx, i, planes, dim, s);
  cramer_numerators(dim, s);
  return shift;
}

// The same vertex as rationals (canonical, as GMP's rational arithmetic needs).
void solve_vertex_exactly(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, Scratch& s,
                          mpq_ptr* y) {
  const int shift = vertex_numerators(ctx, i, planes, s);
  for (int d = 0; d < ctx.dim; ++d) {
    mpq_set_num(y[d], s.minor[d]);
    mpq_set_den(y[d], s.minor[ctx.dim]);
    mpq_canonicalize(y[d]);
    if (shift > 0) mpq_mul_2exp(y[d], y[d], static_cast<mp_bitcnt_t>(shift));
    else if (shift < 0) mpq_div_2exp(y[d], y[d], static_cast<mp_bitcnt_t>(-shift));
  }
}

// num / den * 2^shift rounded toward zero to 66 bits, then to double (within
// 2 ulp): an integer division, where the rational's canonical form cost two
// gcds per coordinate (a lattice jittered by 1e-9 solves a few vertices per
// cell exactly, and those gcds were a fifth of its run). `q` is scratch.
double quotient_to_double(mpz_srcptr num, mpz_srcptr den, long shift, mpz_ptr q) {
  if (mpz_sgn(num) == 0) return 0.0;
  const long k = 66 - (static_cast<long>(mpz_sizeinbase(num, 2)) - static_cast<long>(mpz_sizeinbase(den, 2)));
  if (k >= 0) {
    mpz_mul_2exp(q, num, static_cast<mp_bitcnt_t>(k));
    mpz_tdiv_q(q, q, den);
  } else {
    // trunc(trunc(num / 2^-k) / den) = trunc(num / (2^-k den)): nothing lost.
    mpz_tdiv_q_2exp(q, num, static_cast<mp_bitcnt_t>(-k));
    mpz_tdiv_q(q, q, den);
  }
  // q holds 65 to 67 bits, below the exact quotient by less than one unit
  // of them; mpz_get_d truncates it to 53 (together under 2 ulp), and ldexp
  // scales, rounding once where the result is subnormal (as mpq_get_d did).
  const long e = shift - k;
  const double m = mpz_get_d(q);
  if (e > 2100) return std::copysign(std::numeric_limits<double>::infinity(), m);
  if (e < -2300) return std::copysign(0.0, m);
  return std::ldexp(m, static_cast<int>(e));
}
}  // namespace

void exact_vertex(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, double* y) {
  GridNumerators g;
  if (grid_numerators(ctx, i, planes, g)) {
    for (int d = 0; d < ctx.dim; ++d) y[d] = grid_quotient(g.num[d], g.det, g.shift);
    return;
  }
  thread_local Scratch s;
  const int shift = vertex_numerators(ctx, i, planes, s);
  for (int d = 0; d < ctx.dim; ++d) y[d] = quotient_to_double(s.minor[d], s.minor[ctx.dim], shift, s.t0);
}

void exact_vertex_on_plane(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, int row,
                           const double* n, double d, double* y) {
  const int dim = ctx.dim;
  thread_local Scratch s;
  // The other rows as exact_vertex builds them; build_rows reads a box
  // plane's constant in place of the given row, which is then overwritten.
  std::int32_t ids[Scratch::kMaxDim];
  for (int r = 0; r < dim; ++r) ids[r] = r == row ? box_plane_id(0, false) : planes[r];
  const int shift = build_rows(ctx, i, ids, dim, s);
  // The given row n.y = d, y relative to p_i, reads n.X = (d + n.p_i) 2^-shift
  // in build_rows' integers (x = X 2^shift).
  thread_local struct Rationals {
    mpq_t rhs, t, u;
    Rationals() {
      mpq_init(rhs);
      mpq_init(t);
      mpq_init(u);
    }
    ~Rationals() {
      mpq_clear(rhs);
      mpq_clear(t);
      mpq_clear(u);
    }
  } r;
  const double* pi = ctx.points + static_cast<std::size_t>(i) * static_cast<std::size_t>(dim);
  mpq_set_d(r.rhs, d);
  for (int k = 0; k < dim; ++k) {
    mpq_set_d(r.t, n[k]);
    mpq_set_d(r.u, pi[k]);
    mpq_mul(r.u, r.u, r.t);
    mpq_add(r.rhs, r.rhs, r.u);
  }
  if (shift > 0) mpq_div_2exp(r.rhs, r.rhs, static_cast<mp_bitcnt_t>(shift));
  else if (shift < 0) mpq_mul_2exp(r.rhs, r.rhs, static_cast<mp_bitcnt_t>(-shift));
  exact_rows::set_plane_row(s, row, dim, n, r.rhs);
  cramer_numerators(dim, s);
  for (int c = 0; c < dim; ++c) y[c] = quotient_to_double(s.minor[c], s.minor[dim], shift, s.t0);
}

// ---- The cell measure ----

namespace {
// The distinct planes of a 3D cell's vertices, ascending, each with the first
// vertex on it (dim planes each in `vertex_planes`). The measure's terms find
// their plane here by binary search: a scan per term made the measure
// quadratic in the faces, and the centre of 200,000 sphere points (a
// 200,000-face cell, whose float bound is too loose) took 38 s.
class CellPlanes {
 public:
  void build(std::span<const std::int32_t> vertex_planes, int dim) {
    const auto du = static_cast<std::size_t>(dim);
    entries_.clear();
    for (std::size_t k = 0; k < vertex_planes.size(); ++k)
      entries_.push_back({vertex_planes[k], static_cast<std::uint32_t>(k / du)});
    std::sort(entries_.begin(), entries_.end());  // by plane, then vertex: the first vertex leads
    entries_.erase(std::unique(entries_.begin(), entries_.end(),
                               [](const Entry& x, const Entry& y) { return x.plane == y.plane; }),
                   entries_.end());
  }
  std::size_t size() const { return entries_.size(); }
  /// The plane's place in the ascending list.
  std::size_t slot(std::int32_t plane) const {
    const auto it = std::lower_bound(entries_.begin(), entries_.end(), plane,
                                     [](const Entry& e, std::int32_t p) { return e.plane < p; });
    if (it == entries_.end() || it->plane != plane)
      throw std::logic_error("exact cell measure: a face's plane has no vertex (corrupt cell)");
    return static_cast<std::size_t>(it - entries_.begin());
  }
  /// The first vertex on the plane at `slot`.
  std::size_t first_vertex(std::size_t slot) const { return entries_[slot].vertex; }

 private:
  struct Entry {
    std::int32_t plane;
    std::uint32_t vertex;
    auto operator<=>(const Entry&) const = default;
  };
  std::vector<Entry> entries_;
};
}  // namespace

// In canonical rationals (GMP's mpq): every vertex, term and sum exact, then
// truncated to double. Slow: each operation takes gcds, and the sum's
// denominator grows towards the product of the vertices' determinants (a
// slab cell of 22 vertices and 67 terms: ~2 ms).
double rational_cell_measure(const ExactContext& ctx, std::int32_t i, std::span<const std::int32_t> vertex_planes,
                             std::span<const MeasureTerm> terms, double* centroid) {
  thread_local Scratch s;
  const int dim = ctx.dim;
  const auto du = static_cast<std::size_t>(dim);
  const std::size_t nv = vertex_planes.size() / du;
  // Rationals with RAII: this path is rare (cells the fixed-point tier cannot certify).
  struct Rationals {
    std::vector<__mpq_struct> q;
    explicit Rationals(std::size_t n) : q(n) {
      for (auto& x : q) mpq_init(&x);
    }
    ~Rationals() {
      for (auto& x : q) mpq_clear(&x);
    }
  };
  // The vertices (dim each), then a foot, the weight sum, the moments and
  // three temporaries.
  const std::size_t base = nv * du;
  Rationals r(base + 10);
  auto y = [&](std::size_t v, int d) { return &r.q[v * du + static_cast<std::size_t>(d)]; };
  mpq_ptr foot[3] = {&r.q[base], &r.q[base + 1], &r.q[base + 2]};
  mpq_ptr moment[3] = {&r.q[base + 3], &r.q[base + 4], &r.q[base + 5]};
  mpq_ptr sum = &r.q[base + 6], w = &r.q[base + 7], t0 = &r.q[base + 8], t1 = &r.q[base + 9];
  for (std::size_t v = 0; v < nv; ++v) {
    mpq_ptr yv[Scratch::kMaxDim] = {y(v, 0), y(v, 1), dim == 3 ? y(v, 2) : nullptr};
    solve_vertex_exactly(ctx, i, vertex_planes.data() + v * du, s, yv);
  }
  const double* pi = ctx.points + static_cast<std::size_t>(i) * du;
  thread_local CellPlanes planes;
  if (dim == 3 && (ctx.radii != nullptr || ctx.num_walls > 0)) planes.build(vertex_planes, dim);
  // As measure() in front/cell_geometry.hpp: each term's weight w, summed,
  // and w times the sum of its points (foot and both vertices in 3D, both
  // vertices in 2D) for the centroid.
  mpq_set_ui(sum, 0, 1);
  for (int d = 0; d < dim; ++d) mpq_set_ui(moment[d], 0, 1);
  for (const MeasureTerm& term : terms) {
    for (int d = 0; d < 3; ++d) mpq_set_ui(foot[d], 0, 1);
    if (dim == 2) {  // w = det(y_a, y_b)
      mpq_mul(w, y(term.a, 0), y(term.b, 1));
      mpq_mul(t0, y(term.a, 1), y(term.b, 0));
      mpq_sub(w, w, t0);
    } else {
      // The foot of the plane from p_i: (p_j - p_i) / 2 on a bisector,
      // (bound - p_i) along the axis on a box plane.
      if ((term.plane >= 0 && ctx.radii != nullptr) || is_wall_plane(term.plane)) {
        // A power bisector's or a wall's foot is no simple point; any point of the
        // plane serves (a face's terms sum to its cone whatever point of its
        // plane they share): one of the cell's vertices on it.
        const std::size_t v = planes.first_vertex(planes.slot(term.plane));
        for (int d = 0; d < 3; ++d) mpq_set(foot[d], y(v, d));
      } else if (term.plane >= 0) {
        const double* pj = ctx.points + static_cast<std::size_t>(term.plane) * 3;
        for (int d = 0; d < 3; ++d) {
          mpq_set_d(foot[d], pj[d]);
          mpq_set_d(t0, pi[d]);
          mpq_sub(foot[d], foot[d], t0);
          mpq_div_2exp(foot[d], foot[d], 1);
        }
      } else {
        const auto axis = static_cast<std::size_t>(box_plane_axis(term.plane));
        mpq_set_d(foot[axis], box_plane_upper(term.plane) ? ctx.hi[axis] : ctx.lo[axis]);
        mpq_set_d(t0, pi[axis]);
        mpq_sub(foot[axis], foot[axis], t0);
      }
      mpq_set_ui(w, 0, 1);  // w = foot . (y_a x y_b)
      for (int d = 0; d < 3; ++d) {
        const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
        mpq_mul(t0, y(term.a, d1), y(term.b, d2));
        mpq_mul(t1, y(term.a, d2), y(term.b, d1));
        mpq_sub(t0, t0, t1);
        mpq_mul(t0, t0, foot[d]);
        mpq_add(w, w, t0);
      }
    }
    mpq_add(sum, sum, w);
    for (int d = 0; d < dim; ++d) {
      mpq_add(t0, y(term.a, d), y(term.b, d));
      mpq_add(t0, t0, foot[d]);  // zero in 2D
      mpq_mul(t0, t0, w);
      mpq_add(moment[d], moment[d], t0);
    }
  }
  // Centroid: moment / (4 sum) in 3D (a tetrahedron's is the mean of its
  // corners, one at the origin), moment / (3 sum) in 2D.
  for (int d = 0; d < dim; ++d) {
    if (mpq_sgn(sum) == 0) {
      centroid[d] = 0;
      continue;
    }
    mpq_div(t0, moment[d], sum);
    mpq_set_ui(t1, dim == 2 ? 3 : 4, 1);
    mpq_div(t0, t0, t1);
    centroid[d] = rational_to_double(t0);
  }
  mpq_set_ui(t0, dim == 2 ? 2 : 6, 1);
  mpq_div(sum, sum, t0);
  return rational_to_double(sum);
}

namespace {

// mpz integers reused on one thread across cells (grown, never shrunk): the
// fixed-point measure takes a few per vertex and per term, and GMP's
// allocations would otherwise dominate it.
class IntegerPool {
 public:
  IntegerPool() = default;
  IntegerPool(const IntegerPool&) = delete;
  IntegerPool& operator=(const IntegerPool&) = delete;
  ~IntegerPool() {
    for (auto& x : z_) mpz_clear(&x);
  }
  void reserve(std::size_t n) {
    while (z_.size() < n) {
      z_.emplace_back();
      mpz_init(&z_.back());
    }
  }
  mpz_ptr operator[](std::size_t k) { return &z_[k]; }

 private:
  std::deque<__mpz_struct> z_;  // a deque: growing it never moves an integer
};

long bit_length(mpz_srcptr x) { return static_cast<long>(mpz_sizeinbase(x, 2)); }

// out = trunc(x 2^k); `exact` cleared where that drops a set bit.
void scale_truncated(mpz_ptr out, mpz_srcptr x, long k, bool& exact) {
  if (k >= 0) {
    mpz_mul_2exp(out, x, static_cast<mp_bitcnt_t>(k));
    return;
  }
  // Bits dropped: x has a set bit below 2^-k.
  if (mpz_sgn(x) != 0 && mpz_scan1(x, 0) < static_cast<mp_bitcnt_t>(-k)) exact = false;
  mpz_tdiv_q_2exp(out, x, static_cast<mp_bitcnt_t>(-k));
}

// out = trunc((a - b) 2^k / 2^g) for doubles a, b: their difference exactly
// on their common grid, then truncated to the unit 2^g (`exact` as above).
void difference_truncated(mpz_ptr out, double a, double b, long k, long g, Scratch& s, bool& exact) {
  const int grid = a == 0 ? lowest_bit_exponent(b)
                   : b == 0 ? lowest_bit_exponent(a)
                            : std::min(lowest_bit_exponent(a), lowest_bit_exponent(b));
  exact_rows::set_scaled(s.t0, a, grid);
  exact_rows::set_scaled(s.t1, b, grid);
  mpz_sub(s.t0, s.t0, s.t1);
  scale_truncated(out, s.t0, grid + k - g, exact);
}

// The double nearest to x = n / d * 2^exp (nearest_double: the doubles of
// rational_to_double), where n is known only to lie within 2^hn of `num`,
// and d is c times a number within 2^hd of `den` (den null: d = c exactly).
// False where those intervals leave that double undetermined (they hold
// zero, or straddle a rounding boundary). Out of double's range it is an
// infinity or a signed zero, as rational_to_double gives. (Until stop 72,
// false outside [2^-1000, 2^1000], which sent every cell whose measure
// leaves double's range to the rationals: 300 points spread over
// 1e-300..1e280 took 20 s, ~60 ms a cell. Until stop 73 the doubles were
// truncated, and a measure that is exactly a double could never be
// certified.) Rounding is monotone, so when both ends of x's interval round
// alike, x does too. hn = -1 (and hd = -1, or den null) says n (and d) is
// exact: x is then rounded exactly. `z[at..at+5)` is scratch.
bool certain_quotient(mpz_srcptr num, long hn, mpz_srcptr den, long hd, unsigned long c, long exp, IntegerPool& z,
                      std::size_t at, double& out) {
  mpz_ptr lo = z[at], hi = z[at + 1], dlo = z[at + 2], dhi = z[at + 3], h = z[at + 4];
  if (hn < 0 && (den == nullptr || hd < 0)) {
    // Exact (hn, hd = -1: no truncation lost a bit): x rounded from its own
    // quotient and remainder, a tie included (the averages that bisectors
    // take make exact midpoints between doubles common: a cell bounded by
    // the bisector of 0.3 and 0.7 has volume 0.5 - 2^-55).
    if (den == nullptr) mpz_set_ui(dlo, c);
    else mpz_mul_ui(dlo, den, c);
    if (mpz_sgn(dlo) <= 0) return false;  // a zero sum: the rationals' convention
    const int sign = mpz_sgn(num);
    if (sign == 0) {
      out = 0.0;
      return true;
    }
    mpz_abs(lo, num);
    const long k = 72 + bit_length(dlo) - bit_length(lo);
    if (k > 0) mpz_mul_2exp(lo, lo, static_cast<mp_bitcnt_t>(k));
    else if (k < 0) mpz_mul_2exp(dlo, dlo, static_cast<mp_bitcnt_t>(-k));
    mpz_tdiv_qr(hi, dhi, lo, dlo);
    out = nearest_double(hi, mpz_sgn(dhi) != 0, k - exp, sign, lo, h);
    return true;
  }
  mpz_set_ui(h, 1);
  mpz_mul_2exp(h, h, static_cast<mp_bitcnt_t>(hn));
  mpz_sub(lo, num, h);
  mpz_add(hi, num, h);
  const int sign = mpz_sgn(lo);
  if (sign == 0 || mpz_sgn(hi) != sign) return false;  // n may be zero
  if (den != nullptr) {
    mpz_set_ui(h, 1);
    mpz_mul_2exp(h, h, static_cast<mp_bitcnt_t>(hd));
    mpz_sub(dlo, den, h);
    mpz_add(dhi, den, h);
    if (mpz_sgn(dlo) <= 0) return false;
    mpz_mul_ui(dlo, dlo, c);
    mpz_mul_ui(dhi, dhi, c);
  } else {
    mpz_set_ui(dlo, c);
    mpz_set_ui(dhi, c);
  }
  // Quotients of some 72 bits: enough for rounding to 53 to agree at both
  // ends whenever x's interval is narrow.
  const long k = 72 + bit_length(dhi) - bit_length(num);
  if (k > 0) {
    mpz_mul_2exp(lo, lo, static_cast<mp_bitcnt_t>(k));
    mpz_mul_2exp(hi, hi, static_cast<mp_bitcnt_t>(k));
  } else if (k < 0) {
    mpz_mul_2exp(dlo, dlo, static_cast<mp_bitcnt_t>(-k));
    mpz_mul_2exp(dhi, dhi, static_cast<mp_bitcnt_t>(-k));
  }
  // x 2^(k - exp) lies in [floor(lo / d_far), ceil(hi / d_near)], the
  // denominators' ends taken by the numerator's sign.
  if (sign > 0) {
    mpz_fdiv_q(lo, lo, dhi);
    mpz_cdiv_q(hi, hi, dlo);
  } else {
    mpz_fdiv_q(lo, lo, dlo);
    mpz_cdiv_q(hi, hi, dhi);
  }
  // |x| 2^(k - exp) lies in [mag_lo, mag_hi].
  mpz_ptr mag_lo = lo, mag_hi = hi;
  if (sign < 0) {
    mpz_neg(lo, lo);
    mpz_neg(hi, hi);
    std::swap(mag_lo, mag_hi);
  }
  if (mpz_sizeinbase(mag_lo, 2) < 54 || mpz_sgn(mag_lo) <= 0) return false;  // an interval that wide decides nothing
  const double low = nearest_double(mag_lo, false, k - exp, sign, dlo, h);
  const double high = nearest_double(mag_hi, false, k - exp, sign, dhi, h);
  if (low != high) return false;
  out = low;
  return true;
}

}  // namespace

// Every vertex solved exactly (Cramer's numerators and determinant,
// vertex_numerators), then truncated to an integer multiple of a unit 2^g
// set `bits` bits below the largest coordinate; the feet likewise; the
// terms and moments of measure() (front/cell_geometry.hpp) summed in
// integers, exactly. Each truncation is off by under one unit, which bounds
// the sums' errors (the derivation at the bounds below); certain_quotient
// then certifies the doubles, or finds them undetermined. A slab cell's
// measure, 22 vertices and 67 terms, takes ~0.1 ms here against ~2 ms in
// rationals, whose gcds on ever-larger denominators were the whole cost of
// a chain of near copies (5,000 points: 6 s).
bool fixed_point_cell_measure(const ExactContext& ctx, std::int32_t i, std::span<const std::int32_t> vertex_planes,
                              std::span<const MeasureTerm> terms, long bits, double& volume, double* centroid,
                              long* wanted) {
  thread_local Scratch s;
  thread_local IntegerPool z;
  thread_local std::vector<long> shift;
  const int dim = ctx.dim;
  const auto du = static_cast<std::size_t>(dim);
  const std::size_t nv = vertex_planes.size() / du;
  if (nv == 0) return false;
  // Per vertex: its Cramer numerators and determinant, then its fixed-point
  // coordinates. After them: a term, the sums, certain_quotient's five
  // scratch integers, then the feet (3D: three per plane, at its slot).
  thread_local CellPlanes planes;
  if (dim == 3) planes.build(vertex_planes, dim);
  const std::size_t per = 2 * du + 1;
  const std::size_t base = nv * per, spare = base + 6, feet = base + 11;
  z.reserve(feet + (dim == 3 ? 3 * planes.size() : 0));
  auto num = [&](std::size_t v, std::size_t d) { return z[v * per + d]; };  // d = dim: the determinant
  auto fixed = [&](std::size_t v, std::size_t d) { return z[v * per + du + 1 + d]; };
  mpz_ptr w = z[base], sum = z[base + 1], t0 = z[base + 2];
  mpz_ptr moment[3] = {z[base + 3], z[base + 4], z[base + 5]};

  // Whether every truncation to fixed point below was exact (a cell whose
  // vertices and feet lie on the grid of 2^g: dyadic coordinates, such as
  // the bisectors of doubles and box planes): the sums are then exact too.
  bool exact = true;
  shift.resize(nv);
  long top = std::numeric_limits<long>::min();  // |every coordinate| < 2^top
  for (std::size_t v = 0; v < nv; ++v) {
    shift[v] = vertex_numerators(ctx, i, vertex_planes.data() + v * du, s);
    const long det_bits = bit_length(s.minor[dim]);
    for (std::size_t d = 0; d <= du; ++d) mpz_set(num(v, d), s.minor[d]);
    for (std::size_t d = 0; d < du; ++d) top = std::max(top, bit_length(s.minor[d]) - det_bits + 1 + shift[v]);
  }
  // The unit. A foot lies no farther from p_i than the vertices of its face,
  // so its coordinates stay below sqrt(3) 2^top.
  const long g = top - bits;
  for (std::size_t v = 0; v < nv; ++v)
    for (std::size_t d = 0; d < du; ++d) {
      // trunc(trunc(n 2^k) / det) = trunc(n 2^k / det) for k < 0 as well.
      scale_truncated(fixed(v, d), num(v, d), shift[v] - g, exact);
      mpz_tdiv_qr(fixed(v, d), t0, fixed(v, d), num(v, du));
      if (mpz_sgn(t0) != 0) exact = false;
    }

  const double* pi = ctx.points + static_cast<std::size_t>(i) * du;
  // A plane's foot in fixed point, computed once per plane, at its slot:
  // (p_j - p_i) / 2 on a bisector, (bound - p_i) along the axis on a box
  // plane. A cell has a few dozen planes, each in many terms.
  thread_local std::vector<char> have_foot;
  have_foot.assign(dim == 3 ? planes.size() : 0, 0);
  auto foot_of = [&](std::int32_t plane) {
    const std::size_t k = planes.slot(plane);
    mpz_ptr f[3] = {z[feet + 3 * k], z[feet + 3 * k + 1], z[feet + 3 * k + 2]};
    if (!have_foot[k]) {
      have_foot[k] = 1;
      if ((plane >= 0 && ctx.radii != nullptr) || is_wall_plane(plane)) {
        // A power bisector's or a wall's: one of the cell's vertices on the plane
        // (rational_cell_measure). Truncated as every vertex is, it lies
        // within one unit of a point of the plane, as a truncated foot does,
        // and below 2^(bits + 1): the bounds below hold.
        const std::size_t v = planes.first_vertex(k);
        for (std::size_t d = 0; d < 3; ++d) mpz_set(f[d], fixed(v, d));
      } else if (plane >= 0) {
        const double* pj = ctx.points + static_cast<std::size_t>(plane) * 3;
        for (int d = 0; d < 3; ++d) difference_truncated(f[d], pj[d], pi[d], -1, g, s, exact);
      } else {
        const int axis = box_plane_axis(plane);
        for (int d = 0; d < 3; ++d) mpz_set_ui(f[d], 0);
        difference_truncated(f[axis], box_plane_upper(plane) ? ctx.hi[axis] : ctx.lo[axis], pi[axis], 0, g, s, exact);
      }
    }
    return feet + 3 * k;
  };
  mpz_set_ui(sum, 0);
  for (std::size_t d = 0; d < du; ++d) mpz_set_ui(moment[d], 0);
  mpz_ptr foot[3] = {};
  for (const MeasureTerm& term : terms) {
    if (dim == 2) {  // w = det(y_a, y_b)
      mpz_mul(w, fixed(term.a, 0), fixed(term.b, 1));
      mpz_submul(w, fixed(term.a, 1), fixed(term.b, 0));
    } else {
      const std::size_t f = foot_of(term.plane);
      for (std::size_t d = 0; d < 3; ++d) foot[d] = z[f + d];
      mpz_set_ui(w, 0);  // w = foot . (y_a x y_b)
      for (int d = 0; d < 3; ++d) {
        const std::size_t d1 = static_cast<std::size_t>((d + 1) % 3), d2 = static_cast<std::size_t>((d + 2) % 3);
        mpz_mul(t0, fixed(term.a, d1), fixed(term.b, d2));
        mpz_submul(t0, fixed(term.a, d2), fixed(term.b, d1));
        mpz_addmul(w, t0, foot[d]);
      }
    }
    mpz_add(sum, sum, w);
    for (std::size_t d = 0; d < du; ++d) {
      mpz_add(t0, fixed(term.a, d), fixed(term.b, d));
      if (dim == 3) mpz_add(t0, t0, foot[d]);
      mpz_addmul(moment[d], t0, w);
    }
  }

  // Error bounds, in units 2^(D g) for the sum and 2^((D + 1) g) for the
  // moments. Every fixed coordinate and foot is below 2^(bits + 1), and its
  // true value within one unit, so both lie within M = 2^(bits + 2). With
  // a, b perturbed by under 1 each, a b moves by under 2M + 1. In 3D a
  // cross product's coordinate moves by under 4M + 2 and is at most 2M^2,
  // so a term (the foot's dot product) moves by under 3 (2M^2 + M (4M + 2)
  // + 4M + 2) <= 32 M^2 and is at most 6 M^3; its moment (the term times a
  // sum s of three coordinates, |s| <= 3M, moved by under 3) by under
  // 6M^3 3 + 32M^2 3M + 32M^2 3 <= 128 M^3. In 2D a term moves by under
  // 2 (2M + 1) <= 8M and is at most 2M^2; its moment (s of two) by under
  // 2M^2 2 + 8M 2M + 8M 2 <= 32 M^2. Summed over n terms.
  const long terms_bits = static_cast<long>(std::bit_width(terms.size()));  // n <= 2^terms_bits
  const long m = bits + 2;
  const long sum_error = dim == 3 ? terms_bits + 5 + 2 * m : terms_bits + 3 + m;
  const long moment_error = dim == 3 ? terms_bits + 7 + 3 * m : terms_bits + 5 + 2 * m;
  // Volume = sum 2^(D g) / (6 or 2); centroid = moment 2^((D + 1) g) / ((4
  // or 3) sum 2^(D g)), as in rational_measure.
  const long sum_h = exact ? -1 : sum_error, moment_h = exact ? -1 : moment_error;
  bool sure = certain_quotient(sum, sum_h, nullptr, 0, dim == 3 ? 6 : 2, dim * g, z, spare, volume);
  for (std::size_t d = 0; sure && d < du; ++d)
    sure = certain_quotient(moment[d], moment_h, sum, sum_h, dim == 3 ? 4 : 3, g, z, spare, centroid[d]);
  if (!sure && wanted != nullptr) {
    // The bits that should certify them: each bit more adds one to every
    // margin (the sum grows by 2^D, its error bound by 2^(D - 1); the
    // moments by 2^(D + 1) and 2^D), and a margin of 80 bits leaves the
    // interval under 2^-79 of its value. A sum or moment that came out
    // zero gives no measure of what it lacks: twice the bits.
    long deficit = 80 - (bit_length(sum) - sum_error);
    bool zero = mpz_sgn(sum) == 0;
    for (std::size_t d = 0; d < du; ++d) {
      deficit = std::max(deficit, 80 - (bit_length(moment[d]) - moment_error));
      zero |= mpz_sgn(moment[d]) == 0;
    }
    *wanted = zero ? 2 * bits : bits + std::max(deficit, 16L);
  }
  return sure;
}

double exact_cell_measure(const ExactContext& ctx, std::int32_t i, std::span<const std::int32_t> vertex_planes,
                          std::span<const MeasureTerm> terms, double* centroid) {
  // 200 bits certify a cell whose volume is down to ~2^-80 of its largest
  // coordinate cubed and whose centroid is not far nearer its generator
  // than that. A cell that needs more gets a second try with the bits the
  // first found wanting (a slab in a cluster of points a few ulps apart:
  // ~250), and the thread's next cell starts from those (its neighbours
  // are alike), drifting back towards 200 while they suffice; the doubles
  // are the same whatever the bits. The rational path serves zero centroid
  // coordinates, quantities that are exactly doubles (the centroid of a
  // prism spanning the box: no interval certifies them), and cancellation
  // beyond 4,000 bits. (The start is kept even where the second try failed:
  // tried in stop 72, restoring it made such inputs 10-40% slower.)
  constexpr long least = 200, most = 4000;
  thread_local long start = least;
  double volume;
  long wanted = 0;
  if (fixed_point_cell_measure(ctx, i, vertex_planes, terms, start, volume, centroid, &wanted)) {
    start = std::max(least, start - 8);
    return volume;
  }
  if (wanted > 0 && wanted <= most) {
    start = wanted;
    if (fixed_point_cell_measure(ctx, i, vertex_planes, terms, wanted, volume, centroid)) return volume;
  }
  return rational_cell_measure(ctx, i, vertex_planes, terms, centroid);
}

}  // namespace tessera::kernels
