// Filtered orientation and in-sphere predicates; see delaunay_predicates.hpp.
#include "tessera/kernels/delaunay_predicates.hpp"

#include <gmp.h>

#include <cmath>
#include <limits>
#include <cstdint>
#include <type_traits>

#include "tessera/kernels/box_ties.hpp"
#include "tessera/kernels/expansion.hpp"
#include "tessera/kernels/filter.hpp"
#include "tessera/kernels/prepared_signs.hpp"

namespace tessera::kernels {
namespace {

const double* pt(const ExactContext& ctx, std::int32_t id) {
  return ctx.points + static_cast<std::size_t>(id) * static_cast<std::size_t>(ctx.dim);
}

// Exact orientation in 128-bit integers when every coordinate is a 25-bit
// integer times one common power of two (lattices, voxel centres, integer and
// dyadic grids — where exact zeros are common and GMP would dominate).
// Differences need 26 bits, a 3x3 determinant 3*26+3 < 127. False otherwise.
bool orientation_int128(int D, const double* const* p, int& sign) {
  GridScale g;
  for (int k = 0; k <= D; ++k)
    for (int d = 0; d < D; ++d) g.see(p[k][d]);
  if (!g.fits(25)) return false;
  std::int64_t c[4][3] = {};
  for (int k = 0; k <= D; ++k)
    for (int d = 0; d < D; ++d) g.scaled(p[k][d], 25, c[k][d]);
  __int128 r[3][3] = {};
  for (int k = 0; k < D; ++k)
    for (int d = 0; d < D; ++d) r[k][d] = static_cast<__int128>(c[k + 1][d]) - c[0][d];
  __int128 det;
  if (D == 2) det = r[0][0] * r[1][1] - r[0][1] * r[1][0];
  else
    det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
          r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
  sign = det > 0 ? 1 : (det < 0 ? -1 : 0);
  return true;
}

// The exact stage by expansions (expansion.hpp): rows of differences p_k - p_0
// held exactly, determinants of up to 3x3 of them, and the lifted column.
struct ExpansionStage {
  using E = expansion::Expansion;
  E r[3][3];  // row k, coordinate d
  E t[5];     // temporaries
  E det_r;
  expansion::Workspace ws;

