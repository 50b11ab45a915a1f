// The cell clippers, Hull (3D) and Tile (2D), driven directly.
//
// Every check recomputes from the raw vertices and planes: volumes by the
// divergence theorem over Newell face normals (3D) or the shoelace formula
// (2D), face loops walked and verified edge by edge, Euler's formula, each
// vertex on its own planes and inside all others, and the Voronoi property
// (no other generator nearer to a vertex than the cell's own). Whole
// tessellations built by brute force (every cell clipped by every other
// point) must partition the box and agree on every vertex, on random and on
// fully degenerate lattice input, whatever the clip order.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "tessera/kernels/assembly.hpp"
#include "tessera/kernels/exact_predicates.hpp"
#include "tessera/kernels/hull.hpp"
#include "tessera/kernels/tile.hpp"
#include "scene.hpp"

namespace {

using namespace kernels_test;
using tessera::kernels::Hull;
using tessera::kernels::Tile;

double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// ------------------------------------------------------------------ 3D checks

/// Every structural invariant of a hull; returns its volume (by Newell
/// normals: V = 1/3 sum_f A_f h_f with the generator at the origin).
double check_hull(Hull& h, const std::string& what) {
  SCOPED_TRACE(what);
  const auto& V = h.vertices();
  const auto& P = h.planes();
  const double scale = [&] {
    double m = 0;
    for (const auto& v : V) m = std::max({m, std::fabs(v.y[0]), std::fabs(v.y[1]), std::fabs(v.y[2])});
    return m;
  }();
  const double tol = 1e-9 * scale;
  for (std::size_t t = 0; t < V.size(); ++t) {
    const auto& v = V[t];
    EXPECT_TRUE(v.p[0] != v.p[1] && v.p[1] != v.p[2] && v.p[0] != v.p[2]) << "vertex " << t << " repeats a plane";
    std::set<std::int32_t> ids;
    for (int k = 0; k < 3; ++k) {
      if (v.p[k] >= P.size()) { ADD_FAILURE() << "vertex " << t << " plane index out of range"; return 0; }
      ids.insert(P[v.p[k]].id);
      const auto& pl = P[v.p[k]];
      EXPECT_NEAR(dot3(pl.n, v.y), pl.d, tol * pl.n1 + 1e-12 * std::fabs(pl.d)) << "vertex " << t << " off its plane";
    }
    EXPECT_EQ(ids.size(), 3u) << "vertex " << t << " has two planes with the same id";
    // Convexity: inside every plane of the cell.
    for (const auto& pl : P) EXPECT_LE(dot3(pl.n, v.y), pl.d + tol * pl.n1 + 1e-12 * std::fabs(pl.d));
    EXPECT_LE(4 * v.r2, h.security_radius2()) << "security radius below a vertex";
    EXPECT_GE(v.r2, dot3(v.y, v.y)) << "r2 is not an upper bound";
  }
  // Faces: closed loops, each directed edge once, orientation outward.
  std::size_t faces = 0, edges2 = 0;
  std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
  std::vector<int> faces_per_vertex(V.size(), 0);
  double volume = 0;
  h.for_each_face([&](std::uint16_t p, const std::uint32_t* loop, std::size_t m) {
    ++faces;
    edges2 += m;
    ASSERT_GE(m, 3u) << "face " << p;
    ASSERT_LE(m, V.size());
    double N[3] = {0, 0, 0}, c[3] = {0, 0, 0};
    for (std::size_t k = 0; k < m; ++k) {
      const std::uint32_t a = loop[k], b = loop[(k + 1) % m];
      ASSERT_LT(a, V.size());
      ++faces_per_vertex[a];
      const auto& va = V[a];
      EXPECT_TRUE(va.p[0] == p || va.p[1] == p || va.p[2] == p) << "loop vertex " << a << " not on face " << p;
      // Consecutive loop vertices share an edge: plane p and one more.
      int shared = 0;
      for (int x = 0; x < 3; ++x)
        for (int y = 0; y < 3; ++y) shared += va.p[x] == V[b].p[y];
      EXPECT_EQ(shared, 2) << "loop step " << a << " -> " << b << " is not an edge";
      EXPECT_TRUE(directed.insert({a, b}).second) << "directed edge " << a << " -> " << b << " twice";
      const double* ya = va.y;
      const double* yb = V[b].y;
      N[0] += (ya[1] - yb[1]) * (ya[2] + yb[2]);
      N[1] += (ya[2] - yb[2]) * (ya[0] + yb[0]);
      N[2] += (ya[0] - yb[0]) * (ya[1] + yb[1]);
      for (int d = 0; d < 3; ++d) c[d] += ya[d] / static_cast<double>(m);
    }
    // Newell normal (twice the vector area) points away from the generator.
    // Faces of zero area (degenerate vertices) are allowed: N = 0 then.
    const double area2 = std::sqrt(dot3(N, N));
    const double nn = std::sqrt(dot3(P[p].n, P[p].n));
    EXPECT_GE(dot3(N, P[p].n), 0.999 * area2 * nn - 1e-12 * scale * scale * nn) << "face " << p << " turns inward";
    EXPECT_GE(dot3(N, c), -1e-12 * scale * scale * scale) << "face " << p << " faces the generator";
    volume += dot3(N, c) / 6.0;
  });
  for (std::size_t t = 0; t < V.size(); ++t) EXPECT_EQ(faces_per_vertex[t], 3) << "vertex " << t;
  for (const auto& e : directed) EXPECT_TRUE(directed.count({e.second, e.first})) << "edge without twin";
  EXPECT_EQ(edges2 % 2, 0u);
  EXPECT_EQ(static_cast<long>(V.size()) - static_cast<long>(edges2 / 2) + static_cast<long>(faces), 2) << "Euler";
  EXPECT_EQ(edges2, 3 * V.size()) << "every vertex has degree 3";
  return volume;
}

/// The vertex keys of a cell: sorted {generator, plane ids}.
template <class CellT>
std::set<std::vector<std::int32_t>> keys(const CellT& c) {
  std::set<std::vector<std::int32_t>> out;
  for (const auto& v : c.vertices()) {
    std::vector<std::int32_t> k{c.generator()};
    for (int d = 0; d < CellT::dim; ++d) k.push_back(c.planes()[v.p[d]].id);
    std::sort(k.begin(), k.end());
    out.insert(k);
  }
  return out;
}

/// Voronoi property: no generator is nearer to a cell vertex than its own.
template <int D, class CellT>
void check_voronoi(const Scene<D>& s, const CellT& c) {
  const double* pi = s.p(c.generator());
  const double tol = 1e-9 * s.scale() * s.scale();
  for (const auto& v : c.vertices()) {
    double own = 0;
    for (int d = 0; d < D; ++d) own += v.y[d] * v.y[d];
    for (std::int32_t j = 0; j < s.size(); ++j) {
      double dj = 0;
      for (int d = 0; d < D; ++d) {
        double e = v.y[d] - (s.p(j)[d] - pi[d]);  // relative: no cancellation far from the origin
        dj += e * e;
      }
      EXPECT_GE(dj, own - tol) << "generator " << j << " nearer to a vertex of cell " << c.generator();
    }
  }
}

TEST(Hull, ResetIsTheBox) {
  Scene<3> s({0.3, 0.2, 0.9}, {-1, 0, 0.5}, {2, 0.5, 1});
  Hull h;
  s.reset(h, 0);
  EXPECT_EQ(h.num_vertices(), 8u);
  EXPECT_EQ(h.planes().size(), 6u);
  EXPECT_NEAR(check_hull(h, "box"), 3 * 0.5 * 0.5, 1e-15);
  // Vertices are the box corners relative to the generator.
  for (const auto& v : h.vertices())
    for (int d = 0; d < 3; ++d) EXPECT_TRUE(v.y[d] == s.lo[d] - s.p(0)[d] || v.y[d] == s.hi[d] - s.p(0)[d]);
  std::set<std::int32_t> ids;
  for (const auto& pl : h.planes()) ids.insert(pl.id);
  EXPECT_EQ(ids, (std::set<std::int32_t>{-6, -5, -4, -3, -2, -1}));
}

// A bisector through the box centre halves the volume (central symmetry),
// whatever its direction; the generator's side is the one kept.
TEST(Hull, ClipThroughTheMiddleHalves) {
  std::mt19937_64 g(3);
  std::normal_distribution<double> nd;
  for (int t = 0; t < 50; ++t) {
    double dir[3] = {nd(g), nd(g), nd(g)};
    if (t == 0) { dir[0] = 1; dir[1] = dir[2] = 0; }  // axis-aligned: plane x = 0.5
    const double r = 0.1 / std::sqrt(dot3(dir, dir));
    std::vector<double> p{0.5 - r * dir[0], 0.5 - r * dir[1], 0.5 - r * dir[2],
                          0.5 + r * dir[0], 0.5 + r * dir[1], 0.5 + r * dir[2]};
    Scene<3> s(p, {0, 0, 0}, {1, 1, 1});
    Hull h;
    s.reset(h, 0);
    ASSERT_EQ(s.clip(h, 1), ClipResult::clipped);
    EXPECT_NEAR(check_hull(h, "half"), 0.5, 1e-9);  // the midpoint is rounded, so not exact
    // The kept vertices are on the generator's side of the bisector.
    for (const auto& v : h.vertices()) {
      double y[3] = {v.y[0] - r * dir[0], v.y[1] - r * dir[1], v.y[2] - r * dir[2]};  // relative to the centre
      EXPECT_LE(dot3(y, dir), 1e-12);
    }
    Hull o;  // and the other generator gets the other half
    s.reset(o, 1);
    ASSERT_EQ(s.clip(o, 0), ClipResult::clipped);
    EXPECT_NEAR(check_hull(o, "other half"), 0.5, 1e-9);
  }
}

// A candidate beyond the security radius leaves the cell unchanged; so does
// one whose bisector misses the cell; a duplicate empties the higher id.
TEST(Hull, FarAndDuplicateCandidates) {
  auto pts = random_points<3>(30, 4);
  pts.insert(pts.end(), {50, 50, 50, -40, 0.5, 0.5});  // ids 30, 31: far outside the box
  pts.insert(pts.end(), pts.begin(), pts.begin() + 3);  // id 32: duplicate of 0
  Scene<3> s(pts, {0, 0, 0}, {1, 1, 1});
  Hull h;
  s.reset(h, 5);
  for (std::int32_t j = 0; j < 30; ++j)
    if (j != 5) s.clip(h, j);
  const auto before = keys(h);
  const double vol = check_hull(h, "cell 5");
  EXPECT_EQ(s.clip(h, 30), ClipResult::unchanged);
  EXPECT_EQ(s.clip(h, 31), ClipResult::unchanged);
  EXPECT_EQ(keys(h), before);
  EXPECT_DOUBLE_EQ(check_hull(h, "cell 5 after far clips"), vol);
  // Everything beyond 2R, in all directions.
  std::mt19937_64 g(5);
  std::normal_distribution<double> nd;
  for (int t = 0; t < 200; ++t) {
    double q[3] = {nd(g), nd(g), nd(g)};
    const double f = std::sqrt(h.security_radius2() / dot3(q, q)) * 1.0001;
    for (double& x : q) x *= f;
    EXPECT_EQ(h.clip(7, q), ClipResult::unchanged);
  }
  // Duplicates: p_32 == p_0. The lower id keeps the cell.
  Hull a, b;
  s.reset(a, 0);
  EXPECT_EQ(s.clip(a, 32), ClipResult::unchanged);
  s.reset(b, 32);
  EXPECT_EQ(s.clip(b, 0), ClipResult::emptied);
  EXPECT_EQ(b.num_vertices(), 0u);
}

double check_tile_volume(Tile& t, const std::string& what);  // below, with the 2D tests

/// Build every cell of the scene by clipping with every other point in a
/// random order; checks each cell and returns the cells' vertex keys.
template <class CellT, int D>
std::vector<std::set<std::vector<std::int32_t>>> brute_force(const Scene<D>& s, std::uint64_t seed, double& total,
                                                            std::uint64_t& exact_calls, bool check_each_step) {
  std::mt19937_64 g(seed);
  std::vector<std::set<std::vector<std::int32_t>>> out;
  total = 0;
  exact_calls = 0;
  CellT c;
  for (std::int32_t i = 0; i < s.size(); ++i) {
    std::vector<std::int32_t> order(static_cast<std::size_t>(s.size()));
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), g);
    s.reset(c, i);
    for (std::int32_t j : order) {
      if (j == i) continue;
      const auto r = s.clip(c, j);
      EXPECT_NE(r, ClipResult::emptied);
      if (check_each_step && r == ClipResult::clipped) {
        if constexpr (D == 3) check_hull(c, "cell " + std::to_string(i) + " after clip " + std::to_string(j));
      }
    }
    exact_calls += c.exact_calls();
    if constexpr (D == 3) total += check_hull(c, "cell " + std::to_string(i));
    else total += check_tile_volume(c, "cell " + std::to_string(i));
    check_voronoi(s, c);
    out.push_back(keys(c));
  }
  return out;
}

