// A slab bound for a group of points: the thin disc (a thin rectangle in 2D)
// that holds them, for pruning ball queries on points sampled on a surface.
//
// A tree node's axis-aligned box is a poor bound for a patch of a curved
// surface: unless the surface is parallel to an axis, the box is about as
// thick as it is wide. A ball that nearly touches the surface (a petal inside
// a closed surface, the circumsphere of a thin simplex near a terrain's hull)
// then meets the boxes of every patch within a wide band around the contact,
// and each must be opened. The points themselves lie within a thin slab
// around their best-fit plane, and the distance from a query to that slab
// bounds the distance to every point: only the patches within about a patch
// width of the contact remain (the ellipsoid's petal searches opened ~80
// leaves by their boxes, ~7 by slabs).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

namespace tessera::kernels {

template <int D>
struct Slab {
  std::array<double, D> c{}, nrm{};  ///< centre (the points' centroid) and unit normal
  double rho = 0;                    ///< largest distance from c within the plane, grown by a margin
  double thick = std::numeric_limits<double>::infinity();  ///< largest distance along nrm, grown likewise

  /// Only a slab much thinner than it is wide bounds better than the box it
  /// comes with; the others are never tested (excludes() returns false).
  static constexpr double flat = 0.25;

  /// The slab of `count` points, at(k) the coordinates of the k-th. nrm is
  /// the direction of least spread (the covariance's smallest eigenvector,
  /// by power iteration on trace - covariance): any unit vector gives a
  /// valid bound, a good one a tight bound. rho and thick are measured from
  /// the same rounded c and nrm the queries use, then grown by a margin far
  /// above the rounding of these sums (relative ~1e-15 of the magnitudes).
  template <class At>
  static Slab fit(std::size_t count, At&& at) {
    Slab s;
    if (count == 0) return s;
    for (std::size_t k = 0; k < count; ++k)
      for (int d = 0; d < D; ++d) s.c[d] += at(k)[d];
    for (int d = 0; d < D; ++d) s.c[d] /= static_cast<double>(count);
    double cov[D][D] = {};
    for (std::size_t k = 0; k < count; ++k) {
      double w[D];
      for (int d = 0; d < D; ++d) w[d] = at(k)[d] - s.c[d];
      for (int a = 0; a < D; ++a)
        for (int b = 0; b < D; ++b) cov[a][b] += w[a] * w[b];
    }
    double tr = 0;
    for (int d = 0; d < D; ++d) tr += cov[d][d];
    double n[D];
    for (int d = 0; d < D; ++d) n[d] = 1.0 + 0.1 * d;  // not orthogonal to any axis
    double top = 0;  // the last |(tr - cov) n|: tr less the least variance, once converged
    for (int it = 0; it < 24; ++it) {
      double y[D], len = 0;
      for (int a = 0; a < D; ++a) {
        y[a] = tr * n[a];
        for (int b = 0; b < D; ++b) y[a] -= cov[a][b] * n[b];
        len += y[a] * y[a];
      }
      len = std::sqrt(len);
      if (!(len > 0) || !std::isfinite(len)) break;  // all points equal, or overflow: keep n
      top = len;
      for (int d = 0; d < D; ++d) n[d] = y[d] / len;
    }
    // A set whose least variance is over 1/8 of the mean of the others is
    // no slab (a box of points would have to be 2.8 times wider than
    // thick; flat needs 4): thick stays infinite and the measuring pass is
    // skipped. Such are nearly all the nodes of a volume's points (the
    // skipped cells' candidates), whose slabs cost 1% of a Delaunay run.
    // Only a performance choice: any slab, or none, is a valid bound.
    if (top > 0 && tr - top > 0.125 * top / (D - 1)) return s;
    double len = 0;
    for (int d = 0; d < D; ++d) len += n[d] * n[d];
    len = std::sqrt(len);
    for (int d = 0; d < D; ++d) s.nrm[d] = n[d] / len;
    s.thick = 0;
    for (std::size_t k = 0; k < count; ++k) {
      double w[D], a = 0, b2 = 0;
      for (int d = 0; d < D; ++d) {
        w[d] = at(k)[d] - s.c[d];
        a += w[d] * s.nrm[d];
      }
      for (int d = 0; d < D; ++d) {
        const double u = w[d] - a * s.nrm[d];
        b2 += u * u;
      }
      s.rho = std::max(s.rho, std::sqrt(b2));
      s.thick = std::max(s.thick, std::fabs(a));
    }
    double mag = 0;
    for (int d = 0; d < D; ++d) mag = std::max(mag, std::fabs(s.c[d]));
    const double margin = 1e-9 * (mag + s.rho + s.thick);
    s.rho += margin;
    s.thick += margin;
    if (!std::isfinite(s.rho) || !std::isfinite(s.thick)) s.thick = std::numeric_limits<double>::infinity();
    return s;
  }

