// .npy reader/writer: round trips, dtypes, byte order, header versions, and
// Fortran order, and the errors for bad shapes and truncated data.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "io/io_test_util.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"

using namespace tessera_test;
using tessera::io::npy_bytes;
using tessera::io::read_npy_double;
using tessera::io::read_npy_int;
using tessera::io::read_points;

TEST(Npy, WriterHeaderIsVersion1PaddedTo64) {
  const std::vector<double> v{1, 2, 3, 4, 5, 6};
  const std::string b = npy_bytes(v.data(), {3, 2});
  ASSERT_GE(b.size(), 10u);
  EXPECT_EQ(b.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(b[6], 1);
  EXPECT_EQ(b[7], 0);
  const std::size_t hlen = static_cast<unsigned char>(b[8]) | (static_cast<unsigned char>(b[9]) << 8);
  EXPECT_EQ((10 + hlen) % 64, 0u);
  EXPECT_EQ(b[10 + hlen - 1], '\n');
  const std::string header = b.substr(10, hlen);
  EXPECT_NE(header.find("'descr': '<f8'"), std::string::npos);
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos);
  EXPECT_NE(header.find("'shape': (3, 2)"), std::string::npos);
  EXPECT_EQ(b.size(), 10 + hlen + 6 * sizeof(double));
}

TEST(Npy, OneDimensionalShapeHasTrailingComma) {
  const std::vector<std::int64_t> v{7, 8, 9};
  const std::string b = npy_bytes(v.data(), {3});
  EXPECT_NE(b.find("'shape': (3,)"), std::string::npos);
  EXPECT_NE(b.find("'descr': '<i8'"), std::string::npos);
}

TEST(Npy, DoubleRoundTrip) {
  TempDir dir;
  const std::vector<double> v{0.1, -2.5, 3e300, 4, 5.25, 1e-310};
  const std::string p = dir.file("a.npy");
  tessera::io::write_file_atomic(p, npy_bytes(v.data(), {2, 3}));
  auto a = read_npy_double(p);
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(a.kind, 'f');
  EXPECT_EQ(a.item_size, 8);
  EXPECT_EQ(a.as_double, v);

  auto pc = read_points(p);
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.n, 2u);
  EXPECT_EQ(pc.coords, v);
}

TEST(Npy, IntRoundTrip) {
  TempDir dir;
  const std::vector<std::int32_t> v32{-1, 0, 2147483647, -2147483647 - 1};
  const std::vector<std::int64_t> v64{-5, 1LL << 40, 3};
  tessera::io::write_file_atomic(dir.file("i4.npy"), npy_bytes(v32.data(), {4}));
  tessera::io::write_file_atomic(dir.file("i8.npy"), npy_bytes(v64.data(), {3, 1}));
  auto a = read_npy_int(dir.file("i4.npy"));
  EXPECT_EQ(a.kind, 'i');
  EXPECT_EQ(a.item_size, 4);
  EXPECT_EQ(a.as_int, (std::vector<std::int64_t>{-1, 0, 2147483647, -2147483648LL}));
  auto b = read_npy_int(dir.file("i8.npy"));
  EXPECT_EQ(b.shape, (std::vector<std::size_t>{3, 1}));
  EXPECT_EQ(b.as_int, v64);
}

TEST(Npy, EmptyArrayRoundTrip) {
  TempDir dir;
  tessera::io::write_file_atomic(dir.file("e.npy"), npy_bytes(static_cast<const double*>(nullptr), {0, 3}));
  auto a = read_npy_double(dir.file("e.npy"));
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{0, 3}));
  EXPECT_TRUE(a.as_double.empty());
  // ... but zero points is not a valid point cloud.
  EXPECT_NE(input_error([&] { read_points(dir.file("e.npy")); }).find("no points"), std::string::npos);
}

TEST(Npy, Float32Points) {
  TempDir dir;
  const std::vector<float> v{1.5f, 2.25f, -3.f, 4.f, 5.f, 6.f};
  const std::string p = dir.write("f4.npy", make_npy("<f4", "(3, 2)", raw_bytes(v)));
  auto pc = read_points(p);
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.n, 3u);
  EXPECT_EQ(pc.coords, (std::vector<double>{1.5, 2.25, -3, 4, 5, 6}));
}

