// Regular (weighted Delaunay) triangulations: the dual of power cells.
// CGAL's Regular_triangulation_2/3 is the oracle on points in general
// position (random points and radii): the same simplices and the same
// hidden points. Elsewhere (ties: lattices with tied radii) the triangulation
// certifies itself through validate(): local regularity on every interior
// facet, a closed convex boundary, and every point a vertex or hidden under a
// simplex it is not in conflict with.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "random_points.hpp"
#include "simplex_set.hpp"
#include "tessera/cells.hpp"
#include "tessera/delaunay.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb3 = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K, CGAL::Regular_triangulation_vertex_base_3<K>>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3, CGAL::Regular_triangulation_cell_base_3<K>>;
using RT3 = CGAL::Regular_triangulation_3<K, Tds3>;
using Vb2 = CGAL::Triangulation_vertex_base_with_info_2<std::int32_t, K, CGAL::Regular_triangulation_vertex_base_2<K>>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2, CGAL::Regular_triangulation_face_base_2<K>>;
using RT2 = CGAL::Regular_triangulation_2<K, Tds2>;


struct Oracle {
  SimplexSet simplices;
  std::vector<std::int32_t> hidden;  // ascending
};

// CGAL's regular triangulation (weights: squared radii, as ours).
Oracle cgal_regular(const std::vector<double>& p, const std::vector<double>& radii, int dim) {
  Oracle out;
  const std::size_t n = radii.size();
  std::vector<std::uint8_t> vertex(n, 0);
  auto add = [&](std::vector<std::int32_t> s) {
    std::sort(s.begin(), s.end());
    out.simplices.insert(std::move(s));
  };
  if (dim == 3) {
    std::vector<std::pair<K::Weighted_point_3, std::int32_t>> wp;
    for (std::size_t i = 0; i < n; ++i)
      wp.emplace_back(K::Weighted_point_3(K::Point_3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), radii[i] * radii[i]),
                      static_cast<std::int32_t>(i));
    RT3 rt(wp.begin(), wp.end());
    for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c)
      add({c->vertex(0)->info(), c->vertex(1)->info(), c->vertex(2)->info(), c->vertex(3)->info()});
    for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) vertex[static_cast<std::size_t>(v->info())] = 1;
  } else {
    std::vector<std::pair<K::Weighted_point_2, std::int32_t>> wp;
    for (std::size_t i = 0; i < n; ++i)
      wp.emplace_back(K::Weighted_point_2(K::Point_2(p[2 * i], p[2 * i + 1]), radii[i] * radii[i]),
                      static_cast<std::int32_t>(i));
    RT2 rt(wp.begin(), wp.end());
    for (auto f = rt.finite_faces_begin(); f != rt.finite_faces_end(); ++f)
      add({f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()});
    for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) vertex[static_cast<std::size_t>(v->info())] = 1;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!vertex[i]) out.hidden.push_back(static_cast<std::int32_t>(i));
  return out;
}

tessera::Delaunay regular(const std::vector<double>& p, const std::vector<double>& radii, int dim, int threads = 2,
                          const std::vector<std::int32_t>& labels = {},
                          tessera::DelaunayMethod method = tessera::DelaunayMethod::automatic) {
  tessera::DelaunayOptions o;
  o.dim = dim;
  o.threads = threads;
  o.radii = radii;
  o.method = method;
  return tessera::delaunay(p, dim, labels, o);
}

// The cells pass (and hull completion) and the insertion: two algorithms
// asking the same perturbed power tests, so the same rows and hidden points.
void expect_methods_agree(const tessera::Delaunay& dt, const std::vector<double>& p, const std::vector<double>& radii,
                          int dim) {
  for (const auto method : {tessera::DelaunayMethod::cells, tessera::DelaunayMethod::insertion}) {
    const tessera::Delaunay other = regular(p, radii, dim, 2, {}, method);
    EXPECT_EQ(other.simplices, dt.simplices) << (method == tessera::DelaunayMethod::cells ? "cells" : "insertion");
    EXPECT_EQ(other.hidden, dt.hidden);
    EXPECT_EQ(other.duplicates, dt.duplicates);
  }
}

