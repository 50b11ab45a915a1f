// Cheap tests that candidates cannot clip a cell, ahead of the sign pass:
// SupportBound for one candidate, PetalCover for a whole box of them.
//
// SupportBound: a bound on the cell's support function from its extents
// along a fixed set of directions.
//
// A bisector with q = p_j - p_i cuts vertex v iff q.v > |q|^2 / 2. The cell
// measures, once, the largest and smallest value over its vertices of the
// linear forms u.y for every direction u with entries in {0, +1, -1}
// (3D: 26 directions from 13 forms; 2D: 8 from 4). Any q is a non-negative
// combination of three such directions in its own octant: with the |q_d|
// sorted a1 >= a2 >= a3 along axes i, j, k and s_d = sign(q_d),
//     q = a3 (s_i e_i + s_j e_j + s_k e_k) + (a2 - a3) (s_i e_i + s_j e_j) + (a1 - a2) s_i e_i,
// so max_v q.v <= a3 h(body) + (a2 - a3) h(face) + (a1 - a2) h(axis), with h
// the measured extents. When that bound stays below |q|^2 / 2 by more than
// the rounding of every quantity involved, the clip predicate is positive at
// every vertex, exactly (strictly, so the symbolic perturbation never enters):
// the candidate leaves the cell unchanged, and its sign pass is skipped.
//
// Clipping only shrinks a cell, so extents measured earlier remain valid
// bounds; a stale measure is looser, never wrong. (Likewise for PetalCover.)
//
// Where they pay: a cell reaching into empty space (the edge of a cluster)
// has a security radius that holds a whole cluster of candidates, nearly all
// of them behind its generator. Their sign passes, and on the k-d tree path
// their queueing, dominated such cells.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "tessera/kernels/filter.hpp"

namespace tessera::kernels {

template <int D>
class SupportBound {
  static_assert(D == 2 || D == 3);
  // Forms: the axes, then for each axis pair (i < j) e_i + e_j and e_i - e_j,
  // then (3D) e_0 + s1 e_1 + s2 e_2 for (s1, s2) = (+,+), (+,-), (-,+), (-,-).
  static constexpr int forms = D == 3 ? 13 : 4;

 public:
  /// Measure the extents of `vertices` (each with y[D], the position relative
  /// to the generator, and e >= its error bound in the infinity norm).
  /// `slack`: a power cell's power_slack (power.hpp), 0 for an ordinary one:
  /// its bisector with q lies at d >= (|q|^2 - slack) / 2.
  template <class Vertices>
  void measure(const Vertices& vertices, double slack) {
    slack_ = slack;
    for (int f = 0; f < forms; ++f) {
      hi_[f] = -std::numeric_limits<double>::infinity();
      lo_[f] = std::numeric_limits<double>::infinity();
    }
    emax_ = 0;
    rinf_ = 0;
    for (const auto& v : vertices) {
      double f[forms];
      const double x = v.y[0], y = v.y[1];
      f[0] = x;
      f[1] = y;
      if constexpr (D == 2) {
        f[2] = x + y;
        f[3] = x - y;
      } else {
        const double z = v.y[2];
        f[2] = z;
        f[3] = x + y;
        f[4] = x - y;
        f[5] = x + z;
        f[6] = x - z;
        f[7] = y + z;
        f[8] = y - z;
        f[9] = f[3] + z;
        f[10] = f[3] - z;
        f[11] = f[4] + z;
        f[12] = f[4] - z;
      }
      for (int k = 0; k < forms; ++k) {
        hi_[k] = std::max(hi_[k], f[k]);
        lo_[k] = std::min(lo_[k], f[k]);
      }
      emax_ = std::max(emax_, v.e);
      for (int d = 0; d < D; ++d) rinf_ = std::max(rinf_, std::fabs(v.y[d]));
    }
  }

