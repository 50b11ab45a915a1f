// Face sets of some cells (VoronoiOptions::only_with_faces): the cells with a
// face of the set's classes alone give the face set of all cells, field for
// field and bit for bit (vertices, their order, faces, sides, labels,
// classes), as the CLI's `faces`, Python's faces of points and the surface
// nets build them. The cells built are exactly those with such a face, each
// the whole computation's. Uniform 2D and 3D points on 1 and 2 threads,
// exact lattices (ties), points on a sphere (the insertion), duplicates,
// labels with outside points, points set aside outside the bounds, power
// cells, both cell methods; periodic boxes build every cell. Partial cells
// are refused by validate, the graph and the face sets they do not cover.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>

#include "cells/helpers.hpp"
#include "tessera/faces.hpp"
#include "tessera/flower.hpp"
#include "tessera/graph.hpp"
#include "tessera/surface_nets.hpp"

namespace {

using namespace cells_test;
using tessera::FaceSetKind;
using tessera::SpokeClass;

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_same_face_set(const tessera::FaceSet& a, const tessera::FaceSet& b, const std::string& what) {
  EXPECT_EQ(a.dim, b.dim) << what;
  EXPECT_EQ(a.kind, b.kind) << what;
  EXPECT_TRUE(same_bytes(a.vertices, b.vertices)) << what << ": vertices (" << a.n_vertices() << " vs "
                                                  << b.n_vertices() << ")";
  EXPECT_EQ(a.vertex_keys, b.vertex_keys) << what;
  EXPECT_EQ(a.face_offsets, b.face_offsets) << what;
  EXPECT_EQ(a.face_vertices, b.face_vertices) << what;
  EXPECT_EQ(a.sides, b.sides) << what;
  EXPECT_EQ(a.boundary_labels, b.boundary_labels) << what;
  EXPECT_EQ(a.face_class, b.face_class) << what;
  EXPECT_EQ(a.side_shifts, b.side_shifts) << what;
  EXPECT_EQ(a.vertex_key_shifts, b.vertex_key_shifts) << what;
  EXPECT_EQ(a.periodic, b.periodic) << what;
  EXPECT_EQ(a.lattice, b.lattice) << what;
}

/// The generators of `c`'s cells that have a face of one of `classes`.
std::vector<std::int32_t> cells_with_faces(const tessera::Cells& c, tessera::SpokeClassSet classes) {
  std::vector<std::int32_t> out;
  for (std::size_t k = 0; k < c.n_cells(); ++k)
    for (auto f = c.cell_face_offsets[k]; f < c.cell_face_offsets[k + 1]; ++f)
      if ((classes & tessera::spoke_class_bit(c.face_class[static_cast<std::size_t>(f)])) != 0) {
        out.push_back(c.generator[k]);
        break;
      }
  return out;
}

struct Kind {
  FaceSetKind kind;
  bool capping;
  const char* name;
};
constexpr Kind boundary_set{FaceSetKind::boundary, false, "boundary"};
constexpr Kind net_set{FaceSetKind::surface_net, false, "surface net"};
constexpr Kind capped_set{FaceSetKind::surface_net, true, "capped surface net"};
constexpr Kind complex_set{FaceSetKind::complex, false, "complex"};
const std::vector<Kind> three{boundary_set, net_set, capped_set};  // the kinds that need some cells

/// For each kind: the cells computed with only_with_faces = its classes
/// against all cells (`full`, computed with `opt`): the cells built are
/// those with such a face, each as in `full`, and the face sets are equal.
/// Returns how many kinds left some cell out.
int compare_kinds(const tessera::Cells& full, const std::vector<double>& pts, int dim,
                  const std::vector<std::int32_t>& labels, tessera::VoronoiOptions opt,
                  const std::vector<Kind>& kinds, const std::string& what_in) {
  const auto D = static_cast<std::size_t>(dim);
  int partial = 0;
  for (const Kind& k : kinds) {
    const std::string what = what_in + ", " + k.name;
    tessera::FaceSetOptions fo;
    fo.kind = k.kind;
    fo.capping = k.capping;
    fo.background_label = -7;
    opt.only_with_faces = tessera::face_set_classes(fo);
    opt.only_with_faces_up_to = 1;  // some cells, however many have such faces
    const tessera::Cells some = tessera::voronoi(pts, dim, labels, opt);
    EXPECT_EQ(some.generators, full.generators) << what;
    EXPECT_EQ(some.duplicates, full.duplicates) << what;
    EXPECT_EQ(some.empty_cells, full.empty_cells) << what;  // every generator's, from the first pass
    EXPECT_EQ(some.ignored_outside_bounds, full.ignored_outside_bounds) << what;
    EXPECT_EQ(some.from_insertion, full.from_insertion) << what;
    EXPECT_EQ(some.power, full.power) << what;
    EXPECT_EQ(some.bounds.lo, full.bounds.lo) << what;
    EXPECT_EQ(some.bounds.hi, full.bounds.hi) << what;
    // The cells built: those with a face of the set's classes (every cell
    // for the complex and in a periodic box), each the whole computation's.
    const std::vector<std::int32_t> expected =
        k.kind == FaceSetKind::complex || full.is_periodic()
            ? std::vector<std::int32_t>(full.generator.begin(), full.generator.end())
            : cells_with_faces(full, opt.only_with_faces);
    EXPECT_EQ(std::vector<std::int32_t>(some.generator.begin(), some.generator.end()), expected) << what;
    EXPECT_EQ(some.partial, some.n_cells() < full.n_cells()) << what;
    EXPECT_EQ(some.with_faces_of, some.partial ? opt.only_with_faces : 0) << what;
    partial += some.partial;
    for (std::size_t c = 0; c < some.n_cells(); ++c) {
      const std::int32_t g = some.generator[c];
      if (full.cell_of[static_cast<std::size_t>(g)] < 0 ||
          some.cell_of[static_cast<std::size_t>(g)] != static_cast<std::int32_t>(c)) {
        ADD_FAILURE() << what << ": cell of " << g << " is no cell of all, or not at its index";
        break;
      }
      const auto f = static_cast<std::size_t>(full.cell_of[static_cast<std::size_t>(g)]);
      EXPECT_EQ(std::memcmp(&some.volume[c], &full.volume[f], sizeof(double)), 0) << what << ", cell of " << g;
      EXPECT_EQ(std::memcmp(&some.centroid[c * D], &full.centroid[f * D], D * sizeof(double)), 0) << what;
      EXPECT_EQ(neighbours_of(some, c), neighbours_of(full, f)) << what << ", cell of " << g;
      EXPECT_EQ(some.cell_face_offsets[c + 1] - some.cell_face_offsets[c],
                full.cell_face_offsets[f + 1] - full.cell_face_offsets[f])
          << what;
    }
    // The face sets, field for field.
    expect_same_face_set(tessera::extract_faces(some, labels, fo), tessera::extract_faces(full, labels, fo), what);
    if (some.partial) {
      // Not a whole tessellation: refused where every cell is needed.
      EXPECT_THROW(tessera::validate(some, labels), std::invalid_argument) << what;
      EXPECT_THROW(tessera::adjacency_graph(some), std::invalid_argument) << what;
      tessera::FaceSetOptions all;
      all.kind = FaceSetKind::complex;
      EXPECT_THROW(tessera::extract_faces(some, labels, all), std::invalid_argument) << what;
    }
  }
  return partial;
}

/// compare_kinds against all cells computed with `opt`.
int expect_same_faces(const std::vector<double>& pts, int dim, const std::vector<std::int32_t>& labels,
                      const tessera::VoronoiOptions& opt, const std::vector<Kind>& kinds,
                      const std::string& what) {
  const tessera::Cells full = tessera::voronoi(pts, dim, labels, opt);
  return compare_kinds(full, pts, dim, labels, opt, kinds, what);
}

/// Labels by orthant (2^dim regions, 0..), about the box's centre `mid`.
std::vector<std::int32_t> orthants(const std::vector<double>& pts, int dim, double mid = 0.5) {
  std::vector<std::int32_t> l(pts.size() / static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < l.size(); ++i)
    for (int a = 0; a < dim; ++a) l[i] |= (pts[i * dim + a] < mid ? 0 : 1) << a;
  return l;
}

TEST(FacesOfSomeCells, Uniform) {
  for (int dim : {2, 3}) {
    const std::size_t n = dim == 3 ? 6000 : 8000;
    const auto pts = random_points(n, dim, 1301 + dim);
    const auto labels = orthants(pts, dim);
    for (int threads : {1, 2}) {
      const std::string what = std::to_string(dim) + "D uniform, " + std::to_string(threads) + " threads";
      EXPECT_EQ(expect_same_faces(pts, dim, {}, options(dim, std::nullopt, threads), {boundary_set, complex_set}, what),
                1);
      EXPECT_EQ(expect_same_faces(pts, dim, labels, options(dim, unit_box(), threads), three,
                                  what + ", orthants"),
                3);
    }
    // The cells built do not depend on the thread count: nor do the faces.
    auto opt = options(dim, std::nullopt, 1);
    tessera::FaceSetOptions fo;
    opt.only_with_faces = tessera::face_set_classes(fo);
    const auto one = tessera::voronoi(pts, dim, {}, opt);
    opt.threads = 2;
    const auto two = tessera::voronoi(pts, dim, {}, opt);
    expect_same_face_set(tessera::extract_faces(one, {}, fo), tessera::extract_faces(two, {}, fo),
                         std::to_string(dim) + "D, 1 vs 2 threads");
  }
}

// Exact ties: a lattice's vertices are met by more than D + 1 points, which
// the symbolic perturbation settles by id; region boundaries along lattice
// planes and across them.
TEST(FacesOfSomeCells, ExactLattices) {
  for (int dim : {2, 3}) {
    const auto pts = grid_points(dim == 3 ? 10 : 30, dim, 0.1);
    std::vector<std::int32_t> halves(pts.size() / dim), random(pts.size() / dim);
    std::mt19937 rng(1311);
    for (std::size_t i = 0; i < halves.size(); ++i) {
      halves[i] = pts[i * dim] < 0.45 ? 0 : 1;
      random[i] = static_cast<std::int32_t>(rng() % 3);
    }
    const std::string what = std::to_string(dim) + "D lattice";
    expect_same_faces(pts, dim, {}, options(dim), {boundary_set}, what);
    expect_same_faces(pts, dim, halves, options(dim), three, what + ", halves");
    expect_same_faces(pts, dim, random, options(dim, std::nullopt, 2), {net_set, capped_set}, what + ", random labels");
    // Lattice points on the box planes (bounds through the outermost ones).
    const double top = *std::max_element(pts.begin(), pts.end());
    const auto on_box = make_bounds({0, 0, 0}, {top, top, top});
    expect_same_faces(pts, dim, halves, options(dim, on_box), {boundary_set, capped_set}, what + ", on the box");
  }
}

// Points nearly on a sphere (a circle in 2D): the automatic method takes the
// insertion, and the sphere's cells reach the box.
TEST(FacesOfSomeCells, SphereByInsertion) {
  for (int dim : {2, 3}) {
    std::mt19937_64 rng(1321);
    std::normal_distribution<double> g(0, 1);
    const std::size_t n = dim == 3 ? 6000 : 4000;
    std::vector<double> pts;
    std::vector<std::int32_t> labels;
    for (std::size_t i = 0; i < n; ++i) {
      double v[3] = {g(rng), g(rng), dim == 3 ? g(rng) : 0.0}, s = 0;
      for (int a = 0; a < dim; ++a) s += v[a] * v[a];
      for (int a = 0; a < dim; ++a) pts.push_back(v[a] / std::sqrt(s));
      labels.push_back(v[0] < 0 ? 0 : i % 7 == 0 ? -1 : 1);  // hemispheres, some outside points
    }
    const std::string what = std::to_string(dim) + "D sphere";
    const tessera::Cells full = tessera::voronoi(pts, dim, {}, options(dim));
    EXPECT_TRUE(full.from_insertion) << what;
    compare_kinds(full, pts, dim, {}, options(dim), {boundary_set}, what);
    expect_same_faces(pts, dim, labels, options(dim, std::nullopt, 2), three, what + ", labels");
  }
}

// Both cell methods asked for.
TEST(FacesOfSomeCells, CellMethods) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(3000, dim, 1331 + dim);
    const auto labels = orthants(pts, dim, 0.37);
    for (auto method : {tessera::CellMethod::search, tessera::CellMethod::insertion}) {
      auto opt = options(dim, std::nullopt, 2);
      opt.cell_method = method;
      const std::string what =
          std::to_string(dim) + (method == tessera::CellMethod::search ? "D search" : "D insertion");
      EXPECT_EQ(expect_same_faces(pts, dim, labels, opt, three, what), 3);
    }
  }
}