void expect_valid(const tessera::Delaunay& dt, const std::vector<double>& p, const std::vector<double>& radii,
                  const std::vector<std::int32_t>& labels = {}) {
  const tessera::DelaunayReport r = tessera::validate(dt, p, labels, radii);
  for (const auto& m : r.messages) ADD_FAILURE() << m;
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(as_set(dt).size(), dt.n_simplices()) << "a simplex is listed twice";
}

// Radii uniform in [0, scale * spacing), spacing the mean distance between
// neighbours (n^(-1/dim) in the unit cube): small scales hide a few points,
// large ones most of them.
std::vector<double> random_radii(std::size_t n, int dim, double scale, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, scale * std::pow(static_cast<double>(n), -1.0 / dim));
  std::vector<double> r(n);
  for (double& x : r) x = u(rng);
  return r;
}

void expect_equal_to_cgal(const tessera::Delaunay& dt, const Oracle& cgal) {
  const SimplexSet ours = as_set(dt);
  std::size_t missing = 0, extra = 0;
  for (const auto& s : cgal.simplices) missing += !ours.count(s);
  for (const auto& s : ours) extra += !cgal.simplices.count(s);
  EXPECT_EQ(missing, 0u);
  EXPECT_EQ(extra, 0u);
  EXPECT_EQ(ours.size(), cgal.simplices.size());
  EXPECT_EQ(dt.hidden, cgal.hidden);
}

class RegularEqualsCgal : public ::testing::TestWithParam<std::tuple<int, int, double, int>> {};

TEST_P(RegularEqualsCgal, RandomPointsAndRadii) {
  const auto [dim, n, scale, seed] = GetParam();
  const auto p = uniform_points(static_cast<std::size_t>(n), dim, static_cast<std::uint64_t>(seed));
  const auto radii = random_radii(static_cast<std::size_t>(n), dim, scale, static_cast<std::uint64_t>(seed) + 100);
  const tessera::Delaunay dt = regular(p, radii, dim);
  EXPECT_TRUE(dt.power);
  EXPECT_TRUE(dt.hull_completed);
  expect_equal_to_cgal(dt, cgal_regular(p, radii, dim));
  expect_valid(dt, p, radii);
  expect_methods_agree(dt, p, radii, dim);
  const tessera::Delaunay one = regular(p, radii, dim, 1);
  EXPECT_EQ(one.simplices, dt.simplices) << "1 and 2 threads";
  EXPECT_EQ(one.hidden, dt.hidden);
}

INSTANTIATE_TEST_SUITE_P(Regular, RegularEqualsCgal,
                         ::testing::Values(std::tuple{2, 12, 1.0, 1}, std::tuple{2, 2000, 0.5, 2}, std::tuple{2, 2000, 2.5, 3},
                                           std::tuple{2, 20000, 1.0, 4}, std::tuple{3, 12, 1.0, 5},
                                           std::tuple{3, 2000, 0.5, 6}, std::tuple{3, 2000, 2.5, 7},
                                           std::tuple{3, 20000, 1.0, 8}));

