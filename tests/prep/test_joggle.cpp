// tessera::joggle: displacement bounds, determinism, masks, plane modes, threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/prep/joggle.hpp"

namespace {

using tessera::JoggleMode;
using tessera::JoggleOptions;

std::vector<double> random_points(std::size_t n, int dim, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> c(n * static_cast<std::size_t>(dim));
  for (double& v : c) v = u(rng);
  return c;
}

double displacement(const std::vector<double>& a, const std::vector<double>& b, std::size_t i, int dim) {
  double s = 0;
  for (int d = 0; d < dim; ++d) {
    const double x = a[i * dim + d] - b[i * dim + d];
    s += x * x;
  }
  return std::sqrt(s);
}

bool bit_equal(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(PrepJoggle, DisplacementWithinAbsoluteRadiusAndUniformInBall) {
  const std::size_t n = 20000;
  const auto p = random_points(n, 3, 1);
  JoggleOptions o;
  o.radius = 0.01;
  o.absolute = true;
  const auto q = tessera::joggle(p, 3, o);
  ASSERT_EQ(q.size(), p.size());
  double sum = 0;
  std::size_t inner = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = displacement(p, q, i, 3);
    EXPECT_LE(d, 0.01 * (1 + 1e-9)) << i;
    sum += d;
    inner += d < 0.005;
  }
  // Uniform in the ball: E|d| = 3R/4, P(|d| < R/2) = 1/8.
  EXPECT_NEAR(sum / n, 0.0075, 0.0002);
  EXPECT_NEAR(static_cast<double>(inner) / n, 0.125, 0.01);
}

TEST(PrepJoggle, RelativeRadiusIsAFractionOfTheDiagonal) {
  // Bounding box 3 x 4 x 0 (diagonal 5), radius 0.1 -> 0.5.
  std::vector<double> p = {0, 0, 0, 3, 4, 0};
  for (int i = 0; i < 2000; ++i) p.insert(p.end(), {1.5, 2.0, 0.0});
  JoggleOptions o;
  o.radius = 0.1;
  const auto q = tessera::joggle(p, 3, o);
  double largest = 0;
  for (std::size_t i = 0; i < p.size() / 3; ++i) largest = std::max(largest, displacement(p, q, i, 3));
  EXPECT_LE(largest, 0.5 * (1 + 1e-12));
  EXPECT_GT(largest, 0.45);
}

// Extents whose squares overflow or underflow double: the relative radius is
// still the asked fraction of the diagonal (until stop 17, extents past
// ~1.3e154 gave infinite points with exit 0, and below ~1e-154 nothing moved).
TEST(PrepJoggle, RelativeRadiusAtExtremeExtents) {
  for (const double scale : {2e154, 1e300, 1e-170, 1e-300}) {
    std::vector<double> p = {0, 0, 0, 3 * scale, 4 * scale, 0};  // diagonal 5 scale
    for (int i = 0; i < 200; ++i) p.insert(p.end(), {1.5 * scale, 2.0 * scale, 0.0});
    JoggleOptions o;
    o.radius = 0.1;
    const auto q = tessera::joggle(p, 3, o);
    double largest = 0;
    for (std::size_t i = 0; i < p.size() / 3; ++i) {
      double m = 0;
      for (int d = 0; d < 3; ++d) m = std::max(m, std::fabs(q[3 * i + static_cast<std::size_t>(d)] - p[3 * i + static_cast<std::size_t>(d)]));
      largest = std::max(largest, m / scale);  // the largest component, in units of scale
    }
    for (double x : q) EXPECT_TRUE(std::isfinite(x)) << scale;
    EXPECT_LE(largest, 0.5 * (1 + 1e-9)) << scale;
    EXPECT_GT(largest, 0.2) << scale;
  }
  // A radius that moves points past double's range is an input error.
  std::vector<double> h = {-1.7e308, 0, 1.7e308, 0};
  JoggleOptions big;
  big.radius = 0.3;
  EXPECT_THROW(tessera::joggle(h, 2, big), tessera::InputError);
  big.radius = 1e-4;
  for (double x : tessera::joggle(h, 2, big)) EXPECT_TRUE(std::isfinite(x));
}

TEST(PrepJoggle, TwoDimensionalDisk) {
  const std::size_t n = 20000;
  const auto p = random_points(n, 2, 2);
  JoggleOptions o;
  o.radius = 0.5;
  o.absolute = true;
  const auto q = tessera::joggle(p, 2, o);
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = displacement(p, q, i, 2);
    EXPECT_LE(d, 0.5 * (1 + 1e-12));
    sum += d;
  }
  EXPECT_NEAR(sum / n, 2.0 / 3.0 * 0.5, 0.01);  // E|d| = 2R/3 in a disk
}

