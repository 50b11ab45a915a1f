// Simulation of Simplicity for the 3D orientation; see sphere_predicates.hpp.
#include "tessera/kernels/sphere_predicates.hpp"

#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <stdexcept>

#include "tessera/kernels/delaunay_predicates.hpp"

namespace tessera::kernels {
namespace {

// det of a 4x4 rational matrix by cofactors along the first row (only
// reached on exact ties: a few hundred operations on small rationals).
mpq_class det3(const std::array<std::array<mpq_class, 4>, 4>& m, int r0, int r1, int r2, int c0, int c1, int c2) {
  return m[r0][c0] * (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) -
         m[r0][c1] * (m[r1][c0] * m[r2][c2] - m[r1][c2] * m[r2][c0]) +
         m[r0][c2] * (m[r1][c0] * m[r2][c1] - m[r1][c1] * m[r2][c0]);
}

int det4_sign(const std::array<std::array<mpq_class, 4>, 4>& m) {
  mpq_class det = 0;
  for (int c = 0; c < 4; ++c) {
    if (sgn(m[0][c]) == 0) continue;
    int cols[3], k = 0;
    for (int e = 0; e < 4; ++e)
      if (e != c) cols[k++] = e;
    const mpq_class minor = det3(m, 1, 2, 3, cols[0], cols[1], cols[2]);
    det += (c % 2 == 0 ? 1 : -1) * m[0][c] * minor;
  }
  return sgn(det);
}

}  // namespace

int orientation_tie_break(const double* const* pts, const std::int32_t* ids) {
  // Rows [x y z 1] in increasing id; det[b-a, c-a, s-a] = -det of the 4x4
  // [[a 1], [b 1], [c 1], [s 1]] (subtract the first row, expand along the
  // ones), and sorting the rows multiplies the sign by the permutation's.
  std::array<int, 4> order{0, 1, 2, 3};
  std::sort(order.begin(), order.end(), [&](int x, int y) { return ids[x] < ids[y]; });
  int parity = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (order[i] > order[j]) parity = -parity;
  // The first three terms (masks 1, 2, 4: the lowest id moved along x, y,
  // z) are the cofactors of its row, (-1)^axis times the orientation of the
  // other three points projected on the other two axes: exact 2D
  // orientations on the doubles, no rationals. Three points of a sphere
  // are never collinear, so for four cocircular points one of them decides.
  for (int axis = 0; axis < 3; ++axis) {
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    double q[3][2];
    for (int r = 1; r < 4; ++r) {
      q[r - 1][0] = pts[order[r]][u];
      q[r - 1][1] = pts[order[r]][v];
    }
    // Three projections on one axis-parallel line (a row of a lon/lat grid
    // seen along x or y) are collinear without arithmetic.
    if ((q[0][0] == q[1][0] && q[0][0] == q[2][0]) || (q[0][1] == q[1][1] && q[0][1] == q[2][1])) continue;
    const double* tri[3] = {q[0], q[1], q[2]};
    if (const int o = orientation(2, tri)) return -parity * (axis == 1 ? -o : o);
  }
  std::array<std::array<mpq_class, 4>, 4> rows;
  for (int r = 0; r < 4; ++r) {
    for (int d = 0; d < 3; ++d) rows[r][d] = pts[order[r]][d];
    rows[r][3] = 1;
  }
  // The determinant is multilinear in the rows: the coefficient of the
  // monomial that moves row r along axis c(r) for the rows of a set S is the
  // determinant with those rows replaced by the unit vectors e_c(r). With
  // exponents 2^(3r + c), a monomial's exponent is the bit mask of its
  // (row, axis) pairs, so increasing masks are decreasing terms. A mask that
  // moves a row twice is no term; one that uses an axis twice has a zero
  // coefficient. The mask moving three rows along x, y, z leaves the fourth
  // row's 1 alone in the last column: its coefficient is +-1, so the loop
  // always ends.
  for (unsigned mask = 8; mask < (1u << 12); ++mask) {  // (1, 2, 4 were zero)
    unsigned axes = 0;
    bool valid = true;
    for (int r = 0; r < 4 && valid; ++r) {
      const unsigned bits = (mask >> (3 * r)) & 7u;
      if (bits == 0) continue;
      if ((bits & (bits - 1)) != 0 || (axes & bits) != 0) valid = false;
      axes |= bits;
    }
    if (!valid) continue;
    auto m = rows;
    for (int r = 0; r < 4; ++r) {
      const unsigned bits = (mask >> (3 * r)) & 7u;
      if (bits == 0) continue;
      for (int c = 0; c < 4; ++c) m[r][c] = 0;
      m[r][bits == 1 ? 0 : (bits == 2 ? 1 : 2)] = 1;
    }
    if (const int s = det4_sign(m)) return -parity * s;
  }
  throw std::logic_error("orientation_tie_break: no non-zero coefficient (impossible)");
}

int orientation_sos(const double* a, const double* b, const double* c, const double* s, std::int32_t ia,
                    std::int32_t ib, std::int32_t ic, std::int32_t is) {
  const double* pts[4] = {a, b, c, s};
  const std::int32_t ids[4] = {ia, ib, ic, is};
  // Four points on one axis-aligned plane are coplanar: no arithmetic (a
  // lon/lat grid's row shares its z, a pole's points their z = R; most of a
  // grid's ties are these).
  for (int d = 0; d < 3; ++d)
    if (a[d] == b[d] && a[d] == c[d] && a[d] == s[d]) return orientation_tie_break(pts, ids);
  if (const int sign = orientation_past_filter(3, pts)) return sign;
  return orientation_tie_break(pts, ids);
}

}  // namespace tessera::kernels
