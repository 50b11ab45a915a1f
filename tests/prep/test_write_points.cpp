// io::write_points round trips: .npy and .ply through io::read_points, .vtp
// through VTK's own reader (Debian python3-vtk9); io::read_point_scalars.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"

namespace {

using tessera_test::TempDir;

tessera::LabelledPoints sample(std::size_t n, int dim, bool labels, unsigned seed = 1) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-10, 10);
  tessera::LabelledPoints p;
  p.dim = dim;
  p.coords.resize(n * static_cast<std::size_t>(dim));
  for (double& v : p.coords) v = u(rng);
  if (labels)
    for (std::size_t i = 0; i < n; ++i) p.labels.push_back(static_cast<std::int32_t>(i % 5) - 2);
  return p;
}

TEST(PrepWritePoints, NpyRoundTripWithLabels) {
  TempDir dir;
  const auto p = sample(1000, 3, true);
  const std::string out = dir.file("pts.npy");
  const auto written = tessera::io::write_points(out, p);
  EXPECT_EQ(written, (std::vector<std::string>{out, dir.file("pts_labels.npy")}));
  tessera::io::ReadOptions ro;
  ro.labels = dir.file("pts_labels.npy");
  const auto pc = tessera::io::read_points(out, ro);
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.coords, p.coords);
  EXPECT_EQ(pc.labels, p.labels);
}

TEST(PrepWritePoints, Npy2DWithoutLabelsAndWithScalarsAndLabelsPath) {
  TempDir dir;
  const auto p = sample(10, 2, false);
  EXPECT_EQ(tessera::io::write_points(dir.file("a.npy"), p).size(), 1u);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"a.npy"}));
  EXPECT_EQ(tessera::io::read_points(dir.file("a.npy")).coords, p.coords);

  const auto q = sample(10, 2, true);
  std::vector<double> s(10);
  for (std::size_t i = 0; i < 10; ++i) s[i] = 0.5 * static_cast<double>(i);
  tessera::io::WritePointsOptions wo;
  wo.labels_path = dir.file("lab.npy");
  wo.scalars.push_back({"density", s});
  const auto written = tessera::io::write_points(dir.file("b.npy"), q, wo);
  EXPECT_EQ(written, (std::vector<std::string>{dir.file("b.npy"), dir.file("lab.npy"), dir.file("b_density.npy")}));
  EXPECT_EQ(tessera::io::read_labels_npy(dir.file("lab.npy")), q.labels);
  EXPECT_EQ(tessera::io::read_point_scalars(dir.file("b.npy"), dir.file("b_density.npy")), s);
}

TEST(PrepWritePoints, PlyRoundTrip) {
  TempDir dir;
  const auto p = sample(500, 3, true);
  std::vector<double> s(500);
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = 1.0 / static_cast<double>(i + 1);
  tessera::io::WritePointsOptions wo;
  wo.scalars.push_back({"w", s});
  const std::string out = dir.file("pts.ply");
  EXPECT_EQ(tessera::io::write_points(out, p, wo), std::vector<std::string>{out});
  tessera::io::ReadOptions ro;
  ro.labels = "label";
  const auto pc = tessera::io::read_points(out, ro);
  EXPECT_EQ(pc.coords, p.coords);
  EXPECT_EQ(pc.labels, p.labels);
  EXPECT_EQ(tessera::io::read_point_scalars(out, "w"), s);
  EXPECT_THROW(tessera::io::read_point_scalars(out, "nope"), tessera::InputError);
}

TEST(PrepWritePoints, Ply2DHasZeroZ) {
  TempDir dir;
  const auto p = sample(20, 2, false);
  const std::string out = dir.file("flat.ply");
  tessera::io::write_points(out, p);
  tessera::io::ReadOptions ro;
  ro.dim = 2;
  EXPECT_EQ(tessera::io::read_points(out, ro).coords, p.coords);
  const auto pc3 = tessera::io::read_points(out);
  ASSERT_EQ(pc3.dim, 3);
  for (std::size_t i = 0; i < 20; ++i) {
    EXPECT_EQ(pc3.coords[3 * i], p.coords[2 * i]);
    EXPECT_EQ(pc3.coords[3 * i + 2], 0.0);
  }
}

TEST(PrepWritePoints, ReadPointScalarsFromCsvColumn) {
  TempDir dir;
  const std::string csv = dir.write("s.csv", "x,y,value\n0,0,1.5\n1,0,nan\n0,1,-2\n");
  const auto s = tessera::io::read_point_scalars(csv, "value");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0], 1.5);
  EXPECT_TRUE(std::isnan(s[1]));
  EXPECT_EQ(s[2], -2);
  EXPECT_THROW(tessera::io::read_point_scalars(csv, "nope"), tessera::InputError);
  const std::string bad = dir.write("t.csv", "x,y,value\n0,0,abc\n");
  EXPECT_THROW(tessera::io::read_point_scalars(bad, "value"), tessera::InputError);
  const std::string nohead = dir.write("u.csv", "0,0,1\n");
  EXPECT_THROW(tessera::io::read_point_scalars(nohead, "value"), tessera::InputError);
}

