// Power (radical) cells: VoronoiOptions::radii.
//
// What this proves:
// * every cell is the box clipped by every other point's radical plane (the
//   brute-force oracle with radii): volume, centroid, face neighbours, and
//   the empty cells are exactly those the oracle finds empty (volume 0);
// * the cells tile the box, spokes are symmetric, every merged vertex has
//   D+1 generators, and the exact measure of sampled cells (validate with
//   the radii) agrees, on random input and on lattices whose radii tie;
// * 1 and 2 threads give identical output;
// * equal radii give the ordinary cells bit for bit;
// * of coincident points the largest radius owns the cell;
// * a plane through p_i exactly (d = 0) and one beyond it are exact;
// * bad radii and unsupported combinations are refused with InputError.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "helpers.hpp"
#include "oracle.hpp"
#include "tessera/flower.hpp"
#include "tessera/surface_nets.hpp"

namespace {

using namespace cells_test;

std::vector<double> random_radii(std::size_t n, double rmax, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, rmax);
  std::vector<double> r(n);
  for (double& x : r) x = u(rng);
  return r;
}

tessera::Cells run_power(const std::vector<double>& pts, int dim, const tessera::Bounds& box,
                         const std::vector<double>& radii, int threads = 1, bool mesh = true,
                         tessera::CellMethod method = tessera::CellMethod::search) {
  auto o = options(dim, box, threads);
  o.radii = radii;
  o.build_mesh = mesh;
  o.cell_method = method;
  return tessera::voronoi(pts, dim, {}, o);
}

void expect_valid(const tessera::Cells& c, const std::vector<double>& pts, const std::vector<double>& radii,
                  const std::string& what) {
  const auto r = tessera::validate(c, {}, pts, radii);
  EXPECT_TRUE(r.ok) << what << ": " << (r.messages.empty() ? "" : r.messages[0]);
  EXPECT_EQ(r.asymmetric_spokes, 0u) << what;
  EXPECT_EQ(r.bad_vertex_degree, 0u) << what;
  EXPECT_GT(r.measures_checked, 0u) << what;
  EXPECT_NEAR(r.volume_sum, r.domain_volume, 1e-12 * r.domain_volume) << what;
}

void compare_with_oracle(int dim, std::size_t n, double rmax, std::uint64_t seed,
                         tessera::CellMethod method = tessera::CellMethod::search) {
  SCOPED_TRACE(::testing::Message() << "dim " << dim << " n " << n << " rmax " << rmax << " seed " << seed);
  const auto box = make_bounds({-1, 0, 2}, {1, 1.5, 3});
  const auto pts = random_points(n, dim, seed, box);
  const auto radii = random_radii(n, rmax, seed + 1);
  const auto c = run_power(pts, dim, box, radii, 1, true, method);
  EXPECT_TRUE(c.power);
  EXPECT_EQ(c.from_insertion, method == tessera::CellMethod::insertion);
  const double L = box_size(box, dim), V = box_volume(box, dim);
  std::size_t empty = 0, bad = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const oracle::Cell o = oracle::cell(pts, dim, i, box.lo, box.hi, radii);
    const std::int32_t k = c.cell_of[i];
    if (k < 0) {
      ++empty;
      EXPECT_TRUE(std::binary_search(c.empty_cells.begin(), c.empty_cells.end(), std::int32_t(i))) << i;
      if (!(o.volume <= 1e-12 * V) && ++bad <= 5) ADD_FAILURE() << "point " << i << " has no cell, oracle " << o.volume;
      continue;
    }
    const auto ku = static_cast<std::size_t>(k);
    if (!(std::abs(c.volume[ku] - o.volume) <= 1e-9 * o.volume + 1e-13 * V) && ++bad <= 5)
      ADD_FAILURE() << "point " << i << " volume " << c.volume[ku] << " oracle " << o.volume;
    for (int a = 0; a < dim; ++a)
      if (!(std::abs(c.centroid[ku * dim + a] - o.centroid[a]) <= 1e-9 * L) && ++bad <= 5)
        ADD_FAILURE() << "point " << i << " centroid differs";
    std::set<int> want;
    for (auto [id, area] : o.face)
      if (id >= 0 && area > 1e-12 * std::pow(L, dim - 1)) want.insert(id);
    const auto nb = neighbours_of(c, ku);
    std::set<int> got(nb.begin(), nb.end());
    std::set<int> big;  // tessera's, less faces too small for the float oracle to see
    const auto areas = mesh_face_measures(c, ku);
    for (int j : got)
      if (!areas.count(j) || areas.at(j) > 1e-12 * std::pow(L, dim - 1)) big.insert(j);
    if (big != want && ++bad <= 5) ADD_FAILURE() << "point " << i << " neighbours differ";
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_EQ(empty, c.empty_cells.size());
  // The stars' cells are assembled (their planes weighed), not clipped:
  // all but those with a vertex within rounding of the box.
  if (method == tessera::CellMethod::insertion) EXPECT_GE(c.assembled_from_stars, (n - empty) * 9 / 10);
  std::printf("[ power ] dim %d n %zu: %zu empty cells\n", dim, n, empty);
  expect_valid(c, pts, radii, "random");
}

