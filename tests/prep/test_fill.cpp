// tessera::fill: bins, uniform and adaptive strategies, labels, bounds, joggle, threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/prep/fill.hpp"

namespace {

using tessera::FillOptions;
using tessera::FillStrategy;

tessera::Bounds box(double x0, double x1, double y0, double y1, double z0 = 0, double z1 = 0) {
  tessera::Bounds b;
  b.lo = {x0, y0, z0};
  b.hi = {x1, y1, z1};
  return b;
}

TEST(PrepFill, UniformTwoByTwoByHand) {
  // Bounds [0,1]^2, 2 points at 0.5 points per bin -> 4 bins of edge 1/2.
  const std::vector<double> p = {0.1, 0.1, 0.9, 0.9};
  FillOptions o;
  o.points_per_bin = 0.5;
  o.bounds = box(0, 1, 0, 1);
  const auto out = tessera::fill(p, 2, {}, o);
  EXPECT_EQ(out.dim, 2);
  // Input first and unchanged (label in_label = 0), then bins (1,0) and (0,1) in bin order.
  const std::vector<double> want = {0.1, 0.1, 0.9, 0.9, 0.75, 0.25, 0.25, 0.75};
  EXPECT_EQ(out.coords, want);
  EXPECT_EQ(out.labels, (std::vector<std::int32_t>{0, 0, -1, -1}));
}

TEST(PrepFill, UniformOnePointPerEmptyBinAtItsCentre) {
  // [0,4]^3 with 1/64 point per bin: 64 unit bins; the data occupies bin (0,0,0).
  const std::vector<double> p = {0.5, 0.25, 0.75};
  const std::vector<std::int32_t> labels = {7};
  FillOptions o;
  o.points_per_bin = 1.0 / 64;
  o.bounds = box(0, 4, 0, 4, 0, 4);
  o.background_label = -5;
  const auto out = tessera::fill(p, 3, labels, o);
  ASSERT_EQ(out.size(), 64u);
  EXPECT_EQ(out.labels[0], 7);
  EXPECT_EQ(std::vector<double>(out.coords.begin(), out.coords.begin() + 3), p);
  std::set<std::vector<double>> centres;
  for (std::size_t i = 1; i < out.size(); ++i) {
    EXPECT_EQ(out.labels[i], -5);
    std::vector<double> c(out.coords.begin() + 3 * i, out.coords.begin() + 3 * i + 3);
    for (double v : c) EXPECT_EQ(v - std::floor(v), 0.5);  // exact bin centres
    centres.insert(c);
  }
  EXPECT_EQ(centres.size(), 63u);
  EXPECT_FALSE(centres.count({0.5, 0.5, 0.5}));
  // Bin order: x fastest, so the first added point is bin (1,0,0), the last (3,3,3).
  EXPECT_EQ(std::vector<double>(out.coords.begin() + 3, out.coords.begin() + 6), (std::vector<double>{1.5, 0.5, 0.5}));
  EXPECT_EQ(std::vector<double>(out.coords.end() - 3, out.coords.end()), (std::vector<double>{3.5, 3.5, 3.5}));
}

TEST(PrepFill, BinsFollowTheAspectRatio) {
  // 4 x 1 box, 4 bins asked -> 4 x 1 unit bins.
  const std::vector<double> p = {0.5, 0.5, 2.5, 0.5};
  FillOptions o;
  o.points_per_bin = 0.5;
  o.bounds = box(0, 4, 0, 1);
  const auto out = tessera::fill(p, 2, {}, o);
  EXPECT_EQ(out.coords, (std::vector<double>{0.5, 0.5, 2.5, 0.5, 1.5, 0.5, 3.5, 0.5}));
  // A thin slab is not cut across its thickness: 100 x 0.001 with 10 bins -> 10 x 1.
  o.points_per_bin = 0.1;
  o.bounds = box(0, 100, 0, 0.001);
  const std::vector<double> q = {5, 0.0005};
  const auto slab = tessera::fill(q, 2, {}, o);
  ASSERT_EQ(slab.size(), 10u);
  for (std::size_t i = 1; i < 10; ++i) {
    EXPECT_EQ(slab.coords[2 * i], 10.0 * static_cast<double>(i) + 5);
    EXPECT_EQ(slab.coords[2 * i + 1], 0.0005);
  }
}

TEST(PrepFill, DefaultRegionIsTheBoundingBoxAndFarFaceIsInside) {
  // Points on the corners: bins at the far faces are occupied, not overflowed.
  const std::vector<double> p = {0, 0, 2, 2, 0, 2, 2, 0};
  FillOptions o;
  o.points_per_bin = 4.0 / 16;  // 16 bins of edge 1/2
  const auto out = tessera::fill(p, 2, {}, o);
  EXPECT_EQ(out.size(), 4u + 12u);
  for (std::size_t i = 4; i < out.size(); ++i) {
    const double x = out.coords[2 * i], y = out.coords[2 * i + 1];
    EXPECT_FALSE((x == 0.25 || x == 1.75) && (y == 0.25 || y == 1.75)) << x << " " << y;
  }
}

TEST(PrepFill, JoggleStaysNearTheCentreAndIsDeterministic) {
  const std::vector<double> p = {0.5, 0.5, 0.5};
  FillOptions o;
  o.points_per_bin = 1.0 / 1000;  // 10^3 bins of edge 0.1 in [0,1]^3
  o.bounds = box(0, 1, 0, 1, 0, 1);
  o.joggle = 0.5;
  o.seed = 3;
  const auto a = tessera::fill(p, 3, {}, o);
  const auto b = tessera::fill(p, 3, {}, o);
  ASSERT_EQ(a.size(), 1000u);
  EXPECT_EQ(a.coords, b.coords);
  o.joggle = 0;
  const auto exact = tessera::fill(p, 3, {}, o);
  double largest = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    double s = 0;
    for (int d = 0; d < 3; ++d) s += std::pow(a.coords[3 * i + d] - exact.coords[3 * i + d], 2);
    largest = std::max(largest, std::sqrt(s));
  }
  EXPECT_LE(largest, 0.05 * (1 + 1e-9));
  EXPECT_GT(largest, 0.03);
}

