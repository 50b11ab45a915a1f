// tessera::threshold: half-open intervals, overlaps, NaN, against brute force.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/prep/threshold.hpp"

namespace {

using tessera::ThresholdOptions;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(PrepThreshold, HalfOpenIntervalEdges) {
  ThresholdOptions o;
  o.intervals = {{1, 2, 20}, {0, 1, 10}};  // given out of order; [0,1) and [1,2) touch
  o.background_label = -7;
  const std::vector<double> s = {-0.5, 0.0, std::nextafter(1.0, 0.0), 1.0, 1.5, std::nextafter(2.0, 0.0), 2.0,
                                 kNaN, kInf, -kInf, -0.0};
  const auto l = tessera::threshold(s, o);
  const std::vector<std::int32_t> want = {-7, 10, 10, 20, 20, 20, -7, -7, -7, -7, 10};
  EXPECT_EQ(l, want);
}

TEST(PrepThreshold, InfiniteEnds) {
  ThresholdOptions o;
  o.intervals = {{-kInf, 0, 1}, {5, kInf, 2}};
  const std::vector<double> s = {-kInf, -1e300, 0, 4.999, 5, 1e300, kInf};
  // +inf is not below hi = +inf: half-open all the way.
  const std::vector<std::int32_t> want = {1, 1, -1, -1, 2, 2, -1};
  EXPECT_EQ(tessera::threshold(s, o), want);
}

TEST(PrepThreshold, MatchesBruteForce) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1, 11);
  ThresholdOptions o;
  for (int k = 0; k < 10; k += 2) o.intervals.push_back({double(k), k + 1.5, k});
  std::vector<double> s(10000);
  for (double& v : s) v = std::round(u(rng) * 4) / 4;  // many values exactly on edges
  const auto l = tessera::threshold(s, o);
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::int32_t want = -1;
    for (const auto& iv : o.intervals)
      if (iv.lo <= s[i] && s[i] < iv.hi) want = iv.label;
    ASSERT_EQ(l[i], want) << s[i];
  }
}

TEST(PrepThreshold, BadIntervals) {
  ThresholdOptions o;
  EXPECT_THROW(tessera::threshold(std::vector<double>{1.0}, o), tessera::InputError);  // none
  o.intervals = {{0, 2, 1}, {1, 3, 2}};
  EXPECT_THROW(tessera::threshold(std::vector<double>{1.0}, o), tessera::InputError);  // overlap
  o.intervals = {{0, 10, 1}, {2, 3, 2}};
  EXPECT_THROW(tessera::threshold(std::vector<double>{1.0}, o), tessera::InputError);  // nested
  o.intervals = {{1, 1, 1}};
  EXPECT_THROW(tessera::threshold(std::vector<double>{1.0}, o), tessera::InputError);  // empty
  o.intervals = {{2, 1, 1}};
  EXPECT_THROW(tessera::threshold(std::vector<double>{1.0}, o), tessera::InputError);  // reversed
  o.intervals = {{kNaN, 1, 1}};
  EXPECT_THROW(tessera::threshold(std::vector<double>{1.0}, o), tessera::InputError);
  try {
    o.intervals = {{0, 2, 1}, {1, 3, 2}};
    tessera::threshold(std::vector<double>{}, o);
    FAIL();
  } catch (const tessera::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("overlap"), std::string::npos) << e.what();
  }
}

}  // namespace
