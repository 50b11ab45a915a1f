// Exact evaluation of the clip predicate; see exact_predicates.hpp for the math.
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/box_ties.hpp"
#include "tessera/kernels/expansion.hpp"
#include "exact_rows.hpp"

#include <gmp.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <limits>
#include <cmath>
#include <span>
#include <stdexcept>
#include <vector>

namespace tessera::kernels {

namespace exact_rows {

// The integer rows (contracts in exact_rows.hpp).

void set_scaled(mpz_t out, double x, int shift) {
  if (x == 0) { mpz_set_ui(out, 0); return; }
  int e;
  double f = std::frexp(x, &e);
  // f * 2^53 is an exact integer (|f| < 1 has at most 53 significant bits).
  mpz_set_d(out, std::ldexp(f, 53));
  int s = e - 53 - shift;
  if (s > 0) mpz_mul_2exp(out, out, static_cast<mp_bitcnt_t>(s));
  else if (s < 0) mpz_tdiv_q_2exp(out, out, static_cast<mp_bitcnt_t>(-s));  // exact: those bits are zero
}

void det_rows(mpz_t out, mpz_t (*a)[Scratch::kMaxDim], const int* rows, int k, Scratch& s) {
  if (k == 2) {
    mpz_mul(s.t0, a[rows[0]][0], a[rows[1]][1]);
    mpz_submul(s.t0, a[rows[0]][1], a[rows[1]][0]);
    mpz_set(out, s.t0);
    return;
  }
  // 3x3 by cofactors along the first row.
  auto& r0 = a[rows[0]];
  auto& r1 = a[rows[1]];
  auto& r2 = a[rows[2]];
  mpz_set_ui(s.acc, 0);
  mpz_mul(s.t0, r1[1], r2[2]); mpz_submul(s.t0, r1[2], r2[1]); mpz_addmul(s.acc, r0[0], s.t0);
  mpz_mul(s.t0, r1[2], r2[0]); mpz_submul(s.t0, r1[0], r2[2]); mpz_addmul(s.acc, r0[1], s.t0);
  mpz_mul(s.t0, r1[0], r2[1]); mpz_submul(s.t0, r1[1], r2[0]); mpz_addmul(s.acc, r0[2], s.t0);
  mpz_set(out, s.acc);
}

int build_rows(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, int rows, Scratch& s) {
  const int dim = ctx.dim;

  // Common scale: the smallest mantissa lsb among all doubles involved.
  GridScale grid;
  const double* pi = ctx.points + static_cast<std::size_t>(i) * dim;
  for (int d = 0; d < dim; ++d) grid.see(pi[d]);
  for (int r = 0; r < rows; ++r) {
    if (gen[r] >= 0) {
      const double* pk = ctx.points + static_cast<std::size_t>(gen[r]) * dim;
      for (int d = 0; d < dim; ++d) grid.see(pk[d]);
    } else if (!is_wall_plane(gen[r])) {  // a wall's row is cleared of its own denominators below
      int axis = box_plane_axis(gen[r]);
      grid.see(box_plane_upper(gen[r]) ? ctx.hi[axis] : ctx.lo[axis]);
    }
  }
  // The radii join the grid: their squares enter b with the coordinates'.
  if (ctx.radii != nullptr) {
    grid.see(ctx.radii[i]);
    for (int r = 0; r < rows; ++r)
      if (gen[r] >= 0) grid.see(ctx.radii[gen[r]]);
  }
  const int shift = grid.scale();

  // Scaled p_i and |p_i|^2.
  mpz_t* ci = s.coord[Scratch::kRows];
  for (int d = 0; d < dim; ++d) set_scaled(ci[d], pi[d], shift);
  mpz_set_ui(s.t1, 0);
  for (int d = 0; d < dim; ++d) mpz_addmul(s.t1, ci[d], ci[d]);  // t1 = |p_i|^2
  if (ctx.radii != nullptr) {  // t1 = |p_i|^2 - r_i^2: the row's constant is p_k's power less p_i's
    set_scaled(s.t2, ctx.radii[i], shift);
    mpz_submul(s.t1, s.t2, s.t2);
  }

  // Build M = [a | b] row by row.
  for (int r = 0; r < rows; ++r) {
    if (gen[r] >= 0) {
      const double* pk = ctx.points + static_cast<std::size_t>(gen[r]) * dim;
      mpz_set_ui(s.b[r], 0);
      for (int d = 0; d < dim; ++d) {
        set_scaled(s.coord[r][d], pk[d], shift);
        mpz_sub(s.a[r][d], s.coord[r][d], ci[d]);
        mpz_mul_2exp(s.a[r][d], s.a[r][d], 1);          // 2 (p_k - p_i)
        mpz_addmul(s.b[r], s.coord[r][d], s.coord[r][d]);
      }
      if (ctx.radii != nullptr) {
        set_scaled(s.t2, ctx.radii[gen[r]], shift);
        mpz_submul(s.b[r], s.t2, s.t2);                   // - r_k^2
      }
      mpz_sub(s.b[r], s.b[r], s.t1);                      // |p_k|^2 - |p_i|^2 (- r_k^2 + r_i^2)
    } else if (is_wall_plane(gen[r])) {
      // n.x = d reads n.X = d 2^-shift in these integers (x = X 2^shift).
      const Wall& w = ctx.walls[wall_index(gen[r])];
      thread_local struct Rhs {
        mpq_t q;
        Rhs() { mpq_init(q); }
        ~Rhs() { mpq_clear(q); }
      } rhs;
      mpq_set_d(rhs.q, w.d);
      if (shift > 0) mpq_div_2exp(rhs.q, rhs.q, static_cast<mp_bitcnt_t>(shift));
      else if (shift < 0) mpq_mul_2exp(rhs.q, rhs.q, static_cast<mp_bitcnt_t>(-shift));
      set_plane_row(s, r, dim, w.n, rhs.q);
    } else {
      int axis = box_plane_axis(gen[r]);
      for (int d = 0; d < dim; ++d) mpz_set_ui(s.a[r][d], d == axis ? 1 : 0);
      set_scaled(s.b[r], box_plane_upper(gen[r]) ? ctx.hi[axis] : ctx.lo[axis], shift);
    }
  }

  return shift;
}

void set_plane_row(Scratch& s, int row, int dim, const double* n, mpq_srcptr rhs) {
  thread_local struct Rationals {
    mpq_t v[Scratch::kMaxDim];
    Rationals() {
      for (auto& q : v) mpq_init(q);
    }
    ~Rationals() {
      for (auto& q : v) mpq_clear(q);
    }
  } r;
  for (int k = 0; k < dim; ++k) mpq_set_d(r.v[k], n[k]);
  // Every value is canonical with a power of two below: the largest clears them all.
  auto den_exponent = [](mpq_srcptr q) { return mpz_sizeinbase(mpq_denref(q), 2) - 1; };
  std::size_t top = den_exponent(rhs);
  for (int k = 0; k < dim; ++k) top = std::max(top, den_exponent(r.v[k]));
  for (int k = 0; k < dim; ++k)
    mpz_mul_2exp(s.a[row][k], mpq_numref(r.v[k]), top - den_exponent(r.v[k]));
  mpz_mul_2exp(s.b[row], mpq_numref(rhs), top - den_exponent(rhs));
}

void row_parts(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, int rows, DoubleParts (*pv)[3],
               GridScale& span) {
  const int dim = ctx.dim;
  const double* pi = ctx.points + static_cast<std::size_t>(i) * dim;
  for (int d = 0; d < dim; ++d) pv[rows][d] = span.see(pi[d]);
  for (int r = 0; r < rows; ++r) {
    if (gen[r] >= 0) {
      const double* pk = ctx.points + static_cast<std::size_t>(gen[r]) * dim;
      for (int d = 0; d < dim; ++d) pv[r][d] = span.see(pk[d]);
    } else {
      const int axis = box_plane_axis(gen[r]);
      pv[r][0] = span.see(box_plane_upper(gen[r]) ? ctx.hi[axis] : ctx.lo[axis]);
    }
  }
}

}  // namespace exact_rows

using exact_rows::on_grid;
using exact_rows::row_parts;
using exact_rows::Scratch;
using exact_rows::build_rows;
using exact_rows::det_rows;
using exact_rows::set_scaled;

namespace {

// What the decision needs from M = [[A, b], [a_j, b_j]]: the sign of det M0
// (weights zero), of each minor of the rows x dim block without row r (the
// last-column cofactor of row r is (-1)^(r+dim) * minor[r]; det A = minor[dim]),
// and of w_i's coefficient (the sum of the bisector rows' cofactors).
struct ClipSigns {
  int det_m0 = 0;
  int minor[Scratch::kRows] = {0, 0, 0, 0};
  int weight_i = 0;
};

int cofactor_sign(int r, int dim) { return ((r + dim) & 1) == 0 ? 1 : -1; }

// Exact signs in GMP integers: any input.
void signs_gmp(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, ClipSigns& out) {
  thread_local Scratch s;
  const int dim = ctx.dim, rows = dim + 1;
  build_rows(ctx, i, gen, rows, s);
  for (int r = 0; r < rows; ++r) {
    int sel[Scratch::kMaxDim] = {0, 0, 0};
    int k = 0;
    for (int q = 0; q < rows; ++q) if (q != r) sel[k++] = q;
    det_rows(s.minor[r], s.a, sel, dim, s);
    out.minor[r] = mpz_sgn(s.minor[r]);
  }
  mpz_set_ui(s.t2, 0);
  for (int r = 0; r < rows; ++r) {
    if (cofactor_sign(r, dim) > 0) mpz_addmul(s.t2, s.b[r], s.minor[r]);
    else mpz_submul(s.t2, s.b[r], s.minor[r]);
  }
  out.det_m0 = mpz_sgn(s.t2);
  mpz_set_ui(s.t2, 0);
  for (int r = 0; r < rows; ++r) {
    if (gen[r] < 0) continue;
    if (cofactor_sign(r, dim) > 0) mpz_add(s.t2, s.t2, s.minor[r]);
    else mpz_sub(s.t2, s.t2, s.minor[r]);
  }
  out.weight_i = mpz_sgn(s.t2);
}

// The signs from M's integer rows a (D + 1 rows of D entries) and b: the
// minors in Minor, det M0 and w_i's coefficient in Sum, each wide enough for
// the caller's bounds.
template <int D, class Minor, class Sum>
void signs_from_rows(const std::int64_t (*a)[3], const std::int64_t* b, const std::int32_t* gen, ClipSigns& out) {
  Sum m0 = 0, wi = 0;
  for (int r = 0; r <= D; ++r) {
    // The rows other than r, in order.
    const std::int64_t* u = a[r == 0 ? 1 : 0];
    const std::int64_t* v = a[r <= 1 ? 2 : 1];
    Minor minor;
    if constexpr (D == 2) {
      minor = static_cast<Minor>(u[0]) * v[1] - static_cast<Minor>(u[1]) * v[0];
    } else {
      const std::int64_t* w = a[r <= 2 ? 3 : 2];
      minor = u[0] * (static_cast<Minor>(v[1]) * w[2] - static_cast<Minor>(v[2]) * w[1]) +
              u[1] * (static_cast<Minor>(v[2]) * w[0] - static_cast<Minor>(v[0]) * w[2]) +
              u[2] * (static_cast<Minor>(v[0]) * w[1] - static_cast<Minor>(v[1]) * w[0]);
    }
    out.minor[r] = (minor > 0) - (minor < 0);
    const Sum cof = cofactor_sign(r, D) * static_cast<Sum>(minor);
    m0 += b[r] * cof;
    if (gen[r] >= 0) wi += cof;
  }
  out.det_m0 = (m0 > 0) - (m0 < 0);
  out.weight_i = (wi > 0) - (wi < 0);
}

// The same in 128-bit integers when every scaled coordinate has at most 22
// bits (lattices, voxel centres, integer and dyadic grids: where ties are
// common). Bounds: |a| < 2^24, |b| < 2^46, 3x3 minors < 2^(3*24+3), det M0 <
// 2^(46+75+2) < 2^127. Returns false when the input does not fit.
bool signs_int128(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, ClipSigns& out) {
  using I = __int128;
  const int dim = ctx.dim, rows = dim + 1;
  if (dim != 2 && dim != 3) return false;
  constexpr int kBits = 22;
  // Each double by its bits (double_parts), and the common scale.
  DoubleParts pv[Scratch::kRows + 1][Scratch::kMaxDim];
  GridScale span;
  row_parts(ctx, i, gen, rows, pv, span);
  if (!span.fits(kBits)) return false;
  const int shift = span.scale();
  auto scaled_p = [&](const DoubleParts& pt) { return on_grid(pt, shift); };
  std::int64_t ci[Scratch::kMaxDim];
  I ci2 = 0;
  for (int d = 0; d < dim; ++d) {
    ci[d] = scaled_p(pv[rows][d]);
    ci2 += static_cast<I>(ci[d]) * ci[d];
  }
  std::int64_t a[Scratch::kRows][Scratch::kMaxDim], b[Scratch::kRows];
  for (int r = 0; r < rows; ++r) {
    if (gen[r] >= 0) {
      I sq = 0;
      for (int d = 0; d < dim; ++d) {
        std::int64_t x = scaled_p(pv[r][d]);
        a[r][d] = 2 * (x - ci[d]);
        sq += static_cast<I>(x) * x;
      }
      b[r] = static_cast<std::int64_t>(sq - ci2);
    } else {
      int axis = box_plane_axis(gen[r]);
      for (int d = 0; d < dim; ++d) a[r][d] = d == axis ? 1 : 0;
      b[r] = scaled_p(pv[r][0]);
    }
  }
  // The minors in 64 bits when the coordinates have at most 17 bits (|a| <
  // 2^19, a 3x3 minor < 6 * 2^57 < 2^60: small lattices and voxel grids,
  // where this path runs for most clips), else in 128.
  const bool small = span.fits(17);
  if (dim == 3) small ? signs_from_rows<3, std::int64_t, I>(a, b, gen, out) : signs_from_rows<3, I, I>(a, b, gen, out);
  else small ? signs_from_rows<2, std::int64_t, I>(a, b, gen, out) : signs_from_rows<2, I, I>(a, b, gen, out);
  return true;
}

// Below this many grid steps from p_i in every coordinate, a vertex's rows
// and a candidate's fit the 64-bit forms: |a| < 2^11, 3x3 minors and A's
// cofactors along a row < 6 * 2^33, a bisector row's b < 2^22, a box row's
// < 2^23, so det M0 (four products of a b with a minor) < 2^61.
constexpr std::int64_t kNarrowLimit = std::int64_t{1} << 10;

// Row (a, b) of a vertex's system for generator or box id `id` on the global
// grid (ExactContext::grid), relative to p_i at grid point c (translating the
// vertex leaves det M and its minors as they are): a bisector row (2q, |q|^2)
// with q = p_id - p_i, a box row (e_axis, c_box - p_i). Grid integers lie
// below 2^22, so |q| < 2^23 and |b| < 3 * 2^46. Returns whether every |q_d|
// is below kNarrowLimit (a box row: true). Inlined: as a call, the lattice
// cells' queries ran 6% slower.
template <int D>
[[gnu::always_inline]] inline bool grid_row(const ExactContext& ctx, const std::int64_t* c, std::int32_t id, std::int64_t* a,
                                             std::int64_t& b) {
  if (id < 0) {
    const int axis = box_plane_axis(id);
    const auto ax = static_cast<std::size_t>(axis);
    for (int d = 0; d < D; ++d) a[d] = d == axis;
    b = (box_plane_upper(id) ? ctx.grid_hi[ax] : ctx.grid_lo[ax]) - c[axis];
    return true;
  }
  const std::int32_t* g = ctx.grid + static_cast<std::size_t>(id) * D;
  bool near = true;
  b = 0;
  for (int d = 0; d < D; ++d) {
    const std::int64_t q = std::int64_t{g[d]} - c[d];
    near &= q > -kNarrowLimit && q < kNarrowLimit;
    a[d] = 2 * q;
    b += q * q;
  }
  return near;
}

// signs_int128 on the global grid: the rows read as integers instead of
// decoded from the doubles (grid_row). 3x3 minors < 6 * 2^72 and det M0 <
// 4 * 2^48 * 2^75 < 2^126 in 128 bits; within kNarrowLimit, all in 64.
template <int D>
void signs_on_grid(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, ClipSigns& out) {
  const std::int32_t* gi = ctx.grid + static_cast<std::size_t>(i) * D;
  std::int64_t c[D], a[D + 1][3], b[D + 1];
  for (int d = 0; d < D; ++d) c[d] = gi[d];
  bool near = true;
  for (int r = 0; r <= D; ++r) near &= grid_row<D>(ctx, c, gen[r], a[r], b[r]);
  if (near) signs_from_rows<D, std::int64_t, std::int64_t>(a, b, gen, out);
  else signs_from_rows<D, __int128, __int128>(a, b, gen, out);
}

}  // namespace

namespace {

// sign(P) from the signs of det M0, the minors and w_i's coefficient, with
// the symbolic perturbation deciding exact ties. gen[0..dim] are the rows'
// generators (the query row last).
int decide(const ClipSigns& sg, std::int32_t i, const std::int32_t* gen, int dim) {
  // det A = minor[dim]; it is never zero for a real vertex.
  const int sign_det_a = sg.minor[dim];
  if (sign_det_a == 0)
    throw std::logic_error("exact_clip_sign: vertex planes are dependent (corrupt cell)");
  int sign_m = sg.det_m0;
  if (sign_m == 0) {
    // Exact tie: the perturbation decides. det M(w) = det M0 + sum over
    // bisector rows r of (w_i - w_gen[r]) * cofactor(r). Coefficient of
    // w_gen[r] is -cofactor(r); of w_i it is the sum of those cofactors;
    // of w_j (the query row, last) -det A.
    PerturbationTerms terms;
    terms.set(i, gen, dim);
    sign_m = terms.decide(gen[dim], -sign_det_a, [&](int row) {
      return row < 0 ? sg.weight_i : -cofactor_sign(row, dim) * sg.minor[row];
    });
  }
  // sign(P) = sign(det M) * sign(det A); P > 0 keeps the vertex.
  return sign_m * sign_det_a > 0 ? +1 : -1;
}

template <class T>
int sign_of(T x) { return (x > 0) - (x < 0); }

}  // namespace

int exact_clip_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t j) {
  if (ctx.radii != nullptr) return exact_clip_sign_by_arithmetic(ctx, i, planes, j);  // no box-tie pattern with radii
  // A tie at the corners of an axis-aligned box (lattices, voxel centres of
  // any spacing) is decided by the coordinates' pattern; anything else fails
  // that test within a few comparisons.
  if (int s; ctx.dim == 3 ? box_tie_sign<3>(ctx, i, planes, j, s) : box_tie_sign<2>(ctx, i, planes, j, s)) return s;
  return exact_clip_sign_by_arithmetic(ctx, i, planes, j);
}

