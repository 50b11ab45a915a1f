// Spherical Voronoi cells (tessera::spherical_voronoi): the dual triangles
// are the convex hull's facets (brute force on small sets, CGAL's
// convex_hull_3 on larger ones); the cells tile the sphere (areas add to
// 4 pi R^2, V - E + F = 2, symmetric adjacency, each vertex equidistant
// from its three generators and no point nearer); exactly cocircular sets
// (cube corners, an octahedron, lon/lat grids with their poles) get a
// consistent topology with three generators per vertex; the tiny cases
// (one to four points) and duplicates; 1 vs 2 threads identical; bad input
// refused.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>
#include <gmpxx.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/kernels/delaunay_predicates.hpp"
#include "tessera/kernels/sphere_predicates.hpp"
#include "tessera/spherical_voronoi.hpp"

namespace {

using tessera::SphereCellStatus;
using tessera::SphericalVoronoi;
using Tri = std::array<std::int32_t, 3>;
constexpr double pi = std::numbers::pi;

std::vector<double> random_sphere(std::size_t n, std::uint64_t seed, double radius = 1, std::array<double, 3> c = {0, 0, 0}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::vector<double> pts(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    double v[3] = {g(rng), g(rng), g(rng)};
    const double l = std::hypot(v[0], v[1], v[2]);
    for (int d = 0; d < 3; ++d) pts[3 * i + d] = c[d] + radius * v[d] / l;
  }
  return pts;
}

// A triangle by its cyclic order, rotated to start at its lowest id.
Tri canonical(Tri t) {
  while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
  return t;
}

std::set<Tri> triangles(const SphericalVoronoi& sv) {
  std::set<Tri> s;
  for (std::size_t v = 0; v < sv.n_vertices(); ++v)
    s.insert(canonical({sv.triangles[3 * v], sv.triangles[3 * v + 1], sv.triangles[3 * v + 2]}));
  return s;
}

// Every facet (a, b, c), outward, with no point above it: O(n^4).
std::set<Tri> brute_force_hull(const std::vector<double>& pts) {
  const auto n = static_cast<std::int32_t>(pts.size() / 3);
  auto P = [&](std::int32_t i) { return &pts[3 * static_cast<std::size_t>(i)]; };
  std::set<Tri> s;
  for (std::int32_t a = 0; a < n; ++a)
    for (std::int32_t b = a + 1; b < n; ++b)
      for (std::int32_t c = a + 1; c < n; ++c) {
        if (c == b) continue;
        bool empty = true;
        for (std::int32_t q = 0; q < n && empty; ++q) {
          if (q == a || q == b || q == c) continue;
          empty = tessera::kernels::orientation_sos(P(a), P(b), P(c), P(q), a, b, c, q) < 0;
        }
        if (empty) s.insert({a, b, c});
      }
  return s;
}

// The invariants every result must have (file comment); `points` as given.
void check_tiling(const SphericalVoronoi& sv, const std::vector<double>& pts, bool geometric = true) {
  const std::size_t n = sv.n_points;
  const double R = sv.radius;
  ASSERT_EQ(sv.region_offsets.size(), n + 1);
  ASSERT_EQ(sv.neighbor_offsets.size(), n + 1);
  EXPECT_NEAR(sv.area_sum, 4 * pi * R * R, 1e-11 * R * R);
  // Symmetric adjacency: q in p's ring iff p in q's ring, once each.
  std::set<std::pair<std::int32_t, std::int32_t>> edges;
  for (std::size_t i = 0; i < n; ++i)
    for (auto k = sv.neighbor_offsets[i]; k < sv.neighbor_offsets[i + 1]; ++k) {
      EXPECT_TRUE(edges.insert({static_cast<std::int32_t>(i), sv.neighbors[static_cast<std::size_t>(k)]}).second);
      EXPECT_EQ(sv.status[static_cast<std::size_t>(sv.neighbors[static_cast<std::size_t>(k)])], SphereCellStatus::cell);
    }
  for (const auto& [a, b] : edges) EXPECT_TRUE(edges.count({b, a})) << a << " " << b;
  // Each vertex: its three generators' cells hold it; and the rings agree.
  std::vector<int> seen(sv.n_vertices(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto m = sv.region_offsets[i + 1] - sv.region_offsets[i];
    if (m > 0) EXPECT_EQ(m, sv.neighbor_offsets[i + 1] - sv.neighbor_offsets[i]);
    for (auto k = sv.region_offsets[i]; k < sv.region_offsets[i + 1]; ++k) {
      const auto v = static_cast<std::size_t>(sv.region_vertices[static_cast<std::size_t>(k)]);
      ++seen[v];
      const std::int32_t* t = &sv.triangles[3 * v];
      EXPECT_TRUE(t[0] == static_cast<std::int32_t>(i) || t[1] == static_cast<std::int32_t>(i) ||
                  t[2] == static_cast<std::int32_t>(i));
    }
  }
  for (std::size_t v = 0; v < sv.n_vertices(); ++v) EXPECT_EQ(seen[v], 3) << "vertex " << v;
  const auto report = tessera::validate_spherical_voronoi(sv, pts, 64);
  EXPECT_TRUE(report.ok) << (report.messages.empty() ? "" : report.messages[0]);
  // Euler on the sphere (cells with vertices: n >= 3 distinct points).
  if (sv.n_vertices() > 0) {
    const long long E = static_cast<long long>(sv.neighbors.size()) / 2;
    const long long F = static_cast<long long>(sv.n_cells());
    EXPECT_EQ(static_cast<long long>(sv.n_vertices()) - E + F, 2);
  }
  if (!geometric) return;
  // Vertices on the sphere, equidistant from their generators, none nearer.
  for (std::size_t v = 0; v < sv.n_vertices(); ++v) {
    const double* x = &sv.vertices[3 * v];
    EXPECT_NEAR(std::hypot(x[0] - sv.center[0], x[1] - sv.center[1], x[2] - sv.center[2]), R, 1e-12 * R);
    auto dist = [&](std::size_t i) { return std::hypot(x[0] - pts[3 * i], x[1] - pts[3 * i + 1], x[2] - pts[3 * i + 2]); };
    const double d0 = dist(static_cast<std::size_t>(sv.triangles[3 * v]));
    for (int k = 1; k < 3; ++k) EXPECT_NEAR(dist(static_cast<std::size_t>(sv.triangles[3 * v + k])), d0, 1e-9 * R);
    if (n <= 3000)
      for (std::size_t i = 0; i < n; ++i) EXPECT_GE(dist(i), d0 - 1e-9 * R);
  }
}

TEST(SphericalVoronoi, TrianglesAreTheHullByBruteForce) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const auto pts = random_sphere(40, seed);
    const auto sv = tessera::spherical_voronoi(pts);
    EXPECT_EQ(triangles(sv), brute_force_hull(pts));
    check_tiling(sv, pts);
    EXPECT_EQ(sv.n_cells(), 40u);
  }
}

