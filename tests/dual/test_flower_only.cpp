// Some cells only (VoronoiOptions::only), as the CLI's and Python's flower of
// points build them: every cell built is bit for bit the cell of the whole
// computation (measures, neighbours, faces, and the asked cells' merged
// vertices, placed by their owners as there), the flowers are the same but
// for their vertex ids, and what owns no cell is refused with the same words.
// Uniform 2D and 3D points, exact lattices (ties), duplicates (the owner and
// the copy asked for), labels (an asked point outside), bounds with points
// set aside, periodic and triclinic boxes, power cells, and input the
// automatic method sends to the insertion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <string>

#include "cells/helpers.hpp"
#include "tessera/flower.hpp"

namespace {

using namespace cells_test;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <class T>
std::vector<T> slice(const tessera::Buffer<T>& v, std::int64_t a, std::int64_t b) {
  return {v.begin() + a, v.begin() + b};
}

/// The flowers of `ids`, or the error's words.
std::string flowers_or_error(const tessera::Cells& c, const std::vector<double>& pts, std::int32_t id,
                             tessera::Flower& out) {
  try {
    out = tessera::flowers(c, pts, {&id, 1}).front();
    return "";
  } catch (const tessera::InputError& e) {
    return e.what();
  }
}

void expect_same_flower(const tessera::Flower& a, const tessera::Flower& b, const std::string& what) {
  EXPECT_EQ(a.generator, b.generator) << what;
  EXPECT_EQ(a.site, b.site) << what;
  ASSERT_EQ(a.n_petals(), b.n_petals()) << what;
  for (std::size_t k = 0; k < a.petal_centres.size(); ++k)
    ASSERT_TRUE(same_bits(a.petal_centres[k], b.petal_centres[k])) << what << ": petal centre entry " << k;
  for (std::size_t k = 0; k < a.n_petals(); ++k)
    ASSERT_TRUE(same_bits(a.petal_radii[k], b.petal_radii[k])) << what << ": petal radius " << k;
  EXPECT_TRUE(same_bits(a.circumflower_radius, b.circumflower_radius)) << what;
  EXPECT_EQ(a.face_offsets, b.face_offsets) << what;
  EXPECT_EQ(a.face_vertices, b.face_vertices) << what;  // the petals in the same order
  EXPECT_EQ(a.face_neighbor, b.face_neighbor) << what;
  EXPECT_EQ(a.neighbors, b.neighbors) << what;
  EXPECT_EQ(a.neighbor_positions, b.neighbor_positions) << what;
  EXPECT_EQ(a.neighbor_shifts, b.neighbor_shifts) << what;
  EXPECT_EQ(a.face_shifts, b.face_shifts) << what;
  // The vertex ids number the cells built: the same order, other values.
  for (std::size_t k = 1; k < a.n_petals(); ++k) ASSERT_LT(b.vertex_ids[k - 1], b.vertex_ids[k]) << what;
}

/// Builds the cells of `ids` alone (into `some`) and all cells, and compares.
void compare_only(tessera::Cells& some, const std::vector<double>& pts, int dim,
                  const std::vector<std::int32_t>& labels, tessera::VoronoiOptions opt,
                  const std::vector<std::int32_t>& ids, const std::string& what, bool same_layer) {
  const tessera::Cells full = tessera::voronoi(pts, dim, labels, opt);
  opt.only = ids;
  some = tessera::voronoi(pts, dim, labels, opt);
  const auto D = static_cast<std::size_t>(dim);

  EXPECT_EQ(some.generators, full.generators) << what;
  if (!full.power) EXPECT_EQ(full.generators, full.n_cells()) << what;
  EXPECT_EQ(some.duplicates, full.duplicates) << what;
  EXPECT_EQ(some.ignored_outside_bounds, full.ignored_outside_bounds) << what;
  EXPECT_EQ(some.from_insertion, full.from_insertion) << what;
  EXPECT_EQ(some.power, full.power) << what;
  EXPECT_EQ(some.bounds.lo, full.bounds.lo) << what;
  EXPECT_EQ(some.bounds.hi, full.bounds.hi) << what;
  if (same_layer) EXPECT_EQ(some.periodic_images, full.periodic_images) << what;
  // A few cells: those asked for and their neighbours (none where no
  // point asked for owns a cell).
  EXPECT_LT(some.n_cells(), full.n_cells()) << what;
  EXPECT_EQ(some.n_cells() == 0, std::none_of(ids.begin(), ids.end(), [&](std::int32_t g) {
              return full.cell_of[static_cast<std::size_t>(g)] >= 0;
            })) << what;

  for (std::size_t k = 0; k < some.n_cells(); ++k) {
    const std::int32_t g = some.generator[k];
    const std::string cell = what + ", cell of " + std::to_string(g);
    ASSERT_EQ(some.cell_of[static_cast<std::size_t>(g)], static_cast<std::int32_t>(k)) << cell;
    const auto f = static_cast<std::size_t>(full.cell_of[static_cast<std::size_t>(g)]);
    ASSERT_GE(full.cell_of[static_cast<std::size_t>(g)], 0) << cell;
    EXPECT_EQ(some.region[k], full.region[f]) << cell;
    EXPECT_TRUE(same_bits(some.volume[k], full.volume[f])) << cell << ": volume " << some.volume[k] << " vs "
                                                           << full.volume[f];
    for (std::size_t a = 0; a < D; ++a) EXPECT_TRUE(same_bits(some.centroid[k * D + a], full.centroid[f * D + a])) << cell;
    EXPECT_EQ(some.num_faces[k], full.num_faces[f]) << cell;
    EXPECT_EQ(slice(some.neighbors, some.neighbor_offsets[k], some.neighbor_offsets[k + 1]),
              slice(full.neighbors, full.neighbor_offsets[f], full.neighbor_offsets[f + 1]))
        << cell;
    if (full.is_periodic())
      EXPECT_EQ(slice(some.neighbor_shifts, some.neighbor_offsets[k] * dim, some.neighbor_offsets[k + 1] * dim),
                slice(full.neighbor_shifts, full.neighbor_offsets[f] * dim, full.neighbor_offsets[f + 1] * dim))
          << cell;
    // Faces: neighbours, classes, and (the cells asked for) their vertices'
    // keys and positions, as the whole computation places them.
    const bool asked = std::find(ids.begin(), ids.end(), g) != ids.end();
    const auto s0 = some.cell_face_offsets[k], s1 = some.cell_face_offsets[k + 1];
    const auto f0 = full.cell_face_offsets[f];
    ASSERT_EQ(s1 - s0, full.cell_face_offsets[f + 1] - f0) << cell;
    for (auto q = s0; q < s1; ++q) {
      const auto p = f0 + (q - s0);
      EXPECT_EQ(some.face_neighbor[q], full.face_neighbor[p]) << cell;
      EXPECT_EQ(some.face_class[q], full.face_class[p]) << cell;
      const auto sv = slice(some.face_vertices, some.face_vertex_offsets[q], some.face_vertex_offsets[q + 1]);
      const auto fv = slice(full.face_vertices, full.face_vertex_offsets[p], full.face_vertex_offsets[p + 1]);
      ASSERT_EQ(sv.size(), fv.size()) << cell;
      if (!asked) continue;
      for (std::size_t v = 0; v < sv.size(); ++v) {
        const auto a = static_cast<std::size_t>(sv[v]), b = static_cast<std::size_t>(fv[v]);
        for (std::size_t e = 0; e <= D; ++e)
          ASSERT_EQ(some.vertex_keys[a * (D + 1) + e], full.vertex_keys[b * (D + 1) + e]) << cell;
        for (std::size_t e = 0; e < D; ++e)
          ASSERT_TRUE(same_bits(some.vertices[a * D + e], full.vertices[b * D + e]))
              << cell << ": vertex " << b << " at " << full.vertices[b * D + e] << " vs " << some.vertices[a * D + e];
      }
    }
  }

  // Flowers, or the same refusal (an asked point without a cell).
  for (const std::int32_t id : ids) {
    tessera::Flower a, b;
    const std::string ea = flowers_or_error(full, pts, id, a), eb = flowers_or_error(some, pts, id, b);
    EXPECT_EQ(ea, eb) << what << ", point " << id;
    if (ea.empty() && eb.empty()) expect_same_flower(a, b, what + ", flower of " + std::to_string(id));
  }
}

/// compare_only; returns the cells of `ids`.
tessera::Cells expect_only_matches(const std::vector<double>& pts, int dim, const std::vector<std::int32_t>& labels,
                                   const tessera::VoronoiOptions& opt, const std::vector<std::int32_t>& ids,
                                   const std::string& what, bool same_layer = true) {
  tessera::Cells some;
  compare_only(some, pts, dim, labels, opt, ids, what, same_layer);
  return some;
}

TEST(FlowerOnly, UniformRandom) {
  for (int dim : {2, 3}) {
    const std::size_t n = dim == 3 ? 4000 : 6000;
    const auto pts = random_points(n, dim, 8601 + dim);
    for (int threads : {1, 2}) {
      const std::string what = std::to_string(dim) + "D uniform, " + std::to_string(threads) + " threads";
      const auto some = expect_only_matches(pts, dim, {}, options(dim, std::nullopt, threads),
                                            {5, 0, static_cast<std::int32_t>(n - 1), 1234, 5}, what);
      EXPECT_LT(some.n_cells(), 120u) << what;  // 4 cells and their neighbours
      EXPECT_FALSE(some.from_insertion) << what;
    }
    // Explicit bounds, the points set aside outside them.
    auto wide = pts;
    wide[0] = 2.5;
    wide[dim * 7 + 1] = -1;
    auto opt = options(dim, unit_box());
    opt.ignore_outside_points = true;
    const auto some = expect_only_matches(wide, dim, {}, opt, {0, 7, 8, 9}, std::to_string(dim) + "D bounds");
    EXPECT_EQ(some.ignored_outside_bounds, (std::vector<std::int32_t>{0, 7}));
  }
}

// Exact ties: every vertex of a lattice cell is met by more than D+1
// points, which the symbolic perturbation orders by id.
TEST(FlowerOnly, ExactLattice) {
  const auto cube = grid_points(9, 3, 0.1);
  expect_only_matches(cube, 3, {}, options(3), {0, 4 * 81 + 4 * 9 + 4, 728, 100}, "3D lattice");
  const auto square = grid_points(30, 2);
  expect_only_matches(square, 2, {}, options(2), {0, 15 * 30 + 15, 899, 31}, "2D lattice");
}

// Exact duplicates: the lowest id owns the cell; asking for a copy is
// refused with its owner named, as from all cells.
TEST(FlowerOnly, Duplicates) {
  for (int dim : {2, 3}) {
    auto pts = random_points(2000, dim, 8611 + dim);
    for (int a = 0; a < dim; ++a) {
      pts[dim * 9 + a] = pts[dim * 4 + a];      // 9 duplicates 4
      pts[dim * 300 + a] = pts[dim * 1500 + a];  // 1500 duplicates 300 (asked for: the copy only)
    }
    const std::string what = std::to_string(dim) + "D duplicates";
    expect_only_matches(pts, dim, {}, options(dim), {4, 9}, what + ", owner and copy");
    const auto some = expect_only_matches(pts, dim, {}, options(dim), {1500}, what + ", copy alone");
    EXPECT_EQ(some.cell_of[1500], -1);
    for (std::int32_t id : {9, 1500}) {
      tessera::Flower f;
      EXPECT_NE(flowers_or_error(some, pts, id, f).find("duplicates point"), std::string::npos) << what;
    }
  }
}

// Labels: outside points clip but own no cell; an asked point with label <
// 0 is refused as from all cells. Also a copy (label >= 0) of an outside
// point, which owns the place.
TEST(FlowerOnly, Labels) {
  for (int dim : {2, 3}) {
    auto pts = random_points(3000, dim, 8621 + dim);
    std::vector<std::int32_t> labels(3000);
    std::mt19937 rng(86);
    for (auto& l : labels) l = static_cast<std::int32_t>(rng() % 4) - 1;  // -1..2
    labels[10] = -1;
    labels[11] = 2;
    labels[12] = 0;
    for (int a = 0; a < dim; ++a) pts[dim * 20 + a] = pts[dim * 13 + a];  // 20 (inside) copies 13 (outside)
    labels[13] = -1;
    labels[20] = 1;
    const std::string what = std::to_string(dim) + "D labels";
    expect_only_matches(pts, dim, labels, options(dim), {11, 12, 10, 20}, what);
    tessera::Flower f;
    const auto some = expect_only_matches(pts, dim, labels, options(dim), {10}, what + ", outside alone");
    EXPECT_NE(flowers_or_error(some, pts, 10, f).find("outside point"), std::string::npos) << what;
  }
}

// Periodic boxes, orthogonal and triclinic, 2D and 3D: the cells keep their
// images' shifts.
TEST(FlowerOnly, PeriodicBoxes) {
  for (int dim : {2, 3}) {
    const auto box = unit_box();
    const auto pts = random_points(3000, dim, 8631 + dim, box);
    for (int tilted : {0, 1}) {
      auto opt = options(dim, box);
      opt.periodic = {true, true, dim == 3};
      if (tilted) opt.tilt = {0.3, dim == 3 ? -0.2 : 0.0, dim == 3 ? 0.45 : 0.0};
      const std::string what = std::to_string(dim) + "D periodic" + (tilted ? ", tilted" : "");
      // A cell at the box's corner (its neighbours are images), one inside.
      std::int32_t corner = 0;
      double best = 1e9;
      for (std::int32_t i = 0; i < 3000; ++i) {
        double d = 0;
        for (int a = 0; a < dim; ++a) d += pts[i * dim + a] * pts[i * dim + a];
        if (d < best) best = d, corner = i;
      }
      expect_only_matches(pts, dim, {}, opt, {corner, 77}, what, false);
    }
    // Partly periodic: walls along the last axis.
    auto opt = options(dim, box);
    opt.periodic = {true, false, false};
    expect_only_matches(pts, dim, {}, opt, {3, 2999}, std::to_string(dim) + "D periodic along x", false);
  }
}

// Power cells: the same cells (flowers refuse them, with or without only);
// equal radii are ordinary cells, whose flowers are the same.
TEST(FlowerOnly, PowerCells) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(2500, dim, 8641 + dim);
    std::vector<double> radii(2500);
    std::mt19937 rng(8641);
    for (auto& r : radii) r = 0.002 + 0.02 * (rng() % 1000) / 1000.0;
    auto opt = options(dim);
    opt.radii = radii;
    const std::string what = std::to_string(dim) + "D power";
    const auto some = expect_only_matches(pts, dim, {}, opt, {0, 600, 2499}, what);
    EXPECT_TRUE(some.power);
    std::vector<double> equal(2500, 0.01);
    opt.radii = equal;
    expect_only_matches(pts, dim, {}, opt, {0, 600, 2499}, what + ", equal radii");
  }
}