int exact_clip_sign_by_arithmetic(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t j) {
  const int dim = ctx.dim;
  // Row r's generator (or box id); the query row is last.
  std::int32_t gen[Scratch::kRows];
  for (int r = 0; r < dim; ++r) gen[r] = planes[r];
  gen[dim] = j;
  ClipSigns sg;
  if (ctx.radii != nullptr) {  // the integer stages know no radii
    signs_gmp(ctx, i, gen, sg);
    return decide(sg, i, gen, dim);
  }
  if (ctx.grid != nullptr) {
    if (dim == 3) signs_on_grid<3>(ctx, i, gen, sg);
    else signs_on_grid<2>(ctx, i, gen, sg);
    return decide(sg, i, gen, dim);
  }
  if (signs_int128(ctx, i, gen, sg)) return decide(sg, i, gen, dim);
  WidePredicate wide;
  int s;
  if (wide.prepare(ctx, i, planes, j) && wide.sign_on_grid(ctx, j, s)) return s;
  signs_gmp(ctx, i, gen, sg);
  return decide(sg, i, gen, dim);
}

double exact_power_offset(const ExactContext& ctx, std::int32_t i, std::int32_t j) {
  thread_local Scratch s;
  const int dim = ctx.dim;
  const double* pi = ctx.points + static_cast<std::size_t>(i) * dim;
  const double* pj = ctx.points + static_cast<std::size_t>(j) * dim;
  const double ri = ctx.radii != nullptr ? ctx.radii[i] : 0.0, rj = ctx.radii != nullptr ? ctx.radii[j] : 0.0;
  GridScale grid;
  for (int d = 0; d < dim; ++d) {
    grid.see(pi[d]);
    grid.see(pj[d]);
  }
  grid.see(ri);
  grid.see(rj);
  const int shift = grid.scale();
  // 2d / 2^(2 shift) = sum_d (P_j - P_i)^2 + R_i^2 - R_j^2, in integers.
  mpz_set_ui(s.acc, 0);
  for (int d = 0; d < dim; ++d) {
    set_scaled(s.t0, pj[d], shift);
    set_scaled(s.t1, pi[d], shift);
    mpz_sub(s.t0, s.t0, s.t1);
    mpz_addmul(s.acc, s.t0, s.t0);
  }
  set_scaled(s.t0, ri, shift);
  mpz_addmul(s.acc, s.t0, s.t0);
  set_scaled(s.t0, rj, shift);
  mpz_submul(s.acc, s.t0, s.t0);
  if (mpz_sgn(s.acc) == 0) return 0.0;
  // mpz_get_d_2exp truncates to 53 bits (toward zero); ldexp then scales.
  long e = 0;
  const double m = mpz_get_d_2exp(&e, s.acc);
  const long total = e + 2L * shift - 1;
  if (total > 2000) return std::copysign(std::numeric_limits<double>::infinity(), m);
  if (total < -2000) return std::copysign(0.0, m);
  return std::ldexp(m, static_cast<int>(total));
}