std::vector<double> blob(std::size_t n, unsigned seed) {
  // Points in a ball of radius 0.15 around (0.5, 0.5, 0.5), plus the box corners.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> p;
  while (p.size() < 3 * n) {
    const double x = u(rng), y = u(rng), z = u(rng);
    if (x * x + y * y + z * z < 1) p.insert(p.end(), {0.5 + 0.15 * x, 0.5 + 0.15 * y, 0.5 + 0.15 * z});
  }
  return p;
}

TEST(PrepFill, SameResultForAnyThreadCount) {
  const auto p = blob(100000, 11);
  for (FillStrategy s : {FillStrategy::uniform, FillStrategy::adaptive}) {
    FillOptions o;
    o.strategy = s;
    o.points_per_bin = 0.5;
    o.bounds = box(0, 1, 0, 1, 0, 1);
    o.joggle = 0.2;
    o.seed = 5;
    o.threads = 1;
    const auto a = tessera::fill(p, 3, {}, o);
    o.threads = 2;
    const auto b = tessera::fill(p, 3, {}, o);
    ASSERT_EQ(a.coords.size(), b.coords.size());
    EXPECT_EQ(std::memcmp(a.coords.data(), b.coords.data(), a.coords.size() * sizeof(double)), 0);
    EXPECT_EQ(a.labels, b.labels);
  }
}