TEST(Npy, BigEndianIsSwapped) {
  TempDir dir;
  const std::vector<double> d{1.0, -2.0, 3.5, 4.0, 5.0, 6.0};
  const std::vector<float> f{1.0f, -2.0f, 3.5f};
  auto a = read_npy_double(dir.write("be8.npy", make_npy(">f8", "(2, 3)", raw_bytes(d, true))));
  EXPECT_EQ(a.as_double, d);
  auto b = read_npy_double(dir.write("be4.npy", make_npy(">f4", "(1, 3)", raw_bytes(f, true))));
  EXPECT_EQ(b.as_double, (std::vector<double>{1.0, -2.0, 3.5}));
  const std::vector<std::int32_t> i{1, -2, 70000};
  auto c = read_npy_int(dir.write("bei.npy", make_npy(">i4", "(3,)", raw_bytes(i, true))));
  EXPECT_EQ(c.as_int, (std::vector<std::int64_t>{1, -2, 70000}));
}

TEST(Npy, HeaderVersions2And3) {
  TempDir dir;
  const std::vector<double> d{1, 2, 3, 4};
  for (int major : {2, 3}) {
    auto a = read_npy_double(dir.write("v.npy", make_npy("<f8", "(2, 2)", raw_bytes(d), false, major)));
    EXPECT_EQ(a.as_double, d) << "version " << major;
  }
  std::string bad = make_npy("<f8", "(2, 2)", raw_bytes(d));
  bad[6] = 4;
  auto msg = input_error([&] { read_npy_double(dir.write("v4.npy", bad)); });
  EXPECT_NE(msg.find("version 4.0"), std::string::npos) << msg;
}

TEST(Npy, IntegerDtypesForLabels) {
  TempDir dir;
  EXPECT_EQ(tessera::io::read_labels_npy(
                dir.write("i1.npy", make_npy("|i1", "(3,)", raw_bytes(std::vector<std::int8_t>{-1, 0, 5})))),
            (std::vector<std::int32_t>{-1, 0, 5}));
  EXPECT_EQ(tessera::io::read_labels_npy(
                dir.write("u1.npy", make_npy("|u1", "(2,)", raw_bytes(std::vector<std::uint8_t>{255, 1})))),
            (std::vector<std::int32_t>{255, 1}));
  EXPECT_EQ(tessera::io::read_labels_npy(dir.write(
                "u2.npy", make_npy("<u2", "(2,)", raw_bytes(std::vector<std::uint16_t>{65535, 2})))),
            (std::vector<std::int32_t>{65535, 2}));
  EXPECT_EQ(tessera::io::read_labels_npy(dir.write(
                "i2.npy", make_npy(">i2", "(2,)", raw_bytes(std::vector<std::int16_t>{-300, 2}, true)))),
            (std::vector<std::int32_t>{-300, 2}));
  EXPECT_EQ(tessera::io::read_labels_npy(
                dir.write("u4.npy", make_npy("<u4", "(1,)", raw_bytes(std::vector<std::uint32_t>{7})))),
            (std::vector<std::int32_t>{7}));
  EXPECT_EQ(tessera::io::read_labels_npy(
                dir.write("b1.npy", make_npy("|b1", "(3,)", std::string("\x01\x00\x01", 3)))),
            (std::vector<std::int32_t>{1, 0, 1}));
  EXPECT_EQ(tessera::io::read_labels_npy(
                dir.write("u8.npy", make_npy("<u8", "(2, 1)", raw_bytes(std::vector<std::uint64_t>{3, 4})))),
            (std::vector<std::int32_t>{3, 4}));
  // Out of int32 range, float labels, 2-D labels.
  auto msg = input_error([&] {
    tessera::io::read_labels_npy(
        dir.write("big.npy", make_npy("<i8", "(1,)", raw_bytes(std::vector<std::int64_t>{1LL << 33}))));
  });
  EXPECT_NE(msg.find("int32"), std::string::npos) << msg;
  msg = input_error([&] {
    tessera::io::read_labels_npy(
        dir.write("f.npy", make_npy("<f8", "(1,)", raw_bytes(std::vector<double>{1}))));
  });
  EXPECT_NE(msg.find("integer"), std::string::npos) << msg;
  msg = input_error([&] {
    tessera::io::read_labels_npy(
        dir.write("2d.npy", make_npy("<i4", "(2, 2)", raw_bytes(std::vector<std::int32_t>{1, 2, 3, 4}))));
  });
  EXPECT_NE(msg.find("(2, 2)"), std::string::npos) << msg;
}

TEST(Npy, IntegerPointsAreConverted) {
  TempDir dir;
  auto pc = read_points(
      dir.write("ip.npy", make_npy("<i4", "(2, 2)", raw_bytes(std::vector<std::int32_t>{1, 2, -3, 4}))));
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, -3, 4}));
}