int exact_ray_side(const ExactContext& ctx, std::int32_t i, std::int32_t a, std::int32_t b, const double* n) {
  thread_local Scratch s;
  // Rows 0 and 1: 2 (p_a - p_i) and 2 (p_b - p_i) on their common grid. n on
  // its own grid as row 2: a positive scale changes no sign.
  const std::int32_t gen[2] = {a, b};
  build_rows(ctx, i, gen, 2, s);
  GridScale grid;
  for (int d = 0; d < 3; ++d) grid.see(n[d]);
  const int shift = grid.scale();
  for (int d = 0; d < 3; ++d) set_scaled(s.a[2][d], n[d], shift);
  const int rows[3] = {2, 0, 1};
  det_rows(s.t1, s.a, rows, 3, s);  // det[n; q_a; q_b] = n . (q_a x q_b)
  return mpz_sgn(s.t1);
}

int exact_box_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t box) {
  const int dim = ctx.dim;
  std::int32_t gen[Scratch::kRows];
  for (int r = 0; r < dim; ++r) {
    if (planes[r] == box) return 0;
    gen[r] = planes[r];
  }
  gen[dim] = box;
  // GMP alone: a tie with the box is rare (symmetric input whose bisectors
  // pass through the box's edges), and only the vertices within rounding
  // of a box plane ask.
  ClipSigns sg;
  signs_gmp(ctx, i, gen, sg);
  const int sign_det_a = sg.minor[dim];
  if (sign_det_a == 0) return 0;
  int sign_m = sg.det_m0;
  if (sign_m == 0) {
    // As decide(), over every weighted term (the query row has none): an id
    // above every generator's lets decide() read them all, and its
    // coefficient, 0, is returned when none decides.
    PerturbationTerms terms;
    terms.set(i, gen, dim);
    sign_m = terms.decide(std::numeric_limits<std::int32_t>::max(), 0, [&](int row) {
      return row < 0 ? sg.weight_i : -cofactor_sign(row, dim) * sg.minor[row];
    });
    if (sign_m == 0) return 0;
  }
  // sign(c - v_axis); inside is v_axis <= c on an upper plane, >= c on a lower one.
  const int side = sign_m * sign_det_a;
  return box_plane_upper(box) ? side : -side;
}

