// Adjacency graph: wheels agree with the cells, spokes are symmetric (class
// and face measure included), the graph equals the Delaunay edge set (CGAL)
// wherever the dual Voronoi vertex lies in the box, pruning keeps symmetry,
// results do not depend on the thread count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <set>

#include "cells/helpers.hpp"
#include "front/mesh_faces.hpp"
#include "tessera/graph.hpp"
#ifdef TESSERA_HAVE_CGAL
#include "delaunay_oracle.hpp"
#endif

namespace {

using namespace cells_test;
using tessera::SpokeClass;

SpokeClass expected_class(std::int32_t g, std::int32_t j, const std::vector<std::int32_t>& labels) {
  if (j < 0) return SpokeClass::domain_boundary;
  if (labels.empty()) return SpokeClass::same_region;
  if (labels[j] < 0) return SpokeClass::outside;
  return labels[j] == labels[g] ? SpokeClass::same_region : SpokeClass::region_boundary;
}

/// Index of spoke i -> j, or -1.
std::int64_t find_spoke(const tessera::AdjacencyGraph& g, std::int32_t i, std::int32_t j) {
  for (auto s = g.wheel_offsets[i]; s < g.wheel_offsets[i + 1]; ++s)
    if (g.spokes[s] == j) return s;
  return -1;
}

/// The unpruned graph against the cells it was read from.
void check_graph(const tessera::Cells& c, const tessera::AdjacencyGraph& g, const std::vector<std::int32_t>& labels,
                 const std::string& what) {
  Failures fail(what);
  const std::size_t n = c.n_points;
  ASSERT_EQ(g.n_points, n) << what;
  ASSERT_EQ(g.wheel_offsets.size(), n + 1) << what;
  ASSERT_EQ(g.spokes.size(), g.spoke_class.size()) << what;
  ASSERT_EQ(g.spokes.size(), g.spoke_measure.size()) << what;
  ASSERT_EQ(g.wheel_offsets.front(), 0) << what;
  ASSERT_EQ(std::size_t(g.wheel_offsets.back()), g.spokes.size()) << what;
  EXPECT_EQ(g.pruned_spokes, 0u) << what;
  std::size_t total_faces = 0;
  for (auto f : c.num_faces) total_faces += std::size_t(f);
  EXPECT_EQ(g.n_spokes(), total_faces) << what << ": one spoke per cell face";

  for (std::size_t p = 0; p < n; ++p) {
    const auto i = std::int32_t(p);
    const auto b = g.wheel_offsets[p], e = g.wheel_offsets[p + 1];
    if (e < b) { fail.add("wheel ", p, " has negative size"); continue; }
    const auto k = c.cell_of[p];
    if (k < 0) {
      if (e != b) fail.add("point ", p, " has no cell but a wheel of ", e - b);
      continue;
    }
    // The wheel is the cell's faces: its neighbours plus its box planes, ascending.
    std::vector<std::int32_t> want(c.face_neighbor.begin() + c.cell_face_offsets[k],
                                   c.face_neighbor.begin() + c.cell_face_offsets[k + 1]);
    std::sort(want.begin(), want.end());
    const std::vector<std::int32_t> got(g.spokes.begin() + b, g.spokes.begin() + e);
    if (got != want) fail.add("wheel of ", p, " is not its sorted face neighbours");
    const auto measures = mesh_face_measures(c, std::size_t(k));
    for (auto s = b; s < e; ++s) {
      const auto j = g.spokes[s];
      if (g.spoke_class[s] != expected_class(i, j, labels)) fail.add("spoke ", i, "->", j, " has the wrong class");
      const double m = measures.at(j);
      if (!(std::abs(g.spoke_measure[s] - m) <= 1e-12 * std::max(1.0, m) + 1e-15))
        fail.add("spoke ", i, "->", j, " measure ", g.spoke_measure[s], " != face measure ", m);
      if (j < 0 || c.cell_of[j] < 0) continue;
      // Symmetry: the twin exists, with the same class and the very same measure.
      const auto t = find_spoke(g, j, i);
      if (t < 0) { fail.add("one-sided spoke ", i, "->", j); continue; }
      if (g.spoke_class[t] != g.spoke_class[s]) fail.add("spoke ", i, "<->", j, " classes differ");
      if (g.spoke_measure[t] != g.spoke_measure[s]) fail.add("spoke ", i, "<->", j, " measures differ");
    }
  }

  // Edges: every pair of cells once, every cell-outside pair once.
  const auto edges = tessera::graph_edges(g);
  ASSERT_EQ(edges.ends.size(), 2 * edges.size()) << what;
  std::size_t cell_pairs = 0, outside = 0;
  for (std::size_t s = 0; s < g.n_spokes(); ++s) {
    cell_pairs += g.spoke_class[s] == SpokeClass::same_region || g.spoke_class[s] == SpokeClass::region_boundary;
    outside += g.spoke_class[s] == SpokeClass::outside;
  }
  EXPECT_EQ(cell_pairs % 2, 0u) << what;
  EXPECT_EQ(edges.size(), cell_pairs / 2 + outside) << what;
  std::set<std::pair<std::int32_t, std::int32_t>> seen;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto a = edges.ends[2 * e], b = edges.ends[2 * e + 1];
    if (!seen.insert({std::min(a, b), std::max(a, b)}).second) fail.add("edge ", a, "-", b, " listed twice");
    if (g.spokes[edges.spoke[e]] != b) fail.add("edge ", e, " does not name its spoke");
    if (c.cell_of[a] < 0) fail.add("edge ", e, " starts at a point without a cell");
  }
}

