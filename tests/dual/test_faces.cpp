// Face sets: none is dropped or repeated (counts match the adjacency graph),
// vertices are the merged ones compacted, sides and BoundaryLabels follow the
// documented convention, orientation runs from side 0 to side 1, the
// boundary is a closed outward surface, surface nets with capping enclose
// every region, and the result does not depend on the thread count.
#include <gtest/gtest.h>

#include <set>

#include "cells/helpers.hpp"
#include "surface_checks.hpp"
#include "tessera/faces.hpp"
#include "tessera/graph.hpp"

namespace {

using namespace cells_test;
using dual_test::check_surface;
using tessera::FaceSetKind;
using tessera::SpokeClass;

tessera::FaceSet extract(const tessera::Cells& c, const std::vector<std::int32_t>& labels, FaceSetKind kind,
                         bool capping = false) {
  tessera::FaceSetOptions o;
  o.kind = kind;
  o.capping = capping;
  return tessera::extract_faces(c, labels, o);
}

std::array<double, 3> centre(const tessera::Bounds& b) {
  return {(b.lo[0] + b.hi[0]) / 2, (b.lo[1] + b.hi[1]) / 2, (b.lo[2] + b.hi[2]) / 2};
}

/// Structural checks every face set passes: vertices are exactly the used
/// merged vertices (same keys and coordinates as in Cells), sides and labels
/// follow the convention, and each face is a face of side 0's cell in the
/// same orientation.
void check_face_set(const tessera::Cells& c, const tessera::FaceSet& fs, const std::vector<std::int32_t>& labels,
                    std::int32_t background, const std::string& what) {
  Failures fail(what);
  const int dim = c.dim;
  const std::size_t nf = fs.n_faces(), nv = fs.n_vertices();
  ASSERT_EQ(fs.dim, dim) << what;
  ASSERT_EQ(fs.face_offsets.size(), nf + 1) << what;
  ASSERT_EQ(fs.sides.size(), 2 * nf) << what;
  ASSERT_EQ(fs.boundary_labels.size(), 2 * nf) << what;
  ASSERT_EQ(fs.face_class.size(), nf) << what;
  ASSERT_EQ(fs.vertices.size(), nv * dim) << what;

  // Cells' vertex id by key, to map face-set vertices back.
  std::map<std::vector<std::int32_t>, std::int32_t> by_key;
  for (std::size_t v = 0; v < c.n_vertices(); ++v)
    by_key[{c.vertex_keys.begin() + v * (dim + 1), c.vertex_keys.begin() + (v + 1) * (dim + 1)}] = std::int32_t(v);
  std::vector<std::int32_t> to_cells(nv, -1);
  for (std::size_t v = 0; v < nv; ++v) {
    auto it = by_key.find({fs.vertex_keys.begin() + v * (dim + 1), fs.vertex_keys.begin() + (v + 1) * (dim + 1)});
    if (it == by_key.end()) { fail.add("vertex ", v, " has a key unknown to the cells"); continue; }
    to_cells[v] = it->second;
    if (v > 0 && to_cells[v - 1] >= it->second) fail.add("vertices not in ascending Cells order at ", v);
    for (int a = 0; a < dim; ++a)
      if (fs.vertices[v * dim + a] != c.vertices[std::size_t(it->second) * dim + a]) fail.add("vertex ", v, " moved");
  }
  std::vector<int> used(nv, 0);
  for (auto v : fs.face_vertices) {
    if (v < 0 || std::size_t(v) >= nv) { fail.add("face vertex ", v, " out of range"); return; }
    used[v] = 1;
  }
  if (std::count(used.begin(), used.end(), 0)) fail.add("some vertices are used by no face");

  std::set<std::pair<std::int32_t, std::int32_t>> sides_seen;
  for (std::size_t f = 0; f < nf; ++f) {
    const auto g = fs.sides[2 * f], j = fs.sides[2 * f + 1];
    const auto l0 = fs.boundary_labels[2 * f], l1 = fs.boundary_labels[2 * f + 1];
    const auto k = c.cell_of[g];
    if (k < 0) { fail.add("face ", f, ": side 0 ", g, " has no cell"); continue; }
    if (!sides_seen.insert({std::min(g, j), std::max(g, j)}).second) fail.add("face ", g, "|", j, " listed twice");
    if (l0 != c.region[k]) fail.add("face ", f, ": label 0 is not side 0's region");
    const auto cls = fs.face_class[f];
    if (j < 0) {
      if (cls != SpokeClass::domain_boundary || l1 != background) fail.add("face ", f, ": box side wrong");
    } else if (c.cell_of[j] < 0) {
      if (cls != SpokeClass::outside || l1 != labels.at(j)) fail.add("face ", f, ": outside side wrong");
    } else {
      const auto kj = c.cell_of[j];
      if (l1 != c.region[kj]) fail.add("face ", f, ": label 1 is not side 1's region");
      // Side 0 has the smaller (region, id).
      if (!(std::pair(l0, g) < std::pair(l1, j))) fail.add("face ", f, ": sides in the wrong order");
      if ((l0 == l1) != (cls == SpokeClass::same_region)) fail.add("face ", f, ": class does not match the labels");
    }
    // The face is side 0's face towards j, same vertex cycle.
    std::vector<std::int32_t> mine;
    for (auto q = fs.face_offsets[f]; q < fs.face_offsets[f + 1]; ++q) mine.push_back(to_cells[fs.face_vertices[q]]);
    bool found = false;
    for (auto cf = c.cell_face_offsets[k]; cf < c.cell_face_offsets[k + 1]; ++cf)
      if (c.face_neighbor[cf] == j)
        found = std::vector<std::int32_t>(c.face_vertices.begin() + c.face_vertex_offsets[cf],
                                          c.face_vertices.begin() + c.face_vertex_offsets[cf + 1]) == mine;
    if (!found) fail.add("face ", f, " (", g, "|", j, ") is not side 0's face in its orientation");
  }
}

struct Counts {
  std::size_t cell_pairs = 0, box = 0, outside = 0, region_pairs = 0;
};

/// Face counts from the adjacency graph: undirected spokes by kind.
Counts graph_counts(const tessera::Cells& c) {
  const auto g = tessera::adjacency_graph(c);
  Counts n;
  for (std::size_t s = 0; s < g.n_spokes(); ++s) {
    switch (g.spoke_class[s]) {
      case SpokeClass::same_region: ++n.cell_pairs; break;
      case SpokeClass::region_boundary: ++n.cell_pairs; ++n.region_pairs; break;
      case SpokeClass::domain_boundary: ++n.box; break;
      case SpokeClass::outside: ++n.outside; break;
    }
  }
  n.cell_pairs /= 2;
  n.region_pairs /= 2;
  return n;
}

std::vector<std::int32_t> random_labels(std::size_t n, int lo, int hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::int32_t> l(n);
  for (auto& x : l) x = lo + std::int32_t(rng() % unsigned(hi - lo + 1));
  return l;
}

TEST(Faces, CountsMatchTheGraph) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(dim == 3 ? 2000 : 4000, dim, 401 + dim);
    const std::size_t n = pts.size() / dim;
    for (bool with_labels : {false, true}) {
      const auto labels = with_labels ? random_labels(n, -1, 2, 9) : std::vector<std::int32_t>{};
      const std::string what = std::to_string(dim) + "D" + (with_labels ? " labelled" : "");
      const auto c = run(pts, dim, std::nullopt, labels);
      const Counts k = graph_counts(c);
      const auto complex = extract(c, labels, FaceSetKind::complex);
      const auto boundary = extract(c, labels, FaceSetKind::boundary);
      const auto net = extract(c, labels, FaceSetKind::surface_net);
      const auto capped = extract(c, labels, FaceSetKind::surface_net, true);
      check_face_set(c, complex, labels, -1, what + " complex");
      check_face_set(c, boundary, labels, -1, what + " boundary");
      check_face_set(c, net, labels, -1, what + " surface net");
      check_face_set(c, capped, labels, -1, what + " capped surface net");
      EXPECT_EQ(complex.n_faces(), k.cell_pairs + k.box + k.outside) << what;
      EXPECT_EQ(boundary.n_faces(), k.box + k.outside) << what;
      EXPECT_EQ(net.n_faces(), k.region_pairs) << what;
      EXPECT_EQ(capped.n_faces(), k.region_pairs + k.box + k.outside) << what;
      if (with_labels) EXPECT_GT(k.outside * k.region_pairs, 0u) << what << ": the input should exercise every class";
      // The complex holds every Voronoi face: its measure is the sum of all
      // face measures, interior faces counted once.
      const auto g = tessera::adjacency_graph(c);
      double want = 0;
      for (std::size_t s = 0; s < g.n_spokes(); ++s) {
        const auto cls = g.spoke_class[s];
        const bool between_cells = cls == SpokeClass::same_region || cls == SpokeClass::region_boundary;
        want += between_cells ? g.spoke_measure[s] / 2 : g.spoke_measure[s];
      }
      const auto rep = check_surface(dual_test::all_loops(complex), complex.vertices, dim, centre(c.bounds));
      EXPECT_NEAR(rep.measure, want, 1e-9 * want) << what;
    }
  }
}