// Duplicates (the lowest id owns the cell; a copy on the boundary too) and
// an inside point duplicating an outside one.
TEST(FacesOfSomeCells, Duplicates) {
  for (int dim : {2, 3}) {
    auto pts = random_points(3000, dim, 1341 + dim);
    std::vector<std::int32_t> labels = orthants(pts, dim);
    for (int a = 0; a < dim; ++a) {
      pts[dim * 9 + a] = pts[dim * 4 + a];
      pts[dim * 300 + a] = pts[dim * 1500 + a];
      pts[dim * 20 + a] = pts[dim * 13 + a];
    }
    labels[9] = labels[4];
    labels[300] = labels[1500];
    labels[13] = -1;  // 20 (inside) copies 13 (outside), which owns the place
    labels[20] = 1;
    pts[dim * 11] = 0;  // on the box: a boundary cell, copied
    for (int a = 0; a < dim; ++a) pts[dim * 12 + a] = pts[dim * 11 + a];
    labels[12] = labels[11];
    const std::string what = std::to_string(dim) + "D duplicates";
    expect_same_faces(pts, dim, {}, options(dim, unit_box()), {boundary_set}, what);
    expect_same_faces(pts, dim, labels, options(dim, unit_box(), 2), three, what + ", labels");
  }
}