/// Conformity: every vertex key appears in exactly the cells of its generators.
void check_conforming(const std::vector<std::set<std::vector<std::int32_t>>>& cells) {
  std::map<std::vector<std::int32_t>, std::vector<std::int32_t>> owners;
  for (std::size_t i = 0; i < cells.size(); ++i)
    for (const auto& k : cells[i]) owners[k].push_back(static_cast<std::int32_t>(i));
  for (const auto& [k, who] : owners) {
    std::vector<std::int32_t> gens;
    for (std::int32_t id : k)
      if (id >= 0) gens.push_back(id);
    EXPECT_EQ(who, gens) << "a vertex is not shared by exactly its generators";
  }
}

template <class CellT, int D>
void tessellation_test(const Scene<D>& s, const std::string& what, bool expect_exact) {
  SCOPED_TRACE(what);
  double total = 0, total2 = 0;
  std::uint64_t exact = 0, exact2 = 0;
  const auto a = brute_force<CellT>(s, 1, total, exact, false);
  EXPECT_NEAR(total, s.box_volume(), 1e-12 * s.box_volume());
  check_conforming(a);
  // Another clip order: the same cells (the perturbed diagram is unique).
  const auto b = brute_force<CellT>(s, 2, total2, exact2, true);
  EXPECT_EQ(a, b);
  if (expect_exact) {
    EXPECT_GT(exact + exact2, 0u) << "degenerate input should reach the exact predicate";
  }
}