TEST(SphericalVoronoi, TrianglesAreCgalsConvexHull) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Mesh = CGAL::Surface_mesh<K::Point_3>;
  const std::size_t n = 3000;
  const auto pts = random_sphere(n, 7, 2.5, {1, -2, 0.5});
  tessera::SphericalVoronoiOptions o;
  o.center = {1, -2, 0.5};
  const auto sv = tessera::spherical_voronoi(pts, o);
  EXPECT_NEAR(sv.radius, 2.5, 1e-12);
  std::vector<K::Point_3> cp;
  std::map<std::array<double, 3>, std::int32_t> id;
  for (std::size_t i = 0; i < n; ++i) {
    cp.emplace_back(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    id[{pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]}] = static_cast<std::int32_t>(i);
  }
  Mesh mesh;
  CGAL::convex_hull_3(cp.begin(), cp.end(), mesh);
  std::set<Tri> hull;
  for (auto f : mesh.faces()) {
    Tri t{};
    int k = 0;
    for (auto v : mesh.vertices_around_face(mesh.halfedge(f))) {
      const auto& q = mesh.point(v);
      t[k++] = id.at({q.x(), q.y(), q.z()});
    }
    hull.insert(canonical(t));
  }
  EXPECT_EQ(triangles(sv), hull);
  check_tiling(sv, pts);
}

