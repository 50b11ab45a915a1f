// Point location (SimplexLocator) and the Delaunay edge lists
// (vertex_neighbors): against CGAL's own locate and a brute-force scan that
// uses CGAL's orientation predicate, so neither oracle shares our predicates.
#include <gtest/gtest.h>

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "random_points.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/locate.hpp"

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

std::vector<double> uniform(std::size_t n, int dim, std::uint64_t seed, double lo = 0, double hi = 1) {
  return uniform_points(n, dim, seed, lo, hi);
}

tessera::Delaunay triangulate(const std::vector<double>& p, int dim, const std::vector<std::int32_t>& labels = {},
                              int threads = 2) {
  tessera::DelaunayOptions o;
  o.dim = dim;
  o.threads = threads;
  return tessera::delaunay(p, dim, labels, o);
}

// Does the closed simplex s hold x? CGAL's exact orientation, not ours.
bool cgal_contains(const tessera::Delaunay& dt, const std::vector<double>& p, std::size_t s, const double* x) {
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1);
  const std::int32_t* row = dt.simplices.data() + s * w;
  if (dt.dim == 3) {
    K::Point_3 v[4], q(x[0], x[1], x[2]);
    for (std::size_t k = 0; k < 4; ++k) {
      const double* c = p.data() + 3 * static_cast<std::size_t>(row[k]);
      v[k] = K::Point_3(c[0], c[1], c[2]);
    }
    for (std::size_t k = 0; k < 4; ++k) {
      K::Point_3 u[4] = {v[0], v[1], v[2], v[3]};
      u[k] = q;
      if (CGAL::orientation(u[0], u[1], u[2], u[3]) == CGAL::NEGATIVE) return false;
    }
    return true;
  }
  K::Point_2 v[3], q(x[0], x[1]);
  for (std::size_t k = 0; k < 3; ++k) {
    const double* c = p.data() + 2 * static_cast<std::size_t>(row[k]);
    v[k] = K::Point_2(c[0], c[1]);
  }
  for (std::size_t k = 0; k < 3; ++k) {
    K::Point_2 u[3] = {v[0], v[1], v[2]};
    u[k] = q;
    if (CGAL::orientation(u[0], u[1], u[2]) == CGAL::NEGATIVE) return false;
  }
  return true;
}

std::int32_t brute_force(const tessera::Delaunay& dt, const std::vector<double>& p, const double* x) {
  for (std::size_t s = 0; s < dt.n_simplices(); ++s)
    if (cgal_contains(dt, p, s, x)) return static_cast<std::int32_t>(s);
  return -1;
}

// Both methods where both apply (the walk needs a hull-complete triangulation).
void expect_brute_force(const tessera::Delaunay& dt, const std::vector<double>& p, const std::vector<double>& q) {
  std::vector<tessera::LocateMethod> methods{tessera::LocateMethod::grid};
  if (dt.hull_completed) methods.push_back(tessera::LocateMethod::walk);
  const std::size_t D = static_cast<std::size_t>(dt.dim);
  std::vector<std::int32_t> want(q.size() / D);
  for (std::size_t i = 0; i < want.size(); ++i) want[i] = brute_force(dt, p, q.data() + i * D);
  EXPECT_GT(std::count_if(want.begin(), want.end(), [](std::int32_t s) { return s >= 0; }), 0);
  for (const auto method : methods) {
    SCOPED_TRACE(method == tessera::LocateMethod::walk ? "walk" : "grid");
    tessera::SimplexLocator loc(dt, p, 0, method);
    EXPECT_EQ(loc.method(), method);
    const auto found = loc.locate(dt, p, q);
    ASSERT_EQ(found.size(), want.size());
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < found.size(); ++i) wrong += found[i] != want[i];
    EXPECT_EQ(wrong, 0u) << "of " << found.size() << " queries";
    EXPECT_LE(loc.entries(), 16 * dt.n_simplices() + 4096);
  }
}

TEST(Locate, RandomQueriesEqualBruteForce) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    auto p = uniform(800, dim, 7);
    auto q = uniform(600, dim, 8, -0.1, 1.1);  // some outside the hull
    expect_brute_force(triangulate(p, dim), p, q);
  }
}