namespace {
// d - n.p exactly, in a rational of this thread's (the offset's fallback and
// the point's side).
mpq_srcptr wall_offset_rational(const Wall& w, const double* p, int dim) {
  thread_local struct Rationals {
    mpq_t acc, t, u;
    Rationals() {
      mpq_init(acc);
      mpq_init(t);
      mpq_init(u);
    }
    ~Rationals() {
      mpq_clear(acc);
      mpq_clear(t);
      mpq_clear(u);
    }
  } r;
  mpq_set_d(r.acc, w.d);
  for (int a = 0; a < dim; ++a) {
    mpq_set_d(r.t, w.n[a]);
    mpq_set_d(r.u, p[a]);
    mpq_mul(r.t, r.t, r.u);
    mpq_sub(r.acc, r.acc, r.t);
  }
  return r.acc;
}
}  // namespace

int exact_wall_point_side(const Wall& w, const double* p, int dim) { return mpq_sgn(wall_offset_rational(w, p, dim)); }

double exact_wall_offset(const Wall& w, const double* p, int dim) {
  // In expansions where nothing can over- or underflow (every cell a wall
  // may cut asks this: GMP's rationals cost 10% of the cells of a
  // 64-faced domain): the exact sum, then its components added from the
  // smallest up, whose rounding (at most u per partial sum) is accepted
  // where it stays within two ulps of the result. (The largest component
  // alone is no such value: d = -0.4999999995, n.p = -0.5 + 5e-13 left
  // {-1.1e-17, 4.995e-10}, off by 2e-8 of it.)
  double values[7] = {w.d};
  for (int a = 0; a < dim; ++a) values[1 + a] = w.n[a], values[1 + dim + a] = p[a];
  if (expansion::exact_range(values, 1 + 2 * dim)) {
    thread_local expansion::Expansion acc, term, next;
    acc.clear();
    if (w.d != 0) acc.c[acc.n++] = w.d;
    for (int a = 0; a < dim; ++a) {
      double hi, lo;
      expansion::two_product(-w.n[a], p[a], hi, lo);
      term.clear();
      if (lo != 0) term.c[term.n++] = lo;
      if (hi != 0) term.c[term.n++] = hi;
      expansion::sum(acc, term, next);
      expansion::assign(next, acc);
    }
    if (acc.valid()) {
      double sum = 0, bound = 0;
      for (int k = 0; k < acc.n; ++k) {
        sum += acc.c[k];
        bound += std::fabs(sum);
      }
      if (bound <= 2 * std::fabs(sum)) return sum;  // error <= u bound <= 2u |sum|
    }
  }
  return mpq_get_d(wall_offset_rational(w, p, dim));  // truncated toward zero
}

