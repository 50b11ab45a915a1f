// Walls (VoronoiOptions::walls): half-spaces that cut the domain box down to
// a convex polytope.
//
// What this proves: each cell is its box cell's part inside the walls — the
// brute-force oracle clipped by the same half-spaces gives the same volume,
// centroid and face measures per neighbour, box plane and wall (oracle.hpp);
// the cells tile the polytope (volumes sum to its volume); the merged mesh
// is conformal on walls through lattice points and Voronoi vertices (exact
// ties: every vertex has D + 1 distinct ids, each of its generators' cells
// holds it, adjacency is symmetric); a wall on a box plane or cutting
// nothing changes nothing; 1 and 2 threads agree bit for bit; bad walls and
// points outside them are refused with one line, or set aside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>

#include "helpers.hpp"
#include "oracle.hpp"
#include "tessera/delaunay.hpp"

namespace {

using namespace cells_test;

std::vector<tessera::Wall> to_walls(const std::vector<oracle::Wall>& w) {
  std::vector<tessera::Wall> out;
  for (const auto& x : w) out.push_back({{x[0], x[1], x[2]}, x[3]});
  return out;
}

bool inside(const std::vector<oracle::Wall>& walls, const double* p, int dim) {
  for (const auto& w : walls) {
    double s = 0;
    for (int a = 0; a < dim; ++a) s += w[a] * p[a];
    if (s > w[3]) return false;
  }
  return true;
}

/// n random points of the unit box inside the walls.
std::vector<double> points_inside(std::size_t n, int dim, std::uint64_t seed, const std::vector<oracle::Wall>& walls) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> pts;
  while (pts.size() < n * dim) {
    double p[3] = {u(rng), u(rng), u(rng)};
    if (inside(walls, p, dim))
      for (int a = 0; a < dim; ++a) pts.push_back(p[a]);
  }
  return pts;
}

tessera::Cells run_walls(const std::vector<double>& pts, int dim, const std::vector<oracle::Wall>& walls,
                         int threads = 1, const std::vector<double>& radii = {}) {
  tessera::VoronoiOptions o = options(dim, unit_box(), threads);
  o.walls = to_walls(walls);
  o.radii = radii;  // (viewed during the call)
  return tessera::voronoi(std::span<const double>(pts), dim, {}, o);
}

/// The polytope's volume: the oracle's cell of one point, which nothing else clips.
double polytope_volume(int dim, const std::vector<oracle::Wall>& walls, const std::vector<double>& pts) {
  const std::vector<double> one(pts.begin(), pts.begin() + dim);
  const auto b = unit_box();
  return oracle::cell(one, dim, 0, b.lo, b.hi, {}, walls).volume;
}

/// Mesh invariants that exact walls must keep: D + 1 distinct ids per merged
/// vertex, each generator of a key holds the vertex in its cell, symmetric
/// adjacency, and every face on a wall is a domain-boundary face.
void check_mesh(const tessera::Cells& c, const std::string& what) {
  const int D = c.dim;
  const std::size_t nv = c.vertices.size() / D;
  std::vector<std::set<std::int32_t>> cells_of_vertex(nv);
  for (std::size_t k = 0; k < c.n_cells(); ++k)
    for (auto f = c.cell_face_offsets[k]; f < c.cell_face_offsets[k + 1]; ++f) {
      for (auto v = c.face_vertex_offsets[f]; v < c.face_vertex_offsets[f + 1]; ++v)
        cells_of_vertex[c.face_vertices[v]].insert(c.generator[k]);
      if (tessera::is_wall_spoke(c.face_neighbor[f]))
        EXPECT_EQ(c.face_class[f], tessera::SpokeClass::domain_boundary) << what;
    }
  std::size_t on_walls = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    std::set<std::int32_t> ids, gens;
    for (int k = 0; k <= D; ++k) {
      const std::int32_t id = c.vertex_keys[v * (D + 1) + k];
      ids.insert(id);
      if (id >= 0) gens.insert(id);
      on_walls += tessera::is_wall_spoke(id);
    }
    ASSERT_EQ(ids.size(), std::size_t(D + 1)) << what << ": vertex " << v;
    EXPECT_EQ(gens, cells_of_vertex[v]) << what << ": vertex " << v << " is not in exactly its key's cells";
  }
  EXPECT_GT(on_walls, 0u) << what;
  for (std::size_t k = 0; k < c.n_cells(); ++k)
    for (const auto j : neighbours_of(c, k)) {
      const auto nb = neighbours_of(c, static_cast<std::size_t>(c.cell_of[j]));
      EXPECT_TRUE(std::binary_search(nb.begin(), nb.end(), c.generator[k])) << what << ": asymmetric " << k;
    }
}