TEST(Locate, EqualsCgalLocateInsideAndOutsideTheHull) {
  auto p = uniform(3000, 3, 11);
  auto q = uniform(3000, 3, 12, -0.05, 1.05);
  tessera::Delaunay dt = triangulate(p, 3);
  const auto found = tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::walk).locate(dt, p, q);
  EXPECT_EQ(tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::grid).locate(dt, p, q), found);
  std::vector<std::pair<K::Point_3, std::int32_t>> pts;
  for (std::size_t i = 0; i < 3000; ++i)
    pts.emplace_back(K::Point_3(p[3 * i], p[3 * i + 1], p[3 * i + 2]), static_cast<std::int32_t>(i));
  using Vb = CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, K>;
  CGAL::Delaunay_triangulation_3<K, CGAL::Triangulation_data_structure_3<Vb>> cgal(pts.begin(), pts.end());
  std::size_t outside = 0;
  for (std::size_t i = 0; i < found.size(); ++i) {
    const auto c = cgal.locate(K::Point_3(q[3 * i], q[3 * i + 1], q[3 * i + 2]));
    if (cgal.is_infinite(c)) {
      EXPECT_EQ(found[i], -1) << "query " << i << " lies outside the hull";
      ++outside;
      continue;
    }
    ASSERT_GE(found[i], 0) << "query " << i << " lies inside the hull";
    // Random queries lie strictly inside one tetrahedron: the same four points.
    std::vector<std::int32_t> theirs, ours(dt.simplices.begin() + 4 * found[i], dt.simplices.begin() + 4 * found[i] + 4);
    for (int k = 0; k < 4; ++k) theirs.push_back(c->vertex(k)->info());
    std::sort(theirs.begin(), theirs.end());
    std::sort(ours.begin(), ours.end());
    EXPECT_EQ(ours, theirs) << "query " << i;
  }
  EXPECT_GT(outside, 100u);
  EXPECT_LT(outside, 2000u);
}

TEST(Locate, InputPointsFindTheirLowestSimplex) {
  // A query at an input point lies in exactly its own simplices (general
  // position): the answer is the lowest of them.
  auto p = uniform(2000, 3, 21);
  tessera::Delaunay dt = triangulate(p, 3);
  // vertex_to_simplex (checked against its own oracle below) is that lowest.
  for (const auto method : {tessera::LocateMethod::grid, tessera::LocateMethod::walk})
    EXPECT_EQ(tessera::SimplexLocator(dt, p, 0, method).locate(dt, p, p), tessera::vertex_to_simplex(dt));
}

TEST(Locate, DegenerateTriangulationsCoarsenTheGrid) {
  // Integer points on a circle: a fan of long thin triangles, each meeting a
  // whole row of fine bins. And a lattice, where queries on shared facets
  // and edges are common.
  std::vector<double> circle;
  for (int x = -65; x <= 65; ++x)
    for (int y = -65; y <= 65; ++y)
      if (x * x + y * y == 65 * 65) circle.insert(circle.end(), {double(x), double(y)});
  auto q2 = uniform(400, 2, 31, -70, 70);
  for (std::size_t i = 0; i + 1 < circle.size(); i += 2) q2.insert(q2.end(), {0.5 * circle[i], 0.5 * circle[i + 1]});
  expect_brute_force(triangulate(circle, 2), circle, q2);

  // Near the moment curve: a quadratic number of long simplices, which a grid
  // sized by their count would list thousands of times each.
  std::vector<double> spiral;
  for (int i = 0; i < 400; ++i) {
    const double t = 0.05 * i;
    spiral.insert(spiral.end(), {t * std::cos(t), t * std::sin(t), 0.1 * t});
  }
  tessera::Delaunay sdt = triangulate(spiral, 3);
  const tessera::SimplexLocator sloc(sdt, spiral, 0, tessera::LocateMethod::grid);
  EXPECT_LT(sloc.bins()[0] * sloc.bins()[1] * sloc.bins()[2], static_cast<std::int64_t>(sdt.n_simplices() / 8))
      << "the grid was not coarsened";
  auto q = uniform(150, 3, 32, -20, 20);
  for (std::size_t i = 2; i < q.size(); i += 3) q[i] = 0.5 * (q[i] + 20) / 20 * 2;  // z within the spiral's
  expect_brute_force(sdt, spiral, q);

  std::vector<double> lattice, q3;
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 5; ++x) lattice.insert(lattice.end(), {double(x), double(y), double(z)});
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> half(-1, 9);
  for (int i = 0; i < 500; ++i)
    for (int d = 0; d < 3; ++d) q3.push_back(0.5 * half(rng));  // on lattice planes, edges and points
  expect_brute_force(triangulate(lattice, 3), lattice, q3);
}