// NumPy saves an F-contiguous array (a transposed one, a pandas DataFrame's
// to_numpy()) in Fortran order: read back in C order, as np.load gives it.
TEST(Npy, FortranOrderIsReordered) {
  TempDir dir;
  // Points (2, 3) stored column after column: x0 x1, y0 y1, z0 z1.
  const std::vector<double> cols{1, 2, 3, 4, 5, 6};
  auto pc = read_points(dir.write("f.npy", make_npy("<f8", "(2, 3)", raw_bytes(cols), true)));
  EXPECT_EQ(pc.n, 2u);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 3, 5, 2, 4, 6}));
  // Converted dtypes and big-endian data go the same way.
  auto pi = read_points(dir.write("fi.npy", make_npy(">i4", "(2, 2)", raw_bytes(std::vector<std::int32_t>{1, 2, 3, 4}, true), true)));
  EXPECT_EQ(pi.coords, (std::vector<double>{1, 3, 2, 4}));
  // Rank 3 (an image (nz, ny, nx)): element (i, j, k) lies at i + 2 (j + 3 k).
  std::vector<std::int64_t> f(2 * 3 * 4);
  for (std::size_t k = 0; k < 4; ++k)
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t i = 0; i < 2; ++i) f[i + 2 * (j + 3 * k)] = static_cast<std::int64_t>(100 * i + 10 * j + k);
  const auto a = read_npy_int(dir.write("f3.npy", make_npy("<i8", "(2, 3, 4)", raw_bytes(f), true)));
  ASSERT_EQ(a.as_int.size(), f.size());
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t j = 0; j < 3; ++j)
      for (std::size_t k = 0; k < 4; ++k)
        EXPECT_EQ(a.as_int[(i * 3 + j) * 4 + k], static_cast<std::int64_t>(100 * i + 10 * j + k)) << i << j << k;
  const auto d = read_npy_double(dir.write("f3d.npy", make_npy("<i8", "(2, 3, 4)", raw_bytes(f), true)));
  for (std::size_t c = 0; c < f.size(); ++c) EXPECT_EQ(d.as_double[c], static_cast<double>(a.as_int[c]));
  // 1-D: Fortran order is C order.
  const auto l = read_npy_int(dir.write("f1.npy", make_npy("<i4", "(3,)", raw_bytes(std::vector<std::int32_t>{7, 8, 9}), true)));
  EXPECT_EQ(l.as_int, (std::vector<std::int64_t>{7, 8, 9}));
}

// A structured array (PDAL's point views, np.recarray, pandas'
// to_records()): the points from its fields named x, y, z in any case and
// position, labels from an integer field, numpy's padding skipped.
TEST(Npy, StructuredRecords) {
  TempDir dir;
  // Records: id <i4, Z <f4, pad |V4, X >f8 (big-endian), Y <f8, cls |u1, rgb |u1 (3,) -> 32 bytes.
  const std::string descr =
      "[('id', '<i4'), ('Z', '<f4'), ('', '|V4'), ('X', '>f8'), ('Y', '<f8'), ('cls', '|u1'), ('rgb', '|u1', (3,))]";
  std::string data;
  const double xs[2] = {1.5, -2.0}, ys[2] = {0.25, 4.0};
  const float zs[2] = {3.0f, -0.5f};
  for (int i = 0; i < 2; ++i) {
    data += raw_bytes(std::vector<std::int32_t>{100 + i});
    data += raw_bytes(std::vector<float>{zs[i]});
    data += std::string(4, '\x7f');
    data += raw_bytes(std::vector<double>{xs[i]}, true);
    data += raw_bytes(std::vector<double>{ys[i]});
    data += static_cast<char>(i == 0 ? 5 : 200);
    data += std::string(3, '\x01');
  }
  ASSERT_EQ(data.size(), 64u);
  const std::string p = dir.write("rec.npy", make_npy(descr, "(2,)", data));
  auto pc = read_points(p, labels("cls"));
  EXPECT_EQ(pc.dim, 3);
  EXPECT_EQ(pc.coords, (std::vector<double>{1.5, 0.25, 3.0, -2.0, 4.0, -0.5}));
  EXPECT_EQ(pc.labels, (std::vector<std::int32_t>{5, 200}));
  tessera::io::ReadOptions two;
  two.dim = 2;
  EXPECT_EQ(read_points(p, two).coords, (std::vector<double>{1.5, 0.25, -2.0, 4.0}));
  // Scalars by field name (threshold --scalars).
  EXPECT_EQ(tessera::io::read_point_scalars(p, "id"), (std::vector<double>{100, 101}));
  // Errors name the fields.
  auto msg = input_error([&] { read_points(p, labels("rgb")); });
  EXPECT_NE(msg.find("'rgb' is not a number"), std::string::npos) << msg;
  msg = input_error([&] { read_points(p, labels("Z")); });
  EXPECT_NE(msg.find("both a coordinate and the labels"), std::string::npos) << msg;
  msg = input_error([&] { read_points(p, labels("none")); });
  EXPECT_NE(msg.find("no field 'none'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'cls'"), std::string::npos) << msg;
  // Without x and y fields; labels or scalars from a structured file where a plain array is expected.
  const std::string q = dir.write("q.npy", make_npy("[('a', '<f8'), ('b', '<f8')]", "(1,)", raw_bytes(std::vector<double>{1, 2})));
  msg = input_error([&] { read_points(q); });
  EXPECT_NE(msg.find("fields x and y"), std::string::npos) << msg;
  msg = input_error([&] { tessera::io::read_labels_npy(q); });
  EXPECT_NE(msg.find("structured array (fields 'a', 'b')"), std::string::npos) << msg;
  // Truncated records, nested dtypes and 2-D record arrays.
  msg = input_error([&] { read_points(dir.write("t.npy", make_npy(descr, "(3,)", data))); });
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("n.npy", make_npy("[('p', [('x', '<f8')])]", "(1,)", std::string(8, '\0')))); });
  EXPECT_NE(msg.find("nested"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("s.npy", make_npy("[('x', '<f8'), ('y', '<f8')]", "(1, 2)", std::string(32, '\0')))); });
  EXPECT_NE(msg.find("1-D"), std::string::npos) << msg;
}

