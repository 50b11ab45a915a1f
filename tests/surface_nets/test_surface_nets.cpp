// Generalized surface nets: every region's surface is closed, 2-manifold
// and outward; BoundaryLabels follow the convention; enclosed volumes equal
// the cells' exactly before smoothing and stay close after; volumes and
// areas approach the analytic ones; smoothing keeps topology (no flips, no
// self-intersections), respects the constraint, keeps junction vertices on
// their curve, corners fixed and box vertices on the box; the result does
// not depend on the thread count; bad input gives one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <tuple>

#include "front/net_crossings.hpp"
#include "net_test_util.hpp"
#include "tessera/cells.hpp"

namespace {

using namespace net_test;
using tessera::NetVertexKind;
using tessera::SurfaceNet;
using tessera::SurfaceNetsOptions;

constexpr double kPi = std::numbers::pi;

/// Sum of the cell volumes (areas in 2D) per selected region, with every
/// other label as an outside point — what each region's surface must enclose.
std::map<std::int32_t, double> region_volumes(const Labelled& in, const std::set<std::int32_t>& selected) {
  std::vector<std::int32_t> l(in.labels);
  for (auto& x : l)
    if (!selected.count(x)) x = -1;
  tessera::VoronoiOptions o;
  o.dim = in.dim;
  tessera::Bounds b;
  b.hi = {1, 1, in.dim == 3 ? 1.0 : 0.0};
  o.bounds = b;
  o.threads = 1;
  o.build_mesh = false;
  const tessera::Cells c = tessera::voronoi(in.points, in.dim, l, o);
  std::map<std::int32_t, double> v;
  for (std::size_t k = 0; k < c.n_cells(); ++k) v[c.region[k]] += c.volume[k];
  return v;
}

/// Number of distinct regions among a vertex's generators (box planes each
/// their own), recomputed here from the key.
int regions_of_key(const tessera::FaceSet& m, const std::vector<std::int32_t>& labels, std::size_t v) {
  const int kn = m.dim + 1;
  std::set<std::pair<int, std::int64_t>> r;
  for (int a = 0; a < kn; ++a) {
    const std::int32_t id = m.vertex_keys[v * kn + a];
    r.insert(id < 0 ? std::pair<int, std::int64_t>{1, id} : std::pair<int, std::int64_t>{0, labels[id]});
  }
  return static_cast<int>(r.size());
}

/// Distance from a net vertex (original position) to its generators.
double petal_radius(const tessera::FaceSet& m, const Labelled& in, std::size_t v) {
  const int kn = m.dim + 1;
  for (int a = 0; a < kn; ++a) {
    const std::int32_t id = m.vertex_keys[v * kn + a];
    if (id < 0) continue;
    double d2 = 0;
    for (int q = 0; q < m.dim; ++q) {
      const double d = m.vertices[v * m.dim + q] - in.points[static_cast<std::size_t>(id) * in.dim + q];
      d2 += d * d;
    }
    return std::sqrt(d2);
  }
  return 0;
}

double displacement(const tessera::FaceSet& a, const tessera::FaceSet& b, std::size_t v) {
  double d2 = 0;
  for (int q = 0; q < a.dim; ++q) {
    const double d = a.vertices[v * a.dim + q] - b.vertices[v * a.dim + q];
    d2 += d * d;
  }
  return std::sqrt(d2);
}

/// Checks shared by every net: sizes, labels per face against the sides
/// (side 0 a selected region; between selected regions lo < hi; capping
/// faces carry the neighbour's own label or the background), closed
/// outward 2-manifold surfaces for the `closed` labels with the cells'
/// volume (exactly when unsmoothed), kinds from the keys.
void check_net(const SurfaceNet& net, const Labelled& in, const std::set<std::int32_t>& selected,
               const std::set<std::int32_t>& closed, bool smoothed, std::int32_t background = -1,
               double volume_tol = 1e-9) {
  const auto& m = net.mesh;
  const std::size_t nf = m.n_faces(), nv = m.n_vertices();
  ASSERT_EQ(m.boundary_labels.size(), 2 * nf);
  ASSERT_EQ(m.sides.size(), 2 * nf);
  ASSERT_EQ(net.vertex_kind.size(), nv);
  ASSERT_EQ(net.polygon_of_face.size(), nf);
  ASSERT_EQ(std::set<std::int32_t>(net.selected.begin(), net.selected.end()), selected);
  for (std::size_t f = 0; f < nf; ++f) {
    const std::int32_t l0 = m.boundary_labels[2 * f], l1 = m.boundary_labels[2 * f + 1];
    const std::int32_t s0 = m.sides[2 * f], s1 = m.sides[2 * f + 1];
    ASSERT_TRUE(selected.count(l0)) << "face " << f << ": side 0 label " << l0 << " is not selected";
    ASSERT_EQ(l0, in.labels[s0]) << "face " << f;
    if (s1 < 0) {
      ASSERT_EQ(l1, background) << "face " << f;
    } else {
      ASSERT_EQ(l1, in.labels[s1]) << "face " << f;
      ASSERT_NE(l0, l1) << "face " << f << ": a face inside one region";
      if (selected.count(l1)) ASSERT_LT(l0, l1) << "face " << f << ": interface not (lo, hi)";
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    const int k = regions_of_key(m, in.labels, v);
    const NetVertexKind want = k >= m.dim + 1 ? NetVertexKind::corner
                               : k == 3       ? NetVertexKind::junction
                                              : NetVertexKind::surface;
    ASSERT_EQ(net.vertex_kind[v], want) << "vertex " << v << " with " << k << " regions";
  }
  const auto vol = region_volumes(in, selected);
  for (std::int32_t label : closed) {
    const auto r = region_surface(m, label);
    EXPECT_EQ(r.unbalanced_edges, 0u) << "label " << label << ": surface not closed / not consistently oriented";
    EXPECT_EQ(r.nonmanifold_edges, 0u) << "label " << label << ": surface not 2-manifold";
    EXPECT_EQ(r.degenerate_faces, 0u) << "label " << label;
    const double want = vol.at(label);
    if (!smoothed)
      EXPECT_NEAR(r.volume, want, volume_tol * std::max(1.0, want)) << "label " << label << " encloses its cells";
    else
      EXPECT_NEAR(r.volume, want, volume_tol * want) << "label " << label << " after smoothing";
  }
}

SurfaceNetsOptions opts(int dim, int iterations, bool capping = false, bool triangles = false, int threads = 1) {
  SurfaceNetsOptions o = net_options(dim, iterations, triangles, threads);
  o.capping = capping;
  return o;
}

double sphere_volume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

// ------------------------------------------------------------ topology

TEST(SurfaceNets, NestedSpheresClosedOrientedExactVolumes) {
  const Labelled in = grid_points(16, 3, 0.3, 1, nested(3));
  // Without capping the net is the two spheres: every label's surface is
  // closed (label 0's is the outer sphere, reversed).
  const SurfaceNet a = run(in, opts(3, 0));
  check_net(a, in, {0, 1, 2}, {1, 2}, false);
  std::set<std::pair<int, int>> pairs;
  for (std::size_t f = 0; f < a.mesh.n_faces(); ++f)
    pairs.insert({a.mesh.boundary_labels[2 * f], a.mesh.boundary_labels[2 * f + 1]});
  EXPECT_EQ(pairs, (std::set<std::pair<int, int>>{{0, 1}, {1, 2}}));
  EXPECT_EQ(a.max_displacement, 0.0);
  // With capping the box closes label 0 too.
  const SurfaceNet b = run(in, opts(3, 0, true));
  check_net(b, in, {0, 1, 2}, {0, 1, 2}, false);
  pairs.clear();
  for (std::size_t f = 0; f < b.mesh.n_faces(); ++f)
    pairs.insert({b.mesh.boundary_labels[2 * f], b.mesh.boundary_labels[2 * f + 1]});
  EXPECT_EQ(pairs, (std::set<std::pair<int, int>>{{0, -1}, {0, 1}, {1, 2}}));
  // Smoothed: still closed and manifold (same connectivity), volume close.
  const SurfaceNet c = run(in, opts(3, 20, true));
  check_net(c, in, {0, 1, 2}, {0, 1, 2}, true, -1, 0.12);
  EXPECT_EQ(c.mesh.face_vertices, b.mesh.face_vertices);
  EXPECT_GT(c.max_displacement, 0.0);
}

TEST(SurfaceNets, TouchingBoxesAndLabelPairs) {
  const Labelled in = grid_points(20, 3, 0.25, 2, touching_boxes);
  const SurfaceNet a = run(in, opts(3, 0, true));
  check_net(a, in, {0, 1, 2}, {0, 1, 2}, false);
  std::map<std::pair<int, int>, double> area;
  for (std::size_t f = 0; f < a.mesh.n_faces(); ++f)
    area[{a.mesh.boundary_labels[2 * f], a.mesh.boundary_labels[2 * f + 1]}] += 0.5 * norm(face_normal(a.mesh, f));
  EXPECT_EQ(area.size(), 4u);  // (0,-1), (0,1), (0,2), (1,2)
  EXPECT_TRUE(area.count({1, 2}) && area.count({0, 1}) && area.count({0, 2}) && area.count({0, -1}));
  const double box_area = area[{0, -1}], interface_area = area[{1, 2}];
  EXPECT_NEAR(box_area, 6.0, 1e-9);  // the box, exactly
  const SurfaceNet b = run(in, opts(3, 20, true, true));
  check_net(b, in, {0, 1, 2}, {0, 1, 2}, true, -1, 0.06);
  double a12 = 0;
  for (std::size_t f = 0; f < b.mesh.n_faces(); ++f)
    if (b.mesh.boundary_labels[2 * f] == 1 && b.mesh.boundary_labels[2 * f + 1] == 2)
      a12 += 0.5 * norm(face_normal(b.mesh, f));
  // The plane x = 0.5 between the boxes: 0.5 x 0.5. Rough before, close after.
  EXPECT_GT(interface_area, 0.25 * 1.1);
  EXPECT_NEAR(a12, 0.25, 0.25 * 0.06);
  EXPECT_LT(std::fabs(a12 - 0.25), std::fabs(interface_area - 0.25));
}

TEST(SurfaceNets, TrianglesKeepLabelsOrientationAndClosure) {
  const Labelled in = grid_points(14, 3, 0.3, 3, nested(3));
  const SurfaceNet p = run(in, opts(3, 20, true));
  const SurfaceNet t = run(in, opts(3, 20, true, true));
  ASSERT_EQ(p.mesh.vertices, t.mesh.vertices);  // triangulation comes after smoothing
  std::size_t want = 0;
  for (std::size_t f = 0; f < p.mesh.n_faces(); ++f) want += p.mesh.face_offsets[f + 1] - p.mesh.face_offsets[f] - 2;
  ASSERT_EQ(t.mesh.n_faces(), want);
  for (std::size_t f = 0; f < t.mesh.n_faces(); ++f) {
    ASSERT_EQ(t.mesh.face_offsets[f + 1] - t.mesh.face_offsets[f], 3);
    const auto g = static_cast<std::size_t>(t.polygon_of_face[f]);
    ASSERT_EQ(t.mesh.boundary_labels[2 * f], p.mesh.boundary_labels[2 * g]);
    ASSERT_EQ(t.mesh.boundary_labels[2 * f + 1], p.mesh.boundary_labels[2 * g + 1]);
    ASSERT_EQ(t.mesh.sides[2 * f], p.mesh.sides[2 * g]);
    for (int k = 0; k < 3; ++k) {
      const auto v = t.mesh.face_vertices[3 * f + k];
      ASSERT_NE(std::find(p.mesh.face_vertices.begin() + p.mesh.face_offsets[g],
                          p.mesh.face_vertices.begin() + p.mesh.face_offsets[g + 1], v),
                p.mesh.face_vertices.begin() + p.mesh.face_offsets[g + 1]);
    }
  }
  check_net(t, in, {0, 1, 2}, {0, 1, 2}, true, -1, 0.15);
  // Unsmoothed, the triangles cover the planar polygons exactly.
  const SurfaceNet t0 = run(in, opts(3, 0, true, true));
  check_net(t0, in, {0, 1, 2}, {0, 1, 2}, false);
}

// ------------------------------------------------------------ smoothing

TEST(SurfaceNets, SmoothingFlipsNoFaceAndDoesNotSelfIntersect) {
  const std::function<std::int32_t(const V3&)> shapes[] = {nested(3), touching_boxes, three_sectors};
  for (int s = 0; s < 3; ++s)
    for (double jitter : {0.0, 0.25, 0.5}) {
      const Labelled in = grid_points(12, 3, jitter, 10 + s, shapes[s]);
      const SurfaceNet before = run(in, opts(3, 0, true, true));
      const SurfaceNet after = run(in, opts(3, 20, true, true));
      ASSERT_EQ(before.mesh.n_vertices(), after.mesh.n_vertices());
      EXPECT_EQ(flipped_faces(before.mesh, after.mesh, 1.0 / 12), 0u) << "shape " << s << " jitter " << jitter;
      // Coincident vertices of exact lattices touch before smoothing; only
      // jittered inputs are in general position.
      if (jitter > 0) {
        EXPECT_EQ(self_intersections(before.mesh), 0u) << "shape " << s << " jitter " << jitter;
        EXPECT_EQ(self_intersections(after.mesh), 0u) << "shape " << s << " jitter " << jitter;
      }
    }
  // Random (not grid) points.
  Labelled in;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  const auto label = nested(3);
  for (int i = 0; i < 2000; ++i) {
    const V3 p{u(rng), u(rng), u(rng)};
    in.points.insert(in.points.end(), p.begin(), p.end());
    in.labels.push_back(label(p));
  }
  const SurfaceNet before = run(in, opts(3, 0, true, true));
  const SurfaceNet after = run(in, opts(3, 20, true, true));
  EXPECT_EQ(flipped_faces(before.mesh, after.mesh, 1.0 / 12), 0u);
  EXPECT_EQ(self_intersections(after.mesh), 0u);
}

// Voxel centres of a label map with many touching labels (each voxel takes
// the nearest of 8 random seeds, a grain map): where three labels meet, the
// Laplacian step let faces of one label pass through each other (a fuzz
// found 24 crossing pairs of 12,390 triangles at 16^3 with the defaults; 1,005
// of 405,000 with 40 labels at 64^3). The untangling rounds pin those places;
// the net must not self-intersect, and must still be smoothed elsewhere.
TEST(SurfaceNets, SmoothingOfManyTouchingLabelsDoesNotSelfIntersect) {
  for (std::uint64_t seed : {1, 2, 3}) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<V3> seeds(8);
    for (V3& s : seeds) s = {u(rng), u(rng), u(rng)};
    const Labelled in = grid_points(16, 3, 0.0, seed, [&](const V3& p) {
      std::int32_t best = 0;
      for (std::size_t k = 1; k < seeds.size(); ++k)
        if (norm(sub(p, seeds[k])) < norm(sub(p, seeds[static_cast<std::size_t>(best)]))) best = static_cast<std::int32_t>(k);
      return best;
    });
    const SurfaceNet before = run(in, opts(3, 0, true, true));
    const SurfaceNet after = run(in, opts(3, 20, true, true));
    // Every pair of triangles whose boxes meet, by the exact pair test (the
    // float self_intersections counts touching at the coincident vertices of
    // exact lattices).
    const tessera::FaceSet& m = after.mesh;
    std::size_t crossing = 0;
    for (std::size_t s = 0; s < m.n_faces(); ++s)
      for (std::size_t t = s + 1; t < m.n_faces(); ++t) {
        const double* a[3];
        const double* b[3];
        bool apart = false;
        for (int k = 0; k < 3; ++k) {
          a[k] = &m.vertices[3 * static_cast<std::size_t>(m.face_vertices[3 * s + static_cast<std::size_t>(k)])];
          b[k] = &m.vertices[3 * static_cast<std::size_t>(m.face_vertices[3 * t + static_cast<std::size_t>(k)])];
        }
        for (int d = 0; d < 3 && !apart; ++d)
          apart = std::max({a[0][d], a[1][d], a[2][d]}) < std::min({b[0][d], b[1][d], b[2][d]}) ||
                  std::max({b[0][d], b[1][d], b[2][d]}) < std::min({a[0][d], a[1][d], a[2][d]});
        if (!apart) crossing += tessera::front::triangle_pair_crosses(a, &m.face_vertices[3 * s], b, &m.face_vertices[3 * t]);
      }
    EXPECT_EQ(crossing, 0u) << "seed " << seed;
    EXPECT_EQ(flipped_faces(before.mesh, after.mesh, 1.0 / 16), 0u) << "seed " << seed;
    EXPECT_GT(after.max_displacement, 0.2 / 16) << "seed " << seed;  // smoothed, not frozen
  }
}

// The smoothing's pair test (front/net_crossings.hpp): triangles cross when
// they share a point interior to one of them, exactly; touching on their
// boundaries, or a triangle of zero area, is not crossing.
TEST(SurfaceNets, CrossingTestOnHandMadeTriangles) {
  using P = std::array<double, 3>;
  auto crosses = [](const std::array<P, 3>& a, const std::array<P, 3>& b, std::array<std::int32_t, 6> ids) {
    const double* pa[3] = {a[0].data(), a[1].data(), a[2].data()};
    const double* pb[3] = {b[0].data(), b[1].data(), b[2].data()};
    const bool one = tessera::front::triangle_pair_crosses(pa, &ids[0], pb, &ids[3]);
    const bool other = tessera::front::triangle_pair_crosses(pb, &ids[3], pa, &ids[0]);
    EXPECT_EQ(one, other);
    return one;
  };
  const std::array<P, 3> floor{{{0, 0, 0}, {4, 0, 0}, {0, 4, 0}}};
  const std::array<std::int32_t, 6> apart{0, 1, 2, 3, 4, 5};
  EXPECT_TRUE(crosses(floor, {{{1, 1, -1}, {1, 1, 1}, {2, 2, 1}}}, apart));  // through the interior
  EXPECT_FALSE(crosses(floor, {{{1, 1, 0.5}, {1, 1, 1}, {2, 2, 1}}}, apart));  // above it
  EXPECT_TRUE(crosses(floor, {{{1, 1, 0}, {1, 1, 1}, {2, 2, 1}}}, apart));  // a corner on its interior
  EXPECT_FALSE(crosses(floor, {{{2, 2, 0}, {2, 2, 1}, {3, 3, 1}}}, apart));  // a corner on its edge
  EXPECT_TRUE(crosses(floor, {{{1, 0.5, 0}, {1, 2, 0}, {2, 2, 1}}}, apart));  // an edge lying across it
  EXPECT_FALSE(crosses(floor, {{{1, 0, 0}, {3, 0, 0}, {2, 2, 1}}}, apart));  // an edge along its edge
  EXPECT_TRUE(crosses(floor, {{{1, 1, 0}, {5, 1, 0}, {5, 5, 0}}}, apart));  // overlapping in its plane
  EXPECT_FALSE(crosses(floor, {{{4, 0, 0}, {5, 0, 0}, {4, 1, 0}}}, apart));  // a coincident corner, in the plane
  // Of zero area (collinear corners): through the other's interior counts,
  // touching its edge does not.
  EXPECT_TRUE(crosses(floor, {{{1, 1, -1}, {1, 1, 1}, {1, 1, 2}}}, apart));
  EXPECT_FALSE(crosses(floor, {{{2, 2, -1}, {2, 2, 1}, {2, 2, 2}}}, apart));
  // Sharing a corner: crossing away from it counts, meeting at it does not.
  EXPECT_TRUE(crosses(floor, {{{0, 0, 0}, {2, 1, -1}, {1, 2, 1}}}, {0, 1, 2, 0, 6, 7}));
  EXPECT_FALSE(crosses(floor, {{{0, 0, 0}, {2, 1, 1}, {1, 2, 1}}}, {0, 1, 2, 0, 6, 7}));
  // Sharing an edge: folded onto it in its plane counts, a hinge does not.
  EXPECT_TRUE(crosses(floor, {{{4, 0, 0}, {0, 4, 0}, {1, 1, 0}}}, {0, 1, 2, 1, 2, 8}));
  EXPECT_FALSE(crosses(floor, {{{4, 0, 0}, {0, 4, 0}, {4, 4, 1}}}, {0, 1, 2, 1, 2, 8}));
  // In its plane with every corner on its boundary, no edge through it: the
  // same corners (distinct vertices that coincide), or one on an edge.
  EXPECT_TRUE(crosses(floor, {{{0, 0, 0}, {0, 4, 0}, {4, 0, 0}}}, apart));
  EXPECT_TRUE(crosses(floor, {{{4, 0, 0}, {0, 4, 0}, {0, 1, 0}}}, {0, 1, 2, 1, 2, 8}));
  EXPECT_FALSE(crosses(floor, {{{4, 0, 0}, {0, 4, 0}, {4, 4, 0}}}, {0, 1, 2, 1, 2, 8}));  // beside it
  // Distinct corners at one place (exact lattices): a pinched triangle is a
  // segment, crossing only through the other's interior; a corner at
  // another's corner is on its boundary, wherever the rest lies.
  EXPECT_TRUE(crosses(floor, {{{1, 1, -1}, {1, 1, -1}, {1, 1, 1}}}, apart));
  EXPECT_TRUE(crosses(floor, {{{1, 1, 0}, {1, 1, 0}, {3, 0.5, 0}}}, apart));
  EXPECT_FALSE(crosses(floor, {{{4, 0, 0}, {4, 0, 0}, {0, 4, 0}}}, apart));  // along its edge
  EXPECT_FALSE(crosses({{{1, 1, -1}, {1, 1, -1}, {1, 1, 1}}}, {{{0, 1, 0}, {0, 1, 0}, {2, 1, 0}}}, apart));
  EXPECT_FALSE(crosses(floor, {{{4, 0, 0}, {5, 0, 1}, {4, 1, 1}}}, apart));
  EXPECT_TRUE(crosses(floor, {{{4, 0, 0}, {1, 1, -1}, {1, 1, 1}}}, apart));
  EXPECT_FALSE(crosses(floor, {{{0, 4, 0}, {4, 0, 0}, {4, 4, 1e-30}}}, apart));  // an edge on its edge
  EXPECT_FALSE(crosses(floor, {{{0, 4, 0}, {4, 0, 0}, {1, 1, 1e-30}}}, apart));  // a hinge, nearly shut
  EXPECT_TRUE(crosses(floor, {{{0, 4, 0}, {4, 0, 0}, {1, 1, 0}}}, apart));       // folded onto it
  // Meeting along a chord whose ends are on both boundaries (no edge of
  // either crosses the other's interior): an edge across it from corner to
  // edge or from edge to edge, and two triangles with a common corner whose
  // edges meet where they pass through each other.
  EXPECT_TRUE(crosses(floor, {{{0, 0, 0}, {2, 2, 0}, {1, 0, 3}}}, {0, 1, 2, 0, 5, 6}));
  EXPECT_TRUE(crosses(floor, {{{2, 0, 0}, {0, 2, 0}, {1, 1, 3}}}, apart));
  EXPECT_TRUE(crosses(floor, {{{2, 0, 0}, {0, 2, 0}, {1, 1, -3}}}, apart));
  EXPECT_TRUE(crosses({{{0.5, 1, 0.5}, {1, 0, 0.5}, {1.25, 0.15, 0.3}}}, {{{0.5, 0, 0}, {1.25, 0.15, 0.3}, {1, 1, 1}}},
                      {0, 1, 2, 3, 2, 4}));
  EXPECT_FALSE(crosses(floor, {{{0, 0, 0}, {4, 0, 0}, {1, 0, 3}}}, {0, 1, 2, 0, 1, 6}));  // a hinge at its edge
}

// The broad phase (a bounding volume hierarchy) finds every pair the pair
// test finds, once: triangle soups against all pairs, some sharing vertices,
// some on a coarse lattice so that corners and planes coincide exactly, some
// spread over 1,400 orders of magnitude (a cluster 2^-700 wide among
// triangles 2^700 long across it, as outliers make: the grid before the
// hierarchy put such a cluster in one cell, its float boxes at one point),
// with the `changed` and `settled` filters, and a second call of one
// CrossingCheck after some vertices moved (some far), which keeps the
// others' boxes and refits the tree.
TEST(SurfaceNets, CrossingTrianglesFindsEveryCrossingPair) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int soup = 0; soup < 6; ++soup) {
    const bool lattice = soup % 2 == 1, spread = soup >= 4;
    std::vector<double> xyz;
    const int nv = 900;
    for (int v = 0; v < nv; ++v)
      for (int d = 0; d < 3; ++d) {
        const double c = lattice ? std::floor(u(rng) * 12) / 4 : 3 * u(rng);
        xyz.push_back(spread ? std::ldexp(c, v % 10 == 0 ? 700 : -700) : c);
      }
    // Triangles from nearby vertices (sorted along x, a window of 12).
    std::vector<std::int32_t> order(nv);
    for (int v = 0; v < nv; ++v) order[v] = v;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return xyz[3 * a] < xyz[3 * b]; });
    std::vector<std::int32_t> corners;
    std::uniform_int_distribution<int> step(1, 12);
    for (int i = 0; i + 24 < nv; ++i)
      for (int rep = 0; rep < 2; ++rep) {
        const int j = i + step(rng), k = j + step(rng);
        corners.insert(corners.end(), {order[i], order[j], order[k]});
      }
    if (spread)  // long triangles from a corner in the cluster
      for (int v = 1; v + 20 < nv; v += 3) corners.insert(corners.end(), {v, 10 * (v / 30), 10 * (v / 30) + 20});    const std::size_t nt = corners.size() / 3;
    std::vector<std::uint8_t> changed(nt), settled(nt);
    for (std::size_t t = 0; t < nt; ++t) {
      changed[t] = u(rng) < 0.3;
      settled[t] = u(rng) < 0.5;
    }
    std::vector<std::pair<std::size_t, std::size_t>> all, filtered;
    for (std::size_t s = 0; s < nt; ++s)
      for (std::size_t t = s + 1; t < nt; ++t) {
        const double* a[3] = {&xyz[3 * corners[3 * s]], &xyz[3 * corners[3 * s + 1]], &xyz[3 * corners[3 * s + 2]]};
        const double* b[3] = {&xyz[3 * corners[3 * t]], &xyz[3 * corners[3 * t + 1]], &xyz[3 * corners[3 * t + 2]]};
        if (!tessera::front::triangle_pair_crosses(a, &corners[3 * s], b, &corners[3 * t])) continue;
        all.emplace_back(s, t);
        if ((changed[s] || changed[t]) && !(settled[s] && settled[t])) filtered.emplace_back(s, t);
      }
    EXPECT_GT(all.size(), 100u) << soup;
    EXPECT_EQ(tessera::front::crossing_triangles(xyz, corners), all) << soup;
    EXPECT_EQ(tessera::front::crossing_triangles(xyz, corners, changed, settled), filtered) << soup;

    tessera::front::CrossingCheck check;
    EXPECT_EQ(check(xyz, corners), all) << soup;
    std::vector<std::uint8_t> moved(nv, 0);
    for (int v = 0; v < nv; ++v)
      if (u(rng) < 0.05) {
        moved[v] = 1;
        const double scale = spread ? std::ldexp(1.0, v % 10 == 0 ? 700 : -700) : 1.0;
        for (int d = 0; d < 3; ++d) xyz[3 * v + d] += scale * (u(rng) < 0.2 ? 4.0 : 0.3) * (u(rng) - 0.5);
      }
    for (std::size_t t = 0; t < nt; ++t)
      changed[t] = moved[corners[3 * t]] || moved[corners[3 * t + 1]] || moved[corners[3 * t + 2]];
    std::vector<std::pair<std::size_t, std::size_t>> after;
    for (std::size_t s = 0; s < nt; ++s)
      for (std::size_t t = s + 1; t < nt; ++t) {
        if (!(changed[s] || changed[t]) || (settled[s] && settled[t])) continue;
        const double* a[3] = {&xyz[3 * corners[3 * s]], &xyz[3 * corners[3 * s + 1]], &xyz[3 * corners[3 * s + 2]]};
        const double* b[3] = {&xyz[3 * corners[3 * t]], &xyz[3 * corners[3 * t + 1]], &xyz[3 * corners[3 * t + 2]]};
        if (tessera::front::triangle_pair_crosses(a, &corners[3 * s], b, &corners[3 * t])) after.emplace_back(s, t);
      }
    EXPECT_GT(after.size(), 10u) << soup;
    EXPECT_EQ(check(xyz, corners, changed, settled), after) << soup;
  }
}