TEST(PowerCells, OracleSmallRadii2D) { compare_with_oracle(2, 400, 0.02, 11); }
TEST(PowerCells, OracleLargeRadii2D) { compare_with_oracle(2, 400, 0.3, 12); }  // many empty cells
TEST(PowerCells, OracleSmallRadii3D) { compare_with_oracle(3, 250, 0.05, 13); }
TEST(PowerCells, OracleLargeRadii3D) { compare_with_oracle(3, 250, 0.4, 14); }
// From the regular triangulation's stars (the insertion with the power test):
// each cell clipped by its star's points, hidden points' cells empty.
TEST(PowerCells, OracleByInsertion) {
  compare_with_oracle(2, 400, 0.3, 15, tessera::CellMethod::insertion);
  compare_with_oracle(3, 250, 0.4, 16, tessera::CellMethod::insertion);
  compare_with_oracle(3, 250, 0.05, 17, tessera::CellMethod::insertion);
}

// The search and the stars give the same cells: the same owners, empty
// cells and neighbours, and volumes up to the clip order's last bits; on a
// tied checkerboard lattice too.
TEST(PowerCells, InsertionGivesTheSearchsCells) {
  for (int dim : {2, 3}) {
    const std::size_t n = dim == 2 ? 3000 : 2000;
    const auto box = unit_box();
    const auto pts = random_points(n, dim, 18, box);
    const auto radii = random_radii(n, dim == 2 ? 0.03 : 0.1, 19);
    const auto s = run_power(pts, dim, box, radii, 2, true, tessera::CellMethod::search);
    const auto i = run_power(pts, dim, box, radii, 2, true, tessera::CellMethod::insertion);
    EXPECT_TRUE(i.from_insertion);
    EXPECT_GE(i.assembled_from_stars, i.n_cells() * 9 / 10);
    EXPECT_FALSE(s.empty_cells.empty());
    EXPECT_EQ(i.cell_of, s.cell_of);
    EXPECT_EQ(i.empty_cells, s.empty_cells);
    ASSERT_EQ(i.n_cells(), s.n_cells());
    for (std::size_t k = 0; k < s.n_cells(); ++k) {
      EXPECT_NEAR(i.volume[k], s.volume[k], 1e-12) << k;
      EXPECT_EQ(neighbours_of(i, k), neighbours_of(s, k)) << k;
    }
    expect_valid(i, pts, radii, "by insertion");
  }
}

TEST(PowerCells, ThreadsIdentical) {
  for (int dim : {2, 3}) {
    const auto box = unit_box();
    const std::size_t n = dim == 2 ? 20000 : 8000;
    const auto pts = random_points(n, dim, 21, box);
    const auto radii = random_radii(n, 0.05, 22);
    const auto a = run_power(pts, dim, box, radii, 1), b = run_power(pts, dim, box, radii, 2);
    expect_same_cells(a, b, "1 vs 2 threads");
    EXPECT_EQ(a.empty_cells, b.empty_cells);
    expect_valid(a, pts, radii, "threads");
  }
}

// Equal radii add one constant to every power: the ordinary cells, bit for bit.
TEST(PowerCells, EqualRadiiAreTheOrdinaryCells) {
  for (int dim : {2, 3}) {
    const auto box = unit_box();
    const auto pts = random_points(3000, dim, 31, box);
    const std::vector<double> radii(3000, 0.125);
    const auto p = run_power(pts, dim, box, radii);
    EXPECT_FALSE(p.power);
    expect_same_cells(p, run(pts, dim, box), "equal radii");
  }
}

