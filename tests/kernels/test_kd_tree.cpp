// KdTree::nearest against brute force (with and without slab bounds, on
// volume and surface samples, with exact ties and skipped points), its node
// budget, and CellBuilder's long-cell path (certify_by_petals, which searches
// the tree) against the shell walk alone: the same cells, vertex for vertex.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "scene.hpp"
#include "tessera/kernels/cell_builder.hpp"
#include "tessera/kernels/kd_tree.hpp"
#include "tessera/kernels/locator.hpp"
#include "tessera/kernels/tile.hpp"

namespace {

using tessera::kernels::BinLocator;
using tessera::kernels::CellBuilder;
using tessera::kernels::Hull;
using tessera::kernels::KdTree;
using tessera::kernels::SharedKdTree;
using tessera::kernels::Tile;

constexpr double two_pi = 6.283185307179586;

/// Points on an ellipsoid (3D) or an ellipse (2D), the kind of input the
/// slab bounds are for, plus `dups` exact copies of earlier points.
template <int D>
std::vector<double> surface_points(int n, std::uint64_t seed, int dups = 0) {
  std::mt19937_64 g(seed);
  std::normal_distribution<double> normal;
  const double axes[3] = {1.0, 0.7, 0.4};
  std::vector<double> p;
  for (int i = 0; i < n; ++i) {
    double v[D], len = 0;
    for (int d = 0; d < D; ++d) {
      v[d] = normal(g);
      len += v[d] * v[d];
    }
    len = std::sqrt(len);
    for (int d = 0; d < D; ++d) p.push_back(axes[d] * v[d] / len);
  }
  std::uniform_int_distribution<int> pick(0, n - 1);
  for (int k = 0; k < dups; ++k) {
    const int j = pick(g);
    for (int d = 0; d < D; ++d) p.push_back(p[static_cast<std::size_t>(j) * D + d]);
  }
  return p;
}

/// The answer KdTree::nearest must give, by brute force with the same
/// squared distances.
template <int D, class Skip>
std::int32_t brute_nearest(const std::vector<double>& pts, const double* x, std::int32_t self, double r2max,
                           Skip skip) {
  std::int32_t best = -1;
  double bound = r2max;
  const auto n = static_cast<std::int32_t>(pts.size() / D);
  for (std::int32_t j = 0; j < n; ++j) {
    double r2 = 0;
    for (int d = 0; d < D; ++d) {
      const double q = pts[static_cast<std::size_t>(j) * D + d] - x[d];
      r2 += q * q;
    }
    if (j == self || skip(j) || r2 > bound || (r2 == bound && best >= 0)) continue;
    bound = r2;
    best = j;
  }
  return best;
}

template <int D>
void check_nearest(const std::vector<double>& pts, bool slabs, const std::string& what) {
  const auto n = static_cast<std::int32_t>(pts.size() / D);
  std::vector<std::int32_t> ids(static_cast<std::size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) ids[static_cast<std::size_t>(i)] = i;
  const KdTree<D> tree(pts, ids, slabs);
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-1.3, 1.3), scale(0, 1);
  std::uniform_int_distribution<std::int32_t> pick(0, n - 1);
  auto skip = [](std::int32_t j) { return j % 5 == 0; };
  int found = 0;
  for (int t = 0; t < 600; ++t) {
    double x[D];
    std::int32_t self = -1;
    if (t % 3 == 0) {  // at an input point, which is then `self`
      self = pick(g);
      for (int d = 0; d < D; ++d) x[d] = pts[static_cast<std::size_t>(self) * D + d];
    } else {
      for (int d = 0; d < D; ++d) x[d] = u(g);
    }
    // Radii from tiny to the whole set; every fourth exactly some point's
    // squared distance, which is included (<=).
    double r2max = std::pow(10.0, -6 + 7 * scale(g));
    if (t % 4 == 1) {
      const std::int32_t j = pick(g);
      r2max = 0;
      for (int d = 0; d < D; ++d) {
        const double q = pts[static_cast<std::size_t>(j) * D + d] - x[d];
        r2max += q * q;
      }
    }
    std::size_t budget = ~std::size_t{0};
    const std::int32_t got = tree.nearest(x, self, r2max, skip, budget);
    const std::int32_t want = brute_nearest<D>(pts, x, self, r2max, skip);
    ASSERT_EQ(got, want) << what << " query " << t << " r2max " << r2max;
    found += got >= 0;
  }
  EXPECT_GT(found, 100) << what << ": the queries should find points";
}

