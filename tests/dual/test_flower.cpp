// Flowers: petals are the cell's vertices with their distance to the
// generator, petals are empty of input points (the Delaunay property), every
// clipping neighbour lies in the flower and in the circumflower, and the
// cell's faces come through unchanged.
#include <gtest/gtest.h>

#include <cmath>

#include "cells/helpers.hpp"
#include "tessera/flower.hpp"

namespace {

using namespace cells_test;

void check_flower(const tessera::Cells& c, const std::vector<double>& pts, const tessera::Flower& fl,
                  const std::string& what) {
  Failures fail(what);
  const int dim = c.dim;
  const std::size_t n = pts.size() / dim;
  const auto k = c.cell_of[fl.generator];
  ASSERT_GE(k, 0) << what;
  ASSERT_EQ(fl.petal_centres.size(), fl.n_petals() * dim) << what;
  ASSERT_EQ(fl.vertex_ids.size(), fl.n_petals()) << what;
  const V3 p = input_point(pts, dim, fl.generator);
  for (int a = 0; a < dim; ++a) EXPECT_EQ(fl.site[a], p[a]) << what;

  // Faces are the cell's faces, over the petals.
  ASSERT_EQ(fl.face_offsets.size(), std::size_t(c.cell_face_offsets[k + 1] - c.cell_face_offsets[k]) + 1) << what;
  for (std::size_t f = 0; f + 1 < fl.face_offsets.size(); ++f) {
    const auto cf = c.cell_face_offsets[k] + std::int64_t(f);
    if (fl.face_neighbor[f] != c.face_neighbor[cf]) fail.add("face ", f, " neighbour differs");
    std::vector<std::int32_t> mine;
    for (auto q = fl.face_offsets[f]; q < fl.face_offsets[f + 1]; ++q)
      mine.push_back(fl.vertex_ids[fl.face_vertices[q]]);
    if (mine != std::vector<std::int32_t>(c.face_vertices.begin() + c.face_vertex_offsets[cf],
                                          c.face_vertices.begin() + c.face_vertex_offsets[cf + 1]))
      fail.add("face ", f, " vertices differ");
  }
  EXPECT_EQ(fl.neighbors, neighbours_of(c, std::size_t(k))) << what;

  double r_max = 0;
  for (std::size_t v = 0; v < fl.n_petals(); ++v) {
    const V3 x = mesh_vertex(c, fl.vertex_ids[v]);
    for (int a = 0; a < dim; ++a)
      if (fl.petal_centres[v * dim + a] != x[a]) fail.add("petal ", v, " centre is not its vertex");
    const double r = fl.petal_radii[v];
    if (std::abs(r - norm(sub(x, p))) > 1e-12 * r) fail.add("petal ", v, " radius ", r, " is not |v - p|");
    r_max = std::max(r_max, r);
    // The petal is empty: no point strictly closer to its centre than the generator.
    for (std::size_t q = 0; q < n; ++q)
      if (norm(sub(x, input_point(pts, dim, std::int64_t(q)))) < r * (1 - 1e-9)) {
        fail.add("petal ", v, " of ", fl.generator, " contains point ", q);
        break;
      }
  }
  EXPECT_EQ(fl.circumflower_radius, 2 * r_max) << what;
  // Every neighbour that clipped the cell lies in the flower (inside or on a
  // petal: its bisector passes through that vertex) and so in the circumflower.
  for (auto j : fl.neighbors) {
    const V3 q = input_point(pts, dim, j);
    bool in_petal = false;
    for (std::size_t v = 0; v < fl.n_petals() && !in_petal; ++v)
      in_petal = norm(sub(q, mesh_vertex(c, fl.vertex_ids[v]))) <= fl.petal_radii[v] * (1 + 1e-9);
    if (!in_petal) fail.add("neighbour ", j, " is in no petal");
    if (!(norm(sub(q, p)) <= fl.circumflower_radius)) fail.add("neighbour ", j, " is outside the circumflower");
  }
}

TEST(Flower, PetalsCircumflowerAndNeighbours) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(800, dim, 501 + dim);
    const auto c = run(pts, dim);
    const std::vector<std::int32_t> ids{0, 17, 799, 17};
    const auto fl = tessera::flowers(c, pts, ids);
    ASSERT_EQ(fl.size(), ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) {
      EXPECT_EQ(fl[i].generator, ids[i]);
      EXPECT_EQ(fl[i].dim, dim);
      check_flower(c, pts, fl[i], std::to_string(dim) + "D flower of " + std::to_string(ids[i]));
    }
  }
  // A lattice cell: a unit cube whose 8 corners are petals of radius sqrt(3)/2.
  const auto lattice = grid_points(4, 3);
  const auto c = run(lattice, 3);
  const std::int32_t mid = 1 * 16 + 1 * 4 + 1;  // (1,1,1)
  const auto fl = tessera::flowers(c, lattice, {&mid, 1});
  check_flower(c, lattice, fl[0], "lattice");
  for (double r : fl[0].petal_radii) EXPECT_NEAR(r, std::sqrt(3.0) / 2, 1e-15);
  EXPECT_NEAR(fl[0].circumflower_radius, std::sqrt(3.0), 1e-15);
}

// Petal radii far from 1: |v - p| is taken with std::hypot where its
// squares leave double's range (beyond ~1e154 they were inf, below ~1e-154
// wrong or zero). Points scaled by a power of two give the same flower scaled.
TEST(Flower, RadiiAtExtremeScales) {
  for (int dim : {2, 3}) {
    const auto pts = random_points(300, dim, 811 + dim);
    const std::vector<std::int32_t> ids{0, 150, 299};
    const auto ref = tessera::flowers(run(pts, dim), pts, ids);
    for (int e : {-600, 600}) {
      std::vector<double> scaled(pts);
      for (double& x : scaled) x = std::ldexp(x, e);
      const auto fl = tessera::flowers(run(scaled, dim), scaled, ids);
      for (std::size_t i = 0; i < ids.size(); ++i) {
        const std::string what = std::to_string(dim) + "D flower of " + std::to_string(ids[i]) + " at 2^" +
                                 std::to_string(e);
        ASSERT_EQ(fl[i].n_petals(), ref[i].n_petals()) << what;
        for (std::size_t v = 0; v < fl[i].n_petals(); ++v)
          ASSERT_NEAR(std::ldexp(fl[i].petal_radii[v], -e), ref[i].petal_radii[v], 1e-12 * ref[i].petal_radii[v])
              << what << ", petal " << v;
        EXPECT_NEAR(std::ldexp(fl[i].circumflower_radius, -e), ref[i].circumflower_radius,
                    1e-12 * ref[i].circumflower_radius)
            << what;
      }
    }
  }
}

TEST(Flower, PointsWithoutCellsAreRejected) {
  auto pts = random_points(100, 3, 511);
  for (int a = 0; a < 3; ++a) pts[3 * 9 + a] = pts[3 * 4 + a];  // 9 duplicates 4
  std::vector<std::int32_t> labels(100, 0);
  labels[12] = -1;
  const auto c = run(pts, 3, std::nullopt, labels);
  auto fails_with = [&](std::int32_t id, const std::string& fragment) {
    try {
      tessera::flowers(c, pts, {&id, 1});
      ADD_FAILURE() << "point " << id << " accepted";
    } catch (const tessera::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  fails_with(-1, "does not exist");
  fails_with(100, "does not exist");
  fails_with(12, "outside point");
  fails_with(9, "duplicates point 4");
  EXPECT_THROW(tessera::flowers(c, std::vector<double>(30, 0.0), std::vector<std::int32_t>{0}), std::invalid_argument);
}

}  // namespace