TEST(Locate, LabelledRegionsAndHoles) {
  // A shell of inside points (outside points in the middle and around):
  // the triangulation is not convex, and queries in the hole find nothing.
  auto p = uniform(3000, 3, 41);
  std::vector<std::int32_t> labels(3000);
  for (std::size_t i = 0; i < 3000; ++i) {
    double r2 = 0;
    for (int d = 0; d < 3; ++d) r2 += (p[3 * i + static_cast<std::size_t>(d)] - 0.5) * (p[3 * i + static_cast<std::size_t>(d)] - 0.5);
    labels[i] = r2 > 0.04 && r2 < 0.16 ? 0 : -1;
  }
  tessera::Delaunay dt = triangulate(p, 3, labels);
  auto q = uniform(500, 3, 42);
  q.insert(q.end(), {0.5, 0.5, 0.5});
  expect_brute_force(dt, p, q);
  const tessera::SimplexLocator loc(dt, p);
  EXPECT_EQ(loc.method(), tessera::LocateMethod::grid) << "a labelled triangulation is not convex";
  EXPECT_EQ(loc.locate(dt, p, {q.end() - 3, q.end()})[0], -1);
  EXPECT_THROW(tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::walk), tessera::InputError);
}

TEST(Locate, ThreadsAndBadQueries) {
  auto p = uniform(5000, 2, 51);
  auto q = uniform(20000, 2, 52, -0.1, 1.1);
  tessera::Delaunay dt = triangulate(p, 2);
  tessera::SimplexLocator loc(dt, p, 1);
  EXPECT_EQ(loc.method(), tessera::LocateMethod::walk);
  EXPECT_EQ(loc.locate(dt, p, q, 1), tessera::SimplexLocator(dt, p, 2).locate(dt, p, q, 2));
  EXPECT_EQ(loc.locate(dt, p, q, 2), tessera::SimplexLocator(dt, p, 2, tessera::LocateMethod::grid).locate(dt, p, q, 1));
  const double bad[] = {NAN, 0.5, 0.5, INFINITY};
  EXPECT_EQ(loc.locate(dt, p, bad), (std::vector<std::int32_t>{-1, -1}));
  EXPECT_THROW(loc.locate(dt, p, {q.begin(), q.begin() + 3}), tessera::InputError);
  std::vector<double> fewer(p.begin(), p.end() - 2);
  EXPECT_THROW(tessera::SimplexLocator(dt, fewer), tessera::InputError);
  // No simplices (three collinear points): every query is outside.
  std::vector<double> line = {0, 0, 1, 1, 2, 2};
  tessera::Delaunay flat = triangulate(line, 2);
  ASSERT_EQ(flat.n_simplices(), 0u);
  EXPECT_EQ(tessera::SimplexLocator(flat, line).locate(flat, line, line), (std::vector<std::int32_t>{-1, -1, -1}));
}

TEST(Locate, SharedAdjacency) {
  // A walk given simplex_neighbors(dt) uses that very array (no copy) and
  // answers as one that computed its own; the grid keeps none. An adjacency
  // of the wrong size, or naming a simplex that does not exist, could send
  // the walk out of bounds: refused.
  auto p = uniform(3000, 3, 81);
  auto q = uniform(5000, 3, 82, -0.1, 1.1);
  tessera::Delaunay dt = triangulate(p, 3);
  const tessera::SimplexLocator own(dt, p);
  ASSERT_EQ(own.method(), tessera::LocateMethod::walk);
  ASSERT_TRUE(own.neighbors());
  EXPECT_EQ(*own.neighbors(), tessera::simplex_neighbors(dt));
  auto nb = std::make_shared<const std::vector<std::int32_t>>(tessera::simplex_neighbors(dt));
  const tessera::SimplexLocator shared(dt, p, 0, tessera::LocateMethod::automatic, nb);
  EXPECT_EQ(shared.neighbors().get(), nb.get());
  EXPECT_EQ(shared.locate(dt, p, q), own.locate(dt, p, q));
  EXPECT_FALSE(tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::grid, nb).neighbors());

  auto shorter = std::make_shared<const std::vector<std::int32_t>>(nb->begin(), nb->end() - 1);
  EXPECT_THROW(tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::walk, shorter), tessera::InputError);
  for (std::int32_t wrong : {-2, static_cast<std::int32_t>(dt.n_simplices())}) {
    auto bad = std::make_shared<std::vector<std::int32_t>>(*nb);
    (*bad)[bad->size() / 2] = wrong;
    EXPECT_THROW(tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::walk, bad), tessera::InputError) << wrong;
  }
}