int exact_wall_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, int wall) {
  const int dim = ctx.dim;
  std::int32_t gen[Scratch::kRows];
  for (int r = 0; r < dim; ++r) {
    if (planes[r] == wall_plane_id(wall)) return 1;  // on it
    gen[r] = planes[r];
  }
  gen[dim] = wall_plane_id(wall);
  // GMP alone: asked of the vertices within rounding of a wall, and of
  // those on another wall (few: the cells at the domain's edges).
  ClipSigns sg;
  signs_gmp(ctx, i, gen, sg);
  const int side = sg.det_m0 * sg.minor[dim];  // sign(d - n.v)
  return side >= 0 ? 1 : -1;
}

// The prepared form (see VertexPredicate in the header). With the query row
// q = (a_j, b_j) below A, the minor without row r < dim is A with row r
// replaced by a_j, moved to the bottom: (-1)^(dim-1-r) a_j . C_r, C_r being
// row r of A's cofactor matrix. Then det M0 = b_j det A - sum_r b_r (a_j . C_r)
// and w_i's coefficient is det A - sum over bisector rows of a_j . C_r.
// Bounds as in signs_int128: |a| < 2^24, |C| < 2^49, |a_j . C_r| < 2^76,
// |b| < 2^46, so every sum stays below 2^124.
namespace {
constexpr int kGridBits = 22;  // the int128 paths' bound on grid coordinates
}  // namespace

bool make_grid(ExactContext& ctx, std::size_t n, std::vector<std::int32_t>& grid) {
  const int dim = ctx.dim;
  if (dim != 2 && dim != 3) return false;
  const std::size_t m = n * static_cast<std::size_t>(dim);
  // The common grid; stop as soon as its span is too wide (it only widens):
  // on general input, at once.
  GridScale span;
  for (int d = 0; d < dim; ++d) {
    span.see(ctx.lo[static_cast<std::size_t>(d)]);
    span.see(ctx.hi[static_cast<std::size_t>(d)]);
  }
  for (std::size_t k = 0; k < m && span.fits(kGridBits); ++k) span.see(ctx.points[k]);
  if (!span.fits(kGridBits)) return false;
  const int shift = span.scale();
  auto scaled = [&](double x) { return static_cast<std::int32_t>(on_grid(double_parts(x), shift)); };
  grid.resize(m);
  for (std::size_t k = 0; k < m; ++k) grid[k] = scaled(ctx.points[k]);
  for (int d = 0; d < dim; ++d) {
    ctx.grid_lo[static_cast<std::size_t>(d)] = scaled(ctx.lo[static_cast<std::size_t>(d)]);
    ctx.grid_hi[static_cast<std::size_t>(d)] = scaled(ctx.hi[static_cast<std::size_t>(d)]);
  }
  ctx.grid = grid.data();
  ctx.grid_shift = shift;
  return true;
}