TEST(PrepJoggle, DeterministicAndSeeded) {
  const auto p = random_points(1000, 3, 3);
  JoggleOptions o;
  o.seed = 42;
  const auto a = tessera::joggle(p, 3, o);
  const auto b = tessera::joggle(p, 3, o);
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  o.seed = 43;
  const auto c = tessera::joggle(p, 3, o);
  std::size_t same = 0;
  for (std::size_t k = 0; k < a.size(); ++k) same += a[k] == c[k];
  EXPECT_LT(same, 10u);
}

TEST(PrepJoggle, MaskPassesOthersThroughBitForBit) {
  auto p = random_points(1000, 3, 4);
  p[5] = -0.0;  // copied as is, sign included
  std::vector<std::uint8_t> mask(1000);
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = i % 3 == 0 ? 7 : 0;
  JoggleOptions o;
  o.radius = 0.05;
  const auto all = tessera::joggle(p, 3, o);
  const auto q = tessera::joggle(p, 3, o, mask);
  for (std::size_t i = 0; i < 1000; ++i)
    for (int d = 0; d < 3; ++d) {
      if (mask[i])  // a masked point moves exactly as it does without a mask
        EXPECT_TRUE(bit_equal(q[i * 3 + d], all[i * 3 + d])) << i;
      else
        EXPECT_TRUE(bit_equal(q[i * 3 + d], p[i * 3 + d])) << i;
    }
  EXPECT_TRUE(std::signbit(q[5]));
  EXPECT_NE(q[0], p[0]);
}

TEST(PrepJoggle, PlaneModesKeepTheThirdCoordinateExactly) {
  const auto p = random_points(5000, 3, 5);
  const struct {
    JoggleMode mode;
    int fixed;
  } cases[] = {{JoggleMode::xy, 2}, {JoggleMode::xz, 1}, {JoggleMode::yz, 0}};
  for (const auto& c : cases) {
    JoggleOptions o;
    o.mode = c.mode;
    o.radius = 0.02;
    o.absolute = true;
    const auto q = tessera::joggle(p, 3, o);
    std::size_t moved = 0;
    for (std::size_t i = 0; i < 5000; ++i) {
      EXPECT_TRUE(bit_equal(q[i * 3 + c.fixed], p[i * 3 + c.fixed]));
      EXPECT_LE(displacement(p, q, i, 3), 0.02 * (1 + 1e-12));
      moved += displacement(p, q, i, 3) > 0;
    }
    EXPECT_EQ(moved, 5000u);
  }
}

TEST(PrepJoggle, SameResultForAnyThreadCount) {
  const auto p = random_points(200000, 3, 6);
  JoggleOptions o;
  o.radius = 1e-3;
  o.threads = 1;
  const auto a = tessera::joggle(p, 3, o);
  o.threads = 2;
  const auto b = tessera::joggle(p, 3, o);
  o.threads = 5;
  const auto c = tessera::joggle(p, 3, o);
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(double)), 0);
}