// Two sizes (a bidisperse packing's radii, unrelated to the spacing here:
// the large ones hide most small ones near them), and the simplices of the
// power cells found in the box equal to the dual of the cells' vertices.
TEST(Regular, TwoSizesEqualCgalAndDualToThePowerCells) {
  for (int dim : {2, 3}) {
    const std::size_t n = 3000;
    const auto p = uniform_points(n, dim, 11);
    std::vector<double> radii(n);
    std::mt19937_64 rng(12);
    const double spacing = std::pow(static_cast<double>(n), -1.0 / dim);
    for (double& r : radii) r = (rng() % 4 == 0 ? 1.5 : 0.4) * spacing;
    const tessera::Delaunay dt = regular(p, radii, dim);
    expect_equal_to_cgal(dt, cgal_regular(p, radii, dim));
    expect_valid(dt, p, radii);
    EXPECT_FALSE(dt.hidden.empty());

    // Each vertex of the power cells (no box plane) is one simplex.
    tessera::VoronoiOptions vo;
    vo.dim = dim;
    vo.radii = radii;
    const tessera::Cells cells = tessera::voronoi(p, dim, {}, vo);
    std::vector<std::int32_t> empty = cells.empty_cells;
    for (std::int32_t h : dt.hidden) EXPECT_TRUE(std::binary_search(empty.begin(), empty.end(), h)) << h;
    tessera::DelaunayOptions inside;
    inside.dim = dim;
    inside.radii = radii;
    inside.complete_hull = false;
    const tessera::Delaunay boxed = tessera::delaunay(p, dim, {}, inside);
    const SimplexSet all = as_set(dt), in_box = as_set(boxed);
    EXPECT_GT(in_box.size(), all.size() / 2);
    for (const auto& s : in_box) EXPECT_TRUE(all.count(s)) << "a simplex of the box's pass is not regular";
  }
}

// Skipped cells: their simplices come from their neighbours' cells, and the
// cavities of skipped points only are wrapped with the power test. Skipped
// points that are hidden are found hidden all the same.
TEST(Regular, SkippedCellsGiveTheSameRows) {
  for (int dim : {2, 3}) {
    const std::size_t n = 4000;
    const auto p = uniform_points(n, dim, 81);
    const auto radii = random_radii(n, dim, 1.5, 82);
    tessera::DelaunayOptions o;
    o.dim = dim;
    o.radii = radii;
    o.skip_cells = 0;
    const tessera::Delaunay all = tessera::delaunay(p, dim, {}, o);
    ASSERT_FALSE(all.hidden.empty());
    for (double skip : {0.4, 0.9}) {
      o.skip_cells = skip;
      const tessera::Delaunay skipped = tessera::delaunay(p, dim, {}, o);
      EXPECT_GT(skipped.skipped_cells, 0u);
      EXPECT_EQ(skipped.simplices, all.simplices) << dim << "D, skip " << skip;
      EXPECT_EQ(skipped.hidden, all.hidden);
    }
    expect_equal_to_cgal(all, cgal_regular(p, radii, dim));
  }
}

TEST(Regular, EqualRadiiGiveTheOrdinaryTriangulation) {
  for (int dim : {2, 3}) {
    const auto p = uniform_points(1500, dim, 21);
    const std::vector<double> radii(1500, 0.03);
    const tessera::Delaunay weighted = regular(p, radii, dim);
    tessera::DelaunayOptions o;
    o.dim = dim;
    const tessera::Delaunay plain = tessera::delaunay(p, dim, {}, o);
    EXPECT_FALSE(weighted.power);
    EXPECT_EQ(weighted.simplices, plain.simplices);
    EXPECT_TRUE(weighted.hidden.empty());
  }
}

// Ties: a lattice whose radii alternate (a checkerboard), so many
// orthospheres pass through further points with exactly equal power. The
// symbolic perturbation picks one triangulation; it must be regular.
TEST(Regular, LatticeWithTiedRadiiValidates) {
  for (int dim : {2, 3}) {
    const int k = dim == 3 ? 9 : 30;
    std::vector<double> p, radii;
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j)
        for (int l = 0; l < (dim == 3 ? k : 1); ++l) {
          p.insert(p.end(), {double(i), double(j)});
          if (dim == 3) p.push_back(double(l));
          radii.push_back((i + j + l) % 2 ? 0.25 : 0.5);
        }
    const tessera::Delaunay dt = regular(p, radii, dim);
    expect_valid(dt, p, radii);
    EXPECT_EQ(regular(p, radii, dim, 1).simplices, dt.simplices);
    expect_methods_agree(dt, p, radii, dim);
  }
}

