// Power (radical) cells: the clip plane and radius bounds of a weighted cell.
//
// With spheres of radii r_k, point k's power at x is |x - p_k|^2 - r_k^2,
// and the power cell of i is where i's power is the least (Aurenhammer,
// "Power diagrams: properties, algorithms and applications", SIAM J.
// Comput. 16, 1987; Voro++'s container_poly computes the same radical
// tessellation). Relative to p_i the bisector with j is
//     q.y <= d,  q = p_j - p_i,  d = (|q|^2 + r_i^2 - r_j^2) / 2,
// the ordinary bisector moved along q. So a power cell is built exactly as
// an ordinary one, with two changes that this header holds:
//
// * The plane's d (weigh). The filter (filter.hpp) takes d's error as
//   16u|d|: true of |q|^2 / 2 rounded once, but not where |q|^2 and
//   r_i^2 - r_j^2 cancel (the plane passes near p_i, or beyond it: d < 0,
//   when p_i lies outside its own cell; and a cell may be empty). The float
//   d is kept where its error bound is within half the filter's (far
//   candidates, most of them); else d is summed from the exact differences
//   p_j - p_i and the exact squares in a compensated sum (Ogita, Rump &
//   Oishi, "Accurate sum and dot product", SIAM J. Sci. Comput. 26, 2005),
//   within u|d| + 128u^2 m of the exact value, m the terms' magnitude; and
//   where |d| < 2^-46 m (nearly on p_i, and exact ties) it is computed
//   exactly (exact_power_offset).
// * The radius bounds. A candidate q removes vertex y only if
//   |y - q|^2 - r_q^2 < |y|^2 - r_i^2, so within the ball of radius^2
//   |y|^2 + r_q^2 - r_i^2 <= |y|^2 + slack about y, slack = max_k r_k^2 - r_i^2
//   (power_slack). Each vertex's r2 bounds |y|^2 + slack instead of |y|^2:
//   then every test the search makes from r2 stays valid, only wider: the
//   security radius (2 max sqrt(r2): |q| <= |y| + sqrt(r2)), the petals
//   (balls of radius sqrt(r2) about the vertices: flower_bins, PetalCover,
//   certify_by_petals) and classify's radius test (4 r2 < |q|^2 leaves y
//   kept: |y| |q| <= (|q|^2 - slack) / 2 <= d follows from
//   |y|^2 < |q|^2 / 4 - slack). SupportBound compares against |q|^2 - slack.
// Without radii both are the ordinary ones, to the bit (slack 0 is added).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::kernels {

/// An upper bound on max_k r_k^2 - r_i^2 (>= 0), for cell i of a power
/// diagram whose largest radius is rmax: (rmax - r_i)(rmax + r_i), each
/// factor and the product rounded by at most u, widened by far more.
inline double power_slack(double rmax, double ri) {
  const double s = (rmax - ri) * (rmax + ri);
  return s > 0 ? s * (1 + 0x1p-40) : 0.0;
}

namespace power_detail {
/// x^2 = hi + lo exactly (Dekker's product by Veltkamp's split; no FMA: the
/// default x86-64-v2 target has none, and std::fma's emulation costs a call
/// and dozens of cycles). Exact while |x| < 2^995.
inline void two_square(double x, double& hi, double& lo) {
  const double c = 134217729.0 * x;  // 2^27 + 1
  const double xh = c - (c - x), xl = x - xh;
  hi = x * x;
  lo = ((xh * xh - hi) + 2 * xh * xl) + xl * xl;
}
}  // namespace power_detail

/// Turn the ordinary bisector b of cells i and j (built from the rounded
/// q = p_j - p_i) into their power bisector: b.d becomes d above, to 8u|d|
/// (scaled with the plane where Bisector scaled it). b.d_unscaled keeps
/// |q|^2 / 2, which classify's radius test wants (the slack is in the
/// vertices' r2).
template <int D>
void weigh(filter::Bisector<D>& b, const ExactContext& ctx, std::int32_t i, std::int32_t j) {
  const double ri = ctx.radii[i], rj = ctx.radii[j];
  const double qq = 2 * b.d_unscaled;       // |q|^2 as rounded (the halving is exact)
  const double dw = (ri - rj) * (ri + rj);  // r_i^2 - r_j^2
  double d = 0.5 * (qq + dw);
  // First order, |d - exact| <= ((D + 2)u |q|^2 + 3u |dw|) / 2 + u |d| (q
  // rounded per coordinate, D squares summed; two roundings and a product
  // for dw; one sum): within 8u |d|, half the filter's bound, where
  // 2.5 |q|^2 + 1.5 |dw| <= 7 |d|.
  if (2.5 * qq + 1.5 * std::fabs(dw) <= 7 * std::fabs(d)) [[likely]] {
    b.d = b.scale == 0 ? d : std::ldexp(d, -b.scale);
    return;
  }
  const double* pi = ctx.points + static_cast<std::size_t>(i) * D;
  const double* pj = ctx.points + static_cast<std::size_t>(j) * D;
  // 2d = sum_a (p_j - p_i)_a^2 + r_i^2 - r_j^2: the large terms (each
  // square's rounded value) summed by two-sum into s, their errors (each
  // square's exactly, two_square; a difference's is its low part l, which
  // adds 2hl + l^2) into c.
  double s = 0, c = 0, m = 0;
  auto add = [&](double x) {
    const double t = s + x;
    const double z = t - s;
    c += (s - (t - z)) + (x - z);
    s = t;
    m += std::fabs(x);
  };
  double hi, lo;
  for (int a = 0; a < D; ++a) {
    const double h = pj[a] - pi[a];  // Knuth's two-difference: pj - pi = h + l exactly
    const double bv = pj[a] - h;
    const double l = (pj[a] - (h + bv)) + (bv - pi[a]);
    power_detail::two_square(h, hi, lo);
    add(hi);
    c += lo + (2 * h + l) * l;
  }
  power_detail::two_square(ri, hi, lo);
  add(hi);
  c += lo;
  power_detail::two_square(rj, hi, lo);
  add(-hi);
  c -= lo;
  d = 0.5 * (s + c);
  if (!(std::fabs(d) >= 0x1p-46 * m && m <= 0x1p990)) [[unlikely]]  // false on NaN
    d = exact_power_offset(ctx, i, j);
  b.d = b.scale == 0 ? d : std::ldexp(d, -b.scale);
}

}  // namespace tessera::kernels