TEST(Locate, PowerOfTwoScalesLocateAlike) {
  // Scaling by 2^e is exact: the same triangulation and the same answers, with
  // coordinates near double's smallest and largest normal exponents.
  auto p = uniform(400, 3, 71);
  auto q = uniform(400, 3, 72, -0.1, 1.1);
  tessera::Delaunay dt = triangulate(p, 3);
  const auto want = tessera::SimplexLocator(dt, p, 0, tessera::LocateMethod::grid).locate(dt, p, q);
  for (int e : {-900, 900}) {
    SCOPED_TRACE(e);
    auto ps = p, qs = q;
    for (double& x : ps) x = std::ldexp(x, e);
    for (double& x : qs) x = std::ldexp(x, e);
    tessera::Delaunay dts = triangulate(ps, 3);
    ASSERT_EQ(dts.n_simplices(), dt.n_simplices());
    EXPECT_EQ(tessera::SimplexLocator(dts, ps).locate(dts, ps, qs), want);
  }
}

TEST(VertexNeighbors, HubOfHighDegree) {
  // Point 0 at the centre of points on a sphere: every hull point is its
  // neighbour, and its bucket (each edge once per tetrahedron around it)
  // holds thousands of entries, past the branch-free deduplication's cap;
  // the others hold tens. Both must give the simplices' edges.
  std::mt19937_64 rng(91);
  std::normal_distribution<double> g;
  std::vector<double> p = {0, 0, 0};
  for (int i = 0; i < 500; ++i) {
    double x = g(rng), y = g(rng), z = g(rng), r = std::sqrt(x * x + y * y + z * z);
    p.insert(p.end(), {x / r, y / r, z / r});
  }
  tessera::Delaunay dt = triangulate(p, 3);
  const std::size_t n = dt.n_points, w = 4;
  std::vector<std::set<std::int32_t>> want(n);
  for (std::size_t s = 0; s < dt.n_simplices(); ++s)
    for (std::size_t a = 0; a < w; ++a)
      for (std::size_t b = 0; b < w; ++b)
        if (a != b) want[static_cast<std::size_t>(dt.simplices[s * w + a])].insert(dt.simplices[s * w + b]);
  ASSERT_EQ(want[0].size(), n - 1) << "the centre sees every point";
  const tessera::VertexNeighbors nb = tessera::vertex_neighbors(dt);
  for (std::size_t v = 0; v < n; ++v) {
    std::vector<std::int32_t> got(nb.ids.begin() + nb.offsets[v], nb.ids.begin() + nb.offsets[v + 1]);
    EXPECT_EQ(got, std::vector<std::int32_t>(want[v].begin(), want[v].end())) << "point " << v;
  }
}

TEST(VertexNeighbors, AreTheSimplicesEdgesAndVertexToSimplexTheLowest) {
  for (int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    auto p = uniform(1500, dim, 61);
    p.insert(p.end(), p.begin(), p.begin() + dim);  // a duplicate of point 0: no neighbours
    tessera::Delaunay dt = triangulate(p, dim);
    const std::size_t n = dt.n_points, w = static_cast<std::size_t>(dim + 1);
    std::vector<std::set<std::int32_t>> want(n);
    for (std::size_t s = 0; s < dt.n_simplices(); ++s)
      for (std::size_t a = 0; a < w; ++a)
        for (std::size_t b = 0; b < w; ++b)
          if (a != b) want[static_cast<std::size_t>(dt.simplices[s * w + a])].insert(dt.simplices[s * w + b]);
    const tessera::VertexNeighbors nb = tessera::vertex_neighbors(dt);
    ASSERT_EQ(nb.offsets.size(), n + 1);
    for (std::size_t v = 0; v < n; ++v) {
      std::vector<std::int32_t> got(nb.ids.begin() + nb.offsets[v], nb.ids.begin() + nb.offsets[v + 1]);
      EXPECT_EQ(got, std::vector<std::int32_t>(want[v].begin(), want[v].end())) << "point " << v;
    }
    EXPECT_EQ(nb.offsets[n], static_cast<std::int64_t>(nb.ids.size()));
    EXPECT_EQ(nb.offsets[n - 1], nb.offsets[n]) << "the duplicate has no neighbours";
    const tessera::VertexNeighbors one = tessera::vertex_neighbors(triangulate(p, dim, {}, 1));
    EXPECT_EQ(one.offsets, nb.offsets) << "1 vs 2 threads";
    EXPECT_EQ(one.ids, nb.ids) << "1 vs 2 threads";
    const std::vector<std::int32_t> v2s = tessera::vertex_to_simplex(dt);
    std::vector<std::int32_t> lowest(n, -1);
    for (std::size_t s = 0; s < dt.n_simplices(); ++s)
      for (std::size_t k = 0; k < w; ++k) {
        std::int32_t& l = lowest[static_cast<std::size_t>(dt.simplices[s * w + k])];
        if (l < 0) l = static_cast<std::int32_t>(s);
      }
    EXPECT_EQ(v2s, lowest);
    EXPECT_EQ(v2s[n - 1], -1);
  }
}

}  // namespace