// Most points hidden: a few large spheres over many small ones.
TEST(Regular, FewLargeSpheresHideTheRest) {
  // 2D: three huge weights at a triangle's corners hide every point inside it.
  std::vector<double> p = {0, 0, 1, 0, 0, 1};
  std::vector<double> radii = {10, 10, 10};
  const auto inner = uniform_points(200, 2, 31, 0.1, 0.4);
  p.insert(p.end(), inner.begin(), inner.end());
  radii.resize(203, 0.01);
  const tessera::Delaunay dt = regular(p, radii, 2);
  EXPECT_EQ(dt.n_simplices(), 1u);
  EXPECT_EQ(dt.hidden.size(), 200u);
  expect_valid(dt, p, radii);
  expect_methods_agree(dt, p, radii, 2);
  expect_equal_to_cgal(dt, cgal_regular(p, radii, 2));

  // Two huge weights at (0,0) and (1,1): the points between them on the
  // diagonal are hidden (they lie over the lifted segment), and all but
  // two of those off it too (CGAL agrees).
  std::vector<double> q = {0, 0, 1, 1};
  std::vector<double> rq = {10, 10};
  for (int i = 1; i <= 9; ++i) q.insert(q.end(), {0.1 * i, 0.1 * i});
  const auto off = uniform_points(20, 2, 32, 0.3, 0.7);
  q.insert(q.end(), off.begin(), off.end());
  rq.resize(q.size() / 2, 0.01);
  const tessera::Delaunay dt2 = regular(q, rq, 2);
  for (std::int32_t i = 2; i <= 10; ++i) EXPECT_TRUE(std::binary_search(dt2.hidden.begin(), dt2.hidden.end(), i)) << i;
  EXPECT_EQ(dt2.hidden.size(), 27u);
  expect_valid(dt2, q, rq);
  expect_equal_to_cgal(dt2, cgal_regular(q, rq, 2));
}

// One sphere far larger than the box: its power is the least all over the
// box, so no power vertex lies in it (nor in one 2^50 times larger: a radius
// of 1e12 beside unit points puts the orthocentres ~1e24 out). The cells
// pass found no simplex and reported the points flat; the triangulation is
// the cone from that sphere's centre over the hull, every inner point
// hidden. Radii whose squares overflow double (1e200) too, with CGAL as the
// oracle where the weights are finite.
TEST(Regular, OneSphereBeyondTheBox) {
  for (int dim : {2, 3}) {
    const auto p = uniform_points(300, dim, 35, 0, 1);
    for (const double big : {1e12, 1e200}) {
      SCOPED_TRACE(::testing::Message() << dim << "D, radius " << big);
      auto radii = random_radii(300, dim, 0.5, 36);
      radii[7] = big;
      const tessera::Delaunay dt = regular(p, radii, dim, 2, {}, tessera::DelaunayMethod::cells);
      expect_valid(dt, p, radii);
      expect_methods_agree(dt, p, radii, dim);
      for (std::size_t k = 0; k < dt.n_simplices(); ++k) {  // every simplex has the big sphere's centre
        const auto* row = dt.simplices.data() + k * static_cast<std::size_t>(dim + 1);
        EXPECT_NE(std::find(row, row + dim + 1, 7), row + dim + 1) << k;
      }
      if (big < 1e150) expect_equal_to_cgal(dt, cgal_regular(p, radii, dim));
    }
  }
}

// Coincident points: the largest radius is the vertex, the others duplicates.
TEST(Regular, CoincidentPointsKeepTheLargestRadius) {
  auto p = uniform_points(300, 3, 41);
  std::vector<double> radii = random_radii(300, 3, 0.5, 42);
  for (int c = 0; c < 10; ++c) {  // point 300 + c copies point c, larger or smaller
    p.insert(p.end(), p.begin() + 3 * c, p.begin() + 3 * c + 3);
    radii.push_back(c % 2 ? radii[static_cast<std::size_t>(c)] * 2 : radii[static_cast<std::size_t>(c)] / 2);
  }
  const tessera::Delaunay dt = regular(p, radii, 3);
  expect_methods_agree(dt, p, radii, 3);
  ASSERT_EQ(dt.duplicates.size(), 10u);
  for (const auto& [dup, owner] : dt.duplicates) {
    const double rd = radii[static_cast<std::size_t>(dup)], ro = radii[static_cast<std::size_t>(owner)];
    EXPECT_LE(rd, ro);
  }
  expect_valid(dt, p, radii);
}

