// PLY reader: ascii and binary (both byte orders), label properties, other
// elements before/after the vertices, and the errors.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "io/io_test_util.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::read_points;
using tessera::io::ReadOptions;

namespace {

/// Append a scalar in little-endian (or big-endian) byte order.
template <class T>
void put(std::string& s, T v, bool big = false) {
  s += raw_bytes(std::vector<T>{v}, big);
}

const char* kAscii =
    "ply\n"
    "format ascii 1.0\n"
    "comment made by hand\n"
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property uchar region\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0 1\n"
    "1.5 0 0 2\n"
    "0 1 -0.25 1\n"
    "0 0 1 3\n"
    "3 0 1 2\n"
    "3 0 2 3\n";

}  // namespace

TEST(Ply, AsciiWithLabelsAndFaces) {
  TempDir dir;
  const std::string p = dir.write("a.ply", kAscii);
  auto pc = read_points(p, labels("region"));
  expect_cloud(pc, 3, {0, 0, 0, 1.5, 0, 0, 0, 1, -0.25, 0, 0, 1}, {1, 2, 1, 3});
  // Without labels, and forced 2D.
  auto plain = read_points(p);
  EXPECT_TRUE(plain.labels.empty());
  ReadOptions two;
  two.dim = 2;
  auto flat = read_points(p, two);
  EXPECT_EQ(flat.dim, 2);
  EXPECT_EQ(flat.coords, (std::vector<double>{0, 0, 1.5, 0, 0, 1, 0, 0}));
}

TEST(Ply, AsciiCrlfHeader) {
  TempDir dir;
  std::string text =
      "ply\r\nformat ascii 1.0\r\nelement vertex 1\r\nproperty double x\r\n"
      "property double y\r\nproperty double z\r\nend_header\r\n1 2 3\r\n";
  auto pc = read_points(dir.write("a.ply", text));
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3}));
}

TEST(Ply, BinaryWithLabelAndFace) {
  TempDir dir;
  for (const bool big : {false, true}) {
    std::string s = std::string("ply\n") + (big ? "format binary_big_endian 1.0\n" : "format binary_little_endian 1.0\n") +
                    "element vertex 3\n"
                    "property double x\n"
                    "property float32 y\n"
                    "property int16 z\n"
                    "property uint8 red\n"
                    "property int label\n"
                    "element face 1\n"
                    "property list uchar uint vertex_indices\n"
                    "end_header\n";
    const double xs[3] = {0.125, -1.0, 1e10};
    const float ys[3] = {1.5f, 2.0f, -3.0f};
    const std::int16_t zs[3] = {-7, 0, 300};
    const std::int32_t ls[3] = {5, -1, 2000000000};
    for (int i = 0; i < 3; ++i) {
      put(s, xs[i], big);
      put(s, ys[i], big);
      put(s, zs[i], big);
      put<std::uint8_t>(s, 255, big);
      put(s, ls[i], big);
    }
    put<std::uint8_t>(s, 3, big);
    for (std::uint32_t v : {0u, 1u, 2u}) put(s, v, big);
    auto pc = read_points(dir.write(big ? "be.ply" : "b.ply", s), labels("label"));
    EXPECT_EQ(pc.n, 3u) << big;
    EXPECT_EQ(pc.coords, (std::vector<double>{0.125, 1.5, -7, -1, 2, 0, 1e10, -3, 300})) << big;
    EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{5, -1, 2000000000})) << big;
  }
}

TEST(Ply, BinaryElementBeforeVertexIsSkipped) {
  TempDir dir;
  std::string s =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "element face 2\n"
      "property list uchar int vertex_indices\n"
      "property short flags\n"
      "element fixed 1\n"
      "property double w\n"
      "element vertex 2\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "element edge 1\n"
      "property int vertex1\n"
      "end_header\n";
  // face 0: 3 indices; face 1: 4 indices; each followed by a short.
  put<std::uint8_t>(s, 3);
  for (std::int32_t v : {0, 1, 2}) put(s, v);
  put<std::int16_t>(s, 9);
  put<std::uint8_t>(s, 4);
  for (std::int32_t v : {0, 1, 2, 3}) put(s, v);
  put<std::int16_t>(s, 9);
  put<double>(s, 42.0);
  for (float v : {1.f, 2.f, 3.f, 4.f, 5.f, 6.f}) put(s, v);
  put<std::int32_t>(s, 0);
  auto pc = read_points(dir.write("c.ply", s));
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 3, 4, 5, 6}));
}

TEST(Ply, AsciiElementBeforeVertexIsSkipped) {
  TempDir dir;
  std::string s =
      "ply\nformat ascii 1.0\n"
      "element face 1\nproperty list uchar int vertex_indices\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "end_header\n"
      "4 0 1 2 3\n"
      "7 8 9\n";
  EXPECT_EQ(read_points(dir.write("d.ply", s)).coords, (std::vector<double>{7, 8, 9}));
}

TEST(Ply, BigEndianTruncated) {
  TempDir dir;
  std::string s =
      "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n" +
      std::string(11, '\0');
  const std::string p = dir.write("be.ply", s);
  auto msg = input_error([&] { read_points(p); });
  EXPECT_EQ(msg.rfind(p, 0), 0u) << msg;
  EXPECT_NE(msg.find("ends early"), std::string::npos) << msg;
}

TEST(Ply, MissingCoordinateProperty) {
  TempDir dir;
  std::string s =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float nz\nend_header\n1 2 3\n";
  const std::string p = dir.write("m.ply", s);
  auto msg = input_error([&] { read_points(p); });
  EXPECT_NE(msg.find("'z'"), std::string::npos) << msg;
  // 2D does not need z.
  ReadOptions two;
  two.dim = 2;
  EXPECT_EQ(read_points(p, two).coords, (std::vector<double>{1, 2}));
}

TEST(Ply, MissingLabelPropertyListsNames) {
  TempDir dir;
  const std::string p = dir.write("a.ply", kAscii);
  auto msg = input_error([&] { read_points(p, labels("segment")); });
  EXPECT_NE(msg.find("'segment'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("x, y, z, region"), std::string::npos) << msg;
  msg = input_error([&] { read_points(p, labels("x")); });  // a float property
  EXPECT_NE(msg.find("integer"), std::string::npos) << msg;
}

TEST(Ply, TruncatedData) {
  TempDir dir;
  std::string s =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n" +
      std::string(20, '\0');
  auto msg = input_error([&] { read_points(dir.write("t.ply", s)); });
  EXPECT_NE(msg.find("ends early"), std::string::npos) << msg;
  std::string a =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n1 2 3\n4 5\n";
  msg = input_error([&] { read_points(dir.write("t2.ply", a)); });
  EXPECT_NE(msg.find("ends early"), std::string::npos) << msg;
}

TEST(Ply, NotAPlyFileAndNoVertex) {
  TempDir dir;
  input_error([&] { read_points(dir.write("x.ply", "hello\n")); });
  auto msg = input_error([&] {
    read_points(dir.write("y.ply",
                          "ply\nformat ascii 1.0\nelement face 0\n"
                          "property list uchar int vertex_indices\nend_header\n"));
  });
  EXPECT_NE(msg.find("vertex"), std::string::npos) << msg;
}

TEST(Ply, NanRejected) {
  TempDir dir;
  std::string s =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n4 nan 6\n";
  auto msg = input_error([&] { read_points(dir.write("n.ply", s)); });
  EXPECT_NE(msg.find("row 1"), std::string::npos) << msg;
}