double box_surface(const tessera::Bounds& b, int dim) {
  const double x = b.hi[0] - b.lo[0], y = b.hi[1] - b.lo[1], z = b.hi[2] - b.lo[2];
  return dim == 3 ? 2 * (x * y + y * z + z * x) : 2 * (x + y);
}

TEST(Graph, MatchesCellsAndIsSymmetric) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(dim == 3 ? 2000 : 3000, dim, 301 + dim);
    const auto c = run(pts, dim);
    const auto g = tessera::adjacency_graph(c);
    check_graph(c, g, {}, "random " + std::to_string(dim) + "D");
    // The box spokes' faces tile the box surface.
    double box = 0;
    for (std::size_t s = 0; s < g.n_spokes(); ++s)
      if (g.spokes[s] < 0) box += g.spoke_measure[s];
    EXPECT_NEAR(box, box_surface(c.bounds, dim), 1e-9 * box_surface(c.bounds, dim));

    // Labels with outside points and several regions.
    std::vector<std::int32_t> labels(pts.size() / dim);
    std::mt19937 rng(7);
    for (auto& l : labels) l = std::int32_t(rng() % 4) - 1;
    const auto cl = run(pts, dim, std::nullopt, labels);
    check_graph(cl, tessera::adjacency_graph(cl), labels, "labelled " + std::to_string(dim) + "D");
  }
  const auto lattice = grid_points(6, 3);
  const auto cl = run(lattice, 3);
  check_graph(cl, tessera::adjacency_graph(cl), {}, "lattice 6^3");
}