// Triangles of zero area before smoothing (coincident corners of exact
// ties, or a tiny cluster among wide cells) have no shape to keep, but must
// not turn over: the guard once left them out, and a fuzz found them folded
// against their polygon's normal by up to 3% of the spacing squared (a column
// of an exact lattice touching the box, capped: 4 of 250 triangles; a 1e-9
// cluster among uniform points: 5). Each triangle of the smoothed net must
// face its polygon's unsmoothed normal, up to 1e-9 of the polygon's area.
TEST(SurfaceNets, TrianglesDegenerateBeforeSmoothingDoNotTurnOver) {
  Labelled column = grid_points(8, 3, 0.0, 1, [](const V3& p) { return p[0] < 0.5 && p[1] < 0.5 ? 1 : 0; });
  Labelled cluster;
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0, 1);
  std::uniform_int_distribution<int> label(0, 2);
  for (int i = 0; i < 600; ++i) {
    const double s = i < 300 ? 1.0 : 1e-9, o = i < 300 ? 0.0 : 0.5;
    for (int a = 0; a < 3; ++a) cluster.points.push_back(o + s * u(rng));
    cluster.labels.push_back(label(rng));
  }
  for (const Labelled* in : {&column, &cluster}) {
    const SurfaceNet raw = run(*in, opts(3, 0, true));
    const SurfaceNet tri = run(*in, opts(3, 20, true, true));
    std::size_t turned = 0, checked = 0;
    for (std::size_t f = 0; f < tri.mesh.n_faces(); ++f) {
      const auto g = static_cast<std::size_t>(tri.polygon_of_face[f]);
      const V3 n0 = face_normal(raw.mesh, g);  // twice the polygon's area, unsmoothed
      const double nn = norm(n0);
      if (nn == 0) continue;
      const auto* t = &tri.mesh.face_vertices[3 * f];
      const V3 a = cross(sub(vertex(tri.mesh, t[1]), vertex(tri.mesh, t[0])),
                         sub(vertex(tri.mesh, t[2]), vertex(tri.mesh, t[0])));
      ++checked;
      turned += dot(a, n0) < -1e-9 * nn * nn;
    }
    EXPECT_GT(checked, 200u);
    EXPECT_EQ(turned, 0u) << (in == &column ? "lattice column" : "cluster");
  }
}

