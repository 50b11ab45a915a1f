// walls::Index (kernels/wall_index.hpp) against brute force, in 2D and 3D:
// `near` finds every wall that a ball has a point beyond, and no wall far
// from that; `deepest` names the wall a point lies farthest beyond; on the
// tangent planes of a sphere (a sphere's hull: the geometry the index is
// for) a point's query finds its own plane alone. The walls are a polytope
// about a centre away from the origin (the index measures from the box's
// centre), and tangent planes of a sphere.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tessera/kernels/wall_index.hpp"

namespace {

using tessera::kernels::Wall;

constexpr double centre[3] = {40, -30, 20};

/// Wall n.x <= n.centre + s |n|, its normal scaled by a power of two to a
/// largest component in [1, 2) as the front end scales them.
Wall make_wall(const double* normal, double s, int dim) {
  Wall w{};
  double big = 0, norm2 = 0;
  for (int a = 0; a < dim; ++a) big = std::max(big, std::fabs(normal[a]));
  for (int a = 0; a < dim; ++a) w.n[a] = std::ldexp(normal[a], -std::ilogb(big)), norm2 += w.n[a] * w.n[a];
  w.norm = std::sqrt(norm2) * (1 + 1e-15);
  w.d = s * std::sqrt(norm2);
  for (int a = 0; a < dim; ++a) w.d += w.n[a] * centre[a];
  return w;
}

/// Walls tangent to spheres of radius 0.8 to 1 about the centre.
std::vector<Wall> polytope(int dim, int count, std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.8, 1.0);
  std::vector<Wall> walls;
  for (int k = 0; k < count; ++k) {
    const double n[3] = {g(rng), g(rng), g(rng)};
    walls.push_back(make_wall(n, u(rng), dim));
  }
  return walls;
}

/// How far p lies beyond wall w: (n.p - d) / |n|.
double beyond(const Wall& w, const double* p, int dim) {
  long double s = -static_cast<long double>(w.d), n2 = 0;
  for (int a = 0; a < dim; ++a) s += static_cast<long double>(w.n[a]) * p[a], n2 += static_cast<long double>(w.n[a]) * w.n[a];
  return static_cast<double>(s / std::sqrt(n2));
}

TEST(WallIndex, NearFindsEveryWallABallReachesBeyond) {
  for (const int dim : {2, 3}) {
    std::mt19937_64 rng(40 + static_cast<std::uint64_t>(dim));
    const std::vector<Wall> walls = polytope(dim, dim == 3 ? 300 : 200, rng);
    const tessera::kernels::walls::Index index(walls, dim, centre);
    ASSERT_EQ(index.size(), walls.size());
    std::uniform_real_distribution<double> x(-1.2, 1.2);
    std::size_t found = 0, asked = 0, inside = 0;
    std::vector<std::int32_t> got;
    for (int trial = 0; trial < 4000; ++trial) {
      double p[3] = {0, 0, 0};
      for (int a = 0; a < dim; ++a) p[a] = centre[a] + x(rng);
      bool in = true;
      for (const Wall& w : walls) in = in && beyond(w, p, dim) < 0;
      inside += in;
      for (const double r : {0.0, 1e-9, 0.005, 0.03, 0.1, 0.4, 2.0}) {
        ASSERT_TRUE(index.near(p, r, got));
        ASSERT_TRUE(std::is_sorted(got.begin(), got.end()));
        for (std::size_t k = 0; k < walls.size(); ++k) {
          const double t = beyond(walls[k], p, dim) + r;
          const bool listed = std::binary_search(got.begin(), got.end(), static_cast<std::int32_t>(k));
          if (t > 1e-12) EXPECT_TRUE(listed) << dim << "D: wall " << k << " reaches " << t << " into the ball, not found";
          if (t < -1e-9) EXPECT_FALSE(listed) << dim << "D: wall " << k << " " << -t << " clear of the ball, found";
        }
        if (r == 0.03) found += got.size(), ++asked;
      }
    }
    EXPECT_GT(inside, 400u) << dim;
    EXPECT_LT(static_cast<double>(found) / static_cast<double>(asked), 0.25 * static_cast<double>(walls.size())) << dim;
    // A limit: false past it, with one wall more than it in the list; a
    // visit that stops at once calls once.
    const double far[3] = {centre[0] + 5, centre[1] + 5, dim == 3 ? centre[2] + 5 : 0.0};
    EXPECT_FALSE(index.near(far, 0.0, got, 10));
    EXPECT_EQ(got.size(), 11u);
    int calls = 0;
    index.visit(far, 0.0, [&](std::int32_t) { return ++calls < 1; });
    EXPECT_EQ(calls, 1);
  }
}

