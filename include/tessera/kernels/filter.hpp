// The float filter in front of the exact predicate.
//
// A cell keeps its vertices relative to its generator (y = v - p_i), each with
// `err`, a bound on the infinity-norm distance between the computed y and the
// exact vertex of its defining planes. A plane is stored as n.y <= d (for a
// bisector with p_j: n = p_j - p_i, d = |n|^2 / 2, both rounded once). The
// clip quantity P~ = d - n.y then differs from the exact one by at most
//     |n|_1 * (err + 16u |y|_inf) + 16u |d|
// (first-order forward error of the rounded n, d and dot product, with a
// factor of two to spare). When |P~| exceeds it the float sign is certain;
// otherwise the exact predicate decides. Vertices are solved by Cramer's rule
// from three (two) planes; their `err` is u * cond * scale * 64 (Higham,
// "Accuracy and Stability of Numerical Algorithms", §1 and §9 for the bound
// shape); beyond a condition number of 1e6 the vertex is instead solved
// exactly and rounded, so every vertex position is accurate.
#pragma once

#include <cmath>
#include <limits>

namespace tessera::kernels::filter {

inline constexpr double u = std::numeric_limits<double>::epsilon() * 0.5;  // unit roundoff
inline constexpr double plane_eps = 16 * u;
inline constexpr double vertex_eps = 64 * u;
/// Absolute slack for underflow: every rounding below DBL_MIN errs by at most
/// 2^-1074 in absolute terms, far below this. The front end rescales inputs by
/// a power of two so coordinates stay within 2^±200 and this never matters on
/// sane data.
inline constexpr double abs_eps = 0x1p-900;
/// Beyond this condition number the float solve's position is too inaccurate
/// for geometry (volumes, merged coordinates): the vertex is solved exactly.
inline constexpr double exact_vertex_condition = 1e6;

/// Error bound of P~ = d - n.y for a vertex with bound `err` and |y|_inf = ymax.
/// The clippers store e = err + plane_eps * ymax per vertex and evaluate
/// n1 * e + plane_eps * |d| inline; this is the same bound spelled out.
inline double clip_error(double n1, double d, double err, double ymax) {
  return n1 * (err + plane_eps * ymax) + plane_eps * std::fabs(d);
}

}  // namespace tessera::kernels::filter