struct WallCase {
  int dim;
  std::size_t n;
  std::vector<oracle::Wall> walls;
};

std::vector<WallCase> cases() {
  return {
      {2, 300, {{1, 1, 0, 1.4}}},
      {2, 400, {{1, 1, 0, 1.5}, {-1, 1, 0, 0.6}, {0.3, -1, 0, -0.05}, {-1, -0.2, 0, -0.1}}},  // a pentagon-ish
      {2, 200, {{1e-3, 7, 0, 5.5}}},  // nearly axis-aligned, normal far from unit
      {3, 250, {{1, 1, 1, 2.0}}},
      {3, 300, {{1, 1, 1, 2.2}, {-1, 0.5, 0, 0.4}, {0, -1, 2, 1.6}, {0.2, 0.1, -1, -0.05}}},
      {3, 200, {{1, 2, 3, 4.5}, {1, 2, 3, 4.5}}},  // the same wall twice
  };
}

TEST(Walls, CellsAreTheOraclesCellsClippedByTheWalls) {
  std::uint64_t seed = 880;
  for (const auto& wc : cases()) {
    const int dim = wc.dim;
    const auto pts = points_inside(wc.n, dim, ++seed, wc.walls);
    const auto c = run_walls(pts, dim, wc.walls);
    const std::string what = std::to_string(dim) + "D, " + std::to_string(wc.walls.size()) + " walls";
    ASSERT_EQ(c.n_cells(), wc.n) << what;
    ASSERT_EQ(c.walls.size(), wc.walls.size());
    const auto b = unit_box();
    // The same wall given twice: the face lies on the first (a vertex on a
    // wall is inside it, so the second cuts nothing). The oracle, whose
    // float signs on a plane it already cut are noise, takes each once.
    std::vector<oracle::Wall> unique;
    std::vector<int> unique_label;  // oracle label -7-u -> tessera's wall spoke
    for (std::size_t k = 0; k < wc.walls.size(); ++k)
      if (std::find(unique.begin(), unique.end(), wc.walls[k]) == unique.end()) {
        unique.push_back(wc.walls[k]);
        unique_label.push_back(-7 - int(k));
      }
    double sum = 0;
    for (std::size_t i = 0; i < wc.n; ++i) {
      const auto o = oracle::cell(pts, dim, i, b.lo, b.hi, {}, unique);
      const std::size_t k = static_cast<std::size_t>(c.cell_of[i]);
      EXPECT_NEAR(c.volume[k], o.volume, 1e-9 * o.volume) << what << ": cell " << i;
      for (int a = 0; a < dim; ++a) EXPECT_NEAR(c.centroid[k * dim + a], o.centroid[a], 1e-9) << what << ": cell " << i;
      std::map<int, double> want;
      for (const auto& [label, m] : o.face)
        if (m > 1e-9) want[label > -7 ? label : unique_label[static_cast<std::size_t>(-7 - label)]] = m;
      std::map<int, double> got;
      for (const auto& [label, m] : mesh_face_measures(c, k))
        if (m > 1e-9) got[label] = m;
      ASSERT_EQ(got.size(), want.size()) << what << ": cell " << i;
      for (const auto& [label, m] : want) {
        ASSERT_TRUE(got.count(label)) << what << ": cell " << i << " lacks a face on " << label;
        EXPECT_NEAR(got[label], m, 1e-8 * std::max(1.0, m)) << what << ": cell " << i << " face " << label;
      }
      sum += c.volume[k];
    }
    const double poly = polytope_volume(dim, wc.walls, pts);
    EXPECT_NEAR(sum, poly, 1e-12 * poly) << what;
    check_mesh(c, what);
    const auto v = tessera::validate(c, {}, pts);
    EXPECT_TRUE(v.ok) << what << ": " << (v.messages.empty() ? "" : v.messages[0]);
  }
}

TEST(Walls, TwoThreadsGiveTheSameCells) {
  for (const auto& wc : cases()) {
    const auto pts = points_inside(wc.n * 4, wc.dim, 77, wc.walls);
    expect_same_cells(run_walls(pts, wc.dim, wc.walls, 1), run_walls(pts, wc.dim, wc.walls, 2),
                      std::to_string(wc.dim) + "D walls, 1 vs 2 threads");
  }
}