// Each spoke's measure, bit for bit, is front::face_measure of the copy of
// its face in the cell that speaks for it: the lower generator's, in a
// periodic box the lower of (i, j, s) and (j, i, -s); the cell's own copy for
// box planes and outside points. Found here by scanning the mesh's faces, the
// reference for adjacency_graph's wheel-ordered passes and twin lookup.
void expect_speaking_measures(const tessera::Cells& c, const tessera::AdjacencyGraph& g, const std::string& what) {
  Failures fail(what);
  const auto du = std::size_t(c.dim);
  const bool periodic = c.is_periodic();
  using Shift = std::array<int, 3>;
  auto spoke_shift = [&](std::size_t s) {
    Shift sh{0, 0, 0};
    if (periodic)
      for (std::size_t a = 0; a < du; ++a) sh[a] = g.spoke_shift[s * du + a];
    return sh;
  };
  auto face_of = [&](std::int32_t cell, std::int32_t j, const Shift& sh) -> std::int64_t {
    for (auto f = c.cell_face_offsets[cell]; f < c.cell_face_offsets[cell + 1]; ++f) {
      if (c.face_neighbor[f] != j) continue;
      bool same = true;
      for (std::size_t a = 0; periodic && a < du; ++a) same = same && c.face_shift[std::size_t(f) * du + a] == sh[a];
      if (same) return f;
    }
    return -1;
  };
  std::size_t twins = 0;
  for (std::size_t p = 0; p < g.n_points; ++p) {
    const auto i = std::int32_t(p);
    for (auto s = g.wheel_offsets[p]; s < g.wheel_offsets[p + 1]; ++s) {
      const auto su = std::size_t(s);
      const std::int32_t j = g.spokes[su];
      const Shift sh = spoke_shift(su);
      const Shift back{-sh[0], -sh[1], -sh[2]};
      const bool lower = i < j || (i == j && !(back < sh));
      std::int64_t f = -1;
      if (j >= 0 && c.cell_of[j] >= 0 && !lower) {
        f = face_of(c.cell_of[j], i, back);
        ++twins;
      } else {
        f = face_of(c.cell_of[p], j, sh);
      }
      if (f < 0) { fail.add("spoke ", i, " -> ", j, ": no face"); continue; }
      const double want = tessera::front::face_measure(c, f);
      if (std::memcmp(&want, &g.spoke_measure[su], sizeof want) != 0)
        fail.add("spoke ", i, " -> ", j, ": measure ", g.spoke_measure[su], " is not the speaking face's ", want);
    }
  }
  EXPECT_GT(twins, 0u) << what;
}

TEST(Graph, MeasuresAreTheSpeakingFaces) {
  for (int dim : {2, 3}) {
    const std::string d = std::to_string(dim) + "D";
    const auto pts = random_points(dim == 3 ? 2000 : 3000, dim, 351 + dim);
    const auto c = run(pts, dim, std::nullopt, {}, 2);
    expect_speaking_measures(c, tessera::adjacency_graph(c), "random " + d);
    expect_speaking_measures(c, tessera::adjacency_graph(c, {0.1}), "random, pruned " + d);
    std::vector<std::int32_t> labels(pts.size() / std::size_t(dim));
    std::mt19937 rng(11);
    for (auto& l : labels) l = std::int32_t(rng() % 4) - 1;
    const auto cl = run(pts, dim, std::nullopt, labels);
    expect_speaking_measures(cl, tessera::adjacency_graph(cl), "labelled " + d);
    // An exact lattice: ties, zero-area faces between diagonal neighbours.
    const auto lattice = grid_points(dim == 3 ? 6 : 12, dim);
    const auto cg = run(lattice, dim);
    expect_speaking_measures(cg, tessera::adjacency_graph(cg), "lattice " + d);
    expect_speaking_measures(cg, tessera::adjacency_graph(cg, {1e-9}), "lattice, pruned " + d);
    // Periodic boxes, triclinic too, and two points whose cells face their
    // own images.
    for (double tilt : {0.0, 0.3}) {
      auto o = options(dim, make_bounds({0, 0, 0}, {1, 1, 1}), 2);
      o.periodic = {true, true, dim == 3};
      o.tilt = {tilt, 0, dim == 3 ? -tilt / 2 : 0};
      const auto cp = tessera::voronoi(std::span<const double>(pts), dim, {}, o);
      expect_speaking_measures(cp, tessera::adjacency_graph(cp), "periodic " + d + " tilt " + std::to_string(tilt));
      const std::vector<double> two{0.1, 0.2, 0.3, 0.6, 0.5, 0.4};
      const std::vector<double> pair(two.begin(), two.begin() + 2 * dim);
      const auto c2 = tessera::voronoi(std::span<const double>(pair), dim, {}, o);
      expect_speaking_measures(c2, tessera::adjacency_graph(c2), "two points, periodic " + d);
    }
  }
}

