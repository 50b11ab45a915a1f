// PCD point files (the Point Cloud Library's format) in their three
// encodings, labels and scalars from fields, and the errors.
#include <gtest/gtest.h>
#include <lzf.h>

#include <cmath>
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

// Three points with PCL's PointXYZL-like layout plus a padding field of
// COUNT 2 and a double intensity: x y z (float32), pad (2 x uint8),
// intensity (float64), label (uint32).
const float kX[3] = {0.5f, -1.25f, 3.0f}, kY[3] = {1.0f, 2.0f, -0.75f}, kZ[3] = {0.0f, 4.5f, 1.5f};
const double kI[3] = {0.1, 0.2, 0.3};
const std::uint32_t kL[3] = {7, 0, 4000000000u};  // the last does not fit in int32

std::string header(const char* data, std::size_t points = 3) {
  return "# .PCD v0.7 - Point Cloud Data file format\n"
         "VERSION 0.7\n"
         "FIELDS x y z _ intensity label\n"
         "SIZE 4 4 4 1 8 4\n"
         "TYPE F F F U F U\n"
         "COUNT 1 1 1 2 1 1\n"
         "WIDTH " + std::to_string(points) + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
         "POINTS " + std::to_string(points) + "\nDATA " + data + "\n";
}

template <class T>
void put(std::string& s, T v) {
  char b[sizeof v];
  std::memcpy(b, &v, sizeof v);
  s.append(b, sizeof v);
}

std::string ascii() {
  return header("ascii") + "0.5 1 0 0 0 0.1 7\n-1.25 2 4.5 9 9 0.2 0\n\n3 -0.75 1.5 1 2 0.3 4000000000\n";
}

std::string binary() {
  std::string s = header("binary");
  for (int i = 0; i < 3; ++i) {
    put(s, kX[i]);
    put(s, kY[i]);
    put(s, kZ[i]);
    put<std::uint16_t>(s, 0);
    put(s, kI[i]);
    put(s, kL[i]);
  }
  return s;
}

std::string compressed() {
  std::string plain;  // field by field
  for (float v : kX) put(plain, v);
  for (float v : kY) put(plain, v);
  for (float v : kZ) put(plain, v);
  plain.append(6, '\0');
  for (double v : kI) put(plain, v);
  for (std::uint32_t v : kL) put(plain, v);
  std::string out(plain.size() + 64, '\0');
  const unsigned c = lzf_compress(plain.data(), static_cast<unsigned>(plain.size()), out.data(), static_cast<unsigned>(out.size()));
  EXPECT_GT(c, 0u);
  std::string s = header("binary_compressed");
  put<std::uint32_t>(s, c);
  put<std::uint32_t>(s, static_cast<std::uint32_t>(plain.size()));
  return s + out.substr(0, c);
}

}  // namespace

TEST(Pcd, ThreeEncodings) {
  TempDir dir;
  const std::vector<double> xyz{0.5, 1, 0, -1.25, 2, 4.5, 3, -0.75, 1.5};
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"a.pcd", ascii()},
                                   {"b.pcd", binary()},
                                   {"c.pcd", compressed()}}) {
    const std::string p = dir.write(name, text);
    auto pc = read_points(p);
    EXPECT_EQ(pc.dim, 3) << name;
    EXPECT_EQ(pc.coords, xyz) << name;
    ReadOptions two;
    two.dim = 2;
    EXPECT_EQ(read_points(p, two).coords, (std::vector<double>{0.5, 1, -1.25, 2, 3, -0.75})) << name;
    EXPECT_EQ(read_point_scalars(p, "intensity"), (std::vector<double>{0.1, 0.2, 0.3})) << name;
    // The third label does not fit in int32: the error names it.
    auto msg = input_error([&] { read_points(p, labels("label")); });
    EXPECT_NE(msg.find("at point 2 does not fit in int32"), std::string::npos) << name << ": " << msg;
    msg = input_error([&] { read_points(p, labels("intensity")); });
    EXPECT_NE(msg.find("floating-point"), std::string::npos) << name << ": " << msg;
    msg = input_error([&] { read_points(p, labels("_")); });
    EXPECT_NE(msg.find("2 values per point"), std::string::npos) << name << ": " << msg;
  }
  // Labels that fit; a 2D cloud (no z); POINTS omitted (WIDTH x HEIGHT).
  const std::string lab = dir.write(
      "l.pcd", "FIELDS x y label\nSIZE 8 8 2\nTYPE F F I\nWIDTH 2\nHEIGHT 1\nDATA ascii\n1 2 -1\n3 4 5\n");
  auto pl = read_points(lab, labels("label"));
  EXPECT_EQ(pl.dim, 2);
  EXPECT_EQ(pl.coords, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_EQ(pl.labels, (std::vector<std::int32_t>{-1, 5}));
}

TEST(Pcd, Errors) {
  TempDir dir;
  auto error = [&](const std::string& name, const std::string& text, const std::string& fragment) {
    const std::string p = dir.write(name, text);
    const auto msg = input_error([&] { read_points(p); });
    EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
    EXPECT_NE(msg.find(fragment), std::string::npos) << name << ": " << msg;
  };
  // An organized cloud's missing return.
  error("nan.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nDATA ascii\n1 2 3\nnan nan nan\n",
        "point 1 has a NaN coordinate");
  {  // kept where the computation is to set them aside (--ignore-outside)
    tessera::io::ReadOptions keep;
    keep.keep_non_finite = true;
    const auto pc = read_points(dir.file("nan.pcd"), keep);
    ASSERT_EQ(pc.n, 2u);
    EXPECT_EQ(pc.coords[2], 3.0);
    EXPECT_TRUE(std::isnan(pc.coords[3]));
  }
  error("short.pcd", header("ascii") + "0.5 1 0 0 0 0.1 7\n", "ends after 1 of 3 points");
  error("cols.pcd", header("ascii") + "0.5 1 0 0 0 0.1\n", "has 6 values, expected 7");
  std::string b = binary();
  error("cut.pcd", b.substr(0, b.size() - 1), "PCD data ends");
  std::string c = compressed();
  error("ccut.pcd", c.substr(0, c.size() - 3), "compressed data ends");
  std::string corrupt = c;
  corrupt[corrupt.size() - 1] = static_cast<char>(0xff);
  corrupt[corrupt.size() - 6] = static_cast<char>(0xe0);
  corrupt[header("binary_compressed").size() + 8] = static_cast<char>(0xff);
  error("corrupt.pcd", corrupt, "corrupt");
  error("noxy.pcd", "FIELDS a b\nSIZE 4 4\nTYPE F F\nPOINTS 0\nDATA ascii\n", "need x and y");
  error("type.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F Q\nPOINTS 0\nDATA ascii\n", "unknown TYPE 'Q'");
  error("size.pcd", "FIELDS x y\nSIZE 4\nTYPE F F\nPOINTS 0\nDATA ascii\n", "SIZE gives 1 values for 2 fields");
  error("nodata.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\n", "no DATA line");
  // A header claiming far more points than its data: refused before
  // anything is sized by the claim (it ran out of memory).
  for (const char* enc : {"ascii", "binary", "binary_compressed"})
    error(std::string("huge_") + enc + ".pcd",
          std::string("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 999999999999\nDATA ") + enc + "\n1 2 3\n",
          "PCD");
  error("enc.pcd", "FIELDS x y\nSIZE 4 4\nTYPE F F\nPOINTS 1\nDATA zip\n", "unknown DATA 'zip'");
}
