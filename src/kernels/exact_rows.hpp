// The exact stages' shared integer machinery: a vertex's planes as integer
// rows on the input's common binary grid, and GMP scratch reused per thread.
// Internal to src/kernels (exact_predicates.cpp decides clip signs with it,
// exact_vertices.cpp solves vertices and measures cells).
#pragma once

#include <gmp.h>

#include <cstdint>

#include "tessera/kernels/exact_predicates.hpp"

namespace tessera::kernels::exact_rows {

// Scratch integers reused across calls on one thread: the exact path is rare on
// random input but common on lattices, and GMP allocation would dominate it.
struct Scratch {
  static constexpr int kMaxDim = 3;
  static constexpr int kRows = kMaxDim + 1;
  mpz_t coord[kRows + 1][kMaxDim];  // scaled coordinates of i, the plane generators and j
  mpz_t box[kRows];                 // scaled box constant for box rows
  mpz_t a[kRows][kMaxDim];          // first dim columns of M
  mpz_t b[kRows];                   // last column of M without weights
  mpz_t minor[kRows];               // minors of M without its last column
  mpz_t t0, t1, t2, acc;
  Scratch() { each(mpz_init); }
  ~Scratch() { each(mpz_clear); }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;

 private:
  // f on every integer above: the one list that init and clear share.
  template <class F>
  void each(F f) {
    for (auto& r : coord) for (auto& c : r) f(c);
    for (auto& c : box) f(c);
    for (auto& r : a) for (auto& c : r) f(c);
    for (auto& c : b) f(c);
    for (auto& c : minor) f(c);
    for (mpz_ptr c : {t0, t1, t2, acc}) f(c);
  }
};

// out = x * 2^(-shift), exactly an integer because shift <= lowest_bit_exponent(x).
void set_scaled(mpz_t out, double x, int shift);

// x / 2^shift for x = pt on a grid of step 2^shift (its bits below 2^shift
// are zero, so the arithmetic right shift is exact, negative or not; C++20
// defines it).
inline std::int64_t on_grid(const DoubleParts& pt, int shift) {
  if (pt.mant == 0) return 0;
  const int k = pt.e2 - shift;
  return k >= 0 ? pt.mant * (std::int64_t{1} << k) : pt.mant >> -k;
}

// The doubles of a vertex's rows by their bits, and their common grid: p_i
// into pv[rows], each generator row's point into pv[r], a box row's constant
// into pv[r][0]. For the integer paths, which go on to put them on the grid.
void row_parts(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, int rows, DoubleParts (*pv)[3],
               GridScale& span);

// A vertex's rows relative to p_i on the grid of step 2^shift, from the
// doubles' parts as row_parts leaves them (p_i in pv[dim]): a bisector's row
// a = 2 q, b = |q|^2 with q = p_k - p_i; a box plane's the unit axis and
// its bound less p_i; ci = p_i on the grid. Every value must lie on the
// grid below 2^61: |a| < 2^62, b < 3 2^122.
inline void relative_rows(const DoubleParts (*pv)[3], const std::int32_t* planes, int dim, int shift,
                          std::int64_t* ci, std::int64_t (*a)[3], __int128* b) {
  for (int d = 0; d < dim; ++d) ci[d] = on_grid(pv[dim][d], shift);
  for (int r = 0; r < dim; ++r) {
    for (int d = 0; d < 3; ++d) a[r][d] = 0;
    if (planes[r] >= 0) {
      __int128 sq = 0;
      for (int d = 0; d < dim; ++d) {
        const std::int64_t q = on_grid(pv[r][d], shift) - ci[d];
        a[r][d] = 2 * q;
        sq += static_cast<__int128>(q) * q;
      }
      b[r] = sq;
    } else {
      const int axis = box_plane_axis(planes[r]);
      a[r][axis] = 1;
      b[r] = on_grid(pv[r][0], shift) - ci[axis];
    }
  }
}

// cof[r][d]: the cofactor of a[r][d] (2D or 3D; below 2^125 for |a| < 2^62),
// so that det A = sum_d a[0][d] cof[0][d] and Cramer's numerator d is
// sum_r b[r] cof[r][d].
inline void cofactors(const std::int64_t (*a)[3], int dim, __int128 (*cof)[3]) {
  using I = __int128;
  if (dim == 2) {
    cof[0][0] = a[1][1], cof[0][1] = -a[1][0];
    cof[1][0] = -a[0][1], cof[1][1] = a[0][0];
    return;
  }
  for (int r = 0; r < 3; ++r) {
    const std::int64_t* u = a[(r + 1) % 3];
    const std::int64_t* w = a[(r + 2) % 3];
    cof[r][0] = static_cast<I>(u[1]) * w[2] - static_cast<I>(u[2]) * w[1];
    cof[r][1] = static_cast<I>(u[2]) * w[0] - static_cast<I>(u[0]) * w[2];
    cof[r][2] = static_cast<I>(u[0]) * w[1] - static_cast<I>(u[1]) * w[0];
  }
}

// Row `row` of s.a / s.b as the plane n.X = rhs in build_rows' integers (n
// any finite doubles, rhs an exact rational whose denominator is a power of
// two): both multiplied by the one power of two that clears every
// denominator, a positive scale that changes no sign or solution.
void set_plane_row(Scratch& s, int row, int dim, const double* n, mpq_srcptr rhs);

// det of the k x k matrix formed by rows `rows` of a (k = 2 or 3).
void det_rows(mpz_t out, mpz_t (*a)[Scratch::kMaxDim], const int* rows, int k, Scratch& s);

// Fill s.a / s.b with the rows of gen[0..rows) on the input scaled to
// integers: a bisector's row is a = 2 (p_k - p_i), b = |p_k|^2 - |p_i|^2; a
// box plane's is the unit axis and its bound; a wall's its normal and
// offset (set_plane_row). Returns the scale exponent
// (coordinates = integers * 2^shift) and leaves the scaled p_i in
// s.coord[kRows].
int build_rows(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, int rows, Scratch& s);

}  // namespace tessera::kernels::exact_rows