TEST(SurfaceNets, SmoothingOfVoxelCentresDoesNotDependOnTheirSpacingBeingBinary) {
  // Voxel centres at a spacing of 1/16 are exact in binary, so their ties
  // (cospherical neighbours) are exact, and the faces between the coincident
  // vertices a tie splits into have zero area. At 0.7/16 the centres round
  // off the lattice, and those faces keep an area of ~1e-13 of the spacing
  // squared: a normal made of rounding noise, which the smoothing guard and
  // the triangulation must ignore as they ignore a zero one. The guard used
  // to keep it, froze those faces' corners, and half the 3D vertices (a
  // quarter in 2D) ended elsewhere; on a 256^3 volume it took four times the
  // rounds. Here the cells agree (same vertex keys), so the nets, scaled
  // back, must agree too: every vertex, and the triangles.
  for (int dim : {2, 3}) {
    const int k = 16;
    const double spacing[2] = {1.0 / k, 0.7 / k};
    SurfaceNet net[2];
    for (int r = 0; r < 2; ++r) {
      Labelled in = grid_points(k, dim, 0.0, 1, nested(dim));
      for (double& x : in.points) x = std::floor(x * k) * spacing[r] + 0.5 * spacing[r];
      SurfaceNetsOptions o = opts(dim, 20, true, dim == 3);
      const double side = k * spacing[r];
      o.voronoi.bounds->hi = {side, side, dim == 3 ? side : 0.0};
      net[r] = run(in, o);
    }
    const tessera::FaceSet &a = net[0].mesh, &b = net[1].mesh;
    ASSERT_EQ(a.vertex_keys, b.vertex_keys) << "dim " << dim << ": the cells differ, so the test says nothing";
    ASSERT_EQ(a.face_offsets, b.face_offsets) << "dim " << dim;
    EXPECT_EQ(a.face_vertices, b.face_vertices) << "dim " << dim << ": another triangulation";
    std::size_t moved_apart = 0;
    for (std::size_t c = 0; c < a.vertices.size(); ++c)
      moved_apart += !(std::fabs(b.vertices[c] / spacing[1] - a.vertices[c] / spacing[0]) < 1e-9);
    EXPECT_EQ(moved_apart, 0u) << "dim " << dim << ": coordinates of " << a.vertices.size();
  }
}