TEST(Hull, RandomTessellation) {
  Scene<3> s(random_points<3>(60, 6), {0, 0, 0}, {1, 1, 1});
  tessellation_test<Hull>(s, "random 60", false);
  Scene<3> far(random_points<3>(40, 7, 1e6, 1e6 + 1e-3), {1e6, 1e6, 1e6}, {1e6 + 1e-3, 1e6 + 1e-3, 1e6 + 1e-3});
  tessellation_test<Hull>(far, "random 40, off the origin", false);
}

TEST(Hull, LatticeTessellation) {
  // Every vertex is shared by 8 cells; the perturbation makes them simple.
  Scene<3> s(lattice<3>(3), {0, 0, 0}, {3, 3, 3});
  tessellation_test<Hull>(s, "3x3x3 lattice", true);
  Hull h;
  s.reset(h, 13);  // the centre: a unit cube
  for (std::int32_t j = 0; j < s.size(); ++j)
    if (j != 13) s.clip(h, j);
  EXPECT_NEAR(check_hull(h, "centre"), 1.0, 1e-15);
  for (const auto& v : h.vertices())
    for (int d = 0; d < 3; ++d) EXPECT_EQ(std::fabs(v.y[d]), 0.5);
  // Rounded (spacing 0.1) and one-ulp-jittered lattices: near ties the float
  // filter must hand to the exact predicate, else neighbours disagree.
  Scene<3> r(lattice<3>(3, 0.1), {0, 0, 0}, {0.30000000000000004, 0.30000000000000004, 0.30000000000000004});
  tessellation_test<Hull>(r, "3x3x3 lattice, spacing 0.1", true);
  Scene<3> j(lattice<3>(3, 1, 1, 17), {0, 0, 0}, {3, 3, 3});
  tessellation_test<Hull>(j, "3x3x3 lattice, 1 ulp jitter", true);
}

