// Exact ties on tensor-product grids, decided from the coordinates' pattern.
//
// Points whose coordinates along each axis come from a per-axis list
// (lattices of any spacing, voxel centres of a scan with spacing 0.7 x 0.7 x
// 1.2 mm, rectilinear grids) tie at every corner of their cells: the corners
// of any axis-aligned box lie on one sphere (circle in 2D), its centre the
// box's centre. So whenever the vertex's generator p_i, its bisectors'
// generators and the candidate p_j all sit at corners of one axis-aligned
// box, exact_clip_sign's determinant det M0 is exactly zero and only the
// symbolic perturbation decides. Its terms are the cofactors of A, and on a
// box every bisector row is a_r = 2 q_r with q_r = E_r diag(Delta): E_r a 0/1
// row saying on which axes p_r leaves p_i, Delta_d the box's extent along d
// from p_i (its sign included). So every cofactor is det(E') * 2^D * prod
// Delta with E' a 0/1 matrix, and its sign is sign(det E') times the sign of
// prod Delta: a handful of small integer products, no arithmetic on the
// coordinates at all, where the integer stages (VertexPredicate, or
// WidePredicate off a 22-bit grid: ~250 cycles per call with its
// preparation) computed the same zero.
//
// A domain-box plane among the vertex's planes (the cells along the box) is
// a unit row e_axis of A. Where every point holds p_i's value on that axis,
// M0's column there has the box row's 1 alone, and expanding along it leaves
// the same question one dimension down: the points at corners of a box in
// the other axes tie. So E takes the unit row, the axis takes no Delta, and
// a candidate must hold p_i's value there too.
//
// Same sign as exact_clip_sign, always: det M0 = 0 is a theorem here, not a
// rounding, and the tie-break is the one of PerturbationTerms with the
// cofactors' exact signs.
#pragma once

#include <cstdint>

#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::kernels {

/// D: the dimension (2 or 3), fixed so that every loop unrolls (with the
/// dimension at run time, the compiler copied rows with generic loops).
template <int D>
class BoxTiePredicate {
  static_assert(D == 2 || D == 3);

 public:
  /// Prepare for the vertex of cell i where planes[0..dim) meet. False
  /// (unusable) when p_i and the bisectors' generators are not corners of one
  /// axis-aligned box spanning every axis no box plane holds, or when every
  /// plane is a box plane.
  bool prepare(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes) {
    const double* pi = ctx.points + static_cast<std::size_t>(i) * D;
    // E's rows: a bisector's 0/1 pattern, a box plane's unit row (it meets
    // no Delta: its axis is held at p_i's value by every point, see sign()).
    int e[3][3] = {};
    unsigned box_axes = 0;
    bool bisector = false;
    for (int r = 0; r < D; ++r) {
      if (planes[r] < 0) {
        const int axis = box_plane_axis(planes[r]);
        e[r][axis] = 1;
        box_axes |= 1u << axis;
      } else {
        bisector = true;
      }
    }
    if (!bisector) return false;  // a corner of the domain: no tie of this kind
    int delta_sign = 1;
    for (int d = 0; d < D; ++d) {
      const double base = pi[d];
      const bool held = (box_axes >> d) & 1u;
      bool seen = false;
      double other = base;
      for (int r = 0; r < D; ++r) {
        if (planes[r] < 0) continue;
        const double x = ctx.points[static_cast<std::size_t>(planes[r]) * D + d];
        if (x == base) continue;
        if (held || (seen && x != other)) return false;  // off a box plane's axis, or a third value
        other = x;
        seen = true;
        e[r][d] = 1;
      }
      if (!held && !seen) return false;  // flat along d: the planes are dependent
      if (other < base) delta_sign = -delta_sign;
      base_[d] = base;
      other_[d] = held ? base : other;  // a held axis admits p_i's value only
    }
    // E's cofactors, so that det(E with row r replaced by e) = e . cof[r].
    int cof[3][3] = {};
    if constexpr (D == 2) {
      cof[0][0] = e[1][1], cof[0][1] = -e[1][0];
      cof[1][0] = -e[0][1], cof[1][1] = e[0][0];
    } else {
      for (int r = 0; r < 3; ++r) {
        const int* u = e[(r + 1) % 3];
        const int* w = e[(r + 2) % 3];
        cof[r][0] = u[1] * w[2] - u[2] * w[1];
        cof[r][1] = u[2] * w[0] - u[0] * w[2];
        cof[r][2] = u[0] * w[1] - u[1] * w[0];
      }
    }
    int det_e = 0;
    for (int d = 0; d < D; ++d) det_e += e[0][d] * cof[0][d];
    if (det_e == 0) return false;  // dependent planes: the later stages report it
    // Stored only now: written as vectors and read back as ints, the
    // cofactors stalled store forwarding.
    for (int r = 0; r < D; ++r)
      for (int d = 0; d < D; ++d) cof_[r][d] = cof[r][d];
    det_e_ = det_e;
    delta_sign_ = delta_sign;
    det_a_sign_ = (det_e > 0 ? 1 : -1) * delta_sign;
    terms_.set(i, planes, D);
    return true;
  }

  /// exact_clip_sign(ctx, i, planes, j) into `out` when p_j is a corner of the
  /// vertex's box (a tie); false otherwise (the caller asks the other stages).
  bool sign(const ExactContext& ctx, std::int32_t j, int& out) const {
    const double* pj = ctx.points + static_cast<std::size_t>(j) * D;
    int ej[3] = {0, 0, 0};
    for (int d = 0; d < D; ++d) {
      if (pj[d] == base_[d]) continue;
      if (pj[d] != other_[d]) return false;
      ej[d] = 1;
    }
    // det M0 = 0 (corners of one box are cospherical), so the weights'
    // coefficients decide, as in VertexPredicate::sign, each a det(E') times
    // 2^D prod Delta. A box row's dr is zero (e_j holds the row's axis at
    // p_i's value, so that column of the replaced matrix is empty), so wi
    // may sum every row.
    int dr[3] = {0, 0, 0}, wi = det_e_;
    for (int r = 0; r < D; ++r) {
      for (int d = 0; d < D; ++d) dr[r] += ej[d] * cof_[r][d];
      wi -= dr[r];
    }
    auto sgn = [&](int x) { return ((x > 0) - (x < 0)) * delta_sign_; };
    const int sign_m = terms_.decide(j, -det_a_sign_, [&](int row) { return row < 0 ? sgn(wi) : sgn(dr[row]); });
    out = sign_m * det_a_sign_ > 0 ? +1 : -1;
    return true;
  }

 private:
  double base_[3] = {0, 0, 0}, other_[3] = {0, 0, 0};  // the box's two values per axis, p_i's first
  int cof_[3][3] = {};
  int det_e_ = 0, delta_sign_ = 1, det_a_sign_ = 0;
  PerturbationTerms terms_;
};

/// One unprepared question: exact_clip_sign(ctx, i, planes, j) into `out`
/// when the vertex and p_j are corners of one box, else false.
template <int D>
bool box_tie_sign(const ExactContext& ctx, std::int32_t i, const std::int32_t* planes, std::int32_t j, int& out) {
  BoxTiePredicate<D> box;
  return box.prepare(ctx, i, planes) && box.sign(ctx, j, out);
}

}  // namespace tessera::kernels
