// Floating-point expansions (kernels/expansion.hpp) against GMP rationals:
// sums, products and compression keep the exact value, and the exact
// orientation built on them agrees with a rational determinant on
// near-degenerate points (rotated lattices, points a few ulps off a plane,
// points exactly on one).
#include <gtest/gtest.h>
#include <gmpxx.h>

#include <cmath>
#include <random>
#include <vector>

#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/expansion.hpp"

namespace {

namespace ex = tessera::kernels::expansion;

mpq_class value(const ex::Expansion& e) {
  mpq_class v = 0;
  for (int i = 0; i < e.n; ++i) v += mpq_class(e.c[i]);
  return v;
}

// Components increase strictly in magnitude and none is zero.
void expect_well_formed(const ex::Expansion& e) {
  ASSERT_TRUE(e.valid());
  for (int i = 0; i < e.n; ++i) {
    EXPECT_NE(e.c[i], 0.0);
    if (i > 0) EXPECT_LT(std::fabs(e.c[i - 1]), std::fabs(e.c[i]));
  }
}

double random_double(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> e(-60, 60);
  return std::ldexp(u(rng), e(rng));
}

TEST(Expansion, SumsAndProductsAreExact) {
  std::mt19937_64 rng(1);
  ex::Workspace ws;
  for (int trial = 0; trial < 2000; ++trial) {
    ex::Expansion a, b, c, s, p;
    ex::difference(random_double(rng), random_double(rng), a);
    ex::difference(random_double(rng), random_double(rng), b);
    ex::product(a, b, c, ws);  // up to 8 components before compression
    expect_well_formed(c);
    EXPECT_EQ(value(c), value(a) * value(b));
    ex::sum(c, a, s);
    expect_well_formed(s);
    EXPECT_EQ(value(s), value(c) + value(a));
    ex::product(s, c, p, ws);
    expect_well_formed(p);
    EXPECT_EQ(value(p), value(s) * value(c));
    EXPECT_EQ(ex::sign(p), sgn(value(p)));
    ex::Expansion q;
    ex::assign(p, q);
    ex::negate(q);
    ex::Expansion zero;
    ex::sum(p, q, zero);
    EXPECT_EQ(zero.n, 0);
    ex::compress(p);
    expect_well_formed(p);
    EXPECT_EQ(value(p), value(s) * value(c));
  }
}

TEST(Expansion, RangeExcludesWhatCouldOverflowOrUnderflow) {
  const double ok[3] = {0.0, 0x1p-120, -0x1p120};
  EXPECT_TRUE(ex::exact_range(ok, 3));
  for (const double bad : {0x1p-121, 0x1p121, 1e-300, 1e300, std::nan(""), static_cast<double>(INFINITY)}) {
    const double x[2] = {1.0, bad};
    EXPECT_FALSE(ex::exact_range(x, 2)) << bad;
  }
}

int rational_orientation(const double* const* p) {
  mpq_class r[3][3];
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) r[k][d] = mpq_class(p[k + 1][d]) - mpq_class(p[0][d]);
  const mpq_class det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) -
                        r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                        r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
  return sgn(det);
}

TEST(Expansion, OrientationAgreesWithRationalsNearDegeneracy) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> g;
  std::uniform_int_distribution<int> cell(0, 40);
  int zero = 0, nonzero = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    double pts[4][3];
    if (trial % 3 == 2) {
      // Exactly on the plane z = x / 2 + y / 4, with 40-bit coordinates (too
      // many bits for the 128-bit integer stage): exact ties.
      std::uniform_int_distribution<std::int64_t> bits(-(std::int64_t{1} << 40), std::int64_t{1} << 40);
      for (auto& p : pts) {
        p[0] = std::ldexp(static_cast<double>(bits(rng)), -20);
        p[1] = std::ldexp(static_cast<double>(bits(rng)), -20);
        p[2] = p[0] / 2 + p[1] / 4;
      }
    } else if (trial % 3 == 0) {
      // Four points of one rotated lattice plane (z = 0 before rotation):
      // coplanar up to the rotation's rounding.
      const double a = g(rng), b = g(rng);
      for (auto& p : pts) {
        const double x = cell(rng), y = cell(rng), z = trial % 2 == 0 ? 0.0 : cell(rng) % 2;
        const double u = std::cos(a) * x - std::sin(a) * y, v = std::sin(a) * x + std::cos(a) * y;
        p[0] = u;
        p[1] = std::cos(b) * v - std::sin(b) * z;
        p[2] = std::sin(b) * v + std::cos(b) * z;
      }
    } else {
      // Three random points and a fourth on their plane, then moved by a
      // few ulps (or not at all).
      for (int k = 0; k < 3; ++k)
        for (double& c : pts[k]) c = random_double(rng);
      const double s = g(rng), t = g(rng);
      for (int d = 0; d < 3; ++d) pts[3][d] = pts[0][d] + s * (pts[1][d] - pts[0][d]) + t * (pts[2][d] - pts[0][d]);
      const int moves = static_cast<int>(rng() % 3);
      for (int m = 0; m < moves; ++m) {
        double& c = pts[3][rng() % 3];
        c = std::nextafter(c, INFINITY);
      }
    }
    const double* p[4] = {pts[0], pts[1], pts[2], pts[3]};
    const int expected = rational_orientation(p);
    EXPECT_EQ(tessera::kernels::orientation(3, p), expected) << "trial " << trial;
    (expected == 0 ? zero : nonzero) += 1;
  }
  EXPECT_GT(zero, 100);  // exact ties were met
  EXPECT_GT(nonzero, 1000);
}

}  // namespace