// A progress callback sees chunks of points and the end, and changes
// nothing; one that throws Cancelled stops the run (Python's Ctrl-C).
TEST(PrepJoggle, ProgressInChunksAndCancelled) {
  const auto p = random_points(200000, 3, 6);
  JoggleOptions o;
  o.radius = 1e-3;
  const auto a = tessera::joggle(p, 3, o);
  std::vector<double> seen;
  o.progress = [&](double f) { seen.push_back(f); };
  const auto b = tessera::joggle(p, 3, o);
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
  ASSERT_GE(seen.size(), 3u);
  EXPECT_EQ(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  int calls = 0;
  o.progress = [&](double) {
    if (++calls == 2) throw tessera::Cancelled();
  };
  EXPECT_THROW(tessera::joggle(p, 3, o), tessera::Cancelled);
  EXPECT_EQ(calls, 2);
}

TEST(PrepJoggle, ZeroRadiusAndEmptyInput) {
  const auto p = random_points(10, 3, 7);
  JoggleOptions o;
  o.radius = 0;
  EXPECT_EQ(tessera::joggle(p, 3, o), p);
  EXPECT_TRUE(tessera::joggle({}, 3).empty());
  // A single point: the diagonal is 0, so a relative radius moves nothing.
  const std::vector<double> one = {1, 2, 3};
  EXPECT_EQ(tessera::joggle(one, 3), one);
}

TEST(PrepJoggle, NonFinitePointsCopiedThroughWhenKept) {
  // An organized cloud's missing returns keep their place and bits; the
  // finite points move as a mask of them would move them where the
  // missing ones are copies of a finite point (the same bounding box).
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (int dim : {2, 3}) {
    const std::size_t n = 3000;  // also the parallel path
    auto p = random_points(n, dim, 11);
    auto same_box = p;
    std::vector<std::uint8_t> finite(n, 1);
    for (std::size_t i = 3; i < n; i += 7) {
      finite[i] = 0;
      const double bad = i % 3 == 0 ? nan : (i % 3 == 1 ? inf : -inf);
      p[i * dim + (i % static_cast<std::size_t>(dim))] = bad;  // one coordinate; the others stay finite
      if (i % 2 == 0)
        for (int d = 0; d < dim; ++d) p[i * dim + d] = nan;  // or all of them
      for (int d = 0; d < dim; ++d) same_box[i * dim + d] = same_box[d];
    }
    JoggleOptions o;
    o.radius = 0.01;
    EXPECT_THROW(tessera::joggle(p, dim, o), tessera::InputError);
    o.keep_non_finite = true;
    const auto out = tessera::joggle(p, dim, o);
    const auto want = tessera::joggle(same_box, dim, o, finite);
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < dim; ++d) {
        const std::size_t k = i * dim + static_cast<std::size_t>(d);
        if (finite[i]) {
          ASSERT_TRUE(bit_equal(out[k], want[k])) << dim << " " << i;
          ASSERT_NE(out[k], p[k]);
        } else {
          ASSERT_TRUE(bit_equal(out[k], p[k])) << dim << " " << i;
        }
      }
    // Absolute radius: the same displacements; only non-finite points: none moves.
    o.absolute = true;
    const auto abs_out = tessera::joggle(p, dim, o), abs_want = tessera::joggle(same_box, dim, o);
    for (std::size_t i = 0; i < n; ++i)
      if (finite[i]) ASSERT_TRUE(bit_equal(abs_out[i * dim], abs_want[i * dim])) << i;
    o.absolute = false;
    const std::vector<double> lost(static_cast<std::size_t>(2 * dim), nan);
    const auto none = tessera::joggle(lost, dim, o);
    for (double v : none) EXPECT_TRUE(std::isnan(v));
  }
}

TEST(PrepJoggle, BadInput) {
  const auto p = random_points(10, 3, 8);
  JoggleOptions o;
  o.radius = -1;
  EXPECT_THROW(tessera::joggle(p, 3, o), tessera::InputError);
  o.radius = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tessera::joggle(p, 3, o), tessera::InputError);
  o.radius = std::numeric_limits<double>::infinity();
  EXPECT_THROW(tessera::joggle(p, 3, o), tessera::InputError);
  o = {};
  o.mode = JoggleMode::xz;
  const auto p2 = random_points(10, 2, 8);
  EXPECT_THROW(tessera::joggle(p2, 2, o), tessera::InputError);
  EXPECT_THROW(tessera::joggle(p, 3, {}, std::vector<std::uint8_t>(9, 1)), tessera::InputError);
  auto bad = p;
  bad[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tessera::joggle(bad, 3), tessera::InputError);
  EXPECT_THROW(tessera::joggle(p, 4), tessera::InputError);
  EXPECT_THROW(tessera::joggle(std::vector<double>(7, 0.0), 3), tessera::InputError);
}

}  // namespace