TEST(SphericalVoronoi, LargerRandomSetTilesTheSphere) {
  const auto pts = random_sphere(50000, 11);
  const auto sv = tessera::spherical_voronoi(pts);
  check_tiling(sv, pts);
  EXPECT_EQ(sv.n_vertices(), 2 * 50000u - 4);  // a simplicial hull of n vertices has 2n - 4 facets
  // Centroids lie on the sphere, inside their own cell (nearest to their point).
  for (std::size_t i = 0; i < 50000; i += 97) {
    const double* g = &sv.centroids[3 * i];
    EXPECT_NEAR(std::hypot(g[0], g[1], g[2]), 1.0, 1e-12);
    for (auto k = sv.neighbor_offsets[i]; k < sv.neighbor_offsets[i + 1]; ++k) {
      const auto q = static_cast<std::size_t>(sv.neighbors[static_cast<std::size_t>(k)]);
      double dp = 0, dq = 0;
      for (int d = 0; d < 3; ++d) {
        dp += g[d] * pts[3 * i + d];
        dq += g[d] * pts[3 * q + d];
      }
      EXPECT_GT(dp, dq);
    }
  }
}

TEST(SphericalVoronoi, OneAndTwoThreadsAreIdentical) {
  const auto pts = random_sphere(20000, 5);
  tessera::SphericalVoronoiOptions o;
  o.threads = 1;
  const auto a = tessera::spherical_voronoi(pts, o);
  o.threads = 2;
  const auto b = tessera::spherical_voronoi(pts, o);
  o.threads = 3;
  o.bin_points = 0.5;  // another grid: the same cells
  const auto c = tessera::spherical_voronoi(pts, o);
  for (const auto* x : {&b, &c}) {
    EXPECT_EQ(a.neighbors, x->neighbors);
    EXPECT_EQ(a.neighbor_offsets, x->neighbor_offsets);
    EXPECT_EQ(a.region_vertices, x->region_vertices);
    EXPECT_EQ(a.triangles, x->triangles);
    EXPECT_EQ(a.vertices, x->vertices);
    EXPECT_EQ(a.areas, x->areas);
    EXPECT_EQ(a.centroids, x->centroids);
  }
}