// Without labels the boundary is the box: a closed 2-manifold (each edge in
// exactly two faces, opposite directions; 2D: one closed loop) facing
// outward, enclosing the domain volume, with the box's surface area.
TEST(Faces, BoundaryIsAClosedOutwardManifold) {
  for (int dim : {2, 3}) {
    for (int lattice : {0, 1}) {
      const auto pts = lattice ? grid_points(dim == 3 ? 7 : 20, dim) : random_points(3000, dim, 411 + dim);
      const std::string what = std::to_string(dim) + "D" + (lattice ? " lattice" : " random");
      const auto c = run(pts, dim);
      const auto fs = extract(c, {}, FaceSetKind::boundary);
      const auto rep = check_surface(dual_test::all_loops(fs), fs.vertices, dim, centre(c.bounds));
      EXPECT_EQ(rep.degenerate_faces, 0u) << what;
      EXPECT_EQ(rep.unbalanced_edges, 0u) << what;
      EXPECT_EQ(rep.nonmanifold_edges, 0u) << what;
      const double vol = box_volume(c.bounds, dim);
      EXPECT_NEAR(rep.volume, vol, 1e-9 * vol) << what << ": positive = outward";
      for (std::size_t f = 0; f < fs.n_faces(); ++f) EXPECT_LT(fs.sides[2 * f + 1], 0) << what;
    }
  }
}

