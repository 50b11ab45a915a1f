// VTK XML point sets (.vtp, .vtu) as inputs: pieces, value types, labels and
// scalars from point data, the text around VTK's values, and the errors.
// Files from VTK's own writers (every data mode and compressor) are read in
// tests/cli/test_cli.py; these are written by hand.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::read_point_scalars;
using tessera::io::read_points;
using tessera::io::ReadOptions;

namespace {

// Two pieces (2 and 1 points), ascii; the first piece's points are followed
// by an <InformationKey> inside their DataArray, as VTK writes for
// multi-component arrays.
const char* kTwoPieces = R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt32">
  <PolyData>
    <Piece NumberOfPoints="2" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="0">
      <PointData>
        <DataArray type="Float32" Name="temp" format="ascii">0.5 1.5</DataArray>
        <DataArray type="Int16" Name="RegionId" format="ascii">3 -1</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" Name="Points" NumberOfComponents="3" format="ascii">
          0 0.25 1  2 3 4
          <InformationKey name="L2_NORM_RANGE" location="vtkDataArray" length="2">
            <Value index="0">1</Value>
            <Value index="1">5</Value>
          </InformationKey>
        </DataArray>
      </Points>
    </Piece>
    <Piece NumberOfPoints="1">
      <PointData>
        <DataArray type="Float32" Name="temp" format="ascii">2.5</DataArray>
        <DataArray type="Int16" Name="RegionId" format="ascii">7</DataArray>
      </PointData>
      <Points>
        <DataArray type="Int32" NumberOfComponents="3" format="ascii">-1 -2 -3</DataArray>
      </Points>
    </Piece>
  </PolyData>
</VTKFile>
)";

}  // namespace

TEST(VtkPoints, PiecesLabelsAndScalars) {
  TempDir dir;
  const std::string p = dir.write("two.vtp", kTwoPieces);
  auto pc = read_points(p, labels("RegionId"));
  expect_cloud(pc, 3, {0, 0.25, 1, 2, 3, 4, -1, -2, -3}, {3, -1, 7});
  ReadOptions two;
  two.dim = 2;
  EXPECT_EQ(read_points(p, two).coords, (std::vector<double>{0, 0.25, 2, 3, -1, -2}));
  EXPECT_EQ(read_point_scalars(p, "temp"), (std::vector<double>{0.5, 1.5, 2.5}));
  // The same as an unstructured grid.
  std::string u = kTwoPieces;
  for (auto [from, to] : {std::pair<std::string, std::string>{"\"PolyData\"", "\"UnstructuredGrid\""},
                          {"<PolyData>", "<UnstructuredGrid>"},
                          {"</PolyData>", "</UnstructuredGrid>"}})
    u.replace(u.find(from), from.size(), to);
  EXPECT_EQ(read_points(dir.write("two.vtu", u)).coords, pc.coords);
}

TEST(VtkPoints, Errors) {
  TempDir dir;
  const std::string p = dir.write("two.vtp", kTwoPieces);
  auto msg = input_error([&] { read_points(p, labels("temp")); });
  EXPECT_NE(msg.find("floating-point"), std::string::npos) << msg;
  msg = input_error([&] { read_points(p, labels("Region")); });
  EXPECT_NE(msg.find("no point data array 'Region'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'RegionId'"), std::string::npos) << msg;  // lists the arrays
  // The file with one edit each, and what the error must say: an image is
  // not a point set; fewer values than the piece's points; two components;
  // a piece claiming far more points than its data, refused before
  // anything is sized by the claim (it ran out of memory).
  struct Edit {
    const char* file;
    std::string from, to;
    const char* says;
  };
  for (const Edit& e : {Edit{"img.vtp", "type=\"PolyData\"", "type=\"ImageData\"", "expected PolyData or UnstructuredGrid"},
                        Edit{"short.vtp", "-1 -2 -3", "-1 -2", "ascii data has 2 values, shorter than the 3"},
                        Edit{"comps.vtp", "NumberOfComponents=\"3\" format=\"ascii\">-1",
                             "NumberOfComponents=\"2\" format=\"ascii\">-1", "2 components, expected 3"},
                        Edit{"huge.vtp", "NumberOfPoints=\"2\"", "NumberOfPoints=\"999999999999\"", "shorter than"}}) {
    std::string t = kTwoPieces;
    const std::size_t at = t.find(e.from);
    ASSERT_NE(at, std::string::npos) << e.file;
    t.replace(at, e.from.size(), e.to);
    msg = input_error([&] { read_points(dir.write(e.file, t)); });
    EXPECT_NE(msg.find(e.says), std::string::npos) << e.file << ": " << msg;
  }
  // No points array in a piece that has points.
  std::string nopts = kTwoPieces;
  const std::size_t a = nopts.rfind("<Points>"), b = nopts.rfind("</Points>") + 9;
  nopts.erase(a, b - a);
  msg = input_error([&] { read_points(dir.write("nopts.vtp", nopts)); });
  EXPECT_NE(msg.find("no <Points> array"), std::string::npos) << msg;
}