// Many random clips of one cell, invariants after each.
TEST(Hull, ManyRandomClips) {
  Scene<3> s(random_points<3>(400, 8, -1, 2), {-1, -1, -1}, {2, 2, 2});
  std::mt19937_64 g(9);
  for (std::int32_t i : {0, 17, 399}) {
    Hull h;
    s.reset(h, i);
    std::vector<std::int32_t> order(400);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), g);
    int clipped = 0;
    for (std::int32_t j : order) {
      if (j == i) continue;
      if (s.clip(h, j) == ClipResult::clipped) {
        ++clipped;
        check_hull(h, "cell " + std::to_string(i));
      }
    }
    EXPECT_GT(clipped, 5);
    check_voronoi(s, h);
  }
}

// The security radius as update_radius computes it, from the vertices.
double security_radius2_of(const Hull& h) {
  double m = 0;
  for (const auto& v : h.vertices()) m = std::max(m, v.r2);
  return 4.0 * m * (1 + 1e-12);
}

// A cell of thousands of faces takes its sign passes by blocks of slots
// (LaneBlocks): a point beside 2,500 points on a line sees every one of
// them (a face each, ~5,000 vertices), one above a sheet of 72 x 72 sees
// most, and with twins 1e-4 apart along the line its vertices between a
// twin's bisectors are too ill-conditioned for the float solve (deferred,
// then solved exactly). Clipped nearest first and in a random order, the
// cell is the same (its vertices' plane triples), it keeps every invariant
// along the way, its security radius is its vertices' and no vertex is
// left deferred, and no point is nearer to one of its vertices than its
// own (checked against every point: the brute-force oracle).
TEST(Hull, HugeCellSignPassesByBlocks) {
  std::mt19937_64 g(23);
  std::uniform_real_distribution<double> u(0, 1);
  for (int kind = 0; kind < 3; ++kind) {
    std::vector<double> pts;
    std::array<double, 3> lo, hi;
    if (kind != 1) {  // the line (x, 0, 0), x in [0, 2500), and one point off it, all on z = 0
      for (int k = 0; k < 2500; ++k) {
        const double x = k + 0.8 * u(g);
        pts.insert(pts.end(), {x, 0.0, 0.0});
        if (kind == 2 && k % 10 == 0) pts.insert(pts.end(), {x + 1e-4, 0.0, 0.0});
      }
      pts.insert(pts.end(), {1250.3, 900.0, 0.0});
      lo = {-1, -10, -40};
      hi = {2501, 1400, 40};
    } else {  // a sheet jittered off z = 0, and one point above its middle
      for (int a = 0; a < 72; ++a)
        for (int b = 0; b < 72; ++b) pts.insert(pts.end(), {a + 0.4 * u(g), b + 0.4 * u(g), 0.01 * u(g)});
      pts.insert(pts.end(), {35.7, 36.2, 40.0});
      lo = {-1, -1, -2};
      hi = {73, 73, 50};
    }
    Scene<3> s(std::move(pts), lo, hi);
    const std::int32_t lone = s.size() - 1;
    SCOPED_TRACE(kind == 0 ? "beside a line" : kind == 1 ? "above a sheet" : "beside a line with twins");
    std::vector<std::pair<double, std::int32_t>> near;
    for (std::int32_t j = 0; j < lone; ++j) {
      double r2 = 0;
      for (int d = 0; d < 3; ++d) r2 += (s.p(j)[d] - s.p(lone)[d]) * (s.p(j)[d] - s.p(lone)[d]);
      near.push_back({r2, j});
    }
    std::sort(near.begin(), near.end());
    Hull first, shuffled;
    s.reset(first, lone);
    for (const auto& [r2, j] : near) s.clip(first, j);
    std::vector<std::int32_t> order(static_cast<std::size_t>(lone));
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), g);
    s.reset(shuffled, lone);
    std::size_t clips = 0;
    for (const std::int32_t j : order) {
      if (s.clip(shuffled, j) != ClipResult::clipped || !shuffled.blocked()) continue;
      if (++clips % 200 == 0) {
        shuffled.solve_deferred();  // (as a clip may: their float positions are only bounded)
        check_hull(shuffled, "shuffled, clip " + std::to_string(clips));
      }
      ASSERT_EQ(shuffled.security_radius2(), security_radius2_of(shuffled)) << "clip " << clips;
    }
    EXPECT_GT(clips, 200u);
    for (Hull* h : {&first, &shuffled}) {
      h->solve_deferred();
      EXPECT_TRUE(h->blocked());
      EXPECT_GT(h->num_vertices(), std::size_t{4096});
      EXPECT_EQ(h->security_radius2(), security_radius2_of(*h));
      for (const auto& v : h->vertices()) ASSERT_EQ(v.deferred, 0u);
      if (kind == 2) EXPECT_GT(h->exact_solves(), 0u);
    }
    EXPECT_EQ(keys(first), keys(shuffled));
    const double v1 = check_hull(first, "nearest first"), v2 = check_hull(shuffled, "shuffled");
    EXPECT_NEAR(v1, v2, 1e-9 * v1);
    check_voronoi(s, first);
    check_voronoi(s, shuffled);
  }
}

