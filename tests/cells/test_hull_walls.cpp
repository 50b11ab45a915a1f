// tessera::hull_walls: the convex hull of the points as walls.
//
// What this proves: every point lies inside every wall exactly (sums in
// 113-bit floats: the products of two doubles are exact there, and the
// sums err by 2^-113, far below the ulp gaps at stake), and every wall
// passes within 1e-13 of the coordinates' size of some point (it is a
// facet's plane, not a loose bound); facets in one plane make one wall (a cube lattice: 6), which
// then passes through the lattice points exactly, so the cells tile the cube
// exactly; the cells inside the hull are the brute-force oracle's cells
// clipped by the same walls, in a ball and on a sphere (more than 16 walls:
// the wall index decides which walls each cell tests); a dilation moves every wall out by that distance;
// bad input is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "helpers.hpp"
#include "oracle.hpp"

namespace {

using namespace cells_test;

/// Points uniform in a ball (disc) of radius 1 about (2, 3, 4).
std::vector<double> ball_points(std::size_t n, int dim, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> pts;
  while (pts.size() < n * dim) {
    double p[3] = {u(rng), u(rng), dim == 3 ? u(rng) : 0.0};
    if (p[0] * p[0] + p[1] * p[1] + p[2] * p[2] > 1) continue;
    const double c[3] = {2, 3, 4};
    for (int a = 0; a < dim; ++a) pts.push_back(c[a] + p[a]);
  }
  return pts;
}

/// n . p - d, nearly exactly (see the file's comment).
__float128 excess(const tessera::Wall& w, const double* p, int dim) {
  __float128 s = 0;
  for (int a = 0; a < dim; ++a) s += static_cast<__float128>(w.normal[static_cast<std::size_t>(a)]) * p[a];
  return s - w.offset;
}

void check_tight(const std::vector<double>& pts, int dim, const std::vector<tessera::Wall>& walls, double dilation,
                 const std::string& what) {
  const std::size_t n = pts.size() / dim;
  for (std::size_t k = 0; k < walls.size(); ++k) {
    const tessera::Wall& w = walls[k];
    double norm = 0, scale = std::fabs(w.offset);
    for (int a = 0; a < dim; ++a) norm += w.normal[static_cast<std::size_t>(a)] * w.normal[static_cast<std::size_t>(a)];
    norm = std::sqrt(norm);
    __float128 closest = -1e300;
    for (std::size_t i = 0; i < n; ++i) {
      const __float128 e = excess(w, &pts[i * dim], dim);
      ASSERT_LE(static_cast<double>(e), 0.0) << what << ": point " << i << " outside wall " << k;
      if (e > closest) closest = e;
      double m = 0;
      for (int a = 0; a < dim; ++a) m += std::fabs(w.normal[static_cast<std::size_t>(a)] * pts[i * dim + a]);
      scale = std::max(scale, m);
    }
    // The nearest point is `dilation` away, within 1e-13 of the terms' size
    // (the rounded normal's tilt, bounded over the points' extent).
    EXPECT_NEAR(-static_cast<double>(closest) / norm, dilation, 1e-13 * scale / norm + 1e-12 * dilation)
        << what << ": wall " << k;
  }
}

TEST(HullWalls, EveryPointInsideAndEveryWallOnTheHull) {
  for (const int dim : {2, 3}) {
    for (const std::size_t n : {std::size_t{50}, std::size_t{3000}}) {
      const std::string what = std::to_string(dim) + "D, " + std::to_string(n) + " points";
      const auto ball = ball_points(n, dim, 70 + n);
      const auto walls = tessera::hull_walls(ball, dim);
      EXPECT_GT(walls.size(), std::size_t(dim == 3 ? 40 : 10)) << what;
      check_tight(ball, dim, walls, 0, what + " in a ball");
      const auto cube = random_points(n, dim, 90 + n);
      check_tight(cube, dim, tessera::hull_walls(cube, dim), 0, what + " in a cube");
      const auto dilated = tessera::hull_walls(ball, dim, 0.25);
      ASSERT_EQ(dilated.size(), walls.size());
      check_tight(ball, dim, dilated, 0.25, what + ", dilated");
    }
  }
}

// Far from 1: a facet's normal is a product of two differences (3D), 1e-400
// or 1e400 unscaled; the walls still hold every point, tightly.
TEST(HullWalls, TinyAndHugeCoordinates) {
  for (const int dim : {2, 3})
    for (const double scale : {1e-200, 1e-300, 1e200, 1e300}) {
      auto pts = ball_points(500, dim, 11);
      for (double& x : pts) x *= scale;
      const std::string what = std::to_string(dim) + "D at " + std::to_string(std::log10(scale));
      const auto walls = tessera::hull_walls(pts, dim);
      EXPECT_GT(walls.size(), 10u) << what;
      check_tight(pts, dim, walls, 0, what);
      tessera::VoronoiOptions o = options(dim);
      o.walls = walls;
      const auto c = tessera::voronoi(pts, dim, {}, o);
      EXPECT_EQ(c.n_cells(), 500u) << what;
      const auto v = tessera::validate(c, {}, pts);
      EXPECT_TRUE(v.ok) << what << ": " << (v.messages.empty() ? "" : v.messages[0]);
    }
}

TEST(HullWalls, LatticeHullIsExactAndItsCellsTileIt) {
  for (const int dim : {2, 3}) {
    const auto pts = grid_points(dim == 3 ? 6 : 12, dim, 0.5, 1.0);  // 1 .. 3.5 (6.5)
    const auto walls = tessera::hull_walls(pts, dim);
    EXPECT_EQ(walls.size(), std::size_t(2 * dim)) << dim << "D: a box's faces";
    for (const auto& w : walls) {
      __float128 top = -1e300;
      for (std::size_t i = 0; i < pts.size() / dim; ++i) top = std::max(top, excess(w, &pts[i * dim], dim));
      EXPECT_EQ(static_cast<double>(top), 0.0) << dim << "D: a wall off the lattice's face";
    }
    tessera::VoronoiOptions o = options(dim);
    o.walls = walls;
    const auto c = tessera::voronoi(pts, dim, {}, o);
    const double side = dim == 3 ? 2.5 : 5.5, want = dim == 3 ? side * side * side : side * side;
    double sum = 0;
    for (const double v : c.volume) sum += v;
    EXPECT_NEAR(sum, want, 1e-13 * want) << dim;
    const auto v = tessera::validate(c, {}, pts);
    EXPECT_TRUE(v.ok) << dim << "D: " << (v.messages.empty() ? "" : v.messages[0]);
  }
}

/// Points on the sphere (circle) of radius 1 about (2, 3, 4), rounded: all
/// of them hull vertices, nearly co-spherical.
std::vector<double> sphere_points(std::size_t n, int dim, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::vector<double> pts;
  const double c[3] = {2, 3, 4};
  for (std::size_t i = 0; i < n; ++i) {
    double p[3] = {g(rng), g(rng), dim == 3 ? g(rng) : 0.0};
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int a = 0; a < dim; ++a) pts.push_back(c[a] + p[a] / r);
  }
  return pts;
}