// A lattice whose radii tie everywhere: two radii alternating in a
// checkerboard, on exact grid coordinates. Every vertex where four (3D) or
// three (2D) power planes meet ties with others; the symbolic perturbation
// must still give D+1 generators per vertex and a conformal mesh.
TEST(PowerCells, CheckerboardLatticeTies) {
  for (int dim : {2, 3}) {
    const int k = dim == 2 ? 20 : 8;
    const auto pts = grid_points(k, dim, 1.0, 0.5);
    const std::size_t n = pts.size() / dim;
    std::vector<double> radii(n);
    for (std::size_t i = 0; i < n; ++i) {
      int parity = 0;
      for (int a = 0; a < dim; ++a) parity += int(pts[i * dim + a]);
      radii[i] = parity % 2 ? 0.25 : 0.5;
    }
    const auto box = make_bounds({0, 0, 0}, {double(k), double(k), double(k)});
    const auto c = run_power(pts, dim, box, radii, 2);
    EXPECT_TRUE(c.power);
    EXPECT_EQ(c.n_cells(), n);
    expect_valid(c, pts, radii, "checkerboard");
    // By the regular triangulation's stars: the same perturbed ties.
    const auto by_stars = run_power(pts, dim, box, radii, 2, true, tessera::CellMethod::insertion);
    expect_valid(by_stars, pts, radii, "checkerboard by insertion");
    for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(neighbours_of(by_stars, k), neighbours_of(c, k)) << k;
    // Each colour's interior cells are alike, and the oracle's (in plain
    // doubles: right on volumes at ties, whatever it makes of the topology).
    for (std::size_t i = 0; i < n; ++i) {
      bool interior = true;
      for (int a = 0; a < dim; ++a) interior &= pts[i * dim + a] > 1 && pts[i * dim + a] < k - 1;
      if (!interior) continue;
      const oracle::Cell o = oracle::cell(pts, dim, i, box.lo, box.hi, radii);
      EXPECT_NEAR(c.volume[static_cast<std::size_t>(c.cell_of[i])], o.volume, 1e-12) << i;
    }
  }
}

// Coincident points: the largest radius owns the cell (ties: the lowest id).
TEST(PowerCells, CoincidentPointsLargestRadiusOwns) {
  for (int dim : {2, 3}) {
    auto pts = random_points(200, dim, 41);
    std::vector<double> radii = random_radii(200, 0.01, 42);
    // Point 10 repeated as 200, 201, 202; 201 has the largest radius.
    // Point 20 repeated as 203 with an equal radius: 20 (lower id) owns.
    auto copy = [&](std::size_t from, double r) {
      for (int a = 0; a < dim; ++a) pts.push_back(pts[from * dim + a]);
      radii.push_back(r);
    };
    copy(10, 0.001);
    copy(10, 0.05);
    copy(10, radii[10]);
    copy(20, radii[20]);
    const auto c = run_power(pts, dim, unit_box(), radii);
    using P = std::pair<std::int32_t, std::int32_t>;
    const std::vector<P> want = {{10, 201}, {200, 201}, {202, 201}, {203, 20}};
    EXPECT_EQ(c.duplicates, want) << "dim " << dim;
    EXPECT_GE(c.cell_of[201], 0);
    for (std::int32_t d : {10, 200, 202, 203}) EXPECT_EQ(c.cell_of[static_cast<std::size_t>(d)], -1);
    expect_valid(c, pts, radii, "coincident");
  }
}

// Planes through p_i and beyond it: d exactly 0 (r_j^2 - r_i^2 = |q|^2), and
// negative, where p_i lies outside its own cell; a cell emptied by a sphere
// that contains another's whole reach. By the search, and assembled from
// the regular triangulation's stars (every point here is on the hull: open
// stars, closed by the far plane).
TEST(PowerCells, PlanesThroughAndBeyondTheGenerator) {
  const auto box = make_bounds({-2, -2, -2}, {2, 2, 2});
  for (const auto method : {tessera::CellMethod::search, tessera::CellMethod::insertion}) {
    SCOPED_TRACE(method == tessera::CellMethod::search ? "search" : "insertion");
    // 2D: p0 = 0 (r 0), p1 = (1, 0) with r1 = 1: their plane is x = 0, through p0.
    // p2 = (-1, 0.5) with r2 = 1.5: plane with p0 at d = (1.25 - 2.25) / 2 < 0.
    const std::vector<double> pts2 = {0, 0, 1, 0, -1, 0.5, 0, -1.5, 1.5, 1.5};
    const std::vector<double> r2 = {0, 1, 1.5, 0.25, 0.5};
    const auto c2 = run_power(pts2, 2, box, r2, 1, true, method);
    for (std::size_t i = 0; i < 5; ++i) {
      const oracle::Cell o = oracle::cell(pts2, 2, i, box.lo, box.hi, r2);
      const auto k = c2.cell_of[i];
      if (k < 0) {
        EXPECT_LE(o.volume, 1e-15) << i;
      } else {
        EXPECT_NEAR(c2.volume[static_cast<std::size_t>(k)], o.volume, 1e-13) << i;
      }
    }
    expect_valid(c2, pts2, r2, "through p_i (2D)");
    // 3D: a small sphere deep inside a large one's reach owns no cell.
    const std::vector<double> pts3 = {0, 0, 0, 0.1, 0, 0, 1, 1, 1, -1, 1, -1};
    const std::vector<double> r3 = {1, 0.05, 0.5, 0.5};
    const auto c3 = run_power(pts3, 3, box, r3, 1, true, method);
    EXPECT_EQ(c3.empty_cells, std::vector<std::int32_t>{1});
    for (std::size_t i : {0u, 2u, 3u}) {
      const oracle::Cell o = oracle::cell(pts3, 3, i, box.lo, box.hi, r3);
      EXPECT_NEAR(c3.volume[static_cast<std::size_t>(c3.cell_of[i])], o.volume, 1e-12) << i;
    }
    expect_valid(c3, pts3, r3, "emptied (3D)");
    if (method == tessera::CellMethod::insertion) {
      EXPECT_EQ(c2.assembled_from_stars, c2.n_cells());
      EXPECT_EQ(c3.assembled_from_stars, c3.n_cells());
    }
  }
}