// ------------------------------------------------------------------ 2D checks

/// Structural invariants of a tile; returns its area (shoelace).
double check_tile_volume(Tile& t, const std::string& what) {
  SCOPED_TRACE(what);
  const auto& V = t.vertices();
  const auto& P = t.planes();
  const std::size_t m = V.size();
  EXPECT_GE(m, 3u);
  double scale = 0;
  for (const auto& v : V) scale = std::max({scale, std::fabs(v.y[0]), std::fabs(v.y[1])});
  const double tol = 1e-9 * scale;
  double area2 = 0;
  std::set<std::uint16_t> edge_planes;
  for (std::size_t k = 0; k < m; ++k) {
    const auto& a = V[k];
    const auto& b = V[(k + 1) % m];
    EXPECT_NE(a.p[0], a.p[1]) << "vertex " << k << " repeats a plane";
    EXPECT_NE(P[a.p[0]].id, P[a.p[1]].id);
    // Edge k lies on plane a.p[1] = b.p[0]: a closed chain.
    EXPECT_EQ(a.p[1], b.p[0]) << "chain broken after vertex " << k;
    EXPECT_TRUE(edge_planes.insert(a.p[1]).second) << "plane " << a.p[1] << " used by two edges";
    for (int q = 0; q < 2; ++q) {
      const auto& pl = P[a.p[q]];
      EXPECT_NEAR(pl.n[0] * a.y[0] + pl.n[1] * a.y[1], pl.d, tol * pl.n1 + 1e-12 * std::fabs(pl.d));
    }
    for (const auto& pl : P) EXPECT_LE(pl.n[0] * a.y[0] + pl.n[1] * a.y[1], pl.d + tol * pl.n1 + 1e-12 * std::fabs(pl.d));
    EXPECT_LE(4 * a.r2, t.security_radius2());
    // Counter-clockwise: the edge turns left (or goes straight at a degenerate vertex).
    const auto& c = V[(k + 2) % m];
    const double turn = (b.y[0] - a.y[0]) * (c.y[1] - b.y[1]) - (b.y[1] - a.y[1]) * (c.y[0] - b.y[0]);
    EXPECT_GE(turn, -1e-12 * scale * scale) << "clockwise turn at vertex " << (k + 1) % m;
    // The outward edge normal agrees with the plane normal.
    const double en[2] = {b.y[1] - a.y[1], a.y[0] - b.y[0]};
    const auto& pl = P[a.p[1]];
    EXPECT_GE(en[0] * pl.n[0] + en[1] * pl.n[1], -1e-12 * scale * pl.n1);
    area2 += a.y[0] * b.y[1] - a.y[1] * b.y[0];
  }
  EXPECT_GT(area2, 0) << "not counter-clockwise";
  return area2 / 2;
}

TEST(Tile, ResetIsTheBox) {
  Scene<2> s({0.3, 0.2}, {-1, 0}, {2, 0.5});
  Tile t;
  s.reset(t, 0);
  EXPECT_EQ(t.num_vertices(), 4u);
  EXPECT_EQ(t.planes().size(), 4u);
  EXPECT_NEAR(check_tile_volume(t, "box"), 1.5, 1e-15);
}

TEST(Tile, ClipThroughTheMiddleHalves) {
  std::mt19937_64 g(13);
  std::normal_distribution<double> nd;
  for (int k = 0; k < 50; ++k) {
    double dir[2] = {nd(g), nd(g)};
    if (k == 0) { dir[0] = 0; dir[1] = 1; }
    const double r = 0.1 / std::hypot(dir[0], dir[1]);
    Scene<2> s({0.5 - r * dir[0], 0.5 - r * dir[1], 0.5 + r * dir[0], 0.5 + r * dir[1]}, {0, 0}, {1, 1});
    Tile t;
    s.reset(t, 0);
    ASSERT_EQ(s.clip(t, 1), ClipResult::clipped);
    EXPECT_NEAR(check_tile_volume(t, "half"), 0.5, 1e-9);
  }
}