TEST(SurfaceNets, PowerOfTwoScalesGiveTheScaledNet) {
  // Points scaled by 2^600 or 2^-600: the cells are the same (exact
  // predicates, a power-of-two frame), so the net must be the unit points'
  // net scaled. The smoothing's squared lengths overflowed (or underflowed)
  // there, so vertices moved without their constraint (or not at all), and
  // vertices ended up to 0.06 apart in unit terms (stop 52).
  for (int dim : {2, 3}) {
    const Labelled unit = grid_points(12, dim, 0.3, 52, nested(dim));
    SurfaceNetsOptions o = opts(dim, 20, false, dim == 3);
    const SurfaceNet want = run(unit, o);
    for (int e : {600, -600}) {
      Labelled in = unit;
      for (double& x : in.points) x = std::ldexp(x, e);
      SurfaceNetsOptions oe = o;
      for (double& x : oe.voronoi.bounds->hi) x = std::ldexp(x, e);
      const SurfaceNet got = run(in, oe);
      ASSERT_EQ(got.mesh.vertex_keys, want.mesh.vertex_keys) << "dim " << dim << " 2^" << e;
      EXPECT_EQ(got.mesh.face_vertices, want.mesh.face_vertices) << "dim " << dim << " 2^" << e;
      EXPECT_NEAR(std::ldexp(got.max_displacement, -e), want.max_displacement, 1e-12) << "dim " << dim << " 2^" << e;
      std::size_t off = 0;
      for (std::size_t c = 0; c < want.mesh.vertices.size(); ++c)
        off += !(std::fabs(std::ldexp(got.mesh.vertices[c], -e) - want.mesh.vertices[c]) < 1e-12);
      EXPECT_EQ(off, 0u) << "dim " << dim << " 2^" << e << ": coordinates of " << want.mesh.vertices.size();
    }
  }
}