// Outside points (label < 0) clip and own no cell: the boundary runs along
// them too, and the capping faces against them.
TEST(FacesOfSomeCells, OutsidePoints) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(5000, dim, 1351 + dim);
    std::vector<std::int32_t> labels(5000);
    std::mt19937 rng(1351);
    for (auto& l : labels) l = static_cast<std::int32_t>(rng() % 4) - 1;  // -1..2
    const std::string what = std::to_string(dim) + "D outside points";
    // (Mixed so finely that most cells have such faces: the boundary's
    // cells are some, the nets' nearly all.)
    for (int threads : {1, 2})
      EXPECT_GE(expect_same_faces(pts, dim, labels, options(dim, std::nullopt, threads), three, what), 1);
    // A ball of outside points in a uniform cloud: a cavity's boundary.
    std::vector<std::int32_t> cavity(5000, 3);
    for (std::size_t i = 0; i < cavity.size(); ++i) {
      double s = 0;
      for (int a = 0; a < dim; ++a) s += (pts[i * dim + a] - 0.5) * (pts[i * dim + a] - 0.5);
      if (s < 0.09) cavity[i] = -2;
    }
    // (One region: no interfaces, so the net's cells are none.)
    EXPECT_EQ(expect_same_faces(pts, dim, cavity, options(dim), three, what + ", cavity"), 3);
  }
}

