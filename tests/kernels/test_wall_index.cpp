// walls::Index (kernels/wall_index.hpp) against brute force: for a polytope
// of 200 walls (300 in 3D) around the origin, every wall whose plane lies
// within a cell's reach of its generator is among the candidates, every
// point outside a wall is caught by its leaf's list (or its leaf is marked
// outside), and the lists are short where the walls are far.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "tessera/kernels/wall_index.hpp"

namespace {

using tessera::kernels::Wall;

/// Walls tangent to spheres of radius 0.8 to 1 about the origin, each normal
/// scaled by a power of two to a largest component in [1, 2) as the front
/// end scales them.
std::vector<Wall> polytope(int dim, int count, std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.8, 1.0);
  std::vector<Wall> walls;
  for (int k = 0; k < count; ++k) {
    Wall w{};
    double big = 0, norm2 = 0;
    for (int a = 0; a < dim; ++a) w.n[a] = g(rng), big = std::max(big, std::fabs(w.n[a]));
    for (int a = 0; a < dim; ++a) w.n[a] = std::ldexp(w.n[a], -std::ilogb(big)), norm2 += w.n[a] * w.n[a];
    w.norm = std::sqrt(norm2) * (1 + 1e-15);
    w.d = u(rng) * std::sqrt(norm2);
    walls.push_back(w);
  }
  return walls;
}

double distance_inside(const Wall& w, const double* p, int dim) {  // (d - n.p) / |n|
  double s = w.d, n2 = 0;
  for (int a = 0; a < dim; ++a) s -= w.n[a] * p[a], n2 += w.n[a] * w.n[a];
  return s / std::sqrt(n2);
}

TEST(WallIndex, ListsEveryWallACellOrAPointCanMeet) {
  for (const int dim : {2, 3}) {
    std::mt19937_64 rng(40 + static_cast<std::uint64_t>(dim));
    const std::vector<Wall> walls = polytope(dim, dim == 3 ? 300 : 200, rng);
    const double lo[3] = {-1.2, -1.2, -1.2}, hi[3] = {1.2, 1.25, 1.3};
    const tessera::kernels::walls::Index index(walls, dim, lo, hi, 0.04);
    EXPECT_GE(index.depth(), 5) << dim;
    std::uniform_real_distribution<double> x(-1.2, 1.2);
    std::size_t inside = 0, outside = 0, listed = 0, asked = 0;
    for (int trial = 0; trial < 20000; ++trial) {
      double p[3] = {x(rng), x(rng), dim == 3 ? x(rng) : 0.0};
      int first = -1;
      bool near_tie = false;
      for (std::size_t k = 0; k < walls.size(); ++k) {
        const double s = distance_inside(walls[k], p, dim);
        near_tie = near_tie || std::fabs(s) < 1e-9;
        if (s < 0 && first < 0) first = static_cast<int>(k);
      }
      if (near_tie) continue;
      bool all = false;
      const auto maybe = index.may_hold_outside(p, all);
      if (first >= 0) {
        ++outside;
        if (!all) {  // then the list holds the first wall p is outside of, and none before it that p is outside of
          EXPECT_TRUE(std::binary_search(maybe.begin(), maybe.end(), first)) << dim << ": wall " << first;
        }
        continue;
      }
      ++inside;
      EXPECT_FALSE(all) << dim << ": a point inside every wall in a leaf marked outside";
      for (const double reach : {0.005, 0.03, 0.1, 0.4, 2.0, 10.0}) {
        const auto c = index.candidates(p, reach);
        EXPECT_TRUE(std::is_sorted(c.begin(), c.end()));
        for (std::size_t k = 0; k < walls.size(); ++k)
          if (distance_inside(walls[k], p, dim) <= reach)
            EXPECT_TRUE(std::binary_search(c.begin(), c.end(), static_cast<std::int32_t>(k)))
                << dim << ": wall " << k << " within " << reach << " of the point, not a candidate";
        if (reach == 0.03) listed += c.size(), ++asked;
      }
    }
    EXPECT_GT(inside, 3000u) << dim;
    EXPECT_GT(outside, 1000u) << dim;
    // Cells about a leaf wide test a few walls, not all of them.
    EXPECT_LT(static_cast<double>(listed) / static_cast<double>(asked), 0.1 * static_cast<double>(walls.size())) << dim;
  }
}

}  // namespace
