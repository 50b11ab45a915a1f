// Legacy VTK files (.vtk) as point inputs, written by hand: what VTK's own
// writers do not produce (no LOOKUP_TABLE line, METADATA blocks, a dataset
// FIELD, colour scalars, lookup tables, a structured grid, big-endian binary
// written byte by byte) and the errors. Files from VTK's legacy writers (both
// modes, versions 4.2 and 5.1) are read in tests/cli/test_cli.py.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::read_point_scalars;
using tessera::io::read_points;
using tessera::io::ReadOptions;

namespace {

/// Big-endian bytes of `v` as type T (the legacy format's binary order).
template <class T>
std::string be(T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  std::string s;
  for (std::size_t k = sizeof(T); k-- > 0;) s += static_cast<char>(b[k]);
  return s;
}

const char* kAscii = R"(# vtk DataFile Version 5.1
written by hand
ASCII
DATASET POLYDATA
FIELD FieldData 2
TIME 1 1 double
4.5
CYCLE 1 1 int
7
POINTS 3 float
0 0.25 1  2 3 4
-1 -2 -3
METADATA
INFORMATION 1
NAME L2_NORM_RANGE LOCATION vtkDataArray
DATA 2 1 5

VERTICES 4 3
OFFSETS vtktypeint64
0 1 2 3
CONNECTIVITY vtktypeint64
0 1 2
CELL_DATA 3
SCALARS cellid int 1
LOOKUP_TABLE default
10 11 12
POINT_DATA 3
COLOR_SCALARS rgb 3
1 0 0 0 1 0 0 0 1
SCALARS temp float
0.5 1.5 2.5
LOOKUP_TABLE mytable 2
0 0 0 1 1 1 1 1
FIELD FieldData 2
RegionId 1 3 short
3 -1 7
METADATA
INFORMATION 0

vel 3 3 double
1 2 3 4 5 6 7 8 9
)";

}  // namespace

TEST(VtkLegacy, AsciiWithEverythingOnTheWay) {
  TempDir dir;
  const std::string p = dir.write("a.vtk", kAscii);
  ReadOptions o;
  o.labels = "RegionId";
  const auto pc = read_points(p, o);
  ASSERT_EQ(pc.n, 3u);
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.coords, (std::vector<double>{0, 0.25, 1, 2, 3, 4, -1, -2, -3}));
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{3, -1, 7}));
  EXPECT_EQ(read_point_scalars(p, "temp"), (std::vector<double>{0.5, 1.5, 2.5}));
  o.dim = 2;
  o.labels.clear();
  EXPECT_EQ(read_points(p, o).coords, (std::vector<double>{0, 0.25, 2, 3, -1, -2}));
  // Cell data and the dataset's field data are not point data.
  EXPECT_NE(input_error([&] { read_point_scalars(p, "cellid"); }).find("no point data array 'cellid'"),
            std::string::npos);
  EXPECT_NE(input_error([&] { read_point_scalars(p, "TIME"); }).find("(arrays: 'rgb', 'temp', 'RegionId', 'vel')"),
            std::string::npos);
  EXPECT_NE(input_error([&] { read_point_scalars(p, "vel"); }).find("'vel' has 3 components, expected 1"),
            std::string::npos);
  ReadOptions f;
  f.labels = "temp";
  EXPECT_NE(input_error([&] { read_points(p, f); }).find("holds floating-point values"), std::string::npos);
}

TEST(VtkLegacy, BinaryBigEndianAndAStructuredGrid) {
  TempDir dir;
  std::string s = "# vtk DataFile Version 3.0\nsg\nBINARY\nDATASET STRUCTURED_GRID\nDIMENSIONS 2 1 1\n"
                  "POINTS 2 double\n";
  for (const double v : {0.5, -1.25, 3.0, 1e-300, 2.0, -0.0}) s += be(v);
  s += "\nPOINT_DATA 2\nSCALARS label int 1\nLOOKUP_TABLE default\n" + be<std::int32_t>(-5) + be<std::int32_t>(70000) +
       "\nSCALARS flag bit\nLOOKUP_TABLE default\n" + std::string(1, '\x80') +
       "\nSCALARS u unsigned_short\nLOOKUP_TABLE default\n" + be<std::uint16_t>(65535) + be<std::uint16_t>(1) +
       "\nSCALARS c char\nLOOKUP_TABLE default\n" + std::string("\xff\x02", 2) + "\n";
  const std::string p = dir.write("b.vtk", s);
  ReadOptions o;
  o.labels = "label";
  const auto pc = read_points(p, o);
  ASSERT_EQ(pc.n, 2u);
  EXPECT_EQ(pc.coords, (std::vector<double>{0.5, -1.25, 3.0, 1e-300, 2.0, -0.0}));
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{-5, 70000}));
  EXPECT_EQ(read_point_scalars(p, "flag"), (std::vector<double>{1, 0}));
  EXPECT_EQ(read_point_scalars(p, "u"), (std::vector<double>{65535, 1}));
  EXPECT_EQ(read_point_scalars(p, "c"), (std::vector<double>{-1, 2}));
}