TEST(SurfaceNets, SmoothingRespectsConstraintCornersAndBox) {
  const Labelled in = grid_points(16, 3, 0.3, 4, touching_boxes);
  const SurfaceNet before = run(in, opts(3, 0, true));
  for (double c : {0.2, 0.5, 1.0}) {
    SurfaceNetsOptions o = opts(3, 30, true);
    o.smoothing.constraint = c;
    const SurfaceNet after = run(in, o);
    double worst = 0;
    std::size_t corners = 0;
    for (std::size_t v = 0; v < after.mesh.n_vertices(); ++v) {
      const double d = displacement(before.mesh, after.mesh, v);
      const double limit = c * petal_radius(before.mesh, in, v);
      ASSERT_LE(d, limit * (1 + 1e-12) + 1e-15) << "vertex " << v << " constraint " << c;
      worst = std::max(worst, d);
      if (after.vertex_kind[v] == NetVertexKind::corner) {
        ++corners;
        ASSERT_EQ(d, 0.0) << "corner " << v << " moved";
      }
      // Vertices on a box plane keep that coordinate exactly (as computed
      // by the cells: on the plane up to rounding) and stay on the plane.
      for (int a = 0; a < 4; ++a) {
        const std::int32_t id = after.mesh.vertex_keys[4 * v + a];
        if (id >= 0) continue;
        const int axis = (-id - 1) / 2;
        ASSERT_EQ(after.mesh.vertices[3 * v + axis], before.mesh.vertices[3 * v + axis]) << "vertex " << v;
        ASSERT_NEAR(after.mesh.vertices[3 * v + axis], (-id - 1) % 2 == 0 ? 0.0 : 1.0, 1e-15) << "vertex " << v;
      }
    }
    EXPECT_GT(corners, 0u);  // the domain box's corners (capping)
    EXPECT_DOUBLE_EQ(after.max_displacement, worst);
  }
  // Absolute constraint.
  SurfaceNetsOptions o = opts(3, 30, true);
  o.smoothing.constraint = 0.01;
  o.smoothing.constraint_is_absolute = true;
  const SurfaceNet after = run(in, o);
  EXPECT_LE(after.max_displacement, 0.01 * (1 + 1e-12));
  EXPECT_GT(after.max_displacement, 0.009);
}