// The surface checker is not vacuous: a flipped or a missing face is caught.
TEST(Faces, SurfaceCheckCatchesDefects) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(300, dim, 415 + dim);
    const auto c = run(pts, dim);
    const auto fs = extract(c, {}, FaceSetKind::boundary);
    auto loops = dual_test::all_loops(fs);
    std::reverse(loops[3].begin(), loops[3].end());
    EXPECT_GT(check_surface(loops, fs.vertices, dim, centre(c.bounds)).unbalanced_edges, 0u);
    loops.erase(loops.begin() + 3);
    EXPECT_GT(check_surface(loops, fs.vertices, dim, centre(c.bounds)).unbalanced_edges, 0u);
  }
}

// With outside points the boundary is that of the union of the cells: still
// closed and outward (it may pinch, so manifoldness is not required), and it
// encloses exactly the cells' volume.
TEST(Faces, BoundaryAroundOutsidePointsEnclosesTheCells) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(3000, dim, 421 + dim);
    const std::size_t n = pts.size() / dim;
    std::vector<std::int32_t> labels(n);
    for (std::size_t i = 0; i < n; ++i) {  // a ball of inside points, outside points around it
      double r2 = 0;
      for (int a = 0; a < dim; ++a) r2 += (pts[i * dim + a] - 0.5) * (pts[i * dim + a] - 0.5);
      labels[i] = r2 < 0.35 * 0.35 ? 0 : -1 - std::int32_t(i % 3);
    }
    const auto c = run(pts, dim, unit_box(), labels);
    const auto fs = extract(c, labels, FaceSetKind::boundary);
    check_face_set(c, fs, labels, -1, std::to_string(dim) + "D ball boundary");
    const auto rep = check_surface(dual_test::all_loops(fs), fs.vertices, dim, centre(c.bounds));
    EXPECT_EQ(rep.unbalanced_edges, 0u);
    double inside = 0;
    for (double v : c.volume) inside += v;
    EXPECT_NEAR(rep.volume, inside, 1e-9 * inside);
    for (std::size_t f = 0; f < fs.n_faces(); ++f) EXPECT_EQ(fs.face_class[f], SpokeClass::outside);
  }
}

