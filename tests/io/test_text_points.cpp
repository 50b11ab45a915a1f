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
  auto pc = read_points(dir.write("a.csv", "x,y,z,r,g,b\n1,2,3,9,9,9\n4,5,6,9,9,9\n"));
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
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
  auto pd = read_points(dir.write("a.csv", ",x,y,z\n0,1,2,3\n1,4,5,6\n"));
  EXPECT_EQ(pd.dim, 3);
  EXPECT_EQ(pd.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  auto id = read_points(dir.write("b.csv", "id,Z,\"Y\",X,mass\n7,3,2,1,9\n8,6,5,4,9\n"));
  EXPECT_EQ(id.dim, 3);
  EXPECT_EQ(id.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
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
  input_error([&] { read_points(dir.write("a.txt", "1\n2\n")); });
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