// Explicit bounds with points set aside outside them (and a NaN).
TEST(FacesOfSomeCells, PointsSetAside) {
  for (int dim : {2, 3}) {
    auto pts = random_points(3000, dim, 1361 + dim, make_bounds({-0.1, -0.1, -0.1}, {1.1, 1.1, 1.1}));
    pts[dim * 5] = std::nan("");
    auto opt = options(dim, unit_box());
    opt.ignore_outside_points = true;
    const auto labels = orthants(pts, dim);
    const std::string what = std::to_string(dim) + "D set aside";
    const tessera::Cells full = tessera::voronoi(pts, dim, labels, opt);
    EXPECT_GT(full.ignored_outside_bounds.size(), 100u) << what;
    compare_kinds(full, pts, dim, labels, opt, three, what);
  }
}

// Power cells: some are empty (listed all the same), faces on radical planes.
TEST(FacesOfSomeCells, PowerCells) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(3000, dim, 1371 + dim);
    std::vector<double> radii(3000);
    std::mt19937 rng(1371);
    for (auto& r : radii) r = 0.002 + (dim == 3 ? 0.08 : 0.03) * (rng() % 1000) / 1000.0;
    auto opt = options(dim, unit_box(), 2);
    opt.radii = radii;
    const auto labels = orthants(pts, dim);
    const std::string what = std::to_string(dim) + "D power";
    const tessera::Cells full = tessera::voronoi(pts, dim, labels, opt);
    EXPECT_TRUE(full.power) << what;
    EXPECT_FALSE(full.empty_cells.empty()) << what;
    EXPECT_EQ(compare_kinds(full, pts, dim, labels, opt, three, what), 3);
  }
}