// Two regions split by a plane (plus outside points in a corner): the
// interface runs from the lower label to the higher, and with capping each
// region's faces (flipped where it is side 1) enclose exactly its cells.
TEST(Faces, SurfaceNetEnclosesEachRegionWithCapping) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(4000, dim, 431 + dim);
    const std::size_t n = pts.size() / dim;
    std::vector<std::int32_t> labels(n);
    for (std::size_t i = 0; i < n; ++i) {
      labels[i] = pts[i * dim] < 0.5 ? 3 : 7;
      if (pts[i * dim] > 0.8 && pts[i * dim + 1] > 0.8) labels[i] = -2;
    }
    const std::string what = std::to_string(dim) + "D two regions";
    const auto c = run(pts, dim, unit_box(), labels);

    const auto net = extract(c, labels, FaceSetKind::surface_net);
    check_face_set(c, net, labels, -1, what + " net");
    ASSERT_GT(net.n_faces(), 0u);
    double flux = 0;  // sum of the interface's area vectors along x (2D: normals (dy, -dx))
    for (std::size_t f = 0; f < net.n_faces(); ++f) {
      EXPECT_EQ(net.boundary_labels[2 * f], 3) << what;
      EXPECT_EQ(net.boundary_labels[2 * f + 1], 7) << what;
      EXPECT_EQ(net.face_class[f], SpokeClass::region_boundary) << what;
      const auto* fv = &net.face_vertices[net.face_offsets[f]];
      const auto m = net.face_offsets[f + 1] - net.face_offsets[f];
      auto x = [&](std::int64_t t, int a) { return net.vertices[std::size_t(fv[t]) * dim + a]; };
      if (dim == 2) {
        flux += x(1, 1) - x(0, 1);
      } else {
        for (std::int64_t t = 1; t + 1 < m; ++t)
          flux += 0.5 * ((x(t, 1) - x(0, 1)) * (x(t + 1, 2) - x(0, 2)) - (x(t, 2) - x(0, 2)) * (x(t + 1, 1) - x(0, 1)));
      }
    }
    // The interface separates x < 0.5 (label 3) from x > 0.5 (label 7) across
    // the box below the outside corner: its normals point to +x overall.
    EXPECT_GT(flux, 0.5) << what << ": interface must be oriented from label 3 towards label 7";

    const auto capped = extract(c, labels, FaceSetKind::surface_net, true);
    check_face_set(c, capped, labels, -1, what + " capped");
    for (std::int32_t region : {3, 7}) {
      const auto* bl = capped.boundary_labels.data();
      const auto loops = dual_test::loops_of(
          capped, [&](std::size_t f) { return bl[2 * f] == region || bl[2 * f + 1] == region; },
          [&](std::size_t f) { return bl[2 * f] != region; });
      const auto rep = check_surface(loops, capped.vertices, dim, centre(c.bounds));
      double vol = 0;
      for (std::size_t k = 0; k < c.n_cells(); ++k)
        if (c.region[k] == region) vol += c.volume[k];
      EXPECT_EQ(rep.unbalanced_edges, 0u) << what << " region " << region << " is not enclosed";
      EXPECT_NEAR(rep.volume, vol, 1e-9 * vol) << what << " region " << region;
    }
  }
}