TEST(SurfaceNets, JunctionVerticesStayOnTheirLine) {
  // Three sectors meeting along x = y = 0.5: the junction vertices (three
  // labels, no box plane) lie on a zig-zag around that line; smoothing moves
  // them along their curve only, so they come closer to the line, never
  // farther than the constraint, and the curve's ends on the box are fixed.
  const Labelled in = grid_points(16, 3, 0.3, 6, three_sectors);
  const SurfaceNet before = run(in, opts(3, 0, true));
  const SurfaceNet after = run(in, opts(3, 20, true));
  auto dist_to_line = [](const tessera::FaceSet& m, std::size_t v) {
    return std::hypot(m.vertices[3 * v] - 0.5, m.vertices[3 * v + 1] - 0.5);
  };
  double sum0 = 0, sum1 = 0, max0 = 0, max1 = 0;
  std::size_t n = 0, ends = 0;
  for (std::size_t v = 0; v < after.mesh.n_vertices(); ++v) {
    std::set<std::int32_t> labels;
    bool on_box = false;
    for (int a = 0; a < 4; ++a) {
      const auto id = after.mesh.vertex_keys[4 * v + a];
      if (id < 0) on_box = true;
      else labels.insert(in.labels[id]);
    }
    if (labels.size() != 3) continue;
    if (on_box) {  // the curve's ends on z = 0 / z = 1: four regions, fixed
      ++ends;
      EXPECT_EQ(after.vertex_kind[v], NetVertexKind::corner);
      EXPECT_EQ(displacement(before.mesh, after.mesh, v), 0.0);
      continue;
    }
    ASSERT_EQ(after.vertex_kind[v], NetVertexKind::junction);
    ++n;
    const double d0 = dist_to_line(before.mesh, v), d1 = dist_to_line(after.mesh, v);
    sum0 += d0, sum1 += d1;
    max0 = std::max(max0, d0), max1 = std::max(max1, d1);
    EXPECT_LE(displacement(before.mesh, after.mesh, v), 0.5 * petal_radius(before.mesh, in, v) * (1 + 1e-12));
  }
  ASSERT_GT(n, 16u);
  EXPECT_GE(ends, 2u);
  EXPECT_LT(max0, 1.0 / 16);           // the Voronoi junction is within a spacing of the line
  EXPECT_LE(max1, max0);               // and smoothing never pushes a vertex farther out
  EXPECT_LT(sum1, 0.8 * sum0);         // it straightens the curve
}

TEST(SurfaceNets, SmoothingMakesSpheresSmoothVolumeAndAreaClose) {
  // Inner sphere of radius 0.2 in a jittered grid of 24^3 points.
  const Labelled in = grid_points(24, 3, 0.25, 7, nested(3));
  const SurfaceNet before = run(in, opts(3, 0));
  const SurfaceNet after = run(in, opts(3, 20, false, true));
  auto normal_error = [](const tessera::FaceSet& m) {  // area-weighted angle to the radius, degrees
    double sw = 0, sa = 0;
    for (std::size_t f = 0; f < m.n_faces(); ++f) {
      if (m.boundary_labels[2 * f] != 1 || m.boundary_labels[2 * f + 1] != 2) continue;
      const V3 n = face_normal(m, f);
      V3 c{0, 0, 0};
      const auto b = m.face_offsets[f], e = m.face_offsets[f + 1];
      for (auto q = b; q < e; ++q)
        for (int a = 0; a < 3; ++a) c[a] += vertex(m, m.face_vertices[q])[a] / double(e - b);
      const V3 r{c[0] - 0.5, c[1] - 0.5, c[2] - 0.5};
      if (norm(n) == 0) continue;
      // The face points from 1 (outside) into 2 (inside): against the radius.
      sa += norm(n) * std::acos(std::clamp(-dot(n, r) / norm(n) / norm(r), -1.0, 1.0)) * 180 / kPi;
      sw += norm(n);
    }
    return sa / sw;
  };
  const double e0 = normal_error(before.mesh), e1 = normal_error(after.mesh);
  EXPECT_GT(e0, 35.0);  // Voronoi faces: a rough, staircase-like surface
  EXPECT_LT(e1, 0.55 * e0);
  const auto s0 = region_surface(before.mesh, 2), s1 = region_surface(after.mesh, 2);
  const double va = sphere_volume(0.2), aa = 4 * kPi * 0.04;
  EXPECT_NEAR(s0.volume, va, 0.03 * va);
  EXPECT_NEAR(s1.volume, va, 0.06 * va);
  EXPECT_GT(s0.measure, 1.3 * aa);         // about +50% before smoothing
  EXPECT_NEAR(s1.measure, aa, 0.08 * aa);  // within a few percent after
}

TEST(SurfaceNets, VolumeErrorShrinksWithResolution) {
  // The smoothed spheres' volume errors decrease as the spacing does (the
  // area error after smoothing settles at a few percent: the residual
  // roughness is on the scale of the spacing, and so relative to it).
  double prev_v[3] = {1e9, 1e9, 1e9};
  for (int k : {12, 20, 32}) {
    const Labelled in = grid_points(k, 3, 0.25, 8, nested(3));
    const SurfaceNet net = run(in, opts(3, 20));
    const double want[3] = {0, sphere_volume(0.35) - sphere_volume(0.2), sphere_volume(0.2)};
    const double area[3] = {0, 4 * kPi * (0.35 * 0.35 + 0.04), 4 * kPi * 0.04};
    for (int label : {1, 2}) {
      const auto r = region_surface(net.mesh, label);
      const double ev = std::fabs(r.volume - want[label]) / want[label];
      EXPECT_LT(ev, prev_v[label]) << "label " << label << " k " << k;
      prev_v[label] = ev;
      EXPECT_NEAR(r.measure, area[label], 0.1 * area[label]) << "label " << label << " k " << k;
    }
  }
  EXPECT_LT(prev_v[1], 0.01);
  EXPECT_LT(prev_v[2], 0.04);
}

TEST(SurfaceNets, ExactLatticeIsClosedAndSmooths) {
  // Exact voxel centres (what an unjoggled image sample gives): ties are
  // broken symbolically, so faces and edges of zero size appear, yet every
  // surface is closed and manifold and encloses exactly its cells.
  const Labelled in = grid_points(16, 3, 0.0, 0, nested(3));
  const SurfaceNet before = run(in, opts(3, 0, true, true));
  check_net(before, in, {0, 1, 2}, {0, 1, 2}, false);
  const SurfaceNet after = run(in, opts(3, 20, true, true));
  check_net(after, in, {0, 1, 2}, {0, 1, 2}, true, -1, 0.15);
  EXPECT_EQ(flipped_faces(before.mesh, after.mesh, 1.0 / 16), 0u);
}

// ------------------------------------------------------------ selection

TEST(SurfaceNets, SelectionAndOutsideLabels) {
  Labelled in = grid_points(14, 3, 0.3, 9, nested(3));
  // Some outside points of their own (negative) label.
  for (std::size_t i = 0; i < in.labels.size(); i += 97)
    if (in.labels[i] == 0) in.labels[i] = -5;
  SurfaceNetsOptions o = opts(3, 0);
  o.select = {1};
  // Only label 1: no interface between two selected regions...
  const SurfaceNet none = run(in, o);
  EXPECT_EQ(none.mesh.n_faces(), 0u);
  // ...with capping, its shell against the unselected 0 and 2, and side 0
  // is always the selected label even where the other is lower (VTK puts
  // (0, 1) here, notes §6.10).
  o.capping = true;
  o.background_label = -9;
  const SurfaceNet shell = run(in, o);
  check_net(shell, in, {1}, {1}, false, -9);
  std::set<std::pair<int, int>> pairs;
  for (std::size_t f = 0; f < shell.mesh.n_faces(); ++f)
    pairs.insert({shell.mesh.boundary_labels[2 * f], shell.mesh.boundary_labels[2 * f + 1]});
  EXPECT_TRUE(pairs.count({1, 0}) && pairs.count({1, 2}));
  for (auto [a, b] : pairs) EXPECT_EQ(a, 1);
  // Default selection: every label >= 0; faces against outside points carry -5,
  // the box -9.
  o.select = {};
  const SurfaceNet all = run(in, o);
  check_net(all, in, {0, 1, 2}, {0, 1, 2}, false, -9);
  pairs.clear();
  for (std::size_t f = 0; f < all.mesh.n_faces(); ++f)
    pairs.insert({all.mesh.boundary_labels[2 * f], all.mesh.boundary_labels[2 * f + 1]});
  EXPECT_TRUE(pairs.count({0, -5}) && pairs.count({0, -9}));
  // Smoothing counts unselected and outside labels as regions too.
  o.select = {0, 2};
  o.smoothing.iterations = 20;
  const SurfaceNet two = run(in, o);
  check_net(two, in, {0, 2}, {0, 2}, true, -9, 0.15);
}

