// WideInt against GMP: sums, differences and products of random signed
// operands of every size up to the width, including the extremes (zero, one,
// minus one, the largest magnitudes that fit), are the exact results wherever
// those fit, and the sign is right.
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
  using W3 = WideInt<3>;
  using W4 = WideInt<4>;
  using W5 = WideInt<5>;
  int checked = 0;
  for (int t = 0; t < 20000; ++t) {
    // A product of two int128 (below 2^253: 4 limbs), times an int64-sized
    // value (below 2^316: 5 limbs), then summed; sizes drawn at random, up to
    // the largest that fit.
    const __int128 a = random_int128(g, static_cast<int>(g() % 128));
    const __int128 b = random_int128(g, static_cast<int>(g() % 128));
    const __int128 c = random_int128(g, static_cast<int>(g() % 64));
    const W4 ab = W4::from(a) * W4::from(b);
    ASSERT_EQ(to_mpz(ab), to_mpz(a) * to_mpz(b));
    const W5 abc = W5::from(c) * ab.widen<5>();
    ASSERT_EQ(to_mpz(abc), to_mpz(a) * to_mpz(b) * to_mpz(c));
    const W5 sum = abc + W5::from(a), diff = abc - W5::from(b);
    ASSERT_EQ(to_mpz(sum), to_mpz(abc) + to_mpz(a));
    ASSERT_EQ(to_mpz(diff), to_mpz(abc) - to_mpz(b));
    const mpz_class want = to_mpz(diff);
    ASSERT_EQ(diff.sign(), sgn(want));
    ++checked;
  }
  EXPECT_EQ(checked, 20000);
  // The extremes: +-(2^127 - 1) squared fits 4 limbs; -1 times -1; 0.
  const __int128 big = static_cast<__int128>((~static_cast<unsigned __int128>(0)) >> 1);
  EXPECT_EQ(to_mpz(W4::from(big) * W4::from(-big)), -to_mpz(big) * to_mpz(big));
  EXPECT_EQ(to_mpz(W3::from(-1) * W3::from(-1)), 1);
  EXPECT_EQ((W3::from(5) - W3::from(5)).sign(), 0);
  EXPECT_EQ(W3::from(-1).sign(), -1);
  EXPECT_EQ(W3::from(0).widen<5>().sign(), 0);
  EXPECT_EQ(to_mpz(W3::from(-7).widen<5>()), -7);
}

}  // namespace