// Inside one region, complex faces run from the lower generator id to the higher.
TEST(Faces, ComplexOrientsSameRegionFacesByGeneratorId) {
  const auto pts = random_points(500, 3, 441);
  const auto c = run(pts, 3);
  const auto fs = extract(c, {}, FaceSetKind::complex);
  std::size_t interior = 0;
  for (std::size_t f = 0; f < fs.n_faces(); ++f) {
    if (fs.sides[2 * f + 1] < 0) continue;
    ++interior;
    EXPECT_LT(fs.sides[2 * f], fs.sides[2 * f + 1]);
    EXPECT_EQ(fs.face_class[f], SpokeClass::same_region);
    // The polygon's normal points from side 0's generator towards side 1's.
    const auto a = input_point(pts, 3, fs.sides[2 * f]), b = input_point(pts, 3, fs.sides[2 * f + 1]);
    const auto* fv = &fs.face_vertices[fs.face_offsets[f]];
    auto v = [&](int t) { return V3{fs.vertices[3 * fv[t]], fs.vertices[3 * fv[t] + 1], fs.vertices[3 * fv[t] + 2]}; };
    EXPECT_GT(dot(cross(sub(v(1), v(0)), sub(v(2), v(0))), sub(b, a)), 0.0);
  }
  EXPECT_GT(interior, 0u);
}

TEST(Faces, BackgroundLabelAndThreads) {
  const auto pts = random_points(20000, 3, 451);
  const auto labels = random_labels(pts.size() / 3, -1, 3, 5);
  const auto c1 = run(pts, 3, std::nullopt, labels, 1);
  const auto c2 = run(pts, 3, std::nullopt, labels, 2);
  tessera::FaceSetOptions o;
  o.kind = FaceSetKind::complex;
  o.background_label = -100;
  const auto a = tessera::extract_faces(c1, labels, o);
  const auto b = tessera::extract_faces(c2, labels, o);
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.vertex_keys, b.vertex_keys);
  EXPECT_EQ(a.face_offsets, b.face_offsets);
  EXPECT_EQ(a.face_vertices, b.face_vertices);
  EXPECT_EQ(a.sides, b.sides);
  EXPECT_EQ(a.boundary_labels, b.boundary_labels);
  EXPECT_EQ(a.face_class, b.face_class);
  check_face_set(c1, a, labels, -100, "background -100");
}

TEST(Faces, BadInput) {
  const auto pts = random_points(200, 3, 461);
  const auto labels = random_labels(200, -1, 1, 3);
  const auto c = run(pts, 3, std::nullopt, labels);
  tessera::FaceSetOptions o;
  o.background_label = 0;
  EXPECT_THROW(tessera::extract_faces(c, labels, o), tessera::InputError);
  o.background_label = -1;
  EXPECT_THROW(tessera::extract_faces(c, std::vector<std::int32_t>(199, 0), o), tessera::InputError);
  EXPECT_THROW(tessera::extract_faces(c, {}, o), tessera::InputError);  // outside points need their labels
  auto vo = options(3);
  vo.build_mesh = false;
  EXPECT_THROW(tessera::extract_faces(tessera::voronoi(pts, 3, {}, vo), {}, o), std::invalid_argument);
  EXPECT_EQ(tessera::parse_face_set_kind("surface-net"), FaceSetKind::surface_net);
  EXPECT_EQ(tessera::parse_face_set_kind("complex"), FaceSetKind::complex);
  EXPECT_EQ(tessera::parse_face_set_kind("boundary"), FaceSetKind::boundary);
  EXPECT_FALSE(tessera::parse_face_set_kind("surface"));
  for (auto k : {FaceSetKind::boundary, FaceSetKind::complex, FaceSetKind::surface_net})
    EXPECT_EQ(tessera::parse_face_set_kind(tessera::face_set_kind_name(k)), k);
}

}  // namespace
