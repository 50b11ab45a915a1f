// Exact numbers to the nearest double (src/kernels/nearest_double.hpp), as
// the exact cell measure rounds its volumes and centroids: held to the
// definition, checked in rationals: no double lies nearer, a tie goes to
// the even mantissa, an infinity only from 2^1024 - 2^970 on; across the
// subnormals, at the overflow edge, and on exact doubles and exact midpoints.
#include <gtest/gtest.h>
#include <gmpxx.h>

#include <cmath>
#include <limits>
#include <random>

#include "kernels/nearest_double.hpp"

namespace {

double to_double(const mpq_class& x) {
  mpq_class copy = x;
  return tessera::kernels::rational_to_double(copy.get_mpq_t());
}

/// |x - v| for a finite double v, exactly.
mpq_class distance(const mpq_class& x, double v) { return abs(x - mpq_class(v)); }

/// Whether v is the double nearest to x, ties to even.
void expect_nearest(const mpq_class& x, double v) {
  SCOPED_TRACE(testing::Message() << "x = " << x.get_d() << " (" << x.get_str(16) << "), v = " << v);
  constexpr double inf = std::numeric_limits<double>::infinity();
  const mpq_class overflow = mpq_class(std::ldexp(1.0, 1023)) * 2 - mpq_class(std::ldexp(1.0, 970));
  if (sgn(x) == 0) {
    EXPECT_EQ(v, 0.0);
    EXPECT_FALSE(std::signbit(v));
    return;
  }
  EXPECT_EQ(std::signbit(v), sgn(x) < 0);
  if (std::isinf(v)) {
    EXPECT_GE(abs(x), overflow);
    return;
  }
  EXPECT_LT(abs(x), overflow);
  const mpq_class d = distance(x, v);
  for (const double w : {std::nextafter(v, -inf), std::nextafter(v, inf)}) {
    if (std::isinf(w)) continue;
    const mpq_class dw = distance(x, w);
    EXPECT_LE(d, dw) << "nearer: " << w;
    if (d == dw) {  // a tie: v's mantissa is even
      int e;
      const double m = std::frexp(std::fabs(v), &e);
      const double last = std::fabs(v) < std::numeric_limits<double>::min() ? std::fabs(v) / std::ldexp(1.0, -1074)
                                                                            : std::ldexp(m, 53);
      EXPECT_EQ(std::fmod(last, 2.0), 0.0) << "tie to odd";
    }
  }
}

TEST(NearestDouble, MatchesTheDefinition) {
  std::mt19937_64 g(73);
  std::uniform_int_distribution<int> exponent(-1090, 1023);  // 1023: times 7/5 past the overflow edge
  std::uniform_int_distribution<int> kind(0, 5);
  std::uniform_real_distribution<double> unit(0.5, 1.0);
  int checked = 0;
  for (int t = 0; t < 20000; ++t) {
    const int e = exponent(g);
    const double a = std::ldexp(unit(g), std::max(e, -1074)) * (g() & 1 ? 1 : -1);
    const double b = std::nextafter(a, std::copysign(std::numeric_limits<double>::infinity(), a));
    mpq_class x;
    switch (kind(g)) {
      case 0: x = mpq_class(a); break;                                  // a double exactly
      case 1: x = (mpq_class(a) + mpq_class(std::isinf(b) ? a : b)) / 2; break;  // a midpoint: a tie
      case 2: {                                                         // a tie nudged either way
        x = (mpq_class(a) + mpq_class(std::isinf(b) ? a : b)) / 2;
        mpq_class tiny(1);
        mpz_class den(1);
        den <<= 1200;
        tiny /= den;
        x += g() & 1 ? tiny : -tiny;
        break;
      }
      case 3: {  // a random fraction of the binade (a remainder: sticky)
        mpz_class num(static_cast<unsigned long>(g() >> 1)), den(static_cast<unsigned long>((g() >> 2) | 1));
        x = mpq_class(num, den) * mpq_class(a);
        break;
      }
      case 4: x = mpq_class(a) / 3; break;
      default: x = mpq_class(a) * 7 / 5; break;
    }
    x.canonicalize();
    expect_nearest(x, to_double(x));
    ++checked;
  }
  EXPECT_EQ(checked, 20000);
}

TEST(NearestDouble, Edges) {
  const mpq_class half_min = mpq_class(std::ldexp(1.0, -1074)) / 2;  // 2^-1075: a tie between 0 and 2^-1074
  EXPECT_EQ(to_double(half_min), 0.0);                                // to even: zero
  EXPECT_EQ(to_double(half_min * 3), std::ldexp(1.0, -1073));         // 1.5 x 2^-1074: to even, 2 x 2^-1074
  EXPECT_EQ(to_double(half_min + mpq_class(1, 1) / mpq_class(mpz_class(1) << 1200)), std::ldexp(1.0, -1074));
  EXPECT_TRUE(std::signbit(to_double(-half_min)));
  const double max = std::numeric_limits<double>::max();
  const mpq_class edge = mpq_class(max) + mpq_class(std::ldexp(1.0, 970));  // 2^1024 - 2^970: rounds up
  EXPECT_TRUE(std::isinf(to_double(edge)));
  EXPECT_EQ(to_double(edge - mpq_class(1)), max);
  EXPECT_EQ(to_double(-(edge - mpq_class(1))), -max);
  EXPECT_TRUE(std::isinf(to_double(mpq_class(mpz_class(1) << 3000))));
  EXPECT_EQ(to_double(mpq_class(mpz_class(1), mpz_class(1) << 3000)), 0.0);
  EXPECT_EQ(to_double(mpq_class(std::numeric_limits<double>::min())), std::numeric_limits<double>::min());
  EXPECT_EQ(to_double(mpq_class(1, 3)), 1.0 / 3.0);  // the FPU's division rounds to nearest too
  EXPECT_EQ(to_double(mpq_class(-2, 7)), -2.0 / 7.0);
}

}  // namespace