bool VertexPredicate::prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes) {
  using I = __int128;
  constexpr int kBits = kGridBits;
  dim_ = ctx.dim;
  i_ = i;
  if (dim_ != 2 && dim_ != 3) return false;
  for (int r = 0; r < dim_; ++r) gen_[r] = planes[r];
  narrow_ = false;
  if (ctx.grid != nullptr) {
    // The whole input is on one grid: read it.
    shift_ = ctx.grid_shift;
    if (dim_ == 3 ? prepare_narrow<3>(ctx) : prepare_narrow<2>(ctx)) return det_a_sign_ != 0;
    const std::int32_t* gi = ctx.grid + static_cast<std::size_t>(i) * dim_;
    ci2_ = 0;
    for (int d = 0; d < dim_; ++d) {
      ci_[d] = gi[d];
      ci2_ += static_cast<I>(ci_[d]) * ci_[d];
    }
    std::int64_t a[Scratch::kMaxDim][Scratch::kMaxDim] = {};
    for (int r = 0; r < dim_; ++r) {
      if (gen_[r] >= 0) {
        const std::int32_t* gk = ctx.grid + static_cast<std::size_t>(gen_[r]) * dim_;
        I sq = 0;
        for (int d = 0; d < dim_; ++d) {
          a[r][d] = 2 * (std::int64_t{gk[d]} - ci_[d]);
          sq += static_cast<I>(gk[d]) * gk[d];
        }
        b_[r] = sq - ci2_;
      } else {
        const int axis = box_plane_axis(gen_[r]);
        a[r][axis] = 1;
        b_[r] = box_plane_upper(gen_[r]) ? ctx.grid_hi[static_cast<std::size_t>(axis)]
                                         : ctx.grid_lo[static_cast<std::size_t>(axis)];
      }
    }
    set_cofactors(a);
    return det_a_sign_ != 0;  // dependent planes: exact_clip_sign reports it
  }
  // The vertex's doubles by their bits, and their common grid.
  DoubleParts pv[Scratch::kRows][Scratch::kMaxDim];
  GridScale span;
  row_parts(ctx, i, gen_, dim_, pv, span);
  if (!span.fits(kBits)) return false;
  shift_ = span.scale();
  auto scaled = [&](const DoubleParts& pt) { return on_grid(pt, shift_); };
  ci2_ = 0;
  for (int d = 0; d < dim_; ++d) {
    ci_[d] = scaled(pv[dim_][d]);
    ci2_ += static_cast<I>(ci_[d]) * ci_[d];
  }
  std::int64_t a[Scratch::kMaxDim][Scratch::kMaxDim] = {};
  for (int r = 0; r < dim_; ++r) {
    if (gen_[r] >= 0) {
      I sq = 0;
      for (int d = 0; d < dim_; ++d) {
        const std::int64_t x = scaled(pv[r][d]);
        a[r][d] = 2 * (x - ci_[d]);
        sq += static_cast<I>(x) * x;
      }
      b_[r] = sq - ci2_;
    } else {
      a[r][box_plane_axis(gen_[r])] = 1;
      b_[r] = scaled(pv[r][0]);
    }
  }
  set_cofactors(a);
  return det_a_sign_ != 0;
}

void VertexPredicate::set_cofactors(const std::int64_t (*a)[3]) {
  using I = __int128;
  if (dim_ == 2) {
    cof_[0][0] = a[1][1]; cof_[0][1] = -a[1][0];
    cof_[1][0] = -a[0][1]; cof_[1][1] = a[0][0];
    det_a_ = static_cast<I>(a[0][0]) * cof_[0][0] + static_cast<I>(a[0][1]) * cof_[0][1];
  } else {
    for (int r = 0; r < 3; ++r) {
      const std::int64_t* u = a[(r + 1) % 3];
      const std::int64_t* w = a[(r + 2) % 3];
      cof_[r][0] = u[1] * w[2] - u[2] * w[1];
      cof_[r][1] = u[2] * w[0] - u[0] * w[2];
      cof_[r][2] = u[0] * w[1] - u[1] * w[0];
    }
    det_a_ = static_cast<I>(a[0][0]) * cof_[0][0] + static_cast<I>(a[0][1]) * cof_[0][1] +
             static_cast<I>(a[0][2]) * cof_[0][2];
  }
  det_a_sign_ = sign_of(det_a_);
  terms_.set(i_, gen_, dim_);  // the perturbation's terms other than j's
}

// The narrow form (kNarrowLimit's bounds, with the candidate's row as the
// fourth): each candidate costs a dozen 64-bit multiplications instead of
// 128-bit ones.
template <int D>
bool VertexPredicate::prepare_narrow(const ExactContext& ctx) {
  const std::int32_t* gi = ctx.grid + static_cast<std::size_t>(i_) * D;
  for (int d = 0; d < D; ++d) ci_[d] = gi[d];
  std::int64_t a[D][3];
  for (int r = 0; r < D; ++r)
    if (!grid_row<D>(ctx, ci_, gen_[r], a[r], nb_[r])) return false;
  set_cofactors(a);  // translation leaves A's cofactors and det A as they are
  ndet_a_ = static_cast<std::int64_t>(det_a_);
  narrow_ = true;
  return true;
}

template <int D>
int VertexPredicate::sign_narrow(const ExactContext& ctx, std::int32_t j) const {
  std::int64_t aj[3], bj;
  if (!grid_row<D>(ctx, ci_, j, aj, bj)) return exact_clip_sign(ctx, i_, gen_, j);  // a far candidate
  std::int64_t m0 = bj * ndet_a_, wi = ndet_a_, dr[D];
  for (int r = 0; r < D; ++r) {
    dr[r] = 0;
    for (int d = 0; d < D; ++d) dr[r] += aj[d] * cof_[r][d];
    m0 -= nb_[r] * dr[r];
    if (gen_[r] >= 0) wi -= dr[r];
  }
  int sign_m = sign_of(m0);
  if (sign_m == 0)  // as in sign()
    sign_m = terms_.decide(j, -det_a_sign_, [&](int row) { return row < 0 ? sign_of(wi) : sign_of(dr[row]); });
  return sign_m * det_a_sign_ > 0 ? +1 : -1;
}

