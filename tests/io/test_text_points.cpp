// Text point files: separators, headers, comments, column/dimension rules,
// labels columns, and the line-numbered errors.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "io/io_test_util.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::read_points;
using tessera::io::ReadOptions;

TEST(TextPoints, CsvWithHeader) {
  TempDir dir;
  auto pc = read_points(dir.write("a.csv", "x,y,z\n1,2,3\n4.5,-5e-1,+6\n"));
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.n, 2u);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4.5, -0.5, 6}));
  EXPECT_TRUE(pc.labels.empty());
}

TEST(TextPoints, CsvWithoutHeaderCrlfAndSpaces) {
  TempDir dir;
  auto pc = read_points(dir.write("a.csv", "1, 2, 3\r\n 4 ,5,6\r\n"));
  EXPECT_EQ(pc.n, 2u);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
}

TEST(TextPoints, WhitespaceSeparated) {
  TempDir dir;
  auto pc = read_points(dir.write("a.xyz", "  1 2\t3\n4\t\t5   6  \n"));
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
}

TEST(TextPoints, SemicolonSeparated) {
  TempDir dir;
  auto pc = read_points(dir.write("a.txt", "1;2\n3;4\n"));
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4}));
}

TEST(TextPoints, CommentsAndBlankLinesSkipped) {
  TempDir dir;
  auto pc =
      read_points(dir.write("a.csv", "# points\n\n   \nx,y\n# mid comment\n1,2\n\n  # indented\n3,4\n"));
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.n, 2u);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4}));
}

TEST(TextPoints, TwoColumnsAre2D) {
  TempDir dir;
  auto pc = read_points(dir.write("a.txt", "0.5 0.25\n1 1\n"));
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.n, 2u);
}

TEST(TextPoints, ExtraColumnsIgnored) {
  TempDir dir;
  expect_cloud(read_points(dir.write("a.csv", "x,y,z,r,g,b\n1,2,3,9,9,9\n4,5,6,9,9,9\n")), 3, {1, 2, 3, 4, 5, 6});
  // Extra columns are not even parsed (the first line is data: all numeric).
  auto pc2 = read_points(dir.write("b.csv", "1,2,3,4\n4,5,6,more junk\n"));
  EXPECT_EQ(pc2.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  // A first line with a non-numeric field is a header, even among numbers.
  auto pc3 = read_points(dir.write("c.csv", "1,2,3,tag\n4,5,6,7\n"));
  EXPECT_EQ(pc3.coords, (std::vector<double>{4, 5, 6}));
}

// A header naming x and y (and z) picks those columns wherever they stand:
// pandas' to_csv() writes its index first, under an empty name, and tables
// often lead with an id. The first columns would have made those coordinates.
TEST(TextPoints, CoordinatesByHeaderName) {
  TempDir dir;
  expect_cloud(read_points(dir.write("a.csv", ",x,y,z\n0,1,2,3\n1,4,5,6\n")), 3, {1, 2, 3, 4, 5, 6});
  expect_cloud(read_points(dir.write("b.csv", "id,Z,\"Y\",X,mass\n7,3,2,1,9\n8,6,5,4,9\n")), 3, {1, 2, 3, 4, 5, 6});
  // x and y named, no z: 2D, however many columns.
  auto p2 = read_points(dir.write("c.txt", "id x y t\n7 1 2 0.5\n8 3 4 0.5\n"));
  EXPECT_EQ(p2.dim, 2);
  EXPECT_EQ(p2.coords, (std::vector<double>{1, 2, 3, 4}));
  // --dim 2 keeps x and y of named x, y, z.
  ReadOptions two;
  two.dim = 2;
  auto k2 = read_points(dir.write("d.csv", "id,x,y,z\n7,1,2,3\n"), two);
  EXPECT_EQ(k2.coords, (std::vector<double>{1, 2}));
  // With a labels column.
  auto pl = read_points(dir.write("e.csv", "id,region,y,x,z\n7,3,2,1,3\n8,-1,5,4,6\n"), labels("region"));
  EXPECT_EQ(pl.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(pl.labels, (std::vector<std::int32_t>{3, -1}));
  // Only one of x and y named: the first columns, as without names.
  auto px = read_points(dir.write("f.csv", "x,b,c\n1,2,3\n"));
  EXPECT_EQ(px.coords, (std::vector<double>{1, 2, 3}));
  // Errors: --dim 3 without a z column; a coordinate named twice; labels
  // from a coordinate column.
  ReadOptions three;
  three.dim = 3;
  auto msg = input_error([&] { read_points(dir.write("g.csv", "id,x,y,w\n1,2,3,4\n"), three); });
  EXPECT_NE(msg.find("no column is named 'z'"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("h.csv", "x,y,z,X\n1,2,3,4\n")); });
  EXPECT_NE(msg.find("'x' twice"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("i.csv", "x,y,z\n1,2,3\n"), labels("y")); });
  EXPECT_NE(msg.find("both a coordinate and the labels"), std::string::npos) << msg;
}

