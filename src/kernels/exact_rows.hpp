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
  Scratch() {
    for (auto& r : coord) for (auto& c : r) mpz_init(c);
    for (auto& c : box) mpz_init(c);
    for (auto& r : a) for (auto& c : r) mpz_init(c);
    for (auto& c : b) mpz_init(c);
    for (auto& c : minor) mpz_init(c);
    mpz_init(t0); mpz_init(t1); mpz_init(t2); mpz_init(acc);
  }
  ~Scratch() {
    for (auto& r : coord) for (auto& c : r) mpz_clear(c);
    for (auto& c : box) mpz_clear(c);
    for (auto& r : a) for (auto& c : r) mpz_clear(c);
    for (auto& c : b) mpz_clear(c);
    for (auto& c : minor) mpz_clear(c);
    mpz_clear(t0); mpz_clear(t1); mpz_clear(t2); mpz_clear(acc);
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

// det of the k x k matrix formed by rows `rows` of a (k = 2 or 3).
void det_rows(mpz_t out, mpz_t (*a)[Scratch::kMaxDim], const int* rows, int k, Scratch& s);

// Fill s.a / s.b with the rows of gen[0..rows) on the input scaled to
// integers: a bisector's row is a = 2 (p_k - p_i), b = |p_k|^2 - |p_i|^2; a
// box plane's is the unit axis and its bound. Returns the scale exponent
// (coordinates = integers * 2^shift) and leaves the scaled p_i in
// s.coord[kRows].
int build_rows(const ExactContext& ctx, std::int32_t i, const std::int32_t* gen, int rows, Scratch& s);

}  // namespace tessera::kernels::exact_rows
