// read_points dispatch and the checks common to all formats.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "io/io_test_util.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::read_points;
using tessera::io::ReadOptions;

TEST(ReadPoints, UnknownExtension) {
  TempDir dir;
  const std::string p = dir.write("points.foo", "1,2,3\n");
  auto msg = input_error([&] { read_points(p); });
  EXPECT_EQ(msg, p + ": unknown input extension '.foo' (expected .npy, .csv, .xyz, .txt, .ply, .vtp, .vtu, .vtk, .pcd, .las, .dump, .lammpstrj)");
}

TEST(ReadPoints, MissingFile) {
  TempDir dir;
  for (const char* name : {"nope.csv", "nope.npy", "nope.ply", "nope.vtp"}) {
    const std::string p = dir.file(name);
    auto msg = input_error([&] { read_points(p); });
    EXPECT_EQ(msg, "cannot open " + p + ": No such file or directory");
  }
}

TEST(ReadPoints, DirectoryIsNotAFile) {
  TempDir dir;
  fs::create_directory(dir.path() / "d.csv");
  auto msg = input_error([&] { read_points(dir.file("d.csv")); });
  EXPECT_NE(msg.find("cannot open"), std::string::npos) << msg;
}

TEST(ReadPoints, BadDimOption) {
  TempDir dir;
  ReadOptions opt;
  opt.dim = 4;
  input_error([&] { read_points(dir.write("a.csv", "1,2,3\n"), opt); });
}

TEST(ReadPoints, LabelsFromNpy) {
  TempDir dir;
  const std::string pts = dir.write("p.csv", "1,2,3\n4,5,6\n7,8,9\n");
  ReadOptions opt;
  opt.labels = dir.write("l.NPY", make_npy("<i8", "(3,)", raw_bytes(std::vector<std::int64_t>{0, -1, 4})));
  auto pc = read_points(pts, opt);
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{0, -1, 4}));
}

TEST(ReadPoints, LabelsLengthMismatch) {
  TempDir dir;
  const std::string pts = dir.write("p.csv", "1,2,3\n4,5,6\n7,8,9\n");
  ReadOptions opt;
  opt.labels = dir.write("l.npy", make_npy("<i4", "(2,)", raw_bytes(std::vector<std::int32_t>{1, 2})));
  auto msg = input_error([&] { read_points(pts, opt); });
  EXPECT_EQ(msg, opt.labels + ": labels: 2 values for 3 points");
}

TEST(ReadPoints, LabelsFileMissing) {
  TempDir dir;
  const std::string pts = dir.write("p.csv", "1,2,3\n");
  ReadOptions opt;
  opt.labels = dir.file("missing.npy");
  auto msg = input_error([&] { read_points(pts, opt); });
  EXPECT_EQ(msg, "cannot open " + opt.labels + ": No such file or directory");
}

TEST(ReadPoints, NpyPointsWithNamedLabelsRejected) {
  TempDir dir;
  const std::vector<double> d{1, 2, 3};
  const std::string p = dir.write("p.npy", make_npy("<f8", "(1, 3)", raw_bytes(d)));
  ReadOptions opt;
  opt.labels = "region";
  input_error([&] { read_points(p, opt); });
}

TEST(ReadPoints, NonFiniteInNpyNamesRow) {
  TempDir dir;
  const std::vector<double> d{1, 2, 3, 4, 5, std::numeric_limits<double>::infinity()};
  auto msg = input_error([&] { read_points(dir.write("p.npy", make_npy("<f8", "(2, 3)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("row 1"), std::string::npos) << msg;
}

// Error messages quote file contents, which may be any bytes: one printable
// line of valid UTF-8 (Python could not decode raw bytes and showed an
// empty message; the terminal got them raw).
TEST(ReadPoints, ErrorMessagesArePrintableUtf8) {
  using tessera::one_printable_line;
  EXPECT_EQ(one_printable_line("plain"), "plain");
  EXPECT_EQ(one_printable_line("two\nlines\r\tand tab"), "two lines  and tab");
  EXPECT_EQ(one_printable_line(std::string_view("nul\0here\x7f", 9)), "nul?here?");
  EXPECT_EQ(one_printable_line("donn\xc3\xa9" "es \xe2\x82\xac \xf0\x9f\x98\x80"), "donn\xc3\xa9" "es \xe2\x82\xac \xf0\x9f\x98\x80");
  EXPECT_EQ(one_printable_line("fo\xffr \xc3 \xe0\x80\x80 \xed\xa0\x80 \xf5\x80\x80\x80 \x80"), "fo?r ? ??? ??? ???? ?");
  TempDir dir;
  std::string header = make_npy("<f8", "(1, 3)", std::string(24, '\0'));
  const std::size_t at = header.find("fortran_order");
  ASSERT_NE(at, std::string::npos);
  header[at + 2] = '\xff';
  header[at + 3] = '\0';
  const std::string msg = input_error([&] { read_points(dir.write("bad.npy", header)); });
  EXPECT_NE(msg.find("unexpected key 'fo??ran_order'"), std::string::npos) << msg;
  EXPECT_EQ(one_printable_line(msg), msg);
}