TEST(TextPoints, Dim2FromThreeColumns) {
  TempDir dir;
  ReadOptions opt;
  opt.dim = 2;
  auto pc = read_points(dir.write("a.csv", "1,2,3\n4,5,6\n"), opt);
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 4, 5}));
}

TEST(TextPoints, Dim3FromTwoColumnsRejected) {
  TempDir dir;
  ReadOptions opt;
  opt.dim = 3;
  const std::string p = dir.write("a.csv", "1,2\n4,5\n");
  auto msg = input_error([&] { read_points(p, opt); });
  EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
  EXPECT_NE(msg.find("2 coordinate column"), std::string::npos) << msg;
}

TEST(TextPoints, OneColumnRejected) {
  TempDir dir;
  for (const char* text : {"1\n2\n", "3\n5\n7\n"}) {  // the second is no Qhull header: single numbers follow
    const auto msg = input_error([&] { read_points(dir.write("a.txt", text)); });
    EXPECT_NE(msg.find("1 coordinate column"), std::string::npos) << msg;
  }
}

// Qhull's input format, as `rbox` writes it: dimension (and a comment),
// count, then the coordinates.
TEST(TextPoints, QhullFormat) {
  TempDir dir;
  auto pc = read_points(dir.write("r.txt", "3 rbox 4 D3\n4\n0 0 0\n1 0 0\n0 1 -2.5e-1\n0 0 1\n"));
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.n, 4u);
  EXPECT_EQ(pc.coords, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, -0.25, 0, 0, 1}));
  // Count first, then dimension (qhull takes the smaller as the dimension);
  // points in any layout.
  pc = read_points(dir.write("r2.txt", "3\n2 points\n1 2\n3 4 5\n6\n"));
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  // --dim 2 keeps x, y; a 4D file with --dim 3 its first three coordinates.
  ReadOptions two;
  two.dim = 2;
  pc = read_points(dir.write("r3.txt", "3\n4\n1 2 3\n4 5 6\n7 8 9\n0 0 0\n"), two);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 4, 5, 7, 8, 0, 0}));
  ReadOptions three;
  three.dim = 3;
  const std::string four = dir.write("r4.txt", "4 rbox 5 D4\n5\n1 2 3 4\n5 6 7 8\n0 0 0 0\n1 1 1 1\n2 2 2 2\n");
  pc = read_points(four, three);
  EXPECT_EQ(pc.n, 5u);
  EXPECT_EQ(std::vector<double>(pc.coords.begin(), pc.coords.begin() + 6), (std::vector<double>{1, 2, 3, 5, 6, 7}));

  auto msg = input_error([&] { read_points(four); });
  EXPECT_NE(msg.find("dimension 4"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("s.txt", "3\n4\n1 2 3\n4 5 6\n")); });
  EXPECT_NE(msg.find("declares 4 points of dimension 3 (12 numbers), the file holds 6"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("l.txt", "2\n2\n1 2\n3 4\n5 6\n")); });
  EXPECT_NE(msg.find("more numbers than the 2 points"), std::string::npos) << msg;
  EXPECT_NE(msg.find("line 5"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("g.txt", "2\n2\n1 2\n3 x\n")); });
  EXPECT_NE(msg.find("line 4: cannot parse 'x'"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("d.txt", "2\n3\n1 2\n3 4\n5 6\n"), three); });
  EXPECT_NE(msg.find("3D points asked"), std::string::npos) << msg;
  ReadOptions named;
  named.labels = "label";
  msg = input_error([&] { read_points(dir.write("n.txt", "2\n3\n1 2\n3 4\n5 6\n"), named); });
  EXPECT_NE(msg.find("names no columns"), std::string::npos) << msg;
  // "3 10" is a 2D point, not a header.
  pc = read_points(dir.write("p.txt", "3 10\n4 11\n"));
  EXPECT_EQ(pc.n, 2u);
}

