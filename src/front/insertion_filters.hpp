// The float filters of the 2D and 3D insertions (insertion.cpp).
#pragma once

#include <cmath>

#include "tessera/kernels/filter.hpp"

namespace tessera::front::insertion {

// The filters in front of kernels::orientation and kernels::in_sphere,
// written out for 2D and 3D and for points that are ids into one array: the walk and
// the cavity search ask tens of them per point. Each returns the exact sign
// when its float evaluation is certain, and 0 otherwise (then the kernels'
// predicates decide, with their exact arithmetic and perturbation). The
// quantities and bounds are those of the kernels' filters
// (delaunay_predicates.hpp), evaluated in another order: the bounds hold for
// any order of the sums.
//
// `underflow` (ExactContext::may_underflow: no frame fits the input, so
// products may round below DBL_MIN) swaps their absolute term abs_eps for
// filter::underflow_bound, with eta = 2^-1075 the absolute error of one
// product: each filter's comment gives the sum of eta's multipliers
// ("growth"). In a frame that fits, products stay normal and the term, computed
// only where asked, stays abs_eps: computed always, it cost the 3D insertion
// 2.5% (1M uniform points).

// Sign of det[b - a, c - a, d - a].
[[gnu::always_inline]] inline int orientation_filter(const double* a, const double* b, const double* c, const double* d, bool underflow) {
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
  // Growth: each m errs by eta, each (m - m') times |r0[e]|, and its
  // product by eta again: 2 sum |r0| + 3.
  const double abs = underflow ? kernels::filter::underflow_bound(2 * (std::fabs(r0[0]) + std::fabs(r0[1]) + std::fabs(r0[2])) + 3)
                                : kernels::filter::abs_eps;
  const double bound = 16 * kernels::filter::u * perm + abs;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

// For a positively oriented tetrahedron abcd: +1 when q is surely inside its
// circumsphere, -1 surely outside, 0 undecided. With rows r_k = p_k - a and
// s_k = |r_k|^2 (k = b, c, d, q), q is inside iff det[[r_k, s_k]] < 0
// (kernels::in_sphere; det R > 0 here).
//
// Weighted (regular triangulations; `w`: the squared radii of a, b, c, d,
// q): the power test, s_k = |r_k|^2 - (w_k - w_a), its permanent's entries
// |r_k|^2 + w_k + w_a and the bound 128 units, as kernels::in_sphere takes
// them (delaunay_predicates.cpp). Regular triangulations refuse input that
// may underflow (Pass::set_radii), so `underflow` is false with them. A
// template parameter: the ordinary filter is the code it was (a run-time
// null test cost the ordinary insertion ~4% on one thread).
template <bool Weighted = false>
[[gnu::always_inline]] inline int in_sphere_filter(const double* a, const double* b, const double* c, const double* d, const double* q,
                                                 bool underflow, [[maybe_unused]] const double* w = nullptr) {
  double r[4][3], s[4];
  [[maybe_unused]] double sm[4];  // Weighted: the lifted entries' magnitudes
  const double* p[4] = {b, c, d, q};
  for (int k = 0; k < 4; ++k) {
    for (int e = 0; e < 3; ++e) r[k][e] = p[k][e] - a[e];
    s[k] = r[k][0] * r[k][0] + r[k][1] * r[k][1] + r[k][2] * r[k][2];
    if constexpr (Weighted) {
      sm[k] = s[k] + w[k + 1] + w[0];
      s[k] -= w[k + 1] - w[0];
    }
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
  const double* const mag = Weighted ? sm : s;
  const double perm = mag[0] * p0 + mag[1] * p1 + mag[2] * p2 + mag[3] * p3;
  // Growth: a 2x2 minor errs by 2 eta, a 3x3 one by 2 eta Z + 3 eta (Z: the
  // sum of the rows' |z|), s[k] by 3 eta; det's products add s[k] times the
  // minor's error, |d_k| times s[k]'s, and eta: S (2 Z + 3) + 3 sum |d_k| + 4.
  double abs = kernels::filter::abs_eps;
  if (underflow) {
    const double z = std::fabs(r[0][2]) + std::fabs(r[1][2]) + std::fabs(r[2][2]) + std::fabs(r[3][2]);
    abs = kernels::filter::underflow_bound((s[0] + s[1] + s[2] + s[3]) * (2 * z + 3) +
                                           3 * (std::fabs(d0) + std::fabs(d1) + std::fabs(d2) + std::fabs(d3)) + 4);
  }
  const double bound = (Weighted ? 128 : 64) * kernels::filter::u * perm + abs;
  return det < -bound ? 1 : (det > bound ? -1 : 0);
}

// Sign of det[b - a, c - a].
[[gnu::always_inline]] inline int orientation_filter(const double* a, const double* b, const double* c, bool underflow) {
  const double m0 = (b[0] - a[0]) * (c[1] - a[1]), m1 = (b[1] - a[1]) * (c[0] - a[0]);
  const double det = m0 - m1;
  // Growth 2 (the two products).
  const double abs = underflow ? kernels::filter::underflow_bound(2) : kernels::filter::abs_eps;
  const double bound = 16 * kernels::filter::u * (std::fabs(m0) + std::fabs(m1)) + abs;
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

// For a counter-clockwise triangle abc: +1 when q is surely inside its
// circumcircle, -1 surely outside, 0 undecided. With rows r_k = p_k - a and
// s_k = |r_k|^2 (k = b, c, q), q is inside iff det[[r_k, s_k]] < 0.
// Weighted (`w`: the squared radii of a, b, c, q) as in_sphere_filter.
template <bool Weighted = false>
[[gnu::always_inline]] inline int in_circle_filter(const double* a, const double* b, const double* c, const double* q, bool underflow,
                                                 [[maybe_unused]] const double* w = nullptr) {
  double r[3][2], s[3];
  [[maybe_unused]] double sm[3];
  const double* p[3] = {b, c, q};
  for (int k = 0; k < 3; ++k) {
    r[k][0] = p[k][0] - a[0];
    r[k][1] = p[k][1] - a[1];
    s[k] = r[k][0] * r[k][0] + r[k][1] * r[k][1];
    if constexpr (Weighted) {
      sm[k] = s[k] + w[k + 1] + w[0];
      s[k] -= w[k + 1] - w[0];
    }
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
  // Growth: minors and s[k] err by 2 eta each, so det's products by
  // 2 eta (s[k] + |d_k|) + eta: 2 S + 2 sum |d_k| + 3.
  const double abs = underflow ? kernels::filter::underflow_bound(2 * (s[0] + s[1] + s[2]) +
                                                                 2 * (std::fabs(d0) + std::fabs(d1) + std::fabs(d2)) + 3)
                                : kernels::filter::abs_eps;
  const double* const mag = Weighted ? sm : s;
  const double bound = (Weighted ? 128 : 64) * kernels::filter::u * (mag[0] * p0 + mag[1] * p1 + mag[2] * p2) + abs;
  return det < -bound ? 1 : (det > bound ? -1 : 0);
}

}  // namespace tessera::front::insertion