// Labels: the whole regular triangulation's simplices of inside points.
TEST(Regular, LabelledIsTheWholeTriangulationFiltered) {
  const std::size_t n = 2000;
  const auto p = uniform_points(n, 3, 51);
  const auto radii = random_radii(n, 3, 1.0, 52);
  std::vector<std::int32_t> labels(n);
  for (std::size_t i = 0; i < n; ++i) labels[i] = p[3 * i] < 0.6 ? 1 : -1;
  const tessera::Delaunay dt = regular(p, radii, 3, 2, labels);
  const Oracle cgal = cgal_regular(p, radii, 3);
  SimplexSet inside;
  for (const auto& s : cgal.simplices)
    if (std::all_of(s.begin(), s.end(), [&](std::int32_t v) { return labels[static_cast<std::size_t>(v)] >= 0; }))
      inside.insert(s);
  EXPECT_EQ(as_set(dt), inside);
  for (std::int32_t h : dt.hidden) EXPECT_GE(labels[static_cast<std::size_t>(h)], 0);
  expect_valid(dt, p, radii, labels);
}

TEST(Regular, BadRadiiRefused) {
  const auto p = uniform_points(100, 3, 61);
  auto radii = random_radii(100, 3, 1.0, 62);
  tessera::DelaunayOptions o;
  o.dim = 3;
  radii[7] = -1;
  o.radii = radii;
  EXPECT_THROW(tessera::delaunay(p, 3, {}, o), tessera::InputError);
  radii.pop_back();
  o.radii = radii;
  EXPECT_THROW(tessera::delaunay(p, 3, {}, o), tessera::InputError);

  // validate needs the radii of a regular triangulation, and refuses them for an ordinary one.
  const auto good = random_radii(100, 3, 1.0, 62);
  const tessera::Delaunay dt = regular(p, good, 3);
  EXPECT_THROW(tessera::validate(dt, p, {}), tessera::InputError);
  tessera::DelaunayOptions plain;
  plain.dim = 3;
  EXPECT_THROW(tessera::validate(tessera::delaunay(p, 3, {}, plain), p, {}, good), tessera::InputError);
}

// The validator sees a wrong triangulation: the ordinary Delaunay simplices
// checked against radii that hide points fail local regularity or hiding.
TEST(Regular, ValidateCatchesTheOrdinaryTriangulation) {
  const auto p = uniform_points(500, 2, 71);
  const auto radii = random_radii(500, 2, 2.0, 72);
  tessera::Delaunay dt = regular(p, radii, 2);
  ASSERT_FALSE(dt.hidden.empty());
  tessera::DelaunayOptions plain;
  plain.dim = 2;
  tessera::Delaunay wrong = tessera::delaunay(p, 2, {}, plain);
  wrong.power = true;
  const tessera::DelaunayReport r = tessera::validate(wrong, p, {}, radii);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(r.local_delaunay_violations, 0u);
  // Listing a vertex as hidden, or dropping a hidden point's listing, fails too.
  tessera::Delaunay listed = dt;
  listed.hidden.push_back(dt.simplices[0]);
  std::sort(listed.hidden.begin(), listed.hidden.end());
  EXPECT_GT(tessera::validate(listed, p, {}, radii).hidden_not_hidden, 0u);
  tessera::Delaunay unlisted = dt;
  unlisted.hidden.pop_back();
  EXPECT_EQ(tessera::validate(unlisted, p, {}, radii).missing_points, 1u);
}

}  // namespace