// ------------------------------------------------------------ 2D

TEST(SurfaceNets, TwoDimensionalCurves) {
  const Labelled in = grid_points(40, 2, 0.3, 11, nested(2));
  const SurfaceNet before = run(in, opts(2, 0, true));
  check_net(before, in, {0, 1, 2}, {0, 1, 2}, false);
  const SurfaceNet after = run(in, opts(2, 20, true, true));  // triangles: ignored in 2D
  check_net(after, in, {0, 1, 2}, {0, 1, 2}, true, -1, 0.05);
  ASSERT_EQ(after.mesh.face_vertices, before.mesh.face_vertices);
  std::size_t corners = 0;
  for (std::size_t v = 0; v < after.mesh.n_vertices(); ++v) {
    ASSERT_NE(after.vertex_kind[v], NetVertexKind::junction);
    if (after.vertex_kind[v] == NetVertexKind::corner) {
      ++corners;
      EXPECT_EQ(displacement(before.mesh, after.mesh, v), 0.0);
    }
    EXPECT_LE(displacement(before.mesh, after.mesh, v), 0.5 * petal_radius(before.mesh, in, v) * (1 + 1e-12));
  }
  EXPECT_GE(corners, 4u);  // the box corners
  // Segments keep their direction; lengths approach the circles'.
  for (std::size_t f = 0; f < after.mesh.n_faces(); ++f) {
    const auto a = after.mesh.face_vertices[2 * f], b = after.mesh.face_vertices[2 * f + 1];
    const V3 d0 = sub(vertex(before.mesh, b), vertex(before.mesh, a)), d1 = sub(vertex(after.mesh, b), vertex(after.mesh, a));
    if (norm(d0) > 0) EXPECT_GT(dot(d0, d1), 0) << "segment " << f;
  }
  const auto c0 = region_surface(before.mesh, 2), c1 = region_surface(after.mesh, 2);
  EXPECT_NEAR(c1.volume, kPi * 0.04, 0.03 * kPi * 0.04);
  EXPECT_LT(std::fabs(c1.measure - 2 * kPi * 0.2), std::fabs(c0.measure - 2 * kPi * 0.2));
}

// ------------------------------------------------------------ threads

TEST(SurfaceNets, OneAndTwoThreadsIdentical) {
  const Labelled in = grid_points(20, 3, 0.3, 12, three_sectors);
  const SurfaceNet a = run(in, opts(3, 20, true, true, 1));
  const SurfaceNet b = run(in, opts(3, 20, true, true, 2));
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  EXPECT_EQ(std::memcmp(a.mesh.vertices.data(), b.mesh.vertices.data(), a.mesh.vertices.size() * sizeof(double)), 0);
  EXPECT_EQ(a.mesh.vertex_keys, b.mesh.vertex_keys);
  EXPECT_EQ(a.mesh.face_offsets, b.mesh.face_offsets);
  EXPECT_EQ(a.mesh.face_vertices, b.mesh.face_vertices);
  EXPECT_EQ(a.mesh.boundary_labels, b.mesh.boundary_labels);
  EXPECT_EQ(a.mesh.sides, b.mesh.sides);
  EXPECT_EQ(a.vertex_kind, b.vertex_kind);
  EXPECT_EQ(a.polygon_of_face, b.polygon_of_face);
  EXPECT_EQ(a.max_displacement, b.max_displacement);
}

TEST(SurfaceNets, SmoothStepAloneMatchesPipeline) {
  const Labelled in = grid_points(12, 3, 0.3, 13, touching_boxes);
  const SurfaceNet net = run(in, opts(3, 20));
  SurfaceNet raw = run(in, opts(3, 0));
  double moved = -1;
  const auto kinds = tessera::smooth_surface_net(raw.mesh, in.points, in.labels, {}, moved);
  EXPECT_EQ(kinds, net.vertex_kind);
  EXPECT_EQ(raw.mesh.vertices, net.mesh.vertices);
  EXPECT_EQ(moved, net.max_displacement);
}

// ------------------------------------------------------------ bad input

void expect_error(const Labelled& in, const SurfaceNetsOptions& o, const std::string& needle) {
  try {
    (void)tessera::surface_nets(in.points, in.labels, o);
    ADD_FAILURE() << "no error; expected one mentioning '" << needle << "'";
  } catch (const tessera::InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(SurfaceNets, BadInputGivesOneLineErrors) {
  const Labelled in = grid_points(6, 3, 0.2, 14, nested(3));
  SurfaceNetsOptions o = opts(3, 20);
  Labelled nolabels = in;
  nolabels.labels.clear();
  expect_error(nolabels, o, "labels");
  Labelled short_labels = in;
  short_labels.labels.pop_back();
  expect_error(short_labels, o, "labels");
  o.select = {1, 7};
  expect_error(in, o, "unknown label 7");
  o.select = {-1};
  expect_error(in, o, "negative");
  o.select = {};
  Labelled all_outside = in;
  for (auto& l : all_outside.labels) l = -1;
  expect_error(all_outside, o, "empty selection");
  SurfaceNetsOptions b = opts(3, 20);
  b.background_label = 0;
  expect_error(in, b, "background label");
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (int it : {-1}) {
    SurfaceNetsOptions s = opts(3, it);
    expect_error(in, s, "iterations");
  }
  for (double r : {0.0, -0.5, 1.5, nan}) {
    SurfaceNetsOptions s = opts(3, 20);
    s.smoothing.relaxation = r;
    expect_error(in, s, "relaxation");
  }
  for (double c : {-1.0, nan, inf}) {
    SurfaceNetsOptions s = opts(3, 20);
    s.smoothing.constraint = c;
    expect_error(in, s, "constraint");
  }
  SurfaceNetsOptions d = opts(3, 20);
  d.voronoi.dim = 4;
  expect_error(in, d, "dim");
}

}  // namespace

// ------------------------------------------------------------ periodic boxes

namespace {

/// n random points in the unit box, on a grid of 2^-30 (the periodic box's
/// rounding leaves them as they are), labelled in three bands across x + y
/// (junction curves in 3D), so every region wraps around the box.
Labelled periodic_bands(std::size_t n, int dim, std::uint64_t seed) {
  Labelled in;
  in.dim = dim;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0x1p-20, 1 - 0x1p-20);
  for (std::size_t i = 0; i < n; ++i) {
    double s = 0;
    for (int a = 0; a < dim; ++a) {
      const double x = std::ldexp(std::floor(std::ldexp(u(rng), 30)), -30);
      in.points.push_back(x);
      if (a < 2) s += x;
    }
    in.labels.push_back(static_cast<std::int32_t>(std::floor(3 * s)) % 3);
  }
  return in;
}

SurfaceNetsOptions periodic_opts(int dim, int iterations, bool triangles = false, int threads = 1,
                                 std::array<double, 3> tilt = {0, 0, 0}) {
  SurfaceNetsOptions o = net_options(dim, iterations, triangles, threads);
  o.voronoi.periodic = {true, true, dim == 3};
  o.voronoi.tilt = tilt;
  return o;
}

/// Directed edges (3D; 2D: segment ends) of every region's faces over copies
/// of vertices (tessera::vertex_copies) that have no reverse: 0 when each
/// region's surface closes up in the periodic box.
std::size_t open_edges(const tessera::FaceSet& m, const std::vector<std::int32_t>& regions) {
  const tessera::VertexCopies cp = tessera::vertex_copies(m);
  const auto du = static_cast<std::size_t>(m.dim);
  using Key = std::tuple<std::int32_t, std::int32_t, std::int32_t, std::array<std::int32_t, 3>>;
  std::map<Key, int> balance;
  auto shift = [&](std::int32_t v) {
    std::array<std::int32_t, 3> s{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) s[a] = cp.shift[static_cast<std::size_t>(v) * du + a];
    return s;
  };
  for (std::int32_t r : regions)
    for (std::size_t f = 0; f < m.n_faces(); ++f) {
      const bool s0 = m.boundary_labels[2 * f] == r, s1 = m.boundary_labels[2 * f + 1] == r;
      if (s0 == s1) continue;
      std::vector<std::int32_t> loop(m.face_vertices.begin() + m.face_offsets[f],
                                     m.face_vertices.begin() + m.face_offsets[f + 1]);
      if (s1) std::reverse(loop.begin(), loop.end());
      const std::size_t n = loop.size();
      for (std::size_t k = 0; k < (m.dim == 2 ? 1 : n); ++k) {
        const std::int32_t u = loop[k], w = loop[(k + 1) % n];
        const auto gu = cp.group[static_cast<std::size_t>(u)], gw = cp.group[static_cast<std::size_t>(w)];
        if (m.dim == 2) {
          ++balance[{r, gu, -1, {}}];
          --balance[{r, gw, -1, {}}];
          continue;
        }
        const auto a = shift(u), b = shift(w);
        ++balance[{r, gu, gw, {b[0] - a[0], b[1] - a[1], b[2] - a[2]}}];
        --balance[{r, gw, gu, {a[0] - b[0], a[1] - b[1], a[2] - b[2]}}];
      }
    }
  std::size_t open = 0;
  for (const auto& [key, m2] : balance) open += m2 != 0;
  return open;
}

}  // namespace