int VertexPredicate::sign(const ExactContext& ctx, std::int32_t j) const {
  using I = __int128;
  constexpr int kBits = kGridBits;
  if (narrow_) return dim_ == 3 ? sign_narrow<3>(ctx, j) : sign_narrow<2>(ctx, j);
  // p_j on the vertex's grid, within the bounds; else the general path.
  const double* pj = ctx.points + static_cast<std::size_t>(j) * dim_;
  std::int64_t xj[Scratch::kMaxDim];
  for (int d = 0; d < dim_; ++d) {
    if (ctx.grid != nullptr) {  // the whole input is on the grid
      xj[d] = ctx.grid[static_cast<std::size_t>(j) * dim_ + d];
      continue;
    }
    if (!grid_integer(pj[d], shift_, kBits, xj[d])) return exact_clip_sign(ctx, i_, gen_, j);
  }
  std::int64_t aj[Scratch::kMaxDim];
  I bj = -ci2_;
  for (int d = 0; d < dim_; ++d) {
    aj[d] = 2 * (xj[d] - ci_[d]);
    bj += static_cast<I>(xj[d]) * xj[d];
  }
  I m0 = bj * det_a_, wi = det_a_, dr[Scratch::kMaxDim];
  for (int r = 0; r < dim_; ++r) {
    dr[r] = 0;  // det A with row r replaced by a_j
    for (int d = 0; d < dim_; ++d) dr[r] += static_cast<I>(aj[d]) * cof_[r][d];
    m0 -= b_[r] * dr[r];
    if (gen_[r] >= 0) wi -= dr[r];
  }
  int sign_m = sign_of(m0);
  if (sign_m == 0) {
    // decide()'s tie-break with the terms pre-sorted: the coefficient of
    // w_gen[r] has the sign of dr[r] (-cofactor(r) * minor[r], see above),
    // of w_i that of wi, of w_j that of -det A.
    sign_m = terms_.decide(j, -det_a_sign_, [&](int row) { return row < 0 ? sign_of(wi) : sign_of(dr[row]); });
  }
  return sign_m * det_a_sign_ > 0 ? +1 : -1;
}

// ---- WidePredicate (see the header for the bounds) ----

bool WidePredicate::prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t also) {
  dim_ = ctx.dim;
  i_ = i;
  if (dim_ != 2 && dim_ != 3) return false;
  for (int r = 0; r < dim_; ++r) gen_[r] = planes[r];
  // The doubles by their bits (p_i last), and their common grid.
  DoubleParts pv[Scratch::kRows][Scratch::kMaxDim];
  GridScale span;
  row_parts(ctx, i, gen_, dim_, pv, span);
  if (also >= 0)
    for (int d = 0; d < dim_; ++d) span.see(ctx.points[static_cast<std::size_t>(also) * dim_ + d]);
  if (span.all_zero() || !span.fits(bits)) return false;
  // The grid as fine as the bound allows, up to two bits of headroom above:
  // candidates near the vertex may reach a binade lower or higher.
  shift_ = std::min(span.shift, span.top + 2 - bits);
  std::int64_t a[Scratch::kMaxDim][Scratch::kMaxDim];
  exact_rows::relative_rows(pv, gen_, dim_, shift_, ci_, a, b_);
  exact_rows::cofactors(a, dim_, cof_);
  det_a_ = WideInt<3>::from(0);
  for (int d = 0; d < dim_; ++d)
    det_a_ = det_a_ + multiply(WideInt<1>::from_int64(a[0][d]), WideInt<2>::from(cof_[0][d]));
  det_a_sign_ = det_a_.sign();
  terms_.set(i_, gen_, dim_);
  return det_a_sign_ != 0;  // dependent planes: exact_clip_sign reports it
}

bool WidePredicate::sign_on_grid(const ExactContext& ctx, std::int32_t j, int& out) const {
  using I = __int128;
  using W2 = WideInt<2>;
  using W3 = WideInt<3>;
  const double* pj = ctx.points + static_cast<std::size_t>(j) * dim_;
  std::int64_t qj[Scratch::kMaxDim];
  I bj = 0;
  for (int d = 0; d < dim_; ++d) {
    std::int64_t x;
    if (!grid_integer(pj[d], shift_, bits, x)) return false;
    const std::int64_t q = x - ci_[d];
    qj[d] = q;
    bj += static_cast<I>(q) * q;
  }
  // det M0 = b_j det A - sum_r b_r dr_r, dr_r = det A with row r replaced by
  // a_j = 2 q_j (as VertexPredicate::sign); w_i's coefficient det A - the
  // bisector rows' dr_r, below 4 * 3 * 2^187 < 2^191 (3 limbs).
  WideInt<5> m0 = multiply(W2::from(bj), det_a_);
  W3 wi = det_a_, dr[Scratch::kMaxDim];
  for (int r = 0; r < dim_; ++r) {
    // dr_r / 2 = sum_d q_d c_d, each cofactor c = h 2^64 + l split into its
    // signed high and unsigned low limbs: |q| < 2^61 and |h| < 2^61, so the
    // sums of q h (< 3 * 2^122) and of q l (< 3 * 2^125) are exact in
    // int128, and the 3-limb products are left for the combination.
    I hi = 0, lo = 0;
    for (int d = 0; d < dim_; ++d) {
      const I c = cof_[r][d];
      hi += static_cast<I>(qj[d]) * static_cast<std::int64_t>(c >> 64);
      lo += static_cast<I>(qj[d]) * static_cast<I>(static_cast<std::uint64_t>(c));
    }
    W3 h;
    h.limb[0] = 0;
    h.limb[1] = static_cast<std::uint64_t>(hi);
    h.limb[2] = static_cast<std::uint64_t>(hi >> 64);
    const W3 half = h + W3::from(lo);
    dr[r] = half + half;
    m0 = m0 - multiply(W2::from(b_[r]), dr[r]);
    if (gen_[r] >= 0) wi = wi - dr[r];
  }
  int sign_m = m0.sign();
  if (sign_m == 0)
    sign_m = terms_.decide(j, -det_a_sign_, [&](int row) { return row < 0 ? wi.sign() : dr[row].sign(); });
  out = sign_m * det_a_sign_ > 0 ? +1 : -1;
  return true;
}