TEST(PrepFill, AdaptiveIsDenseNextToTheDataAndSparseFarAway) {
  // 32^3 bins of edge 1/32 over [0,1]^3.
  const std::size_t n = 4000;
  const auto p = blob(n, 12);
  FillOptions o;
  o.strategy = FillStrategy::adaptive;
  o.points_per_bin = static_cast<double>(n) / 32768.0;
  o.bounds = box(0, 1, 0, 1, 0, 1);
  o.seed = 1;
  const auto out = tessera::fill(p, 3, {}, o);
  ASSERT_GT(out.size(), n);
  EXPECT_EQ(std::vector<double>(out.coords.begin(), out.coords.begin() + 3 * n), p);

  auto bin = [](double v) { return static_cast<int>(std::floor(v * 32)); };
  std::vector<char> occupied(32768, 0), added(32768, 0);
  for (std::size_t i = 0; i < n; ++i)
    occupied[bin(p[3 * i]) + 32 * (bin(p[3 * i + 1]) + 32 * bin(p[3 * i + 2]))] = 1;
  for (std::size_t i = n; i < out.size(); ++i) {
    EXPECT_EQ(out.labels[i], -1);
    int b[3];
    for (int d = 0; d < 3; ++d) {
      const double v = out.coords[3 * i + d];
      b[d] = bin(v);
      ASSERT_EQ((v - (b[d] + 0.5) / 32) * 32, 0.0) << "not a bin centre: " << v;  // bin centres (VTK: corners)
    }
    const int k = b[0] + 32 * (b[1] + 32 * b[2]);
    EXPECT_FALSE(occupied[k]);
    EXPECT_FALSE(added[k]) << "two points in one bin";
    added[k] = 1;
  }
  // Every empty bin touching an occupied one gets its point; far bins are thinned.
  std::size_t near = 0, near_added = 0, far = 0, far_added = 0;
  for (int z = 0; z < 32; ++z)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        const int k = x + 32 * (y + 32 * z);
        if (occupied[k]) continue;
        bool touches = false;
        const int nb[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
        for (const auto& d : nb) {
          const int a = x + d[0], b = y + d[1], c = z + d[2];
          if (a >= 0 && a < 32 && b >= 0 && b < 32 && c >= 0 && c < 32 && occupied[a + 32 * (b + 32 * c)])
            touches = true;
        }
        if (touches) {
          ++near;
          near_added += added[k];
          EXPECT_TRUE(added[k]) << x << " " << y << " " << z;
        }
        const double r = std::sqrt(std::pow((x + 0.5) / 32 - 0.5, 2) + std::pow((y + 0.5) / 32 - 0.5, 2) +
                                   std::pow((z + 0.5) / 32 - 0.5, 2));
        if (r > 0.4) {
          ++far;
          far_added += added[k];
        }
      }
  ASSERT_GT(near, 0u);
  ASSERT_GT(far, 0u);
  EXPECT_EQ(near_added, near);
  EXPECT_LT(static_cast<double>(far_added) / far, 0.1);
  EXPECT_LT(out.size() - n, 32768u / 4);  // far fewer than uniform would add
}

TEST(PrepFill, BinsAtDoubleResolutionAreAnError) {
  // Four points a few ulps apart (found by stop 17's fuzz): the bins were
  // ~1 ulp wide, and fill added a bin centre that rounded onto an input point.
  const double u = std::numeric_limits<double>::epsilon();
  const std::vector<double> tiny = {1 + 3 * u, 1 + 2 * u, 1 + 2 * u, 1 + 3 * u, 1 + 3 * u, 1, 1 + 2 * u, 1};
  FillOptions o;
  o.points_per_bin = 0.5;
  try {
    tessera::fill(tiny, 2, {}, o);
    FAIL() << "bins below double's resolution were accepted";
  } catch (const tessera::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
  // The same layout 4096 times wider fills, and no added point meets an input one.
  std::vector<double> wide = tiny;
  for (double& x : wide) x = 1 + (x - 1) * 4096;
  const auto out = tessera::fill(wide, 2, {}, o);
  ASSERT_GT(out.coords.size(), wide.size());
  for (std::size_t a = wide.size(); a < out.coords.size(); a += 2)
    for (std::size_t b = 0; b < wide.size(); b += 2)
      EXPECT_FALSE(out.coords[a] == wide[b] && out.coords[a + 1] == wide[b + 1]) << "added point " << a / 2;
}

TEST(PrepFill, RegionPastDoublesRangeIsAnError) {
  // x from -1e308 to 1e308: the extent overflows. The uniform grid made one
  // infinite bin and added nothing; the adaptive one refused its own image's
  // spacing (a fuzz of the Python module found both).
  const std::vector<double> p = {-1e308, 0, 1e308, 1, 0.5, 0.5};
  for (const auto strategy : {tessera::FillStrategy::uniform, tessera::FillStrategy::adaptive}) {
    FillOptions o;
    o.strategy = strategy;
    o.points_per_bin = 0.5;
    try {
      tessera::fill(p, 2, {}, o);
      FAIL() << "a region past double's range was filled";
    } catch (const tessera::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("x extent [-1e+308, 1e+308] overflows double"), std::string::npos)
          << e.what();
    }
  }
}