// Walls through lattice points and the lattice cells' corners: every vertex
// on a wall is an exact tie, decided by the perturbation alike in each cell.
TEST(Walls, LatticeWithWallsThroughItsVerticesStaysConformal) {
  for (int dim : {2, 3}) {
    const int k = dim == 2 ? 8 : 4;  // dyadic: the coordinates, sums and walls exact
    const auto g = grid_points(k, dim, 1.0 / k, 0.5 / k);  // cell centres of the unit box
    std::vector<oracle::Wall> walls = dim == 2 ? std::vector<oracle::Wall>{{1, 1, 0, 1.0}, {1, -1, 0, 0.5}}
                                               : std::vector<oracle::Wall>{{1, 1, 1, 1.5}, {1, 0, -1, 0.5}};
    std::vector<double> pts;
    for (std::size_t i = 0; i < g.size() / dim; ++i)
      if (inside(walls, &g[i * dim], dim))
        for (int a = 0; a < dim; ++a) pts.push_back(g[i * dim + a]);
    const auto c = run_walls(pts, dim, walls);
    const std::string what = std::to_string(dim) + "D lattice";
    ASSERT_EQ(c.n_cells(), pts.size() / dim) << what;
    double sum = 0;
    for (double v : c.volume) {
      EXPECT_GT(v, 0) << what;
      sum += v;
    }
    const double poly = polytope_volume(dim, walls, pts);
    EXPECT_NEAR(sum, poly, 1e-12) << what;
    check_mesh(c, what);
    const auto b = unit_box();
    for (std::size_t i = 0; i < pts.size() / dim; ++i) {
      const auto o = oracle::cell(pts, dim, i, b.lo, b.hi, {}, walls);
      EXPECT_NEAR(c.volume[static_cast<std::size_t>(c.cell_of[i])], o.volume, 1e-12) << what << ": cell " << i;
    }
    expect_same_cells(c, run_walls(pts, dim, walls, 2), what + ", 1 vs 2 threads");
  }
}

// A wall on a box plane, or one the box lies inside, changes no cell.
TEST(Walls, WallsThatCutNothingChangeNothing) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(dim == 2 ? 500 : 300, dim, 5, unit_box());
    const auto plain = run(pts, dim, unit_box());
    for (const auto& w : std::vector<oracle::Wall>{{1, 0, 0, 1}, {0, -1, 0, 0}, {1, 1, 0, 3}, {-2, 0, 0, 0}}) {
      const auto c = run_walls(pts, dim, {w});
      ASSERT_EQ(c.n_cells(), plain.n_cells());
      for (std::size_t k = 0; k < c.n_cells(); ++k) {
        EXPECT_EQ(c.volume[k], plain.volume[k]);
        EXPECT_EQ(neighbours_of(c, k), neighbours_of(plain, k));
      }
      EXPECT_EQ(c.vertices.size(), plain.vertices.size());
    }
  }
}

// A slab 1e-9 thick between two nearly parallel walls, far thinner than
// the points' distance from the origin: each wall's offset relative to a
// point cancels to 1e-9 of its terms, and computed in floats it carried an
// error of 1e-7 of itself (vertices placed 1e-16 off, volumes 1e-8 off,
// where the filters took it for exact). validate() measures sampled cells
// exactly.
TEST(Walls, ThinSlabBetweenNearlyParallelWallsMeasuresRight) {
  for (int dim : {2, 3}) {
    auto pts = random_points(dim == 2 ? 3000 : 5000, dim, 41, unit_box());
    const int a = dim - 1;  // the slab's axis
    for (std::size_t i = 0; i < pts.size() / dim; ++i) pts[i * dim + a] = 0.5 + (pts[i * dim + a] - 0.5) * 1e-9;
    tessera::VoronoiOptions o = options(dim, unit_box());
    tessera::Wall lower, upper;
    upper.normal[static_cast<std::size_t>(a)] = 1;
    upper.offset = 0.5 + 0.5e-9;
    lower.normal[0] = 1e-12;
    lower.normal[static_cast<std::size_t>(a)] = -1;
    lower.offset = -0.5 + 0.5e-9;
    o.walls = {upper, lower};
    o.ignore_outside_points = true;
    const auto c = tessera::voronoi(pts, dim, {}, o);
    ASSERT_GT(c.n_cells(), pts.size() / dim - 10);
    const auto v = tessera::validate(c, {}, pts);
    EXPECT_TRUE(v.ok) << dim << "D: " << (v.messages.empty() ? "" : v.messages[0]);
    EXPECT_GT(v.measures_checked, 100u);
  }
}

