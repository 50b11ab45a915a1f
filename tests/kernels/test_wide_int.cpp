// WideInt against GMP: products of random signed operands of every size
// (exact, in the sum of the operands' limbs), sums and differences wherever
// they fit, and signs, with the extremes (zero, minus one, the most negative
// values).
#include <gtest/gtest.h>
#include <gmpxx.h>

#include <cstdint>
#include <random>

#include "tessera/kernels/wide_int.hpp"

namespace {

using tessera::kernels::WideInt;

template <int N>
mpz_class to_mpz(const WideInt<N>& w) {
  mpz_class r = 0;
  for (int k = N - 1; k >= 0; --k) {
    r <<= 64;
    r += mpz_class(static_cast<unsigned long>(w.limb[k]));
  }
  if (static_cast<std::int64_t>(w.limb[N - 1]) < 0) r -= mpz_class(1) << (64 * N);
  return r;
}

__int128 random_int128(std::mt19937_64& g, int bits) {
  if (bits == 0) return 0;
  unsigned __int128 m = (static_cast<unsigned __int128>(g()) << 64) | g();
  if (bits < 128) m &= (static_cast<unsigned __int128>(1) << bits) - 1;
  const auto v = static_cast<__int128>(m >> 1);  // below 2^(bits-1): fits signed
  return (g() & 1) ? -v : v;
}

mpz_class to_mpz(__int128 x) {
  const bool neg = x < 0;
  unsigned __int128 m = neg ? -static_cast<unsigned __int128>(x) : static_cast<unsigned __int128>(x);
  mpz_class r = mpz_class(static_cast<unsigned long>(m >> 64));
  r <<= 64;
  r += mpz_class(static_cast<unsigned long>(m));
  return neg ? mpz_class(-r) : r;
}

TEST(WideInt, MatchesGmp) {
  std::mt19937_64 g(5);
  using W1 = WideInt<1>;
  using W2 = WideInt<2>;
  int checked = 0;
  for (int t = 0; t < 20000; ++t) {
    // A product of two int128 (4 limbs), times an int64 (5 limbs), then
    // summed with products of that size: sizes drawn at random, up to the
    // largest that fit (so some sums wrap past 5 limbs' signed range and are
    // skipped by the check).
    const __int128 a = random_int128(g, static_cast<int>(g() % 129));
    const __int128 b = random_int128(g, static_cast<int>(g() % 129));
    const auto c = static_cast<std::int64_t>(random_int128(g, static_cast<int>(g() % 65)));
    const WideInt<4> ab = multiply(W2::from(a), W2::from(b));
    ASSERT_EQ(to_mpz(ab), to_mpz(a) * to_mpz(b));
    const WideInt<5> abc = multiply(W1::from_int64(c), ab);
    const mpz_class want = to_mpz(a) * to_mpz(b) * to_mpz(c);
    ASSERT_EQ(to_mpz(abc), want);
    const WideInt<5> sum = abc + multiply(W1::from_int64(c), multiply(W2::from(b), W2::from(a)));
    const WideInt<5> diff = abc - multiply(W1::from_int64(c), multiply(W2::from(a), W2::from(b)));
    const mpz_class limit = mpz_class(1) << 319;
    if (abs(2 * want) < limit) {
      ASSERT_EQ(to_mpz(sum), 2 * want);
      ASSERT_EQ(sum.sign(), sgn(want));
    }
    ASSERT_EQ(diff.sign(), 0);
    ASSERT_EQ((abc - WideInt<5>::from(a)).sign(), sgn(want - to_mpz(a)));
    ++checked;
  }
  EXPECT_EQ(checked, 20000);
  // The extremes: the most negative int128 squared, and times -1; 0; -1 * -1.
  const __int128 lowest = -static_cast<__int128>((~static_cast<unsigned __int128>(0)) >> 1) - 1;
  EXPECT_EQ(to_mpz(multiply(W2::from(lowest), W2::from(lowest))), to_mpz(lowest) * to_mpz(lowest));
  EXPECT_EQ(to_mpz(multiply(W1::from_int64(-1), W2::from(lowest))), -to_mpz(lowest));
  EXPECT_EQ(to_mpz(multiply(W1::from_int64(INT64_MIN), W1::from_int64(INT64_MIN))), mpz_class(1) << 126);
  EXPECT_EQ(multiply(W1::from_int64(0), W2::from(lowest)).sign(), 0);
  EXPECT_EQ(to_mpz(multiply(W1::from_int64(-1), W1::from_int64(-1))), 1);
  EXPECT_EQ((WideInt<3>::from(5) - WideInt<3>::from(5)).sign(), 0);
  EXPECT_EQ(WideInt<3>::from(-1).sign(), -1);
}

}  // namespace
