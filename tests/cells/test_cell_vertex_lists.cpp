// CellVertexLists (tessera/cell_vertex_lists.hpp): each cell's distinct
// vertices in order of first appearance in its faces, the .vtu writer's
// connectivity and Python's to_vtk() point lists. Checked against a plain
// scan of each cell's face stream, on a hand-made mesh and on cells of
// random, lattice, labelled and periodic inputs; listed in parallel, in any
// order of cells and more than once, the lists stay the same.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "helpers.hpp"
#include "tessera/cell_vertex_lists.hpp"

namespace {

using namespace cells_test;
using List = std::vector<std::int32_t>;

/// The brute force: the cell's face stream, each id kept at its first appearance.
List scanned(const tessera::Cells& c, std::size_t cell) {
  List out;
  for (std::int64_t k = c.face_vertex_offsets[c.cell_face_offsets[cell]];
       k < c.face_vertex_offsets[c.cell_face_offsets[cell + 1]]; ++k)
    if (std::find(out.begin(), out.end(), c.face_vertices[k]) == out.end()) out.push_back(c.face_vertices[k]);
  return out;
}

List listed(const tessera::CellVertexLists& lists, std::size_t cell) {
  List out;
  lists.for_each(cell, [&](std::int32_t v) { out.push_back(v); });
  return out;
}

/// Every cell's list against the scan; offsets against the counts; lists made
/// in parallel (cells backwards, on all cores, twice) against those made serially.
void check_lists(const tessera::Cells& c, const char* what) {
  SCOPED_TRACE(what);
  ASSERT_GT(c.n_cells(), 0u);
  const tessera::CellVertexLists lists(c);
  ASSERT_EQ(lists.n_cells(), c.n_cells());
  const std::vector<std::int64_t> off = lists.offsets();
  ASSERT_EQ(off.size(), c.n_cells() + 1);
  EXPECT_EQ(off[0], 0);
  std::vector<List> serial(c.n_cells());
  for (std::size_t ci = 0; ci < c.n_cells(); ++ci) {
    serial[ci] = listed(lists, ci);
    ASSERT_EQ(serial[ci], scanned(c, ci)) << "cell " << ci;
    ASSERT_EQ(off[ci + 1] - off[ci], static_cast<std::int64_t>(serial[ci].size())) << "cell " << ci;
    ASSERT_EQ(lists.count(ci), off[ci + 1] - off[ci]);
    ASSERT_EQ(listed(lists, ci), serial[ci]) << "cell " << ci << ", listed again";
  }
  tbb::task_arena arena;  // all cores
  for (int round = 0; round < 2; ++round) {
    std::vector<List> parallel(c.n_cells());
    arena.execute([&] {
      EXPECT_EQ(lists.offsets(), off);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, c.n_cells(), 16), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          const std::size_t ci = c.n_cells() - 1 - i;
          parallel[ci] = listed(lists, ci);
        }
      });
    });
    EXPECT_EQ(parallel, serial) << "round " << round;
  }
}

TEST(CellVertexLists, HandMadeMesh) {
  // Two unit cubes side by side along x, sharing the face x = 1: vertices
  // 0-7 the first cube's corners (bit 0 x, bit 1 y, bit 2 z), 8-11 the far
  // face's (x = 2). Faces listed in an order that makes the first appearance
  // differ from ascending ids.
  tessera::Cells c;
  c.dim = 3;
  c.generator = {0, 1};
  for (int v = 0; v < 12; ++v) {
    const double x = v < 8 ? (v & 1) : 2.0;
    const int b = v < 8 ? v : (v - 8) << 1;
    c.vertices.insert(c.vertices.end(), {x, double((b >> 1) & 1), double((b >> 2) & 1)});
  }
  // cube 0: x=1 face, z=1, x=0, z=0, y=0, y=1
  const std::vector<List> faces0 = {{1, 3, 7, 5}, {4, 5, 7, 6}, {0, 4, 6, 2},
                                    {0, 2, 3, 1}, {0, 1, 5, 4}, {2, 6, 7, 3}};
  // cube 1: x=2 face first, then the shared face (reversed), z=0, z=1, y=0, y=1
  const std::vector<List> faces1 = {{8, 9, 11, 10}, {1, 5, 7, 3}, {1, 3, 9, 8},
                                    {5, 10, 11, 7}, {1, 8, 10, 5}, {3, 7, 11, 9}};
  c.cell_face_offsets = {0};
  c.face_vertex_offsets = {0};
  for (const auto* faces : {&faces0, &faces1}) {
    for (const List& f : *faces) {
      c.face_vertices.insert(c.face_vertices.end(), f.begin(), f.end());
      c.face_vertex_offsets.push_back(static_cast<std::int64_t>(c.face_vertices.size()));
    }
    c.cell_face_offsets.push_back(static_cast<std::int64_t>(c.face_vertex_offsets.size() - 1));
  }
  const tessera::CellVertexLists lists(c);
  EXPECT_EQ(listed(lists, 0), (List{1, 3, 7, 5, 4, 6, 0, 2}));
  EXPECT_EQ(listed(lists, 1), (List{8, 9, 11, 10, 1, 5, 7, 3}));
  EXPECT_EQ(lists.offsets(), (std::vector<std::int64_t>{0, 8, 16}));
  check_lists(c, "two cubes");
}

TEST(CellVertexLists, Random3D) {
  const auto pts = random_points(3000, 3, 861);
  check_lists(run(pts, 3, unit_box(), {}, 2), "random 3000, 2 threads");
}

TEST(CellVertexLists, Lattice3D) {
  // Cubic lattice: every vertex is shared by 8 cells, and exact ties give
  // faces of area zero (repeated vertices across a cell's faces).
  const auto pts = grid_points(8, 3, 0.1, 0.05);
  check_lists(run(pts, 3, make_bounds({0, 0, 0}, {0.8, 0.8, 0.8})), "lattice 8^3");
}

TEST(CellVertexLists, Labels3D) {
  const auto pts = random_points(2000, 3, 862);
  std::vector<std::int32_t> labels(2000);
  for (std::size_t i = 0; i < labels.size(); ++i) labels[i] = i % 7 == 0 ? -1 : static_cast<std::int32_t>(i % 3);
  check_lists(run(pts, 3, unit_box(), labels), "labels, some outside");
}

TEST(CellVertexLists, Periodic3D) {
  const auto pts = random_points(1500, 3, 863);
  auto o = options(3, unit_box());
  o.periodic = {true, true, true};
  check_lists(tessera::voronoi(pts, 3, {}, o), "periodic xyz");
}

TEST(CellVertexLists, Polygons2D) {
  // In 2D a cell's faces are its edges (v0 v1, v1 v2, ...): its list is the polygon.
  const auto pts = random_points(2000, 2, 864);
  const tessera::Cells c = run(pts, 2, unit_box());
  check_lists(c, "random 2D");
  const tessera::CellVertexLists lists(c);
  for (std::size_t ci = 0; ci < c.n_cells(); ++ci) {
    List polygon;
    for (std::int64_t f = c.cell_face_offsets[ci]; f < c.cell_face_offsets[ci + 1]; ++f)
      polygon.push_back(c.face_vertices[c.face_vertex_offsets[f]]);
    ASSERT_EQ(listed(lists, ci), polygon) << "cell " << ci;
  }
}

}  // namespace
