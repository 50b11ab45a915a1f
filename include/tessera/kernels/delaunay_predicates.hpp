// The predicates the Delaunay side needs beyond the clip predicate: the
// orientation of D+1 points and the in-sphere test of gift wrapping.
//
// Both are filtered (a float evaluation with a static forward error bound,
// after Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
// Geometric Predicates", 1997) and fall back to exact arithmetic. The in-sphere
// test is the clip predicate in disguise (exact_predicates.hpp): "is q inside
// the sphere through a and the points of `planes`" is "does q clip the Voronoi
// vertex of a where those bisectors meet", so it carries the same symbolic
// perturbation and agrees with every decision the cells pass made.
#pragma once

#include <cmath>
#include <cstdint>

#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/filter.hpp"

namespace tessera::kernels {

namespace detail {
/// det of the D x D matrix of rows r0, r1 (and r2 in 3D) and its permanent
/// (for the error bound), in the arithmetic T of the rows.
template <class T>
inline T det_perm(const T* r0, const T* r1, const T* r2, int dim, T& perm) {
  using std::fabs;
  if (dim == 2) {
    const T a = r0[0] * r1[1], b = r0[1] * r1[0];
    perm = fabs(a) + fabs(b);
    return a - b;
  }
  const T c0 = r1[1] * r2[2] - r1[2] * r2[1];
  const T c1 = r1[2] * r2[0] - r1[0] * r2[2];
  const T c2 = r1[0] * r2[1] - r1[1] * r2[0];
  const T p0 = fabs(r1[1] * r2[2]) + fabs(r1[2] * r2[1]);
  const T p1 = fabs(r1[2] * r2[0]) + fabs(r1[0] * r2[2]);
  const T p2 = fabs(r1[0] * r2[1]) + fabs(r1[1] * r2[0]);
  perm = fabs(r0[0]) * p0 + fabs(r0[1]) * p1 + fabs(r0[2]) * p2;
  return r0[0] * c0 + r0[1] * c1 + r0[2] * c2;
}
inline double det_perm(const double (*r)[3], int dim, double& perm) { return det_perm(r[0], r[1], r[2], dim, perm); }
}  // namespace detail

/// The float filter of `orientation`: rows[k] = p_{k+1} - p_0, each
/// coordinate the rounded difference of the input coordinates (a cell's
/// bisector normals are exactly these). +1 / -1 when the sign of the
/// determinant is certain, 0 when only the exact evaluation can tell.
inline int orientation_filter(int D, const double* const* rows) {
  double r[3][3] = {};
  for (int k = 0; k < D; ++k)
    for (int d = 0; d < D; ++d) r[k][d] = rows[k][d];
  double perm;
  const double det = detail::det_perm(r, D, perm);
  // Shewchuk's bounds are 3u (2D) and 7u (3D) of the permanent including the
  // rounded differences; 16u leaves room to spare. Underflow: each cofactor
  // errs by 2 eta, times |r0[e]|, plus eta per product (filter::underflow_bound).
  const double growth = 2 * (std::fabs(r[0][0]) + std::fabs(r[0][1]) + std::fabs(r[0][2])) + 3;
  const double bound = 16 * filter::u * perm + filter::underflow_bound(growth);
  return det > bound ? 1 : (det < -bound ? -1 : 0);
}

/// Exact sign of det[p1-p0, ..., pD-p0] for D+1 points given by id (D = ctx.dim):
/// +1 counter-clockwise (2D) / positively oriented (3D), -1 the reverse, 0 when
/// the points are collinear / coplanar. No perturbation: flat is flat.
int orientation(const ExactContext& ctx, const std::int32_t* ids);

/// The same for D+1 points given by their coordinates (D = 2 or 3), which
/// need not be input points (hull completion asks it of box corners).
int orientation(int D, const double* const* pts);

/// The same sign, for a caller whose own float filter was undecided (the
/// spherical cells' clip): the extended-precision stage first, which
/// decides a near-tie in a few dozen cycles (a lon/lat grid's trapezoids are
/// cocircular to a rounding), then the exact stages. Correct whatever the
/// caller's filter did.
int orientation_past_filter(int D, const double* const* pts);

/// Do three 3D points lie on one line? Exactly: their projections on all
/// three coordinate planes are collinear. No perturbation.
inline bool collinear3(const double* a, const double* b, const double* c) {
  for (int d = 0; d < 3; ++d) {
    const int e = (d + 1) % 3;
    const double x[2] = {a[d], a[e]}, y[2] = {b[d], b[e]}, z[2] = {c[d], c[e]};
    const double* tri[3] = {x, y, z};
    if (orientation(2, tri) != 0) return false;
  }
  return true;
}

/// Is q strictly inside the circumsphere of a and planes[0..D) (D = ctx.dim), in
/// the perturbed sense of the clip predicate? Never undecided. Precondition: a
/// and the planes are affinely independent, q is none of them.
bool in_sphere(const ExactContext& ctx, std::int32_t a, const std::int32_t* planes, std::int32_t q);

/// The same answer, for a caller whose own double filter (the quantities and
/// bound of in_sphere's, evaluated in any order: insertion_filters.hpp) was
/// undecided: starts at the long double stage, as in_sphere's double filter
/// would almost surely be undecided again. Correct whatever the caller did.
bool in_sphere_past_filter(const ExactContext& ctx, std::int32_t a, const std::int32_t* planes, std::int32_t q);

}  // namespace tessera::kernels