TEST(Tile, FarAndDuplicateCandidates) {
  auto pts = random_points<2>(30, 14);
  pts.insert(pts.end(), {40, 40, -30, 0.5, pts[0], pts[1]});  // 30, 31 far; 32 == 0
  Scene<2> s(pts, {0, 0}, {1, 1});
  Tile t;
  s.reset(t, 5);
  for (std::int32_t j = 0; j < 30; ++j)
    if (j != 5) s.clip(t, j);
  const auto before = keys(t);
  EXPECT_EQ(s.clip(t, 30), ClipResult::unchanged);
  EXPECT_EQ(s.clip(t, 31), ClipResult::unchanged);
  std::mt19937_64 g(15);
  std::normal_distribution<double> nd;
  for (int k = 0; k < 200; ++k) {
    double q[2] = {nd(g), nd(g)};
    const double f = std::sqrt(t.security_radius2() / (q[0] * q[0] + q[1] * q[1])) * 1.0001;
    q[0] *= f;
    q[1] *= f;
    EXPECT_EQ(t.clip(7, q), ClipResult::unchanged);
  }
  EXPECT_EQ(keys(t), before);
  Tile a, b;
  s.reset(a, 0);
  EXPECT_EQ(s.clip(a, 32), ClipResult::unchanged);
  s.reset(b, 32);
  EXPECT_EQ(s.clip(b, 0), ClipResult::emptied);
}

TEST(Tile, RandomTessellation) {
  Scene<2> s(random_points<2>(150, 16), {0, 0}, {1, 1});
  tessellation_test<Tile>(s, "random 150", false);
}

TEST(Tile, LatticeTessellation) {
  Scene<2> s(lattice<2>(5), {0, 0}, {5, 5});
  tessellation_test<Tile>(s, "5x5 lattice", true);
  Scene<2> r(lattice<2>(5, 0.1), {0, 0}, {0.5, 0.5});
  tessellation_test<Tile>(r, "5x5 lattice, spacing 0.1", true);
  Scene<2> j(lattice<2>(5, 1, 1, 18), {0, 0}, {5, 5});
  tessellation_test<Tile>(j, "5x5 lattice, 1 ulp jitter", true);
  // Co-circular and duplicate points on top of a lattice.
  auto p = lattice<2>(4);
  p.insert(p.end(), {2, 2, 0.5, 0.5, 1.5, 2.5});  // lattice corner, and two duplicates of lattice points
  Scene<2> t(p, {0, 0}, {4, 4});
  SCOPED_TRACE("with duplicates");
  // Duplicates empty the higher id: check the others only.
  Tile c;
  double total = 0;
  for (std::int32_t i = 0; i < t.size(); ++i) {
    t.reset(c, i);
    bool emptied = false;
    for (std::int32_t j = 0; j < t.size() && !emptied; ++j)
      if (j != i) emptied = t.clip(c, j) == ClipResult::emptied;
    EXPECT_EQ(emptied, i >= 17) << "cell " << i;
    if (!emptied) total += check_tile_volume(c, "cell " + std::to_string(i));
  }
  EXPECT_NEAR(total, 16.0, 1e-12);
}

// exact_cell_measure (the fallback of front/cell_geometry.hpp's measure for
// slivers) on whole tessellations: the exact volumes of all cells sum to the
// box's volume, and their first moments to the box's, to rounding (each cell's
// is exact, rounded once). Terms as measure() forms them: 3D, the cone from
// the generator over each triangle edge (t, k) with its face's foot; 2D, the
// shoelace over the polygon.
/// A finished cell's vertices by their planes and its measure terms, as
/// front/cell_geometry.hpp's measure_exactly passes them.
template <class CellT>
void measure_input(const CellT& c, std::vector<std::int32_t>& vp, std::vector<tessera::kernels::MeasureTerm>& terms) {
  constexpr int D = CellT::dim;
  const auto& v = c.vertices();
  vp.clear();
  terms.clear();
  for (const auto& x : v)
    for (int k = 0; k < D; ++k) vp.push_back(c.planes()[x.p[k]].id);
  for (std::size_t t = 0; t < v.size(); ++t) {
    if constexpr (D == 3) {
      for (int k = 0; k < 3; ++k)
        terms.push_back({c.planes()[v[t].p[(k + 1) % 3]].id, static_cast<std::uint32_t>(t), c.across(t, k)});
    } else {
      terms.push_back({0, static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(t + 1 == v.size() ? 0 : t + 1)});
    }
  }
}

template <class CellT>
void exact_measure_test(const Scene<CellT::dim>& s) {
  constexpr int D = CellT::dim;
  double volume = 0, moment[D] = {}, box_moment[D];
  std::vector<std::int32_t> vp;
  std::vector<tessera::kernels::MeasureTerm> terms;
  for (std::int32_t i = 0; i < s.size(); ++i) {
    CellT c;
    s.clip_by_all(c, i);
    measure_input(c, vp, terms);
    double centroid[D];
    const double vol = tessera::kernels::exact_cell_measure(s.ctx, i, vp, terms, centroid);
    EXPECT_GT(vol, 0) << "cell " << i;
    volume += vol;
    for (int d = 0; d < D; ++d) moment[d] += vol * (s.p(i)[d] + centroid[d]);
  }
  EXPECT_NEAR(volume, s.box_volume(), 1e-13 * s.box_volume());
  for (int d = 0; d < D; ++d) {
    box_moment[d] = s.box_volume() * 0.5 * (s.lo[d] + s.hi[d]);
    EXPECT_NEAR(moment[d], box_moment[d], 1e-13 * s.box_volume() * s.scale()) << "axis " << d;
  }
}

