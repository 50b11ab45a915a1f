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
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

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

/// The sign pass every clip starts with, shared by the 2D tile and the 3D hull.
///
/// Vertices carry y[D] (relative to the generator), e = err + plane_eps*|y|_inf
/// and r2 (an upper bound on the exact |y|^2). The plane is n.y <= d with
/// |n|_1 = n1, d = |q|^2/2. Fills `sign` with +1 (keep) / -1 (remove), asking
/// `exact(vertex)` only where the filter cannot decide, and returns the number
/// removed. A vertex no farther than |q|/2 from the generator cannot be cut:
/// q.y <= |q||y| <= |q|^2/2 (equality would need y = q/2 exactly, which the
/// strict margin excludes). Candidates usually fail to clip; a first pass over
/// the far vertices only proves that, and then `sign` is left untouched.
template <int D, class Vertex, class Exact>
std::size_t classify(const std::vector<Vertex>& verts, const double* n, double d, double n1,
                     std::vector<std::int8_t>& sign, Exact&& exact) {
  const std::size_t nv = verts.size();
  const double q2lo = 2.0 * d * (1.0 - 1e-12) - abs_eps;  // <= the exact |p_j - p_i|^2
  const double de = plane_eps * std::fabs(d) + abs_eps;
  auto plane_value = [&](const Vertex& v) {
    double dot = 0;
    for (int k = 0; k < D; ++k) dot += n[k] * v.y[k];
    return d - dot;
  };
  bool may_cut = false;
  for (std::size_t t = 0; t < nv && !may_cut; ++t) {
    const Vertex& v = verts[t];
    if (4.0 * v.r2 < q2lo) continue;
    may_cut = !(plane_value(v) > n1 * v.e + de);
  }
  if (!may_cut) return 0;
  sign.resize(nv);
  std::size_t removed = 0, uncertain = 0;
  for (std::size_t t = 0; t < nv; ++t) {
    const Vertex& v = verts[t];
    int s = 1;
    if (4.0 * v.r2 >= q2lo) {
      double P = plane_value(v);
      double e = n1 * v.e + de;
      s = (P > e) - (P < -e);
    }
    sign[t] = static_cast<std::int8_t>(s);
    removed += (s < 0);
    uncertain += (s == 0);
  }
  for (std::size_t t = 0; uncertain && t < nv; ++t) {
    if (sign[t] != 0) continue;
    sign[t] = static_cast<std::int8_t>(exact(verts[t]));
    removed += (sign[t] < 0);
    --uncertain;
  }
  return removed;
}

}  // namespace tessera::kernels::filter