// Exact ties: every four corners of a cube's face lie on one circle of
// its circumsphere; the octahedron's six vertices make eight tied facets
// with the perturbation; all break the same way in every cell.
TEST(SphericalVoronoi, CocircularSetsGetOneTopology) {
  std::vector<double> cube;
  for (int k = 0; k < 8; ++k)
    for (int d = 0; d < 3; ++d) cube.push_back((k >> d) & 1 ? 1.0 : -1.0);
  auto sv = tessera::spherical_voronoi(cube);
  check_tiling(sv, cube);
  EXPECT_EQ(sv.n_vertices(), 12u);  // 6 square faces, 2 triangles each
  EXPECT_GT(sv.exact_tests, 0u);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(sv.areas[i], 4 * pi * 3 / 8, 1e-12);
  EXPECT_EQ(triangles(sv), brute_force_hull(cube));

  std::vector<double> octa = {1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1};
  sv = tessera::spherical_voronoi(octa);
  check_tiling(sv, octa);
  EXPECT_EQ(sv.n_vertices(), 8u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(sv.areas[i], 4 * pi / 6, 1e-12);
}

// A lon/lat grid: rows of points on circles of latitude (trapezoids of four
// cocircular points), the poles given once per longitude (which rounds to
// distinct points a hair apart, most of them inside the hull).
TEST(SphericalVoronoi, LonLatGridWithItsPoles) {
  std::vector<double> ll;
  for (int lat = -90; lat <= 90; lat += 10)
    for (int lon = -180; lon < 180; lon += 15) {
      ll.push_back(lon);
      ll.push_back(lat);
    }
  const auto pts = tessera::lonlat_to_points(ll, 6371.0);
  const auto sv = tessera::spherical_voronoi(pts);
  check_tiling(sv, pts, false);
  EXPECT_GT(sv.exact_tests, 0u);
  // Band cells of one row have one area (the grid's symmetry), to rounding.
  const std::size_t row = 24;
  for (std::size_t r = 1; r + 1 < 19; ++r)
    for (std::size_t k = 1; k < row; ++k) EXPECT_NEAR(sv.areas[r * row + k], sv.areas[r * row], 1e-6 * sv.areas[r * row]);
}

TEST(SphericalVoronoi, DegenerateSets) {
  // All points on one great circle: a flat hull, broken by the perturbation.
  std::vector<double> ring;
  for (int k = 0; k < 12; ++k) {
    ring.push_back(std::cos(2 * pi * k / 12));
    ring.push_back(std::sin(2 * pi * k / 12));
    ring.push_back(0);
  }
  auto sv = tessera::spherical_voronoi(ring);
  check_tiling(sv, ring, false);
  EXPECT_EQ(sv.n_cells(), 12u);
  // A closed hemisphere: the equator's points and a cap.
  auto half = ring;
  for (int k = 0; k < 30; ++k) {
    const auto q = random_sphere(1, 100 + static_cast<std::uint64_t>(k));
    half.insert(half.end(), {q[0], q[1], std::fabs(q[2])});
  }
  sv = tessera::spherical_voronoi(half);
  check_tiling(sv, half, false);
  EXPECT_EQ(triangles(sv), brute_force_hull(half));
}

TEST(SphericalVoronoi, TinySetsAndDuplicates) {
  std::vector<double> one = {0, 0, 2};
  auto sv = tessera::spherical_voronoi(one);
  EXPECT_NEAR(sv.areas[0], 16 * pi, 1e-12);
  EXPECT_EQ(sv.n_vertices(), 0u);
  std::vector<double> two = {0, 0, 1, 1, 0, 0, 0, 0, 1};  // the third repeats the first
  sv = tessera::spherical_voronoi(two);
  EXPECT_EQ(sv.status[2], SphereCellStatus::duplicate);
  EXPECT_EQ(sv.duplicate_of[2], 0);
  EXPECT_EQ(sv.duplicates, 1u);
  EXPECT_NEAR(sv.areas[0], 2 * pi, 1e-12);
  EXPECT_NEAR(sv.areas[1], 2 * pi, 1e-12);
  EXPECT_EQ(sv.areas[2], 0);
  EXPECT_EQ(std::vector<std::int32_t>(sv.neighbors.begin(), sv.neighbors.end()), (std::vector<std::int32_t>{1, 0}));
  std::vector<double> three = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  sv = tessera::spherical_voronoi(three);
  check_tiling(sv, three);
  EXPECT_EQ(sv.n_vertices(), 2u);  // the plane's two normals
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(sv.areas[static_cast<std::size_t>(i)], 4 * pi / 3, 1e-12);
  auto four = random_sphere(4, 3);
  sv = tessera::spherical_voronoi(four);
  check_tiling(sv, four);
  EXPECT_EQ(sv.n_vertices(), 4u);
}

// A point rounded inwards next to another lies inside the hull: no cell,
// and the others tile the sphere without it.
TEST(SphericalVoronoi, PointInsideTheHullIsHidden) {
  auto pts = random_sphere(200, 9);
  pts.insert(pts.end(), {pts[0] * (1 - 1e-9), pts[1] * (1 - 1e-9), pts[2] * (1 - 1e-9)});
  const auto sv = tessera::spherical_voronoi(pts);
  EXPECT_EQ(sv.status[200], SphereCellStatus::hidden);
  EXPECT_EQ(sv.hidden, 1u);
  EXPECT_EQ(sv.areas[200], 0);
  check_tiling(sv, pts);
}

TEST(SphericalVoronoi, TieBreakIsAntisymmetricAndConsistent) {
  // Four corners of a square: coplanar. Swapping two points flips the sign;
  // the sign depends on the points and their ids only.
  const double P[4][3] = {{1, 1, 1}, {-1, 1, 1}, {-1, -1, 1}, {1, -1, 1}};
  const double* pts[4] = {P[0], P[1], P[2], P[3]};
  const std::int32_t ids[4] = {5, 2, 9, 4};
  const int s = tessera::kernels::orientation_tie_break(pts, ids);
  EXPECT_NE(s, 0);
  const double* sw[4] = {P[1], P[0], P[2], P[3]};
  const std::int32_t swi[4] = {2, 5, 9, 4};
  EXPECT_EQ(tessera::kernels::orientation_tie_break(sw, swi), -s);
  const double* cyc[4] = {P[1], P[2], P[0], P[3]};
  const std::int32_t cyci[4] = {2, 9, 5, 4};
  EXPECT_EQ(tessera::kernels::orientation_tie_break(cyc, cyci), s);
}

// The oracle of the tie break: every term of the perturbed determinant in
// order, in rationals (sphere_predicates.cpp takes the first three from 2D
// orientations).
int reference_tie_break(const double* const* pts, const std::int32_t* ids) {
  std::array<int, 4> order{0, 1, 2, 3};
  std::sort(order.begin(), order.end(), [&](int x, int y) { return ids[x] < ids[y]; });
  int parity = 1;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j)
      if (order[i] > order[j]) parity = -parity;
  for (unsigned mask = 1; mask < (1u << 12); ++mask) {
    std::array<std::array<mpq_class, 4>, 4> m;
    bool valid = true;
    unsigned axes = 0;
    for (int r = 0; r < 4; ++r) {
      const unsigned bits = (mask >> (3 * r)) & 7u;
      if (bits != 0 && ((bits & (bits - 1)) != 0 || (axes & bits) != 0)) valid = false;
      axes |= bits;
      for (int c = 0; c < 4; ++c) m[r][c] = bits == 0 ? (c < 3 ? mpq_class(pts[order[r]][c]) : mpq_class(1)) : mpq_class(0);
      if (bits != 0) m[r][bits == 1 ? 0 : (bits == 2 ? 1 : 2)] = 1;
    }
    if (!valid) continue;
    // Laplace along the first row, 3x3 minors by Sarrus.
    mpq_class det = 0;
    for (int c = 0; c < 4; ++c) {
      int k[3], j = 0;
      for (int e = 0; e < 4; ++e)
        if (e != c) k[j++] = e;
      const mpq_class minor = m[1][k[0]] * (m[2][k[1]] * m[3][k[2]] - m[2][k[2]] * m[3][k[1]]) -
                              m[1][k[1]] * (m[2][k[0]] * m[3][k[2]] - m[2][k[2]] * m[3][k[0]]) +
                              m[1][k[2]] * (m[2][k[0]] * m[3][k[1]] - m[2][k[1]] * m[3][k[0]]);
      det += (c % 2 == 0 ? 1 : -1) * m[0][c] * minor;
    }
    if (sgn(det) != 0) return -parity * sgn(det);
  }
  return 0;
}