// Every cell has a boundary face (a few points): nothing is left out, and
// the cells are whole (validate takes them).
TEST(FacesOfSomeCells, EveryCellOnTheBoundary) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(5, dim, 1381 + dim);
    EXPECT_EQ(expect_same_faces(pts, dim, {}, options(dim), {boundary_set}, std::to_string(dim) + "D, 5 points"), 0);
    auto opt = options(dim);
    opt.only_with_faces = tessera::spoke_class_bit(SpokeClass::domain_boundary);
    const auto c = tessera::voronoi(pts, dim, {}, opt);
    EXPECT_FALSE(c.partial);
    EXPECT_TRUE(tessera::validate(c, {}).ok);
  }
}

// No cell has a face of the set (one region: no interfaces): no cell built.
TEST(FacesOfSomeCells, NoCellWithSuchFaces) {
  const auto pts = random_points(2000, 3, 1391);
  const std::vector<std::int32_t> one(2000, 4);
  auto opt = options(3);
  tessera::FaceSetOptions fo;
  fo.kind = FaceSetKind::surface_net;
  opt.only_with_faces = tessera::face_set_classes(fo);
  const auto c = tessera::voronoi(pts, 3, one, opt);
  EXPECT_EQ(c.n_cells(), 0u);
  EXPECT_TRUE(c.partial);
  EXPECT_EQ(c.generators, 2000u);
  EXPECT_EQ(tessera::extract_faces(c, one, fo).n_faces(), 0u);
}

// Where more than half the cells have faces of the set (estimated from a
// sample), every cell is built: faster (the first pass costs about half the
// mesh's), the same faces. A share asked for overrides the half.
TEST(FacesOfSomeCells, MostCellsWithSuchFacesBuildEveryCell) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(20000, dim, 1441 + dim);
    std::vector<std::int32_t> labels(20000);
    for (std::size_t i = 0; i < labels.size(); ++i)  // slabs a few cells thick: most cells on an interface
      labels[i] = static_cast<std::int32_t>(pts[i * dim] * (dim == 3 ? 12 : 40)) % 2;
    tessera::FaceSetOptions fo;
    fo.kind = FaceSetKind::surface_net;
    auto opt = options(dim, std::nullopt, 2);
    const tessera::Cells full = tessera::voronoi(pts, dim, labels, opt);
    const double share = static_cast<double>(cells_with_faces(full, tessera::face_set_classes(fo)).size()) /
                         static_cast<double>(full.n_cells());
    opt.only_with_faces = tessera::face_set_classes(fo);
    const tessera::Cells all = tessera::voronoi(pts, dim, labels, opt);
    opt.only_with_faces_up_to = 0.95;
    const tessera::Cells some = tessera::voronoi(pts, dim, labels, opt);
    const std::string what = std::to_string(dim) + "D slabs, a share " + std::to_string(share);
    EXPECT_GT(share, 0.55) << what;  // (well above one half: the sample says so too)
    EXPECT_LT(share, 0.9) << what;
    EXPECT_FALSE(all.partial) << what;
    EXPECT_EQ(all.n_cells(), full.n_cells()) << what;
    EXPECT_TRUE(some.partial) << what;
    const auto faces = tessera::extract_faces(full, labels, fo);
    expect_same_face_set(tessera::extract_faces(all, labels, fo), faces, what + ", all");
    expect_same_face_set(tessera::extract_faces(some, labels, fo), faces, what + ", some");
    // Few such cells: some, automatically.
    fo.kind = FaceSetKind::boundary;
    opt.only_with_faces = tessera::face_set_classes(fo);
    opt.only_with_faces_up_to = 0;
    EXPECT_TRUE(tessera::voronoi(pts, dim, labels, opt).partial) << what;
  }
}

// Periodic boxes: every cell is built (the images of some cells may differ
// in the last bits), and the faces are those of all cells.
TEST(FacesOfSomeCells, PeriodicBoxesBuildEveryCell) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(2000, dim, 1401 + dim);
    auto opt = options(dim, unit_box());
    opt.periodic = {true, dim == 3, false};
    const auto labels = orthants(pts, dim);
    EXPECT_EQ(expect_same_faces(pts, dim, labels, opt, three, std::to_string(dim) + "D periodic"),
              0);
  }
}

