// The support bound (support_bound.hpp) that lets the cell builder skip a
// candidate's sign pass. Soundness: whenever it excludes a candidate,
// clipping a copy of the cell by that candidate (the exact predicates
// deciding) leaves it unchanged, also with a measure taken before later
// clips. Strictness: on a lattice, every neighbour whose bisector merely
// touches the cell is kept. Use: at the edge of a cluster it excludes most
// of the cluster.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/support_bound.hpp"
#include "tessera/kernels/tile.hpp"
#include "scene.hpp"

namespace {

using namespace kernels_test;
using tessera::kernels::Hull;
using tessera::kernels::SupportBound;
using tessera::kernels::Tile;

template <class CellT>
constexpr int dim_of = CellT::dim;

/// The other points of `s` by increasing distance from point i.
template <int D>
std::vector<std::int32_t> by_distance(const Scene<D>& s, std::int32_t i) {
  std::vector<std::int32_t> order;
  std::vector<double> r2(static_cast<std::size_t>(s.size()));
  for (std::int32_t j = 0; j < s.size(); ++j) {
    double d2 = 0;
    for (int d = 0; d < D; ++d) d2 += (s.p(j)[d] - s.p(i)[d]) * (s.p(j)[d] - s.p(i)[d]);
    r2[static_cast<std::size_t>(j)] = d2;
    if (j != i) order.push_back(j);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) { return r2[a] < r2[b]; });
  return order;
}

template <int D>
void diff(const Scene<D>& s, std::int32_t i, std::int32_t j, double* q) {
  for (int d = 0; d < D; ++d) q[d] = s.p(j)[d] - s.p(i)[d];
}

struct Tally {
  std::size_t tested = 0, excluded = 0;
};

/// Cell of point i clipped by its `head` nearest points, measured; then more
/// clips by the next `more` (the measure goes stale). Every candidate the
/// measure excludes must leave both the measured and the further clipped
/// cell unchanged.
template <class CellT>
Tally check_cell(const Scene<dim_of<CellT>>& s, std::int32_t i, std::size_t head, std::size_t more) {
  constexpr int D = dim_of<CellT>;
  SCOPED_TRACE("cell " + std::to_string(i) + " head " + std::to_string(head));
  const auto order = by_distance(s, i);
  CellT cell;
  s.reset(cell, i);
  for (std::size_t k = 0; k < std::min(head, order.size()); ++k) s.clip(cell, order[k]);
  SupportBound<D> bound;
  bound.measure(cell.vertices(), cell.power_slack());
  CellT later = cell;
  for (std::size_t k = head; k < std::min(head + more, order.size()); ++k) s.clip(later, order[k]);
  Tally t;
  for (std::int32_t j : order) {
    double q[D];
    diff(s, i, j, q);
    ++t.tested;
    if (!bound.excludes(q)) continue;
    ++t.excluded;
    CellT a = cell, b = later;
    EXPECT_EQ(s.clip(a, j), ClipResult::unchanged) << "excluded candidate " << j << " clips the measured cell";
    EXPECT_EQ(s.clip(b, j), ClipResult::unchanged) << "excluded candidate " << j << " clips the later cell";
  }
  return t;
}

template <class CellT>
void random_scene(std::uint64_t seed) {
  constexpr int D = dim_of<CellT>;
  std::array<double, D> lo, hi;
  lo.fill(-1);
  hi.fill(2);
  Scene<D> s(random_points<D>(300, seed, -1, 2), lo, hi);
  Tally all;
  for (std::int32_t i : {0, 7, 150, 299})
    for (std::size_t head : {0, 3, 12, 40}) {
      const Tally t = check_cell<CellT>(s, i, head, 10);
      all.tested += t.tested;
      all.excluded += t.excluded;
    }
  // Not vacuous: once the cell is bounded, far points are excluded.
  EXPECT_GT(all.excluded, all.tested / 3);
}

TEST(SupportBound, RandomHull) { random_scene<Hull>(41); }
TEST(SupportBound, RandomTile) { random_scene<Tile>(42); }