  // out = a * d - b * c
  void det2(const E& a, const E& b, const E& c, const E& d, E& out) {
    expansion::product(a, d, t[0], ws);
    expansion::product(b, c, t[1], ws);
    expansion::negate(t[1]);
    expansion::sum(t[0], t[1], out);
  }
  // The determinant of rows `rows` (D of them) of r, into out.
  void det(int D, const int* rows, E& out) {
    if (D == 2) {
      det2(r[rows[0]][0], r[rows[0]][1], r[rows[1]][0], r[rows[1]][1], out);
      return;
    }
    out.clear();
    for (int d = 0; d < 3; ++d) {
      const int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
      det2(r[rows[1]][d1], r[rows[1]][d2], r[rows[2]][d1], r[rows[2]][d2], t[2]);  // cofactor of (0, d)
      expansion::product(r[rows[0]][d], t[2], t[3], ws);
      expansion::sum(out, t[3], t[4]);
      expansion::assign(t[4], out);
    }
  }
  // r's rows 0..count-1 from points p[1..count] minus p[0].
  void rows_from(int D, const double* const* p, int count) {
    for (int k = 0; k < count; ++k)
      for (int d = 0; d < D; ++d) expansion::difference(p[k + 1][d], p[0][d], r[k][d]);
  }
};

ExpansionStage& expansion_stage() {
  thread_local ExpansionStage st;
  return st;
}

bool in_exact_range(int D, const double* const* p, int count) {
  for (int k = 0; k < count; ++k)
    if (!expansion::exact_range(p[k], D)) return false;
  return true;
}

// Orientation in long double, for input out of the expansions' range (no
// frame fits: 1e-155 beside 1e131, front/pass.cpp), where the double minors
// underflow and every undecided test went to GMP rationals (2D: 100,000
// points and one at 1e200 took 20.6 s by insertion, 0.88 s with this). Products of
// up to three doubles neither underflow nor overflow in its 15-bit exponent,
// so the bounds are relative only (7 and 11 units of the permanents after
// Shewchuk; 16 to spare). Two forms, each certain where the other may not be:
//  * det[p_k - p_0], as the double filter: for points close to each other;
//  * the same value as the alternating sum of the D + 1 determinants of the
//    points themselves (the lifted 1 column expanded): no differences, so
//    for points of wildly different magnitudes near the origin (2^-167,
//    2^-232, 2^-435: their differences lose the smaller ones' bits).
// 0 when both are undecided.
int orientation_long_double(int D, const double* const* p) {
  if constexpr (std::numeric_limits<long double>::digits < 64) {
    return 0;
  } else {
    using L = long double;
    constexpr L unit16 = 16 * 0x1p-64L;
    auto sign = [&](L det, L perm) { return det > unit16 * perm ? 1 : (det < -unit16 * perm ? -1 : 0); };
    L r[3][3] = {};
    for (int k = 0; k < D; ++k)
      for (int d = 0; d < D; ++d) r[k][d] = static_cast<L>(p[k + 1][d]) - static_cast<L>(p[0][d]);
    L perm;
    L det = detail::det_perm(r[0], r[1], r[2], D, perm);
    if (const int s = sign(det, perm)) return s;
    L x[4][3] = {};
    for (int k = 0; k <= D; ++k)
      for (int d = 0; d < D; ++d) x[k][d] = static_cast<L>(p[k][d]);
    // 2D: |p1 p2| - |p0 p2| + |p0 p1|; 3D: |p1 p2 p3| - |p0 p2 p3| + |p0 p1 p3| - |p0 p1 p2|.
    det = 0;
    perm = 0;
    for (int skip = 0; skip <= D; ++skip) {
      const L* rows[3] = {};
      for (int k = 0, j = 0; k <= D; ++k)
        if (k != skip) rows[j++] = x[k];
      L pk;
      const L dk = detail::det_perm(rows[0], rows[1], rows[2], D, pk);
      det += skip % 2 == 0 ? dk : -dk;
      perm += pk;
    }
    return sign(det, perm);
  }
}

// Exact orientation by expansions; false when the input is outside their range.
bool orientation_expansion(int D, const double* const* p, int& sign) {
  if (!in_exact_range(D, p, D + 1)) return false;
  ExpansionStage& st = expansion_stage();
  st.rows_from(D, p, D);
  const int rows[3] = {0, 1, 2};
  st.det(D, rows, st.det_r);
  if (!st.det_r.valid()) return false;
  sign = expansion::sign(st.det_r);
  return true;
}

// Exact orientation in rationals: every double is exactly representable.
int orientation_exact(int D, const double* const* pts) {
  struct Q {
    mpq_t m[3][3], t, u, acc;
    Q() {
      for (auto& r : m) for (auto& c : r) mpq_init(c);
      mpq_init(t); mpq_init(u); mpq_init(acc);
    }
    ~Q() {
      for (auto& r : m) for (auto& c : r) mpq_clear(c);
      mpq_clear(t); mpq_clear(u); mpq_clear(acc);
    }
  };
  thread_local Q q;
  const double* p0 = pts[0];
  for (int k = 0; k < D; ++k) {
    const double* p = pts[k + 1];
    for (int d = 0; d < D; ++d) {
      mpq_set_d(q.t, p[d]);
      mpq_set_d(q.u, p0[d]);
      mpq_sub(q.m[k][d], q.t, q.u);
    }
  }
  if (D == 2) {
    mpq_mul(q.t, q.m[0][0], q.m[1][1]);
    mpq_mul(q.u, q.m[0][1], q.m[1][0]);
    mpq_sub(q.acc, q.t, q.u);
    return mpq_sgn(q.acc);
  }
  mpq_set_ui(q.acc, 0, 1);
  for (int c = 0; c < 3; ++c) {
    int c1 = (c + 1) % 3, c2 = (c + 2) % 3;
    mpq_mul(q.t, q.m[1][c1], q.m[2][c2]);
    mpq_mul(q.u, q.m[1][c2], q.m[2][c1]);
    mpq_sub(q.t, q.t, q.u);
    mpq_mul(q.t, q.t, q.m[0][c]);
    mpq_add(q.acc, q.acc, q.t);
  }
  return mpq_sgn(q.acc);
}

// The in-sphere filter on the Schur form of the clip predicate: with rows
// r_k = p_k - p_a, s_k = |r_k|^2 for the planes and for q (last row of p),
// det[[R, s], [r_q, s_q]] = det R * (pow_q(v) - pow_a(v)) (exact_predicates.hpp),
// and q is inside iff that power difference is negative. The determinants
// are evaluated in T, whose operations err by a relative `unit` at most; the
// permanents of the error bounds in P (eps: an absolute floor for underflow);
// +1 when q is surely inside, -1 surely outside, 0 undecided, and
// permanents_out_of_range (undecided too) when P is narrower than T and a
// permanent lies outside [2^-900, P's overflow).
//
// Near-co-spherical input (a sampled sphere, whose every test is nearly a
// tie) leaves most tests to the long double evaluation (x87), where a
// generic evaluation of each minor took two fifths of the run. So:
//  * the D + 1 minors of R's rows share their 2x2 minors of the first two
//    columns (3D: six, each in three of the four minors), computed once;
//  * the permanents are summed in double (P) whatever T is (SSE, beside the
//    x87 stack): from differences rounded to double they are within 2^-47 of
//    those of the differences rounded to T, which the bounds' margin (64
//    units where Shewchuk's analysis needs 16) absorbs. Below 2^-900 their
//    terms' underflow would count, past double's range (coordinates past
//    ~2^200) they overflow: the long double stage then sums them again in
//    long double, whose exponent range holds any product of five doubles.
//    A permanent of 2^-900 or more can still have lost a term to underflow:
//    a row 2^200 long times a minor of rows near 2^-170, which rounds to
//    zero in double (stop 73: unit points beside points at 1e72 and 1e194;
//    the double permanent was 1e49 times too small, the stage certified the
//    wrong sign, and the insertion built a flat tetrahedron). So the terms
//    underflow may have dropped are bounded as the double filter bounds
//    them (filter::underflow_bound), and the double permanents serve only
//    where that is below 2^-60 of them.
// A permanent does not depend on the order of its sum, and the bounds hold
// for any order of evaluation, so these are the quantities and bounds of a
// separate evaluation per minor.
constexpr int permanents_out_of_range = 2;  // in_sphere_filter: undecided, sum them in T

//
// Power test (ExactContext::radii; `rho` non-null: the radii of p[0..D] and,
// last, of a): the lifted column becomes s_k = |p_k - a|^2 - (rho_k^2 -
// rho_a^2), the regular triangulation's lifting translated to a, and q is
// inside when its power distance to the orthocentre is below the orthoradius's
// square (Edelsbrunner and Shah, "Incremental topological flipping works for
// regular triangulations", 1996). sd_k, the entry's magnitude for the
// permanent, gains rho_k^2 + rho_a^2: the weighted entry then errs by at most
// ~9 units of sd_k (5 without weights), and the bound takes 128 units.
template <int D, class T, class P = double>
int in_sphere_filter(const double* pa, const double* const* p, T unit, P eps, const double* rho = nullptr) {
  using std::fabs;
  T r[D + 1][D], s[D + 1];
  P rd[D + 1][D], sd[D + 1];
  for (int k = 0; k <= D; ++k) {
    s[k] = 0;
    sd[k] = 0;
    for (int d = 0; d < D; ++d) {
      r[k][d] = static_cast<T>(p[k][d]) - static_cast<T>(pa[d]);
      rd[k][d] = static_cast<P>(p[k][d]) - static_cast<P>(pa[d]);  // r itself when P is T
      s[k] += r[k][d] * r[k][d];
      sd[k] += rd[k][d] * rd[k][d];
    }
    if (rho != nullptr) {
      const T rk = static_cast<T>(rho[k]), ra = static_cast<T>(rho[D + 1]);
      s[k] -= rk * rk - ra * ra;
      sd[k] += static_cast<P>(rho[k]) * static_cast<P>(rho[k]) + static_cast<P>(rho[D + 1]) * static_cast<P>(rho[D + 1]);
    }
  }
  // xy(i, j) = the 2x2 minor of rows i < j in the first two columns.
  T xy[D + 1][D + 1];
  P axy[D + 1][D + 1];
  for (int i = 0; i <= D; ++i)
    for (int j = i + 1; j <= D; ++j) {
      xy[i][j] = r[i][0] * r[j][1] - r[i][1] * r[j][0];
      axy[i][j] = fabs(rd[i][0] * rd[j][1]) + fabs(rd[i][1] * rd[j][0]);
    }
  // m[k], pm[k]: the minor of the rows other than k (in increasing order),
  // and its permanent; 3D minors expanded along the third column.
  T m[D + 1];
  P pm[D + 1];
  if constexpr (D == 2) {
    m[0] = xy[1][2], pm[0] = axy[1][2];
    m[1] = xy[0][2], pm[1] = axy[0][2];
    m[2] = xy[0][1], pm[2] = axy[0][1];
  } else {
    auto minor = [&](int i, int j, int k, P& perm) {
      perm = fabs(rd[i][2]) * axy[j][k] + fabs(rd[j][2]) * axy[i][k] + fabs(rd[k][2]) * axy[i][j];
      return r[i][2] * xy[j][k] - r[j][2] * xy[i][k] + r[k][2] * xy[i][j];
    };
    m[0] = minor(1, 2, 3, pm[0]);
    m[1] = minor(0, 2, 3, pm[1]);
    m[2] = minor(0, 1, 3, pm[2]);
    m[3] = minor(0, 1, 2, pm[3]);
  }
  // The full determinant by expansion along the s column; the cofactor sign
  // of (row k, column D) is (-1)^(k + D).
  T det_m = 0;
  P perm_m = 0;
  for (int k = 0; k <= D; ++k) {
    det_m += ((k + D) % 2 == 0 ? s[k] : -s[k]) * m[k];
    perm_m += sd[k] * pm[k];
  }
  const T det_r = m[D];
  const P perm_r = pm[D];
  if constexpr (!std::is_same_v<P, T>) {
    constexpr P inf = std::numeric_limits<P>::infinity();
    if (!(perm_m >= P(0x1p-900) && perm_m < inf && perm_r >= P(0x1p-900) && perm_r < inf))
      return permanents_out_of_range;
    // Underflow's losses (P is double here): a 2x2 permanent's products lose
    // eta each, a 3x3 one's 2 eta Z + 3 eta (Z: the rows' sum of |z|), the
    // squared lengths D eta each; the lifted permanent's products multiply
    // those by sd[k] and pm[k], and add eta each.
    P z = 0, s_sum = 0, pm_sum = 0;
    for (int k = 0; k <= D; ++k) {
      z += fabs(rd[k][D - 1]);
      s_sum += sd[k];
      pm_sum += pm[k];
    }
    const P lost_r = filter::underflow_bound(2 * z + 3);
    const P lost_m = filter::underflow_bound(s_sum * (2 * z + 3) + D * pm_sum + D + 1);
    if (!(lost_r <= P(0x1p-60) * perm_r && lost_m <= P(0x1p-60) * perm_m)) return permanents_out_of_range;
  }
  // Underflow, in double only (a product of doubles never underflows in long
  // double): a 2x2 minor errs by 2 eta, a 3x3 one by 2 eta Z + 3 eta (Z: the
  // rows' sum of |z|), s[k] by D eta; det's products add s[k] times the
  // minor's error, |m_k| times s[k]'s, and eta (filter::underflow_bound).
  T abs_r = static_cast<T>(eps), abs_m = static_cast<T>(eps);
  if constexpr (std::is_same_v<T, double>) {
    double z = 0, s_sum = 0, m_sum = 0;
    for (int k = 0; k <= D; ++k) {
      if constexpr (D == 3) z += fabs(r[k][2]);
      s_sum += sd[k];  // s[k] itself without radii (P is T here)
      m_sum += fabs(m[k]);
    }
    abs_r = filter::underflow_bound(2 * z + 3);
    abs_m = filter::underflow_bound(s_sum * (2 * z + 3) + 3 * m_sum + 4);
  }
  const T bound_r = 16 * unit * static_cast<T>(perm_r) + abs_r;
  // The lifted column is itself rounded (relative 3 units per entry): 64
  // units cover the classic 11 of Shewchuk's insphere bound with a wide margin.
  const T bound_m = (rho != nullptr ? 128 : 64) * unit * static_cast<T>(perm_m) + abs_m;
  if (fabs(det_r) > bound_r && fabs(det_m) > bound_m)
    return (det_m > 0) != (det_r > 0) ? 1 : -1;  // P = det M / det R; inside iff P < 0
  return 0;
}

// in_sphere past its double filter: the long double filter, then the exact sign.
template <int D>
bool in_sphere_extended(const ExactContext& ctx, const double* pa, const double* const* p, std::int32_t a,
                        const std::int32_t* planes, std::int32_t q, const double* rho) {
  // Ties at the corners of an axis-aligned box (the in-sphere ties of
  // lattices and voxel centres, whatever the spacing) first: decided from the
  // coordinates' pattern, where the long double stage can only fail. The
  // pattern knows no radii.
  if (int s; rho == nullptr && box_tie_sign<D>(ctx, a, planes, q, s)) return s < 0;
  // Near-degenerate input (a rotated lattice, points nearly on one sphere)
  // leaves a tenth of the tests or more to this stage, where the 64-bit
  // mantissa settles most of what double rounding could not. Exact ties (a
  // lattice's cospherical points, voxel centres) it can never settle: after
  // a run of such failures the gate lets only one test in 64 try it (speed
  // only; the exact sign is the same).
  if constexpr (std::numeric_limits<long double>::digits >= 64) {
    thread_local StageGate gate;
    if (gate.open()) {
      int s = in_sphere_filter<D, long double>(pa, p, 0x1p-64L, 0.0, rho);
      if (s == permanents_out_of_range) s = in_sphere_filter<D, long double, long double>(pa, p, 0x1p-64L, 0.0L, rho);
      gate.record(s == 1 || s == -1);
      if (s == 1 || s == -1) return s > 0;
    }
  }
  return exact_clip_sign_by_arithmetic(ctx, a, planes, q) < 0;  // the box stage ran above
}

// in_sphere's stages for dimension D: the double filter (unless the caller
// ran its own: in_sphere_past_filter), then in_sphere_extended.
template <int D>
bool in_sphere_staged(const ExactContext& ctx, std::int32_t a, const std::int32_t* planes, std::int32_t q,
                      bool double_filter) {
  const double* p[D + 1];
  for (int k = 0; k <= D; ++k) p[k] = pt(ctx, k < D ? planes[k] : q);
  const double* pa = pt(ctx, a);
  double radii[D + 2];
  const double* rho = nullptr;
  if (ctx.radii != nullptr) {
    for (int k = 0; k <= D; ++k) radii[k] = ctx.radii[k < D ? planes[k] : q];
    radii[D + 1] = ctx.radii[a];
    rho = radii;
  }
  if (double_filter)
    if (const int s = in_sphere_filter<D, double>(pa, p, filter::u, filter::abs_eps, rho); s == 1 || s == -1) return s > 0;
  return in_sphere_extended<D>(ctx, pa, p, a, planes, q, rho);
}

}  // namespace

int orientation(int D, const double* const* pts) {
  const double* rows[3] = {};
  double r[3][3] = {};
  const double* p0 = pts[0];
  for (int k = 0; k < D; ++k) {
    const double* p = pts[k + 1];
    for (int d = 0; d < D; ++d) r[k][d] = p[d] - p0[d];
    rows[k] = r[k];
  }
  if (const int sign = orientation_filter(D, rows)) return sign;
  int sign;
  if (orientation_int128(D, pts, sign)) return sign;
  if (orientation_expansion(D, pts, sign)) return sign;
  // Out of the expansions' range (no frame fits): long double, then GMP.
  if ((sign = orientation_long_double(D, pts)) != 0) return sign;
  return orientation_exact(D, pts);
}

int orientation_past_filter(int D, const double* const* pts) {
  if (const int sign = orientation_long_double(D, pts)) return sign;
  int sign;
  if (orientation_int128(D, pts, sign)) return sign;
  if (orientation_expansion(D, pts, sign)) return sign;
  return orientation_exact(D, pts);
}

int orientation(const ExactContext& ctx, const std::int32_t* ids) {
  const double* pts[4] = {};
  for (int k = 0; k <= ctx.dim; ++k) pts[k] = pt(ctx, ids[k]);
  return orientation(ctx.dim, pts);
}

bool in_sphere(const ExactContext& ctx, std::int32_t a, const std::int32_t* planes, std::int32_t q) {
  return ctx.dim == 2 ? in_sphere_staged<2>(ctx, a, planes, q, true) : in_sphere_staged<3>(ctx, a, planes, q, true);
}

bool in_sphere_past_filter(const ExactContext& ctx, std::int32_t a, const std::int32_t* planes, std::int32_t q) {
  return ctx.dim == 2 ? in_sphere_staged<2>(ctx, a, planes, q, false) : in_sphere_staged<3>(ctx, a, planes, q, false);
}

}  // namespace tessera::kernels