TEST(WallIndex, DeepestIsTheWallAPointLiesFarthestBeyond) {
  for (const int dim : {2, 3}) {
    std::mt19937_64 rng(50 + static_cast<std::uint64_t>(dim));
    const std::vector<Wall> walls = polytope(dim, dim == 3 ? 400 : 150, rng);
    const tessera::kernels::walls::Index index(walls, dim, centre);
    std::uniform_real_distribution<double> x(-1.5, 1.5);
    int outside = 0;
    for (int trial = 0; trial < 3000; ++trial) {
      double p[3] = {0, 0, 0};
      for (int a = 0; a < dim; ++a) p[a] = centre[a] + x(rng);
      const double r = trial % 3 == 0 ? 0.0 : 0.05;
      const int parity = trial % 2;  // half the trials pass over the odd walls
      auto skip = [&](std::int32_t k) { return parity == 1 && k % 2 == 1; };
      double top = -1e300;
      int best = -1;
      for (std::size_t k = 0; k < walls.size(); ++k) {
        if (skip(static_cast<std::int32_t>(k))) continue;
        const double t = beyond(walls[k], p, dim);
        if (t > top) top = t, best = static_cast<int>(k);
      }
      const std::int32_t got = index.deepest(p, r, skip);
      if (top + r < -1e-9) {
        EXPECT_EQ(got, -1) << dim << "D: trial " << trial;
      } else if (top + r > 1e-12) {
        ASSERT_GE(got, 0) << dim << "D: trial " << trial << ": wall " << best << " reaches " << top + r;
        EXPECT_FALSE(skip(got));
        EXPECT_NEAR(beyond(walls[static_cast<std::size_t>(got)], p, dim), top, 1e-12) << dim << "D: trial " << trial;
        outside += top > 0;
      }
    }
    EXPECT_GT(outside, 500) << dim;
  }
}

TEST(WallIndex, SphereTangentPlanesMeetAPointQueryAlone) {
  for (const int dim : {2, 3}) {
    std::mt19937_64 rng(60 + static_cast<std::uint64_t>(dim));
    std::normal_distribution<double> g;
    const int n = dim == 3 ? 20000 : 5000;
    std::vector<double> at(static_cast<std::size_t>(n) * 3);
    std::vector<Wall> walls;
    for (int i = 0; i < n; ++i) {
      double u[3] = {g(rng), g(rng), dim == 3 ? g(rng) : 0.0};
      const double len = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
      for (int a = 0; a < 3; ++a) u[a] /= len;
      walls.push_back(make_wall(u, 1.0, dim));
      for (int a = 0; a < dim; ++a) at[static_cast<std::size_t>(i) * 3 + static_cast<std::size_t>(a)] = centre[a] + u[a];
    }
    const tessera::kernels::walls::Index index(walls, dim, centre);
    std::vector<std::int32_t> got;
    int alone = 0;
    for (int i = 0; i < n; i += 7) {
      const double* p = &at[static_cast<std::size_t>(i) * 3];
      ASSERT_TRUE(index.near(p, 0.0, got, 64)) << dim << "D: point " << i;
      // Its own plane passes through it (to rounding); any other found
      // passes within 1e-9 of it (touching the sphere within ~4e-5).
      EXPECT_TRUE(std::binary_search(got.begin(), got.end(), i)) << dim << "D: point " << i;
      for (const std::int32_t k : got)
        EXPECT_GT(beyond(walls[static_cast<std::size_t>(k)], p, dim), -1e-9) << dim << "D: point " << i << ", wall " << k;
      alone += got.size() == 1;
      // Halfway to the centre, a ball through the point meets the planes
      // near it only.
      double q[3] = {0, 0, 0};
      for (int a = 0; a < dim; ++a) q[a] = (p[a] + centre[a]) / 2;
      ASSERT_TRUE(index.near(q, 0.5, got, 64)) << dim << "D: point " << i;
      EXPECT_TRUE(std::binary_search(got.begin(), got.end(), i));
    }
    EXPECT_GT(alone, n / 7 * 9 / 10) << dim;  // (random points: a few lie within 1e-5 of another)
  }
}

}  // namespace