TEST(Graph, ThreadCountDoesNotMatter) {
  const auto pts = random_points(20000, 3, 311);
  const auto g1 = tessera::adjacency_graph(run(pts, 3, std::nullopt, {}, 1), {0.05});
  const auto g2 = tessera::adjacency_graph(run(pts, 3, std::nullopt, {}, 2), {0.05});
  EXPECT_EQ(g1.wheel_offsets, g2.wheel_offsets);
  EXPECT_EQ(g1.spokes, g2.spokes);
  EXPECT_EQ(g1.spoke_class, g2.spoke_class);
  EXPECT_EQ(g1.spoke_measure, g2.spoke_measure);
  EXPECT_EQ(g1.pruned_spokes, g2.pruned_spokes);
}

// Pruning drops exactly the spokes whose face measure is below
// tolerance * (mean cell volume)^((D-1)/D), and drops both directions.
TEST(Graph, PruneIsSymmetricAndFollowsItsDefinition) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(3000, dim, 321 + dim);
    const auto c = run(pts, dim);
    const auto full = tessera::adjacency_graph(c);
    EXPECT_EQ(full.prune_threshold, 0.0);
    double mean = 0;
    for (double v : c.volume) mean += v;
    mean /= double(c.n_cells());
    for (double tol : {0.01, 0.1}) {
      const std::string what = std::to_string(dim) + "D prune " + std::to_string(tol);
      const auto g = tessera::adjacency_graph(c, {tol});
      const double threshold = tol * std::pow(mean, (dim - 1.0) / dim);
      EXPECT_NEAR(g.prune_threshold, threshold, 1e-12 * threshold) << what;
      std::size_t expect_kept = 0;
      for (double m : full.spoke_measure) expect_kept += !(m < g.prune_threshold);
      EXPECT_EQ(g.n_spokes(), expect_kept) << what;
      EXPECT_EQ(g.pruned_spokes, full.n_spokes() - expect_kept) << what;
      EXPECT_GT(g.pruned_spokes, 0u) << what << ": the test should prune something";
      for (std::size_t p = 0; p < g.n_points; ++p)
        for (auto s = g.wheel_offsets[p]; s < g.wheel_offsets[p + 1]; ++s) {
          EXPECT_GE(g.spoke_measure[s], g.prune_threshold) << what;
          const auto j = g.spokes[s];
          if (j >= 0) EXPECT_GE(find_spoke(g, j, std::int32_t(p)), 0) << what << ": pruned one side only";
        }
    }
  }
}

// On an exact lattice the symbolic perturbation splits each 8-cube corner,
// leaving zero-area faces between diagonal neighbours; pruning them leaves
// the 6-neighbour lattice graph (box planes included, six spokes per cube).
TEST(Graph, PruneLeavesTheLatticeGraph) {
  const int k = 5;
  const auto pts = grid_points(k, 3);
  const auto c = run(pts, 3);
  const auto g = tessera::adjacency_graph(c, {1e-9});
  for (std::size_t p = 0; p < g.n_points; ++p) {
    ASSERT_EQ(g.wheel_offsets[p + 1] - g.wheel_offsets[p], 6) << "point " << p;
    for (auto s = g.wheel_offsets[p]; s < g.wheel_offsets[p + 1]; ++s) {
      const auto j = g.spokes[s];
      if (j < 0) continue;
      double d = 0;
      for (int a = 0; a < 3; ++a) d += std::abs(pts[3 * p + a] - pts[3 * j + a]);
      EXPECT_EQ(d, 1.0) << p << "->" << j << " is not an axis neighbour";
    }
  }
}