// Classes that same_region is among ask for every cell (faces inside a
// region have no closure), and only_with_faces does not combine with only.
TEST(FacesOfSomeCells, OptionsThatBuildEveryCellOrNone) {
  const auto pts = random_points(1000, 3, 1411);
  auto opt = options(3);
  opt.only_with_faces = tessera::spoke_class_bit(SpokeClass::same_region) |
                        tessera::spoke_class_bit(SpokeClass::domain_boundary);
  const auto all = tessera::voronoi(pts, 3, {}, opt);
  EXPECT_FALSE(all.partial);
  EXPECT_EQ(all.n_cells(), 1000u);
  const std::vector<std::int32_t> ids{1, 2};
  opt.only = ids;
  EXPECT_THROW(tessera::voronoi(pts, 3, {}, opt), tessera::InputError);
}

// Cells of a set that does not cover a face set's classes, or of `only`,
// are refused by extract_faces (they would miss faces); flowers take them.
TEST(FacesOfSomeCells, FaceSetsTheCellsDoNotCover) {
  const auto pts = random_points(3000, 3, 1421);
  const auto labels = orthants(pts, 3);
  auto opt = options(3);
  opt.only_with_faces = tessera::spoke_class_bit(SpokeClass::region_boundary);
  const auto nets = tessera::voronoi(pts, 3, labels, opt);
  ASSERT_TRUE(nets.partial);
  tessera::FaceSetOptions fo;
  fo.kind = FaceSetKind::surface_net;
  EXPECT_NO_THROW(tessera::extract_faces(nets, labels, fo));
  fo.capping = true;
  EXPECT_THROW(tessera::extract_faces(nets, labels, fo), std::invalid_argument);
  fo.kind = FaceSetKind::boundary;
  EXPECT_THROW(tessera::extract_faces(nets, labels, fo), std::invalid_argument);
  const std::int32_t g = nets.generator[0];
  EXPECT_EQ(tessera::flowers(nets, pts, {&g, 1}).front().generator, g);
  // `only`: partial too, and covers no face set.
  opt.only_with_faces = 0;
  const std::vector<std::int32_t> ids{5};
  opt.only = ids;
  const auto few = tessera::voronoi(pts, 3, labels, opt);
  EXPECT_TRUE(few.partial);
  EXPECT_EQ(few.with_faces_of, 0);
  fo.kind = FaceSetKind::boundary;
  EXPECT_THROW(tessera::extract_faces(few, labels, fo), std::invalid_argument);
  EXPECT_THROW(tessera::validate(few, labels), std::invalid_argument);
  EXPECT_THROW(tessera::adjacency_graph(few), std::invalid_argument);
}

// The surface nets pipeline builds the cells with a face of the net alone:
// its net (smoothed or not) is the one from all cells.
TEST(FacesOfSomeCells, SurfaceNetsPipeline) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(4000, dim, 1431 + dim);
    auto labels = orthants(pts, dim);
    for (std::size_t i = 0; i < labels.size(); i += 11) labels[i] = -3;  // outside points
    for (bool capping : {false, true})
      for (int iterations : {0, 20}) {
        const std::string what = std::to_string(dim) + "D net" + (capping ? ", capped" : "") + ", " +
                                 std::to_string(iterations) + " iterations";
        tessera::SurfaceNetsOptions o;
        o.voronoi = options(dim, unit_box(), 2);
        o.select = {0, 1, 3};  // 2 (and the others in 3D) unselected: outside points of their own label
        o.capping = capping;
        o.background_label = -9;
        o.smoothing.iterations = iterations;
        const tessera::SurfaceNet net = tessera::surface_nets(pts, labels, o);
        // From all cells: the cells' labels as the pipeline gives them, the
        // faces' the original ones.
        std::vector<std::int32_t> cell_labels(labels);
        for (auto& l : cell_labels)
          if (l >= 0 && std::find(o.select.begin(), o.select.end(), l) == o.select.end()) l = -1;
        const tessera::Cells full = tessera::voronoi(pts, dim, cell_labels, o.voronoi);
        EXPECT_EQ(net.n_cells, full.n_cells()) << what;
        tessera::FaceSetOptions fo;
        fo.kind = FaceSetKind::surface_net;
        fo.capping = capping;
        fo.background_label = -9;
        tessera::FaceSet ref = tessera::extract_faces(full, labels, fo);
        double moved = 0;
        const auto kinds = tessera::smooth_surface_net(ref, pts, labels, o.smoothing, moved);
        expect_same_face_set(net.mesh, ref, what);
        EXPECT_EQ(net.vertex_kind, kinds) << what;
        EXPECT_EQ(std::memcmp(&net.max_displacement, &moved, sizeof moved), 0) << what;
      }
  }
}

}  // namespace