TEST(KdTree, NearestEqualsBruteForce) {
  check_nearest<3>(kernels_test::random_points<3>(3000, 1, -1, 1), false, "uniform 3D");
  check_nearest<3>(kernels_test::random_points<3>(3000, 1, -1, 1), true, "uniform 3D, slabs");
  check_nearest<3>(surface_points<3>(4000, 2, 300), true, "ellipsoid with duplicates, slabs");
  check_nearest<3>(surface_points<3>(4000, 2, 300), false, "ellipsoid with duplicates");
  check_nearest<2>(surface_points<2>(3000, 3, 200), true, "ellipse with duplicates, slabs");
  check_nearest<2>(kernels_test::random_points<2>(3000, 4, -1, 1), true, "uniform 2D, slabs");
  // Enough points that the build splits its subtrees among threads.
  check_nearest<3>(surface_points<3>(60000, 8, 2000), true, "large ellipsoid with duplicates, slabs");
  check_nearest<2>(kernels_test::random_points<2>(50000, 9, -1, 1), false, "large uniform 2D");
}

TEST(KdTree, NearestStopsAtItsBudget) {
  const std::vector<double> pts = surface_points<3>(5000, 5);
  std::vector<std::int32_t> ids(5000);
  for (std::int32_t i = 0; i < 5000; ++i) ids[static_cast<std::size_t>(i)] = i;
  const KdTree<3> tree(pts, ids, true);
  const double x[3] = {0, 0, 0};  // the centre: every point is about as near
  auto none = [](std::int32_t) { return false; };
  std::size_t budget = 3;
  EXPECT_EQ(tree.nearest(x, -1, 10.0, none, budget), -2);
  EXPECT_EQ(budget, 0u);
  budget = ~std::size_t{0};
  EXPECT_EQ(tree.nearest(x, -1, 10.0, none, budget), brute_nearest<3>(pts, x, -1, 10.0, none));
}

/// A cell's topology: for each vertex, the sorted ids of the planes meeting
/// there (negative: the domain box).
template <class CellT>
std::set<std::vector<std::int32_t>> topology(const CellT& cell) {
  std::set<std::vector<std::int32_t>> keys;
  for (const auto& v : cell.vertices()) {
    std::vector<std::int32_t> k;
    for (int d = 0; d < CellT::dim; ++d) k.push_back(cell.planes()[v.p[d]].id);
    std::sort(k.begin(), k.end());
    keys.insert(k);
  }
  return keys;
}

// Points sampled on a closed surface have long cells; with a tree that allows
// them (long_cells), the builder finishes most by certifying their petals. The
// cells must be those of the shell walk alone (no tree), vertex for vertex.
template <class CellT>
void check_long_cells(const std::vector<double>& pts, const std::string& what) {
  constexpr int D = CellT::dim;
  const auto n = static_cast<std::int32_t>(pts.size() / D);
  std::array<double, D> lo, hi;
  for (int d = 0; d < D; ++d) {
    lo[d] = -1.1;
    hi[d] = 1.1;
  }
  const kernels_test::Scene<D> scene(pts, lo, hi);
  const BinLocator<D> loc(pts, {}, lo, hi, 2.0);
  const SharedKdTree<D> tree(
      pts,
      [&] {
        std::vector<std::int32_t> ids(loc.size());
        for (std::size_t s = 0; s < ids.size(); ++s) ids[s] = loc.id(s);
        return ids;
      },
      false, true);
  CellBuilder<CellT> with_tree(loc, pts.data(), lo.data(), hi.data(), &scene.ctx, &tree);
  CellBuilder<CellT> shell_walk(loc, pts.data(), lo.data(), hi.data(), &scene.ctx, nullptr);
  CellT a, b;
  for (std::int32_t i = 0; i < n; ++i) {
    const double* p = scene.p(i);
    const auto sa = with_tree.build(i, p, a);
    const auto sb = shell_walk.build(i, p, b);
    ASSERT_EQ(sa.has_cell, sb.has_cell) << what << " cell " << i;
    ASSERT_EQ(sa.duplicate_of, sb.duplicate_of) << what << " cell " << i;
    if (sa.has_cell) ASSERT_EQ(topology(a), topology(b)) << what << " cell " << i;
  }
  EXPECT_GT(with_tree.petal_certified(), static_cast<std::uint64_t>(n / 2)) << what << ": the long-cell path should run";
  EXPECT_EQ(shell_walk.petal_certified(), 0u);
}

TEST(CellBuilder, LongCellsCertifiedByPetalsEqualTheShellWalk) {
  check_long_cells<Hull>(surface_points<3>(3000, 11, 20), "ellipsoid");
  check_long_cells<Tile>(surface_points<2>(3000, 12, 20), "ellipse");
}

}  // namespace
