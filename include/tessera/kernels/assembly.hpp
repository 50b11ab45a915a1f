// What the 2D tile and the 3D hull share in assembling a cell known whole
// in advance (its Delaunay star: CellBuilder::build_from_star) rather than
// clipping it from the box: its bisector planes, and the signs of its
// vertices against the domain box's planes (the box cuts what lies outside).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "tessera/kernels/filter.hpp"

namespace tessera::kernels::assembly {

/// Planes [first, first + m) of `planes` (resized to hold them): the
/// bisectors with the points q (relative to the generator, D each) of
/// generator ids `ids`, written as a clip writes its plane (the same d and
/// n1, so the same vertices).
template <int D, class Plane>
void bisector_planes(std::vector<Plane>& planes, std::size_t first, const std::int32_t* ids, const double* q,
                     std::size_t m) {
  planes.resize(first + m);
  for (std::size_t k = 0; k < m; ++k) {
    Plane& pl = planes[first + k];  // written in place (a copied struct stalls store forwarding)
    const double* n = q + D * k;
    double d = 0, n1 = 0;
    for (int a = 0; a < D; ++a) {
      pl.n[a] = n[a];
      d += n[a] * n[a];
      n1 += std::fabs(n[a]);
    }
    pl.d = 0.5 * d;
    pl.n1 = n1;
    pl.id = ids[k];
  }
}

/// No vertex can be placed against a box plane in floating point (box_signs).
inline constexpr std::size_t undecided = std::numeric_limits<std::size_t>::max();

/// The signs of vertices [0, nv) against the domain box's plane k (axis k / 2,
/// the upper side when k is odd: n.y <= h, n = +-e_axis, h the plane's
/// offset from the generator) by the clip's float test alone, +1 keep and
/// -1 remove, into `sign` (grown to nv + 1 if shorter; untouched when every
/// vertex is kept, and then 0 returned); returns how many are removed, or
/// `undecided` where a vertex lies within its error bound of
/// the plane: the exact clip, whose perturbation decides such a tie, must
/// build that cell. Also where a vertex's bound is NaN (Hull/Tile::solve
/// with exact_ok false: it needed the exact solve).
template <class Vertex>
std::size_t box_signs(const Vertex* verts, std::size_t nv, int k, double h, std::vector<filter::Sign>& sign) {
  const int axis = k / 2;
  const double s = (k & 1) ? 1.0 : -1.0;
  const double de = filter::plane_eps * std::fabs(h) + filter::abs_eps;
  // Nearly every plane keeps every vertex: prove that first, with no stores
  // (as the sign pass's first pass does), and write signs only otherwise.
  std::size_t first = 0;
  while (first < nv && h - s * verts[first].y[axis] > verts[first].e + de) ++first;
  if (first == nv) return 0;
  if (sign.size() < nv + 1) sign.resize(nv + 1);
  std::fill(sign.begin(), sign.begin() + static_cast<std::ptrdiff_t>(first), filter::Sign{1});
  std::size_t removed = 0;
  for (std::size_t t = first; t < nv; ++t) {
    const double P = h - s * verts[t].y[axis], e = verts[t].e + de;
    if (!(P > e || P < -e)) return undecided;
    sign[t] = P > e ? filter::Sign{1} : filter::Sign{-1};
    removed += P < -e;
  }
  return removed;
}

}  // namespace tessera::kernels::assembly