TEST(PrepWritePoints, VtpReadByVtk) {
  const char* py = TESSERA_PYTHON;
  if (std::system((std::string(py) + " -c 'import vtk, numpy' >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << py << " with vtk and numpy not available";
  TempDir dir;
  for (int dim : {2, 3}) {
    const auto p = sample(300, dim, true, 7 + dim);
    std::vector<double> s(300);
    for (std::size_t i = 0; i < s.size(); ++i) s[i] = static_cast<double>(i) * 0.25;
    tessera::io::WritePointsOptions wo;
    wo.scalars.push_back({"s", s});
    const std::string vtp = dir.file("p" + std::to_string(dim) + ".vtp");
    tessera::io::write_points(vtp, p, wo);
    // The expectation, through the (already tested) .npy writer.
    const std::string ref = dir.file("r" + std::to_string(dim) + ".npy");
    tessera::io::write_points(ref, p);
    const std::string script = dir.write("check.py", R"PY(
import sys, numpy as np, vtk
from vtk.util.numpy_support import vtk_to_numpy
vtp, ref, dim = sys.argv[1], sys.argv[2], int(sys.argv[3])
r = vtk.vtkXMLPolyDataReader(); r.SetFileName(vtp); r.Update()
pd = r.GetOutput()
want = np.load(ref); labels = np.load(ref[:-4] + "_labels.npy")
n = want.shape[0]
assert pd.GetNumberOfPoints() == n, pd.GetNumberOfPoints()
assert pd.GetNumberOfVerts() == n and pd.GetNumberOfCells() == n
pts = vtk_to_numpy(pd.GetPoints().GetData())
assert np.array_equal(pts[:, :dim], want), "points"
if dim == 2: assert np.all(pts[:, 2] == 0)
conn = vtk_to_numpy(pd.GetVerts().GetConnectivityArray())
assert np.array_equal(conn, np.arange(n)), "verts"
lab = pd.GetPointData().GetArray("label")
assert lab.GetDataType() == vtk.VTK_INT, lab.GetDataType()
assert np.array_equal(vtk_to_numpy(lab), labels), "labels"
s = vtk_to_numpy(pd.GetPointData().GetArray("s"))
assert np.array_equal(s, np.arange(n) * 0.25), "scalars"
print("ok")
)PY");
    const std::string cmd = std::string(py) + " " + script + " " + vtp + " " + ref + " " + std::to_string(dim);
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
}

// A labelled output with zero points keeps its labels (an empty sidecar, the
// "label" property): an empty label array alone reads as "unlabelled", and
// sample-image's output of an image with nothing to sample lost them.
TEST(PrepWritePoints, ZeroLabelledPointsKeepTheirLabels) {
  TempDir dir;
  tessera::LabelledPoints none;
  none.dim = 3;
  tessera::io::WritePointsOptions wo;
  wo.labelled = true;
  EXPECT_EQ(tessera::io::write_points(dir.file("z.npy"), none, wo),
            (std::vector<std::string>{dir.file("z.npy"), dir.file("z_labels.npy")}));
  EXPECT_TRUE(tessera::io::read_labels_npy(dir.file("z_labels.npy")).empty());
  tessera::io::write_points(dir.file("z.ply"), none, wo);
  std::ifstream ply(dir.file("z.ply"), std::ios::binary);
  const std::string header((std::istreambuf_iterator<char>(ply)), std::istreambuf_iterator<char>());
  EXPECT_NE(header.find("property int label"), std::string::npos) << header;
  EXPECT_EQ(tessera::io::write_points(dir.file("u.npy"), none).size(), 1u);  // unlabelled: no sidecar
  // Asking for labels on points that have none is a caller's error.
  EXPECT_THROW(tessera::io::write_points(dir.file("x.ply"), sample(3, 3, false), wo), tessera::InputError);
}

TEST(PrepWritePoints, BadArgumentsWriteNothing) {
  TempDir dir;
  auto p = sample(10, 3, true);
  EXPECT_THROW(tessera::io::write_points(dir.file("x.xyz"), p), tessera::InputError);
  auto q = p;
  q.labels.pop_back();
  EXPECT_THROW(tessera::io::write_points(dir.file("x.npy"), q), tessera::InputError);
  EXPECT_THROW(tessera::io::write_points(dir.file("x.ply"), q), tessera::InputError);
  std::vector<double> s(9);
  tessera::io::WritePointsOptions wo;
  wo.scalars.push_back({"s", s});
  EXPECT_THROW(tessera::io::write_points(dir.file("x.vtp"), p, wo), tessera::InputError);  // wrong length
  s.resize(10);
  for (const char* name : {"", "a b", "label", "x", "a\"b"}) {
    wo.scalars = {{name, s}};
    EXPECT_THROW(tessera::io::write_points(dir.file("x.ply"), p, wo), tessera::InputError) << name;
  }
  wo.scalars = {{"s", s}, {"s", s}};
  EXPECT_THROW(tessera::io::write_points(dir.file("x.ply"), p, wo), tessera::InputError);
  // A sidecar that cannot be written stops the run before the points file.
  wo.scalars.clear();
  wo.labels_path = dir.file("missing/lab.npy");
  EXPECT_THROW(tessera::io::write_points(dir.file("x.npy"), p, wo), tessera::InputError);
  auto r = p;
  r.dim = 4;
  EXPECT_THROW(tessera::io::write_points(dir.file("x.npy"), r), tessera::InputError);
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