TEST(Hull, ExactMeasureSumsToTheBox) {
  Scene<3> s(random_points<3>(40, 8), {0, 0, 0}, {1, 1, 1});
  exact_measure_test<Hull>(s);
  Scene<3> l(lattice<3>(3), {0, 0, 0}, {3, 3, 3});
  exact_measure_test<Hull>(l);
}

/// The far plane that closes a hull point's cell (assembly::far_plane) when
/// its rays crowd one side of a wide cone: a thousand rays 80 degrees below
/// the x axis and one 80 degrees above it (the end of a thin band: many
/// rays across the band, one along it). Their sum leans 160 degrees away
/// from the lone ray; a direction near the x axis serves them all. A cone
/// that is a whole half space (rays up and down) has none.
TEST(Assembly, FarPlaneCoversAWideCone) {
  struct P { double n[3]; double d, n1; std::int32_t id; int scale; };
  struct V { double y[3]; double e; };
  for (const int dim : {2, 3}) {
    SCOPED_TRACE(dim);
    const double down = -80 * M_PI / 180, up = 80 * M_PI / 180;
    const int k = 1001;
    std::vector<double> dirs;
    for (int r = 0; r < k; ++r) {
      const double a = r + 1 < k ? down : up;
      if (dim == 2) dirs.insert(dirs.end(), {std::cos(a), std::sin(a)});
      else dirs.insert(dirs.end(), {std::cos(a), 0.0, std::sin(a)});
    }
    P box[6];
    for (int q = 0; q < 2 * dim; ++q) box[q].d = 1.0;  // the box [-1, 1]^D about the generator
    const V verts[1] = {{{0.25, -0.5, 0.125}, 1e-12}};
    P far{};
    bool ok = false;
    if (dim == 2) ok = tessera::kernels::assembly::far_plane<2>(dirs.data(), k, box, verts, 1, far);
    else ok = tessera::kernels::assembly::far_plane<3>(dirs.data(), k, box, verts, 1, far);
    ASSERT_TRUE(ok);
    double len = 0;
    for (int a = 0; a < dim; ++a) len += far.n[a] * far.n[a];
    len = std::sqrt(len);
    for (int r = 0; r < k; ++r) {
      double dot = 0;
      for (int a = 0; a < dim; ++a) dot += far.n[a] * dirs[static_cast<std::size_t>(dim * r + a)];
      EXPECT_GE(dot, 1e-3 * len) << "ray " << r;
    }
    // Beyond every box corner and the vertex.
    for (int corner = 0; corner < (1 << dim); ++corner) {
      double dot = 0;
      for (int a = 0; a < dim; ++a) dot += far.n[a] * ((corner >> a) & 1 ? 1.0 : -1.0);
      EXPECT_GT(far.d, dot);
    }
    double dot = 0;
    for (int a = 0; a < dim; ++a) dot += far.n[a] * verts[0].y[a];
    EXPECT_GT(far.d, dot);
    // Up and down: no plane crosses both rays.
    std::vector<double> opposite = dim == 2 ? std::vector<double>{0, 1, 0, -1} : std::vector<double>{0, 0, 1, 0, 0, -1};
    const bool none = dim == 2 ? tessera::kernels::assembly::far_plane<2>(opposite.data(), 2, box, verts, 1, far)
                               : tessera::kernels::assembly::far_plane<3>(opposite.data(), 2, box, verts, 1, far);
    EXPECT_FALSE(none);
  }
}

TEST(Tile, ExactMeasureSumsToTheBox) {
  Scene<2> s(random_points<2>(60, 17), {0, 0}, {1, 1});
  exact_measure_test<Tile>(s);
}

/// Points each with `copies - 1` near copies along a random direction,
/// `step` apart: the cells between copies are slabs thinner than their
/// float vertices' rounding, the cells measure_exactly exists for.
template <int D>
std::vector<double> near_copy_chains(int bases, int copies, double step, std::uint64_t seed) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  std::vector<double> p;
  for (int b = 0; b < bases; ++b) {
    double base[D], dir[D];
    for (int d = 0; d < D; ++d) base[d] = u(g), dir[d] = n(g) * step;
    for (int k = 0; k < copies; ++k)
      for (int d = 0; d < D; ++d) p.push_back(base[d] + k * dir[d]);
  }
  return p;
}

/// exact_cell_measure's fixed-point tier gives rational_cell_measure's
/// doubles, bit for bit, wherever it certifies them; `certified` is the
/// share of cells it must certify at 200 bits. Returns the volumes it
/// certified (NaN where it did not).
template <class CellT>
std::vector<double> fixed_point_tier_test(const Scene<CellT::dim>& s, double certified) {
  constexpr int D = CellT::dim;
  std::vector<std::int32_t> vp;
  std::vector<tessera::kernels::MeasureTerm> terms;
  int sure = 0;
  std::vector<double> volumes(static_cast<std::size_t>(s.size()), std::numeric_limits<double>::quiet_NaN());
  for (std::int32_t i = 0; i < s.size(); ++i) {
    CellT c;
    s.clip_by_all(c, i);
    measure_input(c, vp, terms);
    double exact_centroid[D], fixed_centroid[D], centroid[D];
    const double exact = tessera::kernels::rational_cell_measure(s.ctx, i, vp, terms, exact_centroid);
    double fixed = 0;
    if (tessera::kernels::fixed_point_cell_measure(s.ctx, i, vp, terms, 200, fixed, fixed_centroid)) {
      ++sure;
      volumes[static_cast<std::size_t>(i)] = fixed;
      EXPECT_EQ(fixed, exact) << "cell " << i;
      for (int d = 0; d < D; ++d) EXPECT_EQ(fixed_centroid[d], exact_centroid[d]) << "cell " << i << " axis " << d;
    }
    EXPECT_EQ(tessera::kernels::exact_cell_measure(s.ctx, i, vp, terms, centroid), exact) << "cell " << i;
    for (int d = 0; d < D; ++d) EXPECT_EQ(centroid[d], exact_centroid[d]) << "cell " << i << " axis " << d;
  }
  EXPECT_GE(sure, certified * s.size());
  return volumes;
}

