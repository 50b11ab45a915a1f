// Cell tables (.csv/.npy) and the CSR neighbour array, from hand-made Cells;
// the triangulation writer's check of its points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/tables.hpp"
#include "tessera/io/vtk_simplices.hpp"

using namespace tessera_test;

namespace {

/// Three 3D cells for generators 0, 2, 5 (generator 1 has no cell).
tessera::Cells make_cells3() {
  tessera::Cells c;
  c.dim = 3;
  c.n_points = 6;
  c.generator = {0, 2, 5};
  c.region = {0, 1, 1};
  c.volume = {0.1, 1.0 / 3.0, 0.25};
  c.centroid = {0.5, 0.25, 0.125, 1, 2, 3, -1.5, 0, 1e-20};
  c.num_faces = {6, 7, 5};
  c.neighbor_offsets = {0, 2, 3, 4};
  c.neighbors = {2, 5, 0, 0};
  c.cell_of = {0, -1, 1, -1, -1, 2};
  return c;
}

tessera::Cells make_cells2() {
  tessera::Cells c;
  c.dim = 2;
  c.n_points = 2;
  c.generator = {0, 1};
  c.region = {3, 4};
  c.volume = {0.5, 0.5};
  c.centroid = {0.25, 0.5, 0.75, 0.5};
  c.num_faces = {4, 4};
  c.neighbor_offsets = {0, 1, 2};
  c.neighbors = {1, 0};
  c.cell_of = {0, 1};
  return c;
}

std::vector<std::string> lines_of(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

}  // namespace

TEST(Tables, Csv3D) {
  TempDir dir;
  const std::string p = dir.file("cells.csv");
  tessera::io::write_cell_table(p, make_cells3());
  auto lines = lines_of(read_all(p));
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "id,region,volume,cx,cy,cz,faces,neighbors");
  EXPECT_EQ(lines[1], "0,0,0.1,0.5,0.25,0.125,6,2");
  EXPECT_EQ(lines[2], "2,1,0.3333333333333333,1,2,3,7,1");
  EXPECT_EQ(lines[3], "5,1,0.25,-1.5,0,1e-20,5,1");
  // 1/3 round-trips exactly.
  EXPECT_EQ(std::stod("0.3333333333333333"), 1.0 / 3.0);
}

TEST(Tables, Csv2D) {
  TempDir dir;
  const std::string p = dir.file("cells.CSV");
  tessera::io::write_cell_table(p, make_cells2());
  auto lines = lines_of(read_all(p));
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "id,region,area,cx,cy,edges,neighbors");
  EXPECT_EQ(lines[1], "0,3,0.5,0.25,0.5,4,1");
}

TEST(Tables, Npy3D) {
  TempDir dir;
  const std::string p = dir.file("cells.npy");
  tessera::io::write_cell_table(p, make_cells3());
  auto a = tessera::io::read_npy_double(p);
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{3, 8}));
  EXPECT_EQ(a.kind, 'f');
  const std::vector<double> row1{2, 1, 1.0 / 3.0, 1, 2, 3, 7, 1};
  EXPECT_EQ(std::vector<double>(a.as_double.begin() + 8, a.as_double.begin() + 16), row1);
}

TEST(Tables, Npy2D) {
  TempDir dir;
  const std::string p = dir.file("cells.npy");
  tessera::io::write_cell_table(p, make_cells2());
  auto a = tessera::io::read_npy_double(p);
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 7}));
  EXPECT_EQ(a.as_double, (std::vector<double>{0, 3, 0.5, 0.25, 0.5, 4, 1, 1, 4, 0.5, 0.75, 0.5, 4, 1}));
}

TEST(Tables, NeighborsNpyLayout) {
  TempDir dir;
  const std::string p = dir.file("nb.npy");
  tessera::io::write_neighbors_npy(p, make_cells3());
  auto a = tessera::io::read_npy_int(p);
  EXPECT_EQ(a.kind, 'i');
  EXPECT_EQ(a.item_size, 8);
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{1 + 4 + 4}));
  // [n, offsets (n+1), ids...]
  EXPECT_EQ(a.as_int, (std::vector<std::int64_t>{3, 0, 2, 3, 4, 2, 5, 0, 0}));
  // The documented slicing recipe.
  const std::int64_t n = a.as_int[0];
  auto off = [&](std::int64_t c) { return a.as_int[static_cast<std::size_t>(1 + c)]; };
  const std::size_t ids = static_cast<std::size_t>(n + 2);
  EXPECT_EQ(a.as_int[ids + static_cast<std::size_t>(off(0))], 2);
  EXPECT_EQ(off(1) - off(0), 2);
}

TEST(Tables, EmptyCells) {
  TempDir dir;
  tessera::Cells c;
  tessera::io::write_cell_table(dir.file("e.csv"), c);
  EXPECT_EQ(read_all(dir.file("e.csv")), "id,region,volume,cx,cy,cz,faces,neighbors\n");
  tessera::io::write_neighbors_npy(dir.file("e.npy"), c);
  EXPECT_EQ(tessera::io::read_npy_int(dir.file("e.npy")).as_int, (std::vector<std::int64_t>{0, 0}));
}

TEST(Tables, BadExtensionAndUnwritable) {
  TempDir dir;
  const std::string p = dir.file("cells.txt");
  auto msg = input_error([&] { tessera::io::write_cell_table(p, make_cells3()); });
  EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
  EXPECT_NE(msg.find(".csv or .npy"), std::string::npos) << msg;
  const std::string q = (dir.path() / "missing" / "cells.csv").string();
  msg = input_error([&] { tessera::io::write_cell_table(q, make_cells3()); });
  EXPECT_EQ(msg.rfind("cannot write " + q, 0), 0u) << msg;
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Tables, InconsistentCellsIsAProgrammingError) {
  TempDir dir;
  auto c = make_cells3();
  c.volume.pop_back();
  EXPECT_THROW(tessera::io::write_cell_table(dir.file("x.csv"), c), std::invalid_argument);
}

// The triangulation's writer reads its points by the rows' ids: points of
// another input (too few) are refused, not read past their end, and nothing
// is written.
TEST(SimplicesVtk, PointsMustBeTheTriangulations) {
  TempDir dir;
  tessera::Delaunay dt;
  dt.dim = 2;
  dt.n_points = 4;
  dt.simplices = {0, 1, 2, 1, 3, 2};
  const std::vector<double> points = {0, 0, 1, 0, 0, 1, 1, 1};
  const std::string path = dir.file("t.vtu");
  for (const std::size_t n : {0, 2, 6, 10}) {
    const std::span<const double> some(points.data(), std::min(n, points.size()));
    const std::vector<double> more(n, 0.5);
    const std::string msg = input_error([&] { tessera::io::write_simplices_vtk(path, dt, n > 8 ? more : some); });
    EXPECT_NE(msg.find("coordinates for the 4 points of a 2D triangulation"), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(path));
  }
  tessera::io::write_simplices_vtk(path, dt, points);
  EXPECT_TRUE(fs::exists(path));
}