// ASCII floats are rounded to float as VTK's reader and the binary twin hold
// them; an integer array's text must be a whole number of its type (2.7
// became label 2, 300 an unsigned_char).
TEST(VtkLegacy, AsciiFloatsAndLabelsAsStored) {
  TempDir dir;
  const std::string p = dir.write("f.vtk", "# vtk DataFile Version 3.0\nf\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n"
                                           "0.1 0.2 0.3 1 2 3\nPOINT_DATA 2\nSCALARS d double\n0.1 0.2\n"
                                           "SCALARS i int\n1 2.7\n");
  const auto pc = read_points(p);
  EXPECT_EQ(pc.coords[0], static_cast<double>(0.1f));
  EXPECT_EQ(read_point_scalars(p, "d"), (std::vector<double>{0.1, 0.2}));  // doubles kept
  ReadOptions o;
  o.labels = "i";
  EXPECT_NE(input_error([&] { read_points(p, o); }).find("'2.7' is not a value of its type (int)"), std::string::npos);
  const std::string q = dir.write("u.vtk", "# vtk DataFile Version 3.0\nu\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n"
                                           "0 0 0 1 1 1\nPOINT_DATA 2\nSCALARS c unsigned_char\n+7 300\n");
  EXPECT_NE(input_error([&] { read_point_scalars(q, "c"); }).find("'300' is not a value of its type (unsigned_char)"),
            std::string::npos);
}

// Arrays sharing a name: the last is read, as VTK's legacy readers keep it
// (each replaces the one before in the point data), SCALARS or FIELD.
TEST(VtkLegacy, LastOfArraysSharingAName) {
  TempDir dir;
  const std::string p = dir.write("s.vtk", "# vtk DataFile Version 3.0\ns\nASCII\nDATASET POLYDATA\nPOINTS 2 float\n"
                                           "0 0 0 1 1 1\nPOINT_DATA 2\nSCALARS t int\n1 2\nSCALARS t int\n3 4\n"
                                           "FIELD more 1\nt 1 2 int\n5 6\n");
  EXPECT_EQ(read_point_scalars(p, "t"), (std::vector<double>{5, 6}));
  ReadOptions o;
  o.labels = "t";
  EXPECT_EQ(read_points(p, o).labels, (std::vector<std::int32_t>{5, 6}));
}

TEST(VtkLegacy, Errors) {
  TempDir dir;
  const std::string head = "# vtk DataFile Version 3.0\nx\nASCII\n";
  auto error = [&](const std::string& body) { return input_error([&] { read_points(dir.write("e.vtk", body)); }); };
  auto expect = [&](const std::string& body, const std::string& fragment) {
    const std::string msg = error(body);
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
    EXPECT_NE(msg.find("e.vtk"), std::string::npos) << msg;
  };
  expect("# vtk DataFile\nx\nASCII\n", "not a legacy VTK file");
  expect("# vtk DataFile Version 3.0\nx\n", "ends within its first three lines");
  expect("# vtk DataFile Version 3.0\nx\nTEXT\n", "line 3 must be ASCII or BINARY");
  expect(head + "DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\n", "a legacy VTK image (STRUCTURED_POINTS)");
  expect(head + "DATASET RECTILINEAR_GRID\n", "DATASET 'RECTILINEAR_GRID' is not supported");
  expect(head + "DATASET POLYDATA\n", "without POINTS");
  expect(head + "DATASET POLYDATA\nPOINTS 2 float\n0 0 0 1 1\n", "POINTS: the file ends after 5 of 6 values");
  expect(head + "DATASET POLYDATA\nPOINTS 2 quad\n0 0 0 1 1 1\n", "unknown data type 'quad'");
  expect(head + "DATASET POLYDATA\nPOINTS -2 float\n", "expected a count, got '-2'");
  expect(head + "DATASET POLYDATA\nPOINTS 99999999999 float\n0 0 0\n", "the file ends before its");
  expect(head + "DATASET POLYDATA\nPOINTS 1 float\n0 0 x\n", "'x' is not a number");
  expect(head + "DATASET POLYDATA\nPOINTS 1 float\n0 0 0\nWHATEVER 3\n", "unexpected keyword 'whatever'");
  expect(head + "DATASET POLYDATA\nPOINTS 1 float\n0 0 0\nPOINT_DATA 2\n", "POINT_DATA has 2 values for 1 points");
  // String arrays are stepped over, and are no numbers.
  const std::string strings = dir.write("s.vtk", head + "DATASET POLYDATA\nPOINTS 1 float\n0 0 0\nPOINT_DATA 1\n"
                                                       "FIELD f 2\nname 1 1 string\nabc def\nn 1 1 int\n7\n");
  EXPECT_EQ(read_point_scalars(strings, "n"), (std::vector<double>{7}));
  EXPECT_NE(input_error([&] { read_point_scalars(strings, "name"); }).find("'name' holds strings, not numbers"),
            std::string::npos);
  expect(head + "DATASET POLYDATA\nPOINTS 1 float\n0 0 0\nPOINT_DATA 1\nGLYPHS g float\n1\n", "unknown attribute");
  // Binary data shorter than its count says, refused before it is sized.
  expect("# vtk DataFile Version 3.0\nx\nBINARY\nDATASET POLYDATA\nPOINTS 99999999 float\n" + std::string(12, '\0'),
         "(1199999988 bytes, 12 left)");
}
