// What the 2D tile and the 3D hull share in assembling a cell known whole
// in advance (its Delaunay star: CellBuilder::build_from_star) rather than
// clipping it from the box: its bisector planes, the test that a vertex
// lies inside the domain box, and the signs of the vertices against a box
// plane where some do not.
#pragma once

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

/// Whether vertices lie inside the domain box [lo, hi] around the generator
/// p by more than every rounding: a vertex's error bound err is below
/// e - plane_eps |y|_inf, which covers the rounding of y + e, and the margin
/// covers that of hi - p. False for a vertex that would need the exact
/// solve (its bound is NaN: Hull/Tile::solve with exact_ok false).
template <int D>
class BoxRoom {
 public:
  BoxRoom(const double* p, const double* lo, const double* hi) {
    for (int a = 0; a < D; ++a) {
      hi_[a] = (hi[a] - p[a]) * (1 - 1e-10);
      lo_[a] = (p[a] - lo[a]) * (1 - 1e-10);
    }
  }
  template <class Vertex>
  bool holds(const Vertex& v) const {
    bool in = true;
    for (int a = 0; a < D; ++a) in &= (v.y[a] + v.e < hi_[a]) & (v.e - v.y[a] < lo_[a]);  // false on NaN
    return in;
  }

 private:
  double hi_[D], lo_[D];
};

/// No vertex can be placed against a box plane in floating point (box_signs).
inline constexpr std::size_t undecided = std::numeric_limits<std::size_t>::max();

/// The signs of vertices [0, nv) against the domain box's plane k (axis k / 2,
/// the upper side when k is odd: n.y <= h, n = +-e_axis, h the plane's
/// offset from the generator) by the clip's float test alone, +1 keep and
/// -1 remove, into `sign` (grown to nv + 1 if shorter); returns how many are
/// removed, or `undecided` where a vertex lies within its error bound of
/// the plane (NaN too): the exact clip, whose perturbation decides such a
/// tie, must build that cell.
template <class Vertex>
std::size_t box_signs(const Vertex* verts, std::size_t nv, int k, double h, std::vector<filter::Sign>& sign) {
  const int axis = k / 2;
  const double s = (k & 1) ? 1.0 : -1.0;
  const double de = filter::plane_eps * std::fabs(h) + filter::abs_eps;
  if (sign.size() < nv + 1) sign.resize(nv + 1);
  std::size_t removed = 0;
  for (std::size_t t = 0; t < nv; ++t) {
    const double P = h - s * verts[t].y[axis], e = verts[t].e + de;
    if (!(P > e || P < -e)) return undecided;
    sign[t] = P > e ? filter::Sign{1} : filter::Sign{-1};
    removed += P < -e;
  }
  return removed;
}

}  // namespace tessera::kernels::assembly