TEST(PowerCells, BadRadiiRefused) {
  const auto pts = random_points(50, 3, 51);
  auto bad = [&](std::vector<double> radii, auto&& tweak) {
    auto o = options(3, unit_box());
    o.radii = radii;
    tweak(o);
    EXPECT_THROW(tessera::voronoi(pts, 3, {}, o), tessera::InputError);
  };
  auto none = [](tessera::VoronoiOptions&) {};
  bad(std::vector<double>(49, 0.1), none);  // wrong length
  std::vector<double> r(50, 0.1);
  r[7] = -0.1;
  bad(r, none);
  r[7] = std::nan("");
  bad(r, none);
  r[7] = INFINITY;
  bad(r, none);
  r = random_radii(50, 0.1, 52);
  // Power cells measured without their radii cannot be checked exactly.
  auto o = options(3, unit_box());
  o.radii = r;
  const auto c = tessera::voronoi(pts, 3, {}, o);
  EXPECT_THROW(tessera::validate(c, {}, pts), std::invalid_argument);
  // What assumes ordinary cells refuses power cells: flowers (petals through
  // the generator) and surface nets. (The Delaunay triangulation takes radii:
  // the regular triangulation, tests/delaunay/test_regular.cpp.)
  const std::int32_t id = c.generator[0];
  EXPECT_THROW(tessera::flowers(c, pts, std::span<const std::int32_t>(&id, 1)), tessera::InputError);
  tessera::SurfaceNetsOptions s;
  s.voronoi = o;
  const std::vector<std::int32_t> labels(50, 1);
  EXPECT_THROW(tessera::surface_nets(pts, labels, s), tessera::InputError);
}

}  // namespace

// Radii whose squares overflow double (up to 1e300: finite, so accepted).
// One such sphere owns the whole box; random ones of that size leave a few
// cells. Both methods give the same cells, and `validate` measures their
// corners against the cell radius: it summed s - r_g^2 + r_k^2 for it,
// which is NaN there, and read the radius as 0.
TEST(PowerCells, RadiiBeyondTheSquaresRange) {
  const auto pts = random_points(50, 3, 61);
  for (const double big : {1e160, 1e200, 1e300}) {
    SCOPED_TRACE(big);
    auto one = random_radii(50, 0.1, 62);
    one[3] = big;
    auto all = random_radii(50, big, 63);
    for (const auto& radii : {one, all}) {
      const auto s = run_power(pts, 3, unit_box(), radii, 2, true, tessera::CellMethod::search);
      const auto i = run_power(pts, 3, unit_box(), radii, 2, true, tessera::CellMethod::insertion);
      EXPECT_EQ(i.cell_of, s.cell_of);
      ASSERT_EQ(i.n_cells(), s.n_cells());
      for (std::size_t k = 0; k < s.n_cells(); ++k) EXPECT_EQ(neighbours_of(i, k), neighbours_of(s, k)) << k;
      for (const auto* c : {&s, &i}) {
        expect_valid(*c, pts, radii, "huge radii");
        const auto r = tessera::validate(*c, {}, pts, radii);
        EXPECT_LE(r.vertex_rel_error, 1e-12);
      }
    }
    const auto c = run_power(pts, 3, unit_box(), one, 1);
    ASSERT_EQ(c.n_cells(), 1u);
    EXPECT_EQ(c.cell_of[3], 0);
    EXPECT_NEAR(c.volume[0], 1.0, 1e-15);
  }
}