TEST(SphericalVoronoi, TieBreakEqualsEveryTermInRationals) {
  // Coplanar quadruples: on circles of a sphere, on axis planes, three on a
  // line (the first three terms vanish), in every id order.
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<int> coord(-3, 3);
  int checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    double P[4][3];
    const int kind = trial % 3;
    for (auto& p : P)
      for (double& x : p) x = coord(rng);
    if (kind == 0)
      for (auto& p : P) p[2] = 1;  // a plane z = 1
    else if (kind == 1)
      for (int d = 0; d < 3; ++d) P[3][d] = 2 * P[1][d] - P[0][d];  // P0, P1, P3 on a line
    else
      for (int d = 0; d < 3; ++d) P[3][d] = P[1][d] + P[2][d] - P[0][d];  // a parallelogram
    const double* pts[4] = {P[0], P[1], P[2], P[3]};
    if (tessera::kernels::orientation(3, pts) != 0) continue;
    bool distinct = true;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) distinct = distinct && !std::equal(P[i], P[i] + 3, P[j]);
    if (!distinct) continue;
    std::array<std::int32_t, 4> ids{10, 20, 30, 40};
    std::shuffle(ids.begin(), ids.end(), rng);
    EXPECT_EQ(tessera::kernels::orientation_tie_break(pts, ids.data()), reference_tie_break(pts, ids.data()));
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// The validator finds each kind of damage (and passes the intact result).
TEST(SphericalVoronoi, ValidateFindsDamage) {
  const auto pts = random_sphere(2000, 21);
  const auto good = tessera::spherical_voronoi(pts);
  auto r = tessera::validate_spherical_voronoi(good, pts, 2000);
  EXPECT_TRUE(r.ok);
  EXPECT_EQ(r.vertices_checked, 2000u);
  EXPECT_EQ(r.euler, 2);
  auto bad = good;
  std::swap(bad.neighbors[0], bad.neighbors[10]);  // two cells' rings
  EXPECT_FALSE(tessera::validate_spherical_voronoi(bad, pts).ok);
  bad = good;
  std::swap(bad.region_vertices[3], bad.region_vertices[4]);  // a ring's order
  r = tessera::validate_spherical_voronoi(bad, pts);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(r.bad_rings, 0u);
  bad = good;
  bad.areas[7] *= 1.001;
  bad.area_sum += good.areas[7] * 0.001;
  EXPECT_FALSE(tessera::validate_spherical_voronoi(bad, pts).ok);
  // A facet not of the hull: a point above it (the triangle turned over).
  bad = good;
  std::swap(bad.triangles[0], bad.triangles[1]);
  r = tessera::validate_spherical_voronoi(bad, pts, 2000);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(r.nonempty_facets, 0u);
}