// In a ball, and on a sphere: there every cell is a cone from the centre
// out to the box before its cuts, reaching past hundreds of the hull's
// walls, and engine::clip_walls cuts it by the walls through its generator
// and then by those its vertices lie beyond (the index's point queries).
TEST(HullWalls, CellsInTheHullAreTheOraclesCells) {
  for (const int dim : {2, 3})
  for (const bool sphere : {false, true}) {
    const std::size_t n = dim == 3 ? 250 : 400;
    const auto pts = sphere ? sphere_points(n, dim, 35 + static_cast<std::uint64_t>(dim))
                            : ball_points(n, dim, 33 + static_cast<std::uint64_t>(dim));
    const auto walls = tessera::hull_walls(pts, dim);
    ASSERT_GE(walls.size(), 16u) << dim << "D: the wall index takes part from 16 walls";
    if (sphere) EXPECT_GE(walls.size(), dim == 3 ? 2 * n - 4 : n) << "every point a hull vertex";
    tessera::VoronoiOptions o = options(dim);
    o.walls = walls;
    const auto c = tessera::voronoi(pts, dim, {}, o);
    ASSERT_EQ(c.n_cells(), n);
    std::vector<oracle::Wall> ow;
    for (const auto& w : walls) ow.push_back({w.normal[0], w.normal[1], w.normal[2], w.offset});
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto want = oracle::cell(pts, dim, i, c.bounds.lo, c.bounds.hi, {}, ow);
      const std::size_t k = static_cast<std::size_t>(c.cell_of[i]);
      EXPECT_NEAR(c.volume[k], want.volume, 1e-9 * want.volume) << dim << (sphere ? "D sphere" : "D ball") << ": cell " << i;
      for (int a = 0; a < dim; ++a)
        EXPECT_NEAR(c.centroid[k * dim + a], want.centroid[a], 1e-9) << dim << (sphere ? "D sphere" : "D ball") << ": cell " << i;
      sum += c.volume[k];
    }
    // (Past 256 walls, as on the sphere, domain_volume sums sub-boxes of
    // the box, each cut as a cell is, in parallel: the same on 1 and 2.)
    const double hull = tessera::domain_volume(c.bounds, walls, dim, 1);
    EXPECT_EQ(tessera::domain_volume(c.bounds, walls, dim, 2), hull) << dim << sphere;
    EXPECT_NEAR(sum, hull, 1e-12 * hull) << dim << sphere;
    const auto v = tessera::validate(c, {}, pts);
    EXPECT_TRUE(v.ok) << dim << (sphere ? "D sphere: " : "D ball: ") << (v.messages.empty() ? "" : v.messages[0]);
    // Two threads: the same cells.
    o.threads = 2;
    const auto c2 = tessera::voronoi(pts, dim, {}, o);
    EXPECT_EQ(c2.volume, c.volume) << dim << sphere;
    EXPECT_EQ(c2.vertices, c.vertices) << dim << sphere;
  }
}

TEST(HullWalls, BadInputIsRefused) {
  auto refused = [](const std::vector<double>& pts, int dim, double dilation, const std::string& says) {
    try {
      (void)tessera::hull_walls(pts, dim, dilation);
      ADD_FAILURE() << "accepted: " << says;
    } catch (const tessera::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  refused({0, 0, 1, 0}, 2, 0, "at least 3 points");
  refused({0, 0, 1, 1, 2, 2, 3, 3}, 2, 0, "no area");                       // on a line
  refused({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 3, 0}, 3, 0, "zero extent");      // in a plane z = 0
  refused({1, 0, 0, 0, 1, 0, 0, 0, 1, 0.25, 0.25, 0.5, 0.5, 0.5, 0}, 3, 0, "no area");  // in x + y + z = 1
  refused({0, 0, 1, 0, 0, NAN}, 2, 0, "not finite");
  refused({0, 0, 1, 0, 0, 1}, 2, -1, "dilation");
  refused({0, 0, 1, 0, 0, 1}, 4, 0, "dim");
  // Duplicates and a bare triangle are fine.
  EXPECT_EQ(tessera::hull_walls(std::vector<double>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0}, 2).size(), 3u);
}

}  // namespace