int WidePredicate::sign(const ExactContext& ctx, std::int32_t j) const {
  int s;
  return sign_on_grid(ctx, j, s) ? s : exact_clip_sign(ctx, i_, gen_, j);
}

int lowest_bit_exponent(double x) {
  const DoubleParts p = double_parts(x);
  return p.e2 + std::countr_zero(static_cast<std::uint64_t>(p.mant < 0 ? -p.mant : p.mant));
}

// ---- ExtendedPredicate (see the header for the bound) ----

namespace {
using Ext = long double;
// The bound below takes each operation's relative error as at most 2^-64:
// true of x87 extended (64-bit mantissa, Linux's default precision control)
// and of IEEE quad. Where long double is narrower, the stage stays unused.
constexpr bool kExtUsable = std::numeric_limits<Ext>::digits >= 64;
// gamma_24 = 24 u / (1 - 24 u), u = 2^-64, doubled to spare (and to cover the
// rounding of the absolute-value sums themselves).
constexpr Ext kExtBound = 2 * (24 * 0x1p-64L) / (1 - 24 * 0x1p-64L);

// a x b, and the same on absolute values (each product's magnitude summed).
// Inlined: called out of line, its x87 values went through memory (80-bit
// loads and stores are microcoded), and the prepare of a rotated lattice's
// ties took a fifth of its cells' time (216,000 points: 2.10 -> 1.75 s).
[[gnu::always_inline]] inline void cross_ext(const Ext* a, const Ext* b, Ext* out, Ext* out_abs) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
  out_abs[0] = fabsl(a[1] * b[2]) + fabsl(a[2] * b[1]);
  out_abs[1] = fabsl(a[2] * b[0]) + fabsl(a[0] * b[2]);
  out_abs[2] = fabsl(a[0] * b[1]) + fabsl(a[1] * b[0]);
}
// The rows of a vertex of D bisectors: p_i into pi, q_r = p_{planes[r]} - p_i
// and s_r = |q_r|^2. False when a plane is a box plane.
template <int D>
bool bisector_rows(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, Ext* pi, Ext (*q)[3], Ext* s) {
  for (int r = 0; r < D; ++r)
    if (planes[r] < 0) return false;
  for (int d = 0; d < D; ++d) pi[d] = ctx.points[static_cast<std::size_t>(i) * D + d];
  for (int r = 0; r < D; ++r) {
    const double* pk = ctx.points + static_cast<std::size_t>(planes[r]) * D;
    s[r] = 0;
    for (int d = 0; d < D; ++d) {
      q[r][d] = static_cast<Ext>(pk[d]) - pi[d];
      s[r] += q[r][d] * q[r][d];
    }
  }
  return true;
}
}  // namespace

bool ExtendedPredicate::prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes) {
  dim_ = ctx.dim;
  if (!kExtUsable) return false;
  if (dim_ == 2) return prepare2(ctx, i, planes);
  Ext q[3][3], s[3];
  if (dim_ != 3 || !bisector_rows<3>(ctx, i, planes, pi_, q, s)) return false;
  Ext x12[3], x02[3], x01[3], a12[3], a02[3], a01[3];
  cross_ext(q[1], q[2], x12, a12);
  cross_ext(q[0], q[2], x02, a02);
  cross_ext(q[0], q[1], x01, a01);
  Ext d3 = 0;
  d3_abs_ = 0;
  for (int d = 0; d < 3; ++d) {
    w_[d] = -s[0] * x12[d] + s[1] * x02[d] - s[2] * x01[d];
    w_abs_[d] = s[0] * a12[d] + s[1] * a02[d] + s[2] * a01[d];
    d3 += q[0][d] * x12[d];
    d3_abs_ += fabsl(q[0][d]) * a12[d];
  }
  if (!(fabsl(d3) > kExtBound * d3_abs_)) return false;  // D3's sign uncertain (or NaN)
  d3_ = d3;
  d3_positive_ = d3 > 0;
  return true;
}

// 2D: D2 = q_0 x q_1 and W = (s_1 q_0y - s_0 q_1y, s_0 q_1x - s_1 q_0x), from
// the expansion of det[[q_0, s_0], [q_1, s_1], [q_j, s_j]] along its last
// column; degree-4 monomials, well within the same bound.
bool ExtendedPredicate::prepare2(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes) {
  Ext q[3][3], s[3];
  if (!bisector_rows<2>(ctx, i, planes, pi_, q, s)) return false;
  w_[0] = s[1] * q[0][1] - s[0] * q[1][1];
  w_[1] = s[0] * q[1][0] - s[1] * q[0][0];
  w_abs_[0] = s[1] * fabsl(q[0][1]) + s[0] * fabsl(q[1][1]);
  w_abs_[1] = s[0] * fabsl(q[1][0]) + s[1] * fabsl(q[0][0]);
  const Ext d2 = q[0][0] * q[1][1] - q[0][1] * q[1][0];
  d3_abs_ = fabsl(q[0][0] * q[1][1]) + fabsl(q[0][1] * q[1][0]);
  if (!(fabsl(d2) > kExtBound * d3_abs_)) return false;
  d3_ = d2;
  d3_positive_ = d2 > 0;
  return true;
}

int ExtendedPredicate::sign(const ExactContext& ctx, std::int32_t j) const {
  const double* pj = ctx.points + static_cast<std::size_t>(j) * dim_;
  Ext dot = 0, perm = 0, sj = 0;
  for (int d = 0; d < dim_; ++d) {
    const Ext qj = static_cast<Ext>(pj[d]) - pi_[d];
    sj += qj * qj;
    dot += w_[d] * qj;
    perm += w_abs_[d] * fabsl(qj);
  }
  const Ext d4 = dot + d3_ * sj;
  perm += d3_abs_ * sj;
  if (!(fabsl(d4) > kExtBound * perm)) return 0;
  // sign(P) = sign(D4) sign(D3); P > 0 keeps the vertex.
  return (d4 > 0) == d3_positive_ ? +1 : -1;
}

}  // namespace tessera::kernels