TEST(SurfaceNets, PeriodicNetsCloseUpAndCopiesMoveTogether) {
  // Surface nets in periodic boxes (orthogonal and triclinic 3D, 2D): every
  // region's surface closes up across the box's faces, before and after
  // smoothing and triangulation; the copies of a vertex (one per frame its
  // cells see it from) stay exact lattice translations of each other and
  // have one kind; 1 and 2 threads agree.
  struct Case {
    int dim;
    std::array<double, 3> tilt;
    bool voxels;  // exact voxel centres: several vertices share each corner
    bool walls;   // y not periodic: walls there, capped
  };
  for (const Case& k : {Case{3, {0, 0, 0}, false, false}, Case{3, {0.25, -0.125, 0.375}, false, false},
                        Case{2, {0.375, 0, 0}, false, false}, Case{3, {0, 0, 0}, true, false},
                        Case{2, {0, 0, 0}, true, false}, Case{3, {0, 0, 0}, false, true}, Case{3, {0, 0, 0}, true, true}}) {
    SCOPED_TRACE(k.dim * 1000 + (k.tilt[0] != 0) * 100 + k.voxels * 10 + k.walls);
    Labelled in = periodic_bands(600, k.dim, 50);
    if (k.voxels) {
      in = grid_points(8, k.dim, 0.0, 1, [](const V3& x) { return static_cast<int>(std::floor(3 * (x[0] + x[1]))) % 3; });
      in.dim = k.dim;
    }
    for (bool triangles : {false, true}) {
      if (triangles && k.dim == 2) continue;
      SurfaceNetsOptions o1 = periodic_opts(k.dim, 20, triangles, 1, k.tilt), o2 = o1;
      o2.voronoi.threads = 2;
      if (k.walls) {
        for (SurfaceNetsOptions* o : {&o1, &o2}) {
          o->voronoi.periodic[1] = false;
          o->capping = true;
        }
      }
      const SurfaceNet net = run(in, o1);
      const SurfaceNet two = run(in, o2);
      EXPECT_EQ(net.mesh.vertices, two.mesh.vertices);
      EXPECT_EQ(net.mesh.face_vertices, two.mesh.face_vertices);
      const tessera::FaceSet& m = net.mesh;
      ASSERT_TRUE(m.is_periodic());
      ASSERT_EQ(m.side_shifts.size(), m.n_faces() * static_cast<std::size_t>(k.dim));
      EXPECT_GT(m.n_faces(), 0u);
      EXPECT_GT(net.max_displacement, 0.0);
      EXPECT_EQ(open_edges(m, {0, 1, 2}), 0u);
      const tessera::VertexCopies cp = tessera::vertex_copies(m);
      EXPECT_LT(cp.n_groups(), m.n_vertices());  // some vertices are seen from several frames
      const auto du = static_cast<std::size_t>(k.dim);
      double worst = 0;
      for (std::size_t v = 0; v < m.n_vertices(); ++v) {
        const auto f = static_cast<std::size_t>(cp.first[static_cast<std::size_t>(cp.group[v])]);
        EXPECT_EQ(net.vertex_kind[v], net.vertex_kind[f]);
        for (std::size_t a = 0; a < du; ++a) {
          double t = 0;
          for (std::size_t b = 0; b < du; ++b) t += cp.shift[v * du + b] * m.lattice[b][a];
          worst = std::max(worst, std::fabs(m.vertices[v * du + a] - (m.vertices[f * du + a] + t)));
        }
      }
      EXPECT_LE(worst, 1e-15);
    }
  }
}

TEST(SurfaceNets, PeriodicSmoothingEqualsTheNetOfTiledImages) {
  // The periodic net against an oracle: the ordinary net of the points'
  // 3 x 3 x 3 images (walls far away) smooths each vertex of the middle
  // region as the periodic net smooths it, as long as the smoothing's reach
  // (two iterations: two polygon edges) stays inside the tiling.
  const Labelled in = periodic_bands(150, 3, 51);
  const SurfaceNet before = run(in, periodic_opts(3, 0));
  const SurfaceNet after = run(in, periodic_opts(3, 2));
  Labelled tiled;
  for (int sx = -1; sx <= 1; ++sx)
    for (int sy = -1; sy <= 1; ++sy)
      for (int sz = -1; sz <= 1; ++sz)
        for (std::size_t i = 0; i < 150; ++i) {
          tiled.points.insert(tiled.points.end(),
                              {in.points[3 * i] + sx, in.points[3 * i + 1] + sy, in.points[3 * i + 2] + sz});
          tiled.labels.push_back(in.labels[i]);
        }
  SurfaceNetsOptions o = net_options(3, 0);
  o.voronoi.bounds->lo = {-1, -1, -1};
  o.voronoi.bounds->hi = {2, 2, 2};
  const SurfaceNet tiled_before = run(tiled, o);
  o.smoothing.iterations = 2;
  const SurfaceNet tiled_after = run(tiled, o);
  ASSERT_EQ(before.mesh.n_vertices(), after.mesh.n_vertices());
  ASSERT_EQ(tiled_before.mesh.n_vertices(), tiled_after.mesh.n_vertices());
  std::size_t matched = 0;
  double worst = 0;
  for (std::size_t v = 0; v < before.mesh.n_vertices(); ++v) {
    const double* x = &before.mesh.vertices[3 * v];
    for (std::size_t w = 0; w < tiled_before.mesh.n_vertices(); ++w) {
      const double* y = &tiled_before.mesh.vertices[3 * w];
      if (std::fabs(x[0] - y[0]) + std::fabs(x[1] - y[1]) + std::fabs(x[2] - y[2]) > 1e-12) continue;
      ++matched;
      EXPECT_EQ(after.vertex_kind[v], tiled_after.vertex_kind[w]);
      for (int a = 0; a < 3; ++a) worst = std::max(worst, std::fabs(after.mesh.vertices[3 * v + a] - tiled_after.mesh.vertices[3 * w + a]));
      break;
    }
  }
  EXPECT_EQ(matched, before.mesh.n_vertices());
  EXPECT_LE(worst, 1e-12);
  EXPECT_GT(after.max_displacement, 1e-3);
}