TEST(Hull, ExactMeasureFixedPointMatchesRationals) {
  // Slabs between copies 1e-11 and 1e-13 apart, ordinary cells, and the
  // same at scales far from 1 (the units follow the cell).
  for (const double step : {1e-11, 1e-13}) {
    Scene<3> s(near_copy_chains<3>(12, 4, step, 5), {0, 0, 0}, {1, 1, 1});
    fixed_point_tier_test<Hull>(s, 0.95);
  }
  for (const double scale : {0x1p-300, 0x1p+300}) {
    auto p = near_copy_chains<3>(10, 3, 1e-12, 6);
    for (auto& x : p) x *= scale;
    Scene<3> s(std::move(p), {0, 0, 0}, {scale, scale, scale});
    fixed_point_tier_test<Hull>(s, 0.95);
  }
  Scene<3> r(random_points<3>(40, 8), {0, 0, 0}, {1, 1, 1});
  fixed_point_tier_test<Hull>(r, 0.95);
  // A lattice's cells are cubes about their generators: every centroid
  // coordinate is zero, which no error bound certifies. Their vertices lie
  // on the fixed-point grid, so the sums are exact (stop 73), and the
  // fixed-point tier gives every cell the rationals' doubles.
  Scene<3> l(lattice<3>(3), {0, 0, 0}, {3, 3, 3});
  fixed_point_tier_test<Hull>(l, 1.0);
}

// Measures beyond double's range: a jittered 3x3x3 lattice 1e-104 apart in
// a box 2e110 wide. The lattice's outer cells reach the box (volumes
// ~1e330: an infinity), the centre cell is ~1e-312 (a subnormal). The
// fixed-point tier certifies both as the rationals round them; until
// stop 72 it gave up outside [2^-1000, 2^1000] and every such cell took the
// rationals (300 points spread over 1e-300..1e280: 20 s for their cells,
// now 1.2 s).
TEST(Hull, ExactMeasureBeyondDoubleRange) {
  std::mt19937_64 g(72);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  std::vector<double> p;
  for (int i = 0; i < 27; ++i)
    for (int d = 0; d < 3; ++d) p.push_back((((i / (d == 0 ? 1 : d == 1 ? 3 : 9)) % 3) - 1 + jitter(g)) * 1e-104);
  Scene<3> s(std::move(p), {-1e110, -1e110, -1e110}, {1e110, 1e110, 1e110});
  int infinite = 0, subnormal = 0;
  for (const double v : fixed_point_tier_test<Hull>(s, 0)) {
    infinite += std::isinf(v);
    subnormal += v > 0 && v < std::numeric_limits<double>::min();
  }
  // Certified without the rationals: most outer cells, and the inner ones.
  EXPECT_GE(infinite, 15);
  EXPECT_GE(subnormal, 1);
}

// Measures that are exactly doubles: cells that are prisms spanning the
// box (volume 0.5 or 0.25, centroid coordinates such as 0.25 - 0.3, exact by
// Sterbenz's lemma). Until stop 73 the measure truncated, an exact double
// lay on the edge of its rounding interval, no error bound certified it,
// and every such cell went to the rationals; rounded to nearest, the
// fixed-point tier certifies them all.
TEST(Hull, ExactMeasureOfExactDoublesInFixedPoint) {
  Scene<3> s({0.3, 0.4, 0.45, 0.7, 0.4, 0.45}, {0, 0, 0}, {1, 1, 1});
  fixed_point_tier_test<Hull>(s, 1.0);
  Scene<3> four({0.3, 0.4, 0.45, 0.7, 0.4, 0.45, 0.3, 0.6, 0.45, 0.7, 0.6, 0.45}, {0, 0, 0}, {1, 1, 1});
  for (const double v : fixed_point_tier_test<Hull>(four, 1.0)) EXPECT_EQ(v, 0.25);
}

TEST(Tile, ExactMeasureFixedPointMatchesRationals) {
  for (const double step : {1e-11, 1e-14}) {
    Scene<2> s(near_copy_chains<2>(20, 4, step, 7), {0, 0}, {1, 1});
    fixed_point_tier_test<Tile>(s, 0.95);
  }
  Scene<2> r(random_points<2>(60, 17), {0, 0}, {1, 1});
  fixed_point_tier_test<Tile>(r, 0.95);
}

}  // namespace