TEST(PrepFill, NonFinitePointsKeptUnbinnedWhenKept) {
  // Missing returns between the points: kept in place with their labels,
  // and the added points are those of the finite points alone (the same
  // box, the same bin count), with or without bounds.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const FillStrategy strategy : {FillStrategy::uniform, FillStrategy::adaptive})
    for (int dim : {2, 3})
      for (bool bounded : {false, true}) {
        std::mt19937_64 rng(static_cast<unsigned>(dim));
        std::uniform_real_distribution<double> u(0.2, 0.7);
        std::vector<double> finite_pts, all;
        std::vector<std::int32_t> finite_labels, all_labels;
        for (int i = 0; i < 600; ++i) {
          const bool lost = i % 5 == 2;
          for (int d = 0; d < dim; ++d) {
            const double v = lost ? (d == 0 ? (i % 2 ? nan : -inf) : u(rng)) : u(rng);
            all.push_back(v);
            if (!lost) finite_pts.push_back(v);
          }
          all_labels.push_back(i % 4);
          if (!lost) finite_labels.push_back(i % 4);
        }
        FillOptions o;
        o.strategy = strategy;
        o.joggle = 0.25;
        if (bounded) o.bounds = box(0, 1, -0.5, 1, 0, 2);
        EXPECT_THROW(tessera::fill(all, dim, all_labels, o), tessera::InputError);
        o.keep_non_finite = true;
        const auto out = tessera::fill(all, dim, all_labels, o);
        const auto want = tessera::fill(finite_pts, dim, finite_labels, o);
        const std::size_t n = all_labels.size(), nf = finite_labels.size();
        ASSERT_EQ(out.size() - n, want.size() - nf) << dim << bounded;
        ASSERT_GT(out.size(), n);
        for (std::size_t k = 0; k < all.size(); ++k)
          ASSERT_EQ(std::memcmp(&out.coords[k], &all[k], sizeof(double)), 0) << k;
        EXPECT_TRUE(std::equal(all_labels.begin(), all_labels.end(), out.labels.begin()));
        EXPECT_TRUE(std::equal(out.coords.begin() + static_cast<std::ptrdiff_t>(all.size()), out.coords.end(),
                               want.coords.begin() + static_cast<std::ptrdiff_t>(finite_pts.size())));
        EXPECT_TRUE(std::equal(out.labels.begin() + static_cast<std::ptrdiff_t>(n), out.labels.end(),
                               want.labels.begin() + static_cast<std::ptrdiff_t>(nf)));
      }
  // Only non-finite points: nothing to bin.
  FillOptions o;
  o.keep_non_finite = true;
  EXPECT_THROW(tessera::fill(std::vector<double>{nan, 0, inf, 1}, 2, {}, o), tessera::InputError);
}

TEST(PrepFill, BadInput) {
  const std::vector<double> p = {0, 0, 1, 1};
  FillOptions o;
  EXPECT_THROW(tessera::fill({}, 2, {}, o), tessera::InputError);
  EXPECT_THROW(tessera::fill(p, 2, std::vector<std::int32_t>{1}, o), tessera::InputError);
  o.background_label = 0;
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);
  o = {};
  o.points_per_bin = 0;
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);
  o.points_per_bin = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);
  o = {};
  o.joggle = 0.6;
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);
  o = {};
  o.bounds = box(0, 0.5, 0, 1);  // point (1,1) outside
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);
  o.bounds = box(1, 0, 0, 1);
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);
  o = {};
  EXPECT_THROW(tessera::fill(std::vector<double>{0, 0, 1, 0}, 2, {}, o), tessera::InputError);  // flat
  EXPECT_THROW(tessera::fill(std::vector<double>{0, 0, 0, 1, 1, 0}, 3, {}, o), tessera::InputError);
  EXPECT_THROW(tessera::fill(std::vector<double>{0, std::nan(""), 1, 1}, 2, {}, o), tessera::InputError);
  o.points_per_bin = 1e-12;
  EXPECT_THROW(tessera::fill(p, 2, {}, o), tessera::InputError);  // too many bins
}

}  // namespace