TEST(TextPoints, NanRejectedWithLineNumber) {
  TempDir dir;
  const std::string p = dir.write("a.csv", "x,y,z\n1,2,3\nnan,2,3\n");
  auto msg = input_error([&] { read_points(p); });
  EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
  EXPECT_NE(msg.find("line 3"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("b.csv", "1,2,3\n1,inf,3\n")); });
  EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;
}

TEST(TextPoints, ShortRowRejectedWithLineNumber) {
  TempDir dir;
  auto msg = input_error([&] { read_points(dir.write("a.csv", "x,y,z\n1,2,3\n\n4,5\n")); });
  EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
}

TEST(TextPoints, GarbageRejectedWithLineNumber) {
  TempDir dir;
  auto msg = input_error([&] { read_points(dir.write("a.csv", "1,2,3\n4,abc,6\n")); });
  EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'abc'"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("b.csv", "1,2,3\n4,,6\n")); });
  EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;
}

TEST(TextPoints, EmptyFileRejected) {
  TempDir dir;
  auto msg = input_error([&] { read_points(dir.write("a.csv", "")); });
  EXPECT_NE(msg.find("no points"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("b.csv", "x,y,z\n# nothing\n")); });
  EXPECT_NE(msg.find("no points"), std::string::npos) << msg;
}

TEST(TextPoints, LabelsColumn) {
  TempDir dir;
  ReadOptions opt;
  opt.labels = "region";
  auto pc = read_points(dir.write("a.csv", "region,x,y,z\n3,1,2,3\n-1,4,5,6\n7.0,7,8,9\n"), opt);
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{3, -1, 7}));

  // Labels after the coordinates, whitespace-separated; two coordinates left -> 2D.
  auto pc2 = read_points(dir.write("b.txt", "x y label\n1 2 5\n3 4 6\n"), [] {
    ReadOptions o;
    o.labels = "label";
    return o;
  }());
  EXPECT_EQ(pc2.dim, 2);
  EXPECT_EQ(pc2.coords, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_EQ(pc2.labels, (std::vector<std::int32_t>{5, 6}));
}

TEST(TextPoints, LabelsColumnErrors) {
  TempDir dir;
  ReadOptions opt;
  opt.labels = "region";
  auto msg = input_error([&] { read_points(dir.write("a.csv", "x,y,z,reg\n1,2,3,4\n"), opt); });
  EXPECT_NE(msg.find("'reg'"), std::string::npos) << msg;  // lists the available columns
  msg = input_error([&] { read_points(dir.write("b.csv", "1,2,3,4\n"), opt); });
  EXPECT_NE(msg.find("header"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("c.csv", "x,y,z,region\n1,2,3,4\n1,2,3,2.5\n"), opt); });
  EXPECT_NE(msg.find("line 3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("2.5"), std::string::npos) << msg;
}

TEST(TextPoints, UppercaseExtension) {
  TempDir dir;
  auto pc = read_points(dir.write("A.CSV", "1,2\n"));
  EXPECT_EQ(pc.n, 1u);
}

TEST(TextPoints, MillionLines) {
  TempDir dir;
  std::string text = "x,y,z\n";
  const int n = 1000000;
  text.reserve(static_cast<std::size_t>(n) * 40);
  for (int i = 0; i < n; ++i) {
    text += std::to_string(i * 0.001);
    text += ',';
    text += std::to_string(i % 977 * 0.5);
    text += ",0.123456789012345\n";
  }
  const std::string p = dir.write("big.csv", text);
  const auto t0 = std::chrono::steady_clock::now();
  auto pc = read_points(p);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(pc.n, static_cast<std::size_t>(n));
  EXPECT_DOUBLE_EQ(pc.coords[3 * 999999 + 1], 999999 % 977 * 0.5);
  RecordProperty("parse_seconds", std::to_string(secs));
  // Generous bound: the target is well under a second in Release, but the
  // machine may be shared or the build unoptimised.
  EXPECT_LT(secs, 10.0);
}