// Points nearly on a sphere (a circle in 2D): the automatic method takes
// the insertion for all cells, and so for some.
TEST(FlowerOnly, InsertionPath) {
  for (int dim : {2, 3}) {
    std::mt19937_64 rng(8651);
    std::normal_distribution<double> g(0, 1);
    const std::size_t n = dim == 3 ? 6000 : 4000;
    std::vector<double> pts;
    for (std::size_t i = 0; i < n; ++i) {
      double v[3] = {g(rng), g(rng), dim == 3 ? g(rng) : 0.0}, s = 0;
      for (int a = 0; a < dim; ++a) s += v[a] * v[a];
      for (int a = 0; a < dim; ++a) pts.push_back(v[a] / std::sqrt(s));
    }
    const std::string what = std::to_string(dim) + "D sphere";
    const auto some = expect_only_matches(pts, dim, {}, options(dim), {1, 2000, static_cast<std::int32_t>(n - 1)}, what);
    EXPECT_TRUE(some.from_insertion) << what;
    auto opt = options(dim);
    opt.cell_method = tessera::CellMethod::insertion;
    expect_only_matches(random_points(2000, dim, 8661), dim, {}, opt, {1, 1999}, what + ", insertion asked");
  }
}

TEST(FlowerOnly, IdsThatAreNoPoint) {
  const auto pts = random_points(100, 3, 8671);
  auto opt = options(3);
  for (std::int32_t bad : {-1, 100}) {
    const std::vector<std::int32_t> ids{0, bad};
    opt.only = ids;
    EXPECT_THROW(tessera::voronoi(pts, 3, {}, opt), tessera::InputError) << bad;
  }
}

}  // namespace