/// A lattice cell is a cube (square) whose every vertex lies exactly on the
/// bisectors of all 26 (8) surrounding points: each of them ties at some
/// vertex and must be kept; every point two or more steps away is excluded.
template <class CellT>
void lattice_scene() {
  constexpr int D = dim_of<CellT>;
  const int k = 5;
  std::array<double, D> lo, hi;
  lo.fill(0);
  hi.fill(k);
  Scene<D> s(lattice<D>(k), lo, hi);
  const std::int32_t centre = D == 2 ? 2 + 2 * k : 2 + 2 * k + 2 * k * k;
  CellT cell;
  s.reset(cell, centre);
  for (std::int32_t j = 0; j < s.size(); ++j)
    if (j != centre) s.clip(cell, j);
  SupportBound<D> bound;
  bound.measure(cell.vertices(), cell.power_slack());
  for (std::int32_t j = 0; j < s.size(); ++j) {
    if (j == centre) continue;
    double q[D];
    diff(s, centre, j, q);
    double cheb = 0;
    for (int d = 0; d < D; ++d) cheb = std::max(cheb, std::fabs(q[d]));
    if (cheb <= 1) EXPECT_FALSE(bound.excludes(q)) << "touching neighbour " << j << " excluded";
    else EXPECT_TRUE(bound.excludes(q)) << "point " << j << " at Chebyshev distance " << cheb << " kept";
    // The petal cover, on the point alone as a box: a touching neighbour lies
    // on a petal's sphere and must not be ruled out.
    tessera::kernels::PetalCover<D> cover;
    cover.measure(cell.vertices());
    if (cheb <= 1) EXPECT_FALSE(cover.excludes_box(s.p(j), s.p(j), s.p(centre))) << "touching neighbour " << j;
  }
}

TEST(SupportBound, LatticeTiesKeptHull) { lattice_scene<Hull>(); }
TEST(SupportBound, LatticeTiesKeptTile) { lattice_scene<Tile>(); }

/// 400 points in a dense cluster in the unit box, point 0 at its edge: its
/// cell reaches across the empty box, so the security radius holds the whole
/// cluster, nearly all of which lies behind it.
template <int D>
Scene<D> cluster_edge_scene(std::uint64_t seed) {
  auto pts = random_points<D>(400, seed, 0.45, 0.55);
  for (int d = 0; d < D; ++d) pts[static_cast<std::size_t>(d)] = d == 0 ? 0.56 : 0.5;
  std::array<double, D> lo, hi;
  lo.fill(0);
  hi.fill(1);
  return Scene<D>(std::move(pts), lo, hi);
}

template <class CellT>
void cluster_edge(std::uint64_t seed) {
  const auto s = cluster_edge_scene<dim_of<CellT>>(seed);
  const Tally t = check_cell<CellT>(s, 0, 64, 16);
  EXPECT_GT(t.excluded, t.tested * 3 / 4);
}

TEST(SupportBound, ClusterEdgeHull) { cluster_edge<Hull>(43); }
TEST(SupportBound, ClusterEdgeTile) { cluster_edge<Tile>(44); }

}  // namespace

namespace {

using tessera::kernels::PetalCover;

/// PetalCover: boxes around groups of nearby points. When a box is ruled
/// out, clipping by each of its points leaves the cell unchanged; at a
/// cluster's edge, boxes behind the generator are ruled out.
template <class CellT>
void petal_boxes(std::uint64_t seed) {
  constexpr int D = dim_of<CellT>;
  const auto s = cluster_edge_scene<D>(seed);
  std::mt19937_64 g(seed);
  int excluded = 0, boxes = 0;
  for (std::size_t head : {16, 64, 200}) {
    const auto order = by_distance(s, 0);
    CellT cell;
    s.reset(cell, 0);
    for (std::size_t k = 0; k < head; ++k) s.clip(cell, order[k]);
    PetalCover<D> cover;
    cover.measure(cell.vertices());
    for (int t = 0; t < 200; ++t) {
      // A group: the 8 points nearest to a random member, and their box.
      const std::int32_t c = 1 + static_cast<std::int32_t>(g() % static_cast<std::uint64_t>(s.size() - 1));
      auto near = by_distance(s, c);
      near.resize(7);
      near.push_back(c);
      std::array<double, D> blo, bhi;
      blo.fill(INFINITY);
      bhi.fill(-INFINITY);
      for (std::int32_t j : near)
        for (int d = 0; d < D; ++d) {
          blo[d] = std::min(blo[d], s.p(j)[d]);
          bhi[d] = std::max(bhi[d], s.p(j)[d]);
        }
      ++boxes;
      if (!cover.excludes_box(blo.data(), bhi.data(), s.p(0))) continue;
      ++excluded;
      for (std::int32_t j : near) {
        if (j == 0) continue;
        CellT copy = cell;
        EXPECT_EQ(s.clip(copy, j), ClipResult::unchanged) << "point " << j << " of a ruled-out box clips";
      }
    }
  }
  EXPECT_GT(excluded, boxes / 4) << "the cover hardly rules anything out";
}

TEST(PetalCover, BoxesAtClusterEdgeHull) { petal_boxes<Hull>(45); }
TEST(PetalCover, BoxesAtClusterEdgeTile) { petal_boxes<Tile>(46); }

}  // namespace