TEST(Npy, BadShapeNamesShape) {
  TempDir dir;
  const std::vector<double> d(20, 1.0);
  auto msg = input_error([&] { read_points(dir.write("s.npy", make_npy("<f8", "(5, 4)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("(5, 4)"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("s1.npy", make_npy("<f8", "(20,)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("(20,)"), std::string::npos) << msg;
  msg = input_error([&] { read_points(dir.write("s3.npy", make_npy("<f8", "(5, 2, 2)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("(5, 2, 2)"), std::string::npos) << msg;
}

TEST(Npy, DimOptionOnNpy) {
  TempDir dir;
  const std::vector<double> d{1, 2, 3, 4, 5, 6};
  const std::string p3 = dir.write("p3.npy", make_npy("<f8", "(2, 3)", raw_bytes(d)));
  tessera::io::ReadOptions two;
  two.dim = 2;
  auto pc = read_points(p3, two);
  EXPECT_EQ(pc.dim, 2);
  EXPECT_EQ(pc.coords, (std::vector<double>{1, 2, 4, 5}));
  const std::string p2 = dir.write("p2.npy", make_npy("<f8", "(3, 2)", raw_bytes(d)));
  tessera::io::ReadOptions three;
  three.dim = 3;
  input_error([&] { read_points(p2, three); });
}

TEST(Npy, TruncatedData) {
  TempDir dir;
  const std::vector<double> d{1, 2, 3, 4, 5};  // shape says 6 values
  auto msg = input_error([&] { read_points(dir.write("t.npy", make_npy("<f8", "(2, 3)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  const std::vector<float> f{1, 2, 3};
  msg = input_error([&] { read_points(dir.write("t4.npy", make_npy("<f4", "(2, 2)", raw_bytes(f)))); });
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  // Truncated inside the header.
  std::string full = make_npy("<f8", "(2, 3)", raw_bytes(d));
  msg = input_error([&] { read_points(dir.write("th.npy", full.substr(0, 30))); });
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
  // A header claiming far more data than the file holds (here 48 GiB) is
  // truncated data, reported before anything is allocated for it (it was
  // "out of memory", exit 1).
  msg = input_error([&] { read_points(dir.write("big.npy", make_npy("<f8", "(2147483648, 3)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("truncated data: expected 51539607552 bytes"), std::string::npos) << msg;
  msg = input_error([&] { tessera::io::read_labels_npy(dir.write("bigl.npy", make_npy("<i4", "(4294967296,)", raw_bytes(d)))); });
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;
}

TEST(Npy, BadMagicAndDtype) {
  TempDir dir;
  auto msg = input_error([&] { read_points(dir.write("m.npy", "not numpy at all")); });
  EXPECT_NE(msg.find("magic"), std::string::npos) << msg;
  msg = input_error(
      [&] { read_points(dir.write("c.npy", make_npy("<c16", "(1, 2)", std::string(32, '\0')))); });
  EXPECT_NE(msg.find("<c16"), std::string::npos) << msg;
}
