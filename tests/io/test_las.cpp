// LAS files built by hand from the specification's header layout: the
// coordinates (integer times scale plus offset), the fields by name in the
// old (0-5) and new (6-10) point formats, and the header's errors. Files with
// a VLR, extra bytes and standard input are read in tests/cli/test_cli.py.
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

template <class T>
void put(std::string& s, std::size_t at, T v) {
  std::memcpy(s.data() + at, &v, sizeof(T));
}

/// Two points of format `fmt` (1 or 6) in a LAS 1.`minor` file.
std::string two_points(int minor, int fmt) {
  const std::size_t header = minor == 4 ? 375 : 227, record = fmt == 1 ? 28 : 30;
  std::string s(header + 2 * record, '\0');
  s.replace(0, 4, "LASF");
  s[24] = 1;
  s[25] = static_cast<char>(minor);
  put<std::uint16_t>(s, 94, static_cast<std::uint16_t>(header));
  put<std::uint32_t>(s, 96, static_cast<std::uint32_t>(header));
  s[104] = static_cast<char>(fmt);
  put<std::uint16_t>(s, 105, static_cast<std::uint16_t>(record));
  put<std::uint32_t>(s, 107, minor == 4 ? 0 : 2);
  if (minor == 4) put<std::uint64_t>(s, 247, 2);
  const double scale[3] = {0.01, 0.01, 0.001}, offset[3] = {1000, -2000, 0.5};
  for (int a = 0; a < 3; ++a) {
    put<double>(s, 131 + 8 * static_cast<std::size_t>(a), scale[a]);
    put<double>(s, 155 + 8 * static_cast<std::size_t>(a), offset[a]);
  }
  const std::int32_t xyz[2][3] = {{150, -300, 2000}, {-7, 0, -1}};
  for (std::size_t i = 0; i < 2; ++i) {
    const std::size_t r = header + i * record;
    for (std::size_t a = 0; a < 3; ++a) put<std::int32_t>(s, r + 4 * a, xyz[i][a]);
    put<std::uint16_t>(s, r + 12, static_cast<std::uint16_t>(100 + i));
    if (fmt == 1) {
      s[r + 14] = static_cast<char>(0x12);  // return 2 of 2
      s[r + 15] = static_cast<char>(0xC0 | (3 + i));  // classification 3, 4 (flags above)
      s[r + 16] = static_cast<char>(-5);      // scan angle rank
      put<double>(s, r + 20, 0.25 * static_cast<double>(i));
    } else {
      s[r + 14] = static_cast<char>(0x23);  // return 3 of 2 (as written)
      s[r + 16] = static_cast<char>(200 + i);  // classification, eight bits
      put<std::int16_t>(s, r + 18, -1234);     // scan angle
      put<double>(s, r + 22, 0.25 * static_cast<double>(i));
    }
  }
  return s;
}

}  // namespace

TEST(Las, CoordinatesAndFields) {
  TempDir dir;
  for (const int fmt : {1, 6}) {
    SCOPED_TRACE(fmt);
    const std::string p = dir.write("a.las", two_points(fmt == 1 ? 2 : 4, fmt));
    ReadOptions o;
    o.labels = "classification";
    const auto pc = read_points(p, o);
    ASSERT_EQ(pc.n, 2u);
    EXPECT_EQ(pc.coords, (std::vector<double>{150 * 0.01 + 1000, -300 * 0.01 - 2000, 2000 * 0.001 + 0.5,
                                              -7 * 0.01 + 1000, 0 * 0.01 - 2000, -1 * 0.001 + 0.5}));
    EXPECT_EQ(pc.labels, fmt == 1 ? (std::vector<std::int32_t>{3, 4}) : (std::vector<std::int32_t>{200, 201}));
    EXPECT_EQ(read_point_scalars(p, "intensity"), (std::vector<double>{100, 101}));
    EXPECT_EQ(read_point_scalars(p, "Intensity"), read_point_scalars(p, "intensity"));  // PDAL's spelling
    EXPECT_EQ(read_point_scalars(p, "ReturnNumber"), read_point_scalars(p, "return_number"));
    EXPECT_EQ(read_point_scalars(p, "gps_time"), (std::vector<double>{0, 0.25}));
    EXPECT_EQ(read_point_scalars(p, "return_number"), (fmt == 1 ? std::vector<double>{2, 2} : std::vector<double>{3, 3}));
    EXPECT_EQ(read_point_scalars(p, "scan_angle"),
              (fmt == 1 ? std::vector<double>{-5, -5} : std::vector<double>{-1234, -1234}));
    o.dim = 2;
    o.labels.clear();
    EXPECT_EQ(read_points(p, o).coords.size(), 4u);
  }
}

TEST(Las, HeaderErrors) {
  TempDir dir;
  auto expect = [&](std::string bytes, const std::string& fragment) {
    const std::string p = dir.write("e.las", bytes);
    const std::string msg = input_error([&] { read_points(p); });
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
    EXPECT_NE(msg.find("e.las"), std::string::npos) << msg;
  };
  const std::string good = two_points(2, 1);
  auto with = [&](std::size_t at, std::string_view b) {
    std::string s = good;
    s.replace(at, b.size(), b);
    return s;
  };
  expect("LASX" + good.substr(4), "not a LAS file");
  expect(good.substr(0, 100), "not a LAS file");
  expect(with(24, std::string("\x02\x00", 2)), "LAS version 2.0 is not supported");
  expect(with(104, std::string("\x0b", 1)), "point format 11 is not defined");
  expect(with(104, std::string("\x83", 1)), "LAZ (compressed LAS) is not supported");
  expect(with(105, std::string("\x10\x00", 2)), "records of 16 bytes are shorter than format 1's 28");
  expect(with(96, std::string("\xff\xff\x00\x00", 4)), "offset to the point data (65535) lies outside the file");
  expect(with(107, std::string("\x00\x00\x00\x10", 4)), "data shorter than the header says");
  expect(with(131, std::string(8, '\0')), "x scale and offset must be finite, the scale nonzero");
  const std::string p = dir.write("f.las", good);
  EXPECT_NE(input_error([&] { read_point_scalars(p, "red"); }).find("no LAS field 'red'"), std::string::npos);
}