// Face measures far from 1: the fan's cross products are scaled (mesh_faces.hpp).
// Points scaled by a power of two give the same cells scaled by it, so each
// face's measure is the unit-scale one times its square (its first power in
// 2D); at 2^±300 the squares of the cross products used to leave double's
// range (3D areas inf above ~1e77, zero below ~1e-77).
TEST(Graph, FaceMeasuresAtExtremeScales) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(200, dim, 733 + dim);
    const auto ref = tessera::adjacency_graph(run(pts, dim), {});
    for (int e : {-300, 300, -500, 500}) {
      std::vector<double> scaled(pts);
      for (double& x : scaled) x = std::ldexp(x, e);
      const auto g = tessera::adjacency_graph(run(scaled, dim), {});
      const std::string what = std::to_string(dim) + "D at 2^" + std::to_string(e);
      ASSERT_EQ(g.spokes, ref.spokes) << what;
      for (std::size_t s = 0; s < g.n_spokes(); ++s) {
        const double m = std::ldexp(g.spoke_measure[s], -(dim - 1) * e);
        ASSERT_NEAR(m, ref.spoke_measure[s], 1e-12 * ref.spoke_measure[s]) << what << ", spoke " << s;
      }
    }
  }
}

TEST(Graph, BadInput) {
  const auto pts = random_points(100, 3, 331);
  const auto c = run(pts, 3);
  EXPECT_THROW(tessera::adjacency_graph(c, {-1}), tessera::InputError);
  EXPECT_THROW(tessera::adjacency_graph(c, {NAN}), tessera::InputError);
  EXPECT_THROW(tessera::adjacency_graph(c, {INFINITY}), tessera::InputError);
  auto o = options(3);
  o.build_mesh = false;
  const auto bare = tessera::voronoi(pts, 3, {}, o);
  EXPECT_THROW(tessera::adjacency_graph(bare), std::invalid_argument);
}

#ifdef TESSERA_HAVE_CGAL
// The graph is the Delaunay edge set restricted to the box: every graph edge
// is a Delaunay edge, and every Delaunay edge with a simplex whose
// circumcentre (a Voronoi vertex of that edge's face) lies inside the box is
// a graph edge. (Edges whose whole dual face lies outside the box are the
// only ones missing.)
TEST(Graph, EqualsDelaunayEdgesInsideTheBox) {
  for (int dim : {2, 3}) {
    const std::string what = std::to_string(dim) + "D";
    const auto pts = random_points(dim == 3 ? 3000 : 5000, dim, 341 + dim);
    const auto c = run(pts, dim);
    const auto g = tessera::adjacency_graph(c);
    const auto dt = dual_test::cgal_delaunay(pts, dim);
    std::set<std::pair<std::int32_t, std::int32_t>> graph;
    const auto edges = tessera::graph_edges(g);
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const auto a = edges.ends[2 * e], b = edges.ends[2 * e + 1];
      graph.insert({std::min(a, b), std::max(a, b)});
    }
    for (const auto& e : graph)
      EXPECT_TRUE(dt.edges.count(e)) << what << ": graph edge " << e.first << "-" << e.second << " is not Delaunay";

    const double margin = 1e-9 * box_size(c.bounds, dim);
    std::set<std::pair<std::int32_t, std::int32_t>> must;
    for (const auto& s : dt.simplices) {
      bool inside = true;
      for (int a = 0; a < dim; ++a)
        inside = inside && s.circumcentre[a] > c.bounds.lo[a] + margin && s.circumcentre[a] < c.bounds.hi[a] - margin;
      if (!inside) continue;
      for (std::size_t a = 0; a < s.ids.size(); ++a)
        for (std::size_t b = a + 1; b < s.ids.size(); ++b) must.insert({s.ids[a], s.ids[b]});
    }
    std::size_t missing = 0;
    for (const auto& e : must) missing += !graph.count(e);
    EXPECT_EQ(missing, 0u) << what << ": Delaunay edges with a Voronoi vertex in the box missing from the graph";
    // Most Delaunay edges have a dual vertex in the box (the rest are thin hull simplices),
    // so the check above covers the graph nearly everywhere.
    EXPECT_GT(double(must.size()), 0.9 * double(dt.edges.size())) << what;
    EXPECT_LE(graph.size(), dt.edges.size()) << what;
  }
}
#endif

}  // namespace