TEST(Walls, PowerCellsAreTheOraclesClippedByTheWalls) {
  for (int dim : {2, 3}) {
    const std::vector<oracle::Wall> walls = {{1, 1, dim == 3 ? 1.0 : 0.0, 1.6}, {-1, 0.3, 0, 0.2}};
    const std::size_t n = dim == 2 ? 300 : 200;
    const auto pts = points_inside(n, dim, 31 + dim, walls);
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(0, 0.05);
    std::vector<double> radii(n);
    for (double& r : radii) r = u(rng);
    const auto c = run_walls(pts, dim, walls, 1, radii);
    const auto b = unit_box();
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const auto o = oracle::cell(pts, dim, i, b.lo, b.hi, radii, walls);
      if (c.cell_of[i] < 0) {
        EXPECT_LT(o.volume, 1e-12) << "cell " << i;
        continue;
      }
      EXPECT_NEAR(c.volume[static_cast<std::size_t>(c.cell_of[i])], o.volume, 1e-9) << dim << "D cell " << i;
      sum += c.volume[static_cast<std::size_t>(c.cell_of[i])];
    }
    EXPECT_NEAR(sum, polytope_volume(dim, walls, pts), 1e-12);
  }
}

TEST(Walls, BadWallsAndPointsOutsideAreRefused) {
  const auto pts = random_points(100, 3, 4, unit_box());
  auto expect_refused = [&](std::vector<tessera::Wall> walls, const std::string& part, int dim = 3) {
    tessera::VoronoiOptions o = options(dim, unit_box());
    o.walls = std::move(walls);
    const std::vector<double> p2 = random_points(100, 2, 4, unit_box());
    try {
      tessera::voronoi(dim == 3 ? std::span<const double>(pts) : std::span<const double>(p2), dim, {}, o);
      ADD_FAILURE() << "accepted: " << part;
    } catch (const tessera::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  expect_refused({{{0, 0, 0}, 1}}, "wall 0: its normal is zero");
  expect_refused({{{1, 0, 0}, 2}, {{NAN, 0, 0}, 1}}, "wall 1: its normal is not finite");
  expect_refused({{{1, 0, 0}, INFINITY}}, "its offset is not finite");
  expect_refused({{{1, 0, 1}, 1}}, "third must be 0", 2);
  expect_refused({{{1e300, 1e-300, 0}, 1}}, "normal's components differ");
  expect_refused({{{1, 1, 1}, 1.0}}, "lies outside wall 0");
  expect_refused({{{1, 0, 0}, -1}}, "lies outside wall 0");

  // Set aside instead: the points outside are listed, the rest computed.
  tessera::VoronoiOptions o = options(3, unit_box());
  o.walls = {{{1, 1, 1}, 1.5}};
  o.ignore_outside_points = true;
  const auto c = tessera::voronoi(pts, 3, {}, o);
  std::size_t outside = 0;
  for (std::size_t i = 0; i < 100; ++i) {
    const bool out = pts[3 * i] + pts[3 * i + 1] + pts[3 * i + 2] > 1.5;
    outside += out;
    EXPECT_EQ(c.cell_of[i] < 0, out) << i;
  }
  EXPECT_EQ(c.ignored_outside_bounds.size(), outside);
  o.walls = {{{1, 0, 0}, -1}};
  EXPECT_THROW(tessera::voronoi(pts, 3, {}, o), tessera::InputError);  // all outside

  // Not with a periodic box, nor for delaunay().
  tessera::VoronoiOptions per = options(3, unit_box());
  per.periodic = {true, true, true};
  per.walls = {{{1, 1, 1}, 2.5}};
  EXPECT_THROW(tessera::voronoi(pts, 3, {}, per), tessera::InputError);
  tessera::DelaunayOptions dl;
  dl.bounds = unit_box();
  dl.walls = {{{1, 1, 1}, 2.5}};
  EXPECT_THROW(tessera::delaunay(pts, 3, {}, dl), tessera::InputError);
}

}  // namespace