TEST(SphericalVoronoi, BadInput) {
  using tessera::InputError;
  EXPECT_THROW(tessera::spherical_voronoi(std::vector<double>{}), InputError);
  EXPECT_THROW(tessera::spherical_voronoi(std::vector<double>{0, 0}), InputError);
  EXPECT_THROW(tessera::spherical_voronoi(std::vector<double>{0, 0, 1, 0, NAN, 1}), InputError);
  EXPECT_THROW(tessera::spherical_voronoi(std::vector<double>{0, 0, 1, 0, 0, 0}), InputError);   // at the centre
  EXPECT_THROW(tessera::spherical_voronoi(std::vector<double>{0, 0, 1, 0, 0, 1.1}), InputError); // off the sphere
  tessera::SphericalVoronoiOptions o;
  o.tolerance = 0.2;
  EXPECT_NO_THROW(tessera::spherical_voronoi(std::vector<double>{0, 0, 1, 0, 0, 1.1, 1, 0, 0}, o));
  o.radius = -1;
  EXPECT_THROW(tessera::spherical_voronoi(std::vector<double>{0, 0, 1}, o), InputError);
  EXPECT_THROW(tessera::lonlat_to_points(std::vector<double>{0, 91}), InputError);
  EXPECT_THROW(tessera::lonlat_to_points(std::vector<double>{0, NAN}), InputError);
}

}  // namespace