  /// A plane m.(x - o) = -margin for below(): the normal scaled by a power
  /// of two to a largest component in [1, 2), and the margin with it. A
  /// facet normal of coordinates with subnormal offsets can be so small that
  /// its squares underflow (found by the subnormal-offset test, where |n|
  /// computed as 0 dropped the rho term below). ok is false for a zero or
  /// non-finite normal.
  struct Plane {
    double m[D], o[D], margin, mlen;
    bool ok = false;
    Plane(const double* n, const double* origin, double margin_n) {
      double big = 0;
      for (int d = 0; d < D; ++d) big = std::max(big, std::fabs(n[d]));
      if (!(big > 0) || !std::isfinite(big)) return;
      const int e = std::ilogb(big);
      double mm = 0;
      for (int d = 0; d < D; ++d) {
        m[d] = std::scalbn(n[d], -e);
        o[d] = origin[d];
        mm += m[d] * m[d];
      }
      margin = std::scalbn(margin_n, -e);
      mlen = std::sqrt(mm);
      ok = true;
    }
  };

  /// Whether the slab lies wholly below the plane, m.(x - o) < -margin for
  /// every point x in it: false unless flat. The largest value over the slab
  /// is m.(c - o) plus thick |m.nrm| plus rho |m - (m.nrm) nrm|, and a
  /// tolerance far above the rounding of these sums is added, relative (1e-9
  /// of the magnitudes) and absolute (2^-900, above any underflow of the
  /// products). A curved patch's box crosses a plane tangent to the patch (a
  /// convex hull facet of a surface sample) far more often than its slab does.
  bool below(const Plane& p) const {
    if (!(thick < flat * rho) || !p.ok) return false;
    double top = 0, along = 0, wm = 0;
    for (int d = 0; d < D; ++d) {
      top += p.m[d] * (c[d] - p.o[d]);
      along += p.m[d] * nrm[d];
      wm = std::max(wm, std::fabs(c[d] - p.o[d]));
    }
    top += std::fabs(along) * thick + std::sqrt(std::max(0.0, p.mlen * p.mlen - along * along)) * rho;
    return top + 1e-9 * p.mlen * (D * wm + rho + thick) + 0x1p-900 < -p.margin;
  }

  /// Whether the slab lies wholly farther than r from x (r: the query ball's
  /// radius), so that none of its points is within r: false unless flat.
  /// Every gap is shrunk by a margin m far above the rounding of these sums
  /// and every reach grown by it (r's own rounding included: where a test
  /// can exclude, the offset from c is at least about r).
  bool excludes(const double* x, double r) const {
    if (!(thick < flat * rho)) return false;
    double a = 0, wm = 0;
    for (int d = 0; d < D; ++d) {
      const double w = x[d] - c[d];
      a += w * nrm[d];
      wm = std::max(wm, std::fabs(w));
    }
    const double m = 1e-9 * wm;
    const double ga = std::fabs(a) - thick - m;  // gap along the normal
    if (ga > r) return true;
    // Squared distance from the normal through c. The offsets x - c are
    // recomputed (the same roundings) rather than kept in an array: GCC
    // spilled one and reloaded it as a vector pair, a store-forwarding
    // stall that was a fifth of this test's time.
    double b2 = 0;
    for (int d = 0; d < D; ++d) {
      const double u = (x[d] - c[d]) - a * nrm[d];
      b2 += u * u;
    }
    const double rb = rho + m;
    if (b2 <= rb * rb) return false;  // over the disc: the normal gap decides
    // Beside the disc: the gap in the plane, sqrt(b2) - rb, against the
    // reach left after the normal gap.
    const double reach = ga > 0 ? std::sqrt(std::max(0.0, r * r - ga * ga)) : r;
    return b2 > (rb + reach) * (rb + reach);
  }
};

}  // namespace tessera::kernels