  /// True when the bisector with q = p_j - p_i (as rounded from the input)
  /// surely cuts no vertex of the measured cell.
  bool excludes(const double* q) const {
    double a[3] = {0, 0, 0};
    bool neg[3] = {false, false, false};
    for (int d = 0; d < D; ++d) {
      a[d] = std::fabs(q[d]);
      neg[d] = q[d] < 0;
    }
    int ax[3] = {0, 1, 2};  // axes by decreasing |q_d|
    if (a[ax[0]] < a[ax[1]]) std::swap(ax[0], ax[1]);
    if constexpr (D == 3) {
      if (a[ax[1]] < a[ax[2]]) std::swap(ax[1], ax[2]);
      if (a[ax[0]] < a[ax[1]]) std::swap(ax[0], ax[1]);
    }
    // h of the direction s * (form f): the form's max, or minus its min.
    auto h = [&](int f, bool negative) { return negative ? -lo_[f] : hi_[f]; };
    const int i = ax[0], j = ax[1];
    const int lo = std::min(i, j), hi = std::max(i, j);
    const bool mixed = neg[lo] != neg[hi];
    int face;
    if constexpr (D == 2) face = 2 + mixed;
    else face = (lo == 0 ? (hi == 1 ? 3 : 5) : 7) + mixed;
    double bound = (a[i] - a[j]) * h(i, neg[i]) + (D == 2 ? a[j] : a[j] - a[ax[2]]) * h(face, neg[lo]);
    if constexpr (D == 3) {
      const int body = 9 + 2 * (neg[0] != neg[1]) + (neg[0] != neg[2]);
      bound += a[ax[2]] * h(body, neg[0]);
    }
    double n1 = 0, q2 = 0;
    for (int d = 0; d < D; ++d) {
      n1 += a[d];
      q2 += q[d] * q[d];
    }
    // The vertices' errors (emax per unit of |q|_1: the coefficients' |u|_1
    // sum to |q|_1), and 1e-12 rinf per unit for the rounding of q against
    // the exact difference, of the forms and of this sum; |q|^2 likewise.
    const double slack = n1 * (emax_ + 1e-12 * rinf_);
    const double q2lo = q2 * (1.0 - 1e-12) - filter::abs_eps - slack_;
    return 2.0 * (bound + slack) < q2lo;  // false on NaN (an unbounded measure)
  }

 private:
  double hi_[forms], lo_[forms];
  double emax_ = 0, rinf_ = 0, slack_ = 0;
};

/// A cheap test that no point of a box can clip a cell: the box meets none
/// of the cell's petals. A candidate x (relative to the generator) cuts
/// vertex v iff |x - v| < |v| (q.v > |q|^2 / 2 rearranged): x lies in the
/// petal, the ball centred at v through the generator. The k-d tree path
/// skips whole nodes this way: behind a cell that reaches across empty
/// space lies a cluster no petal reaches.
///
/// Exactness: v* (the exact vertex) is within sqrt(D) e of the stored y and
/// |v*| <= sqrt(r2); the box is widened past the rounding of its corners
/// relative to the generator. A box is ruled out only when its distance to
/// y exceeds sqrt(r2) + 2e, with a relative margin far above the rounding of
/// these sums, so every point in it is strictly outside every exact petal.
/// The radius of vertex v's petal (the ball centred at v through the
/// generator), widened past every rounding: the exact vertex lies within
/// sqrt(D) e < 2e of the stored y and no farther than sqrt(r2) from the
/// generator, with a relative margin far above the rounding of the sum.
/// PetalCover and CellBuilder::certify_by_petals test against it.
template <class Vertex>
double petal_radius(const Vertex& v) {
  return (std::sqrt(v.r2) + 2.0 * v.e) * (1.0 + 1e-9);
}

template <int D>
class PetalCover {
 public:
  template <class Vertices>
  void measure(const Vertices& vertices) {
    petals_.clear();
    for (const auto& v : vertices) {
      Petal pe;
      for (int d = 0; d < D; ++d) pe.y[d] = v.y[d];
      const double r = petal_radius(v);
      pe.r2 = r * r;
      petals_.push_back(pe);
    }
  }

  /// True when no point of the box [lo, hi] (absolute coordinates) can clip
  /// the measured cell of the generator at p.
  bool excludes_box(const double* lo, const double* hi, const double* p) const {
    double blo[D], bhi[D];
    for (int d = 0; d < D; ++d) {
      // Widened by far more than the rounding of the differences.
      const double slack = 1e-15 * (std::fabs(lo[d]) + std::fabs(hi[d]) + 2.0 * std::fabs(p[d]));
      blo[d] = (lo[d] - p[d]) - slack;
      bhi[d] = (hi[d] - p[d]) + slack;
    }
    for (const Petal& pe : petals_) {
      double s2 = 0;
      for (int d = 0; d < D; ++d) {
        const double g = std::max(std::max(blo[d] - pe.y[d], 0.0), pe.y[d] - bhi[d]);
        s2 += g * g;
      }
      if (!(s2 > pe.r2)) return false;  // NaN or infinity: not ruled out
    }
    return true;
  }

 private:
  struct Petal {
    double y[D];
    double r2;  // squared radius, widened
  };
  std::vector<Petal> petals_;
};

}  // namespace tessera::kernels
