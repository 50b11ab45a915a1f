// LAS point clouds (.las, versions 1.0 to 1.4, point formats 0 to 10): the
// airborne and terrestrial lidar files geospatial users hold their scans in
// (what PDAL, LAStools, CloudCompare and the survey vendors write).
//
// The header gives the points' offset, count, record length and format, and
// the scale and offset that turn each record's int32 X, Y, Z into
// coordinates (x = X * scale + offset, in double, as PDAL and laspy compute
// it). Per-point fields by name, for --labels (integers) and scalars:
// classification, intensity, return_number, number_of_returns, user_data,
// point_source_id, scan_angle, gps_time (formats 1, 3 to 10), in any case
// and with or without underscores (PDAL's Classification, ReturnNumber).
// scan_angle is the record's value: degrees in formats 0 to 5, units of
// 0.006 degrees in 6 to 10. A record may be
// longer than its format (extra bytes): the tail is skipped. LAZ (compressed
// LAS) is refused with a hint, as are point counts the file cannot hold.
//
// Written here: the layout is a fixed binary header and fixed records; the
// libraries that read LAS (PDAL, LASlib) are large and not in the
// dependencies.
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "tessera/io/points.hpp"

namespace tessera::io::detail {
namespace {

template <class T>
T le(const std::string& s, std::size_t at) {
  static_assert(std::endian::native == std::endian::little, "LAS is little-endian; a big-endian host would swap");
  T v;
  std::memcpy(&v, s.data() + at, sizeof(T));
  return v;
}

struct LasHeader {
  int major = 1, minor = 0;
  std::size_t offset = 0;  // to the point records
  int format = 0;
  std::size_t record = 0;  // bytes per record
  std::uint64_t points = 0;
  double scale[3] = {1, 1, 1}, add[3] = {0, 0, 0};
};

/// The fields a point format has, with their byte offsets in a record.
struct LasField {
  const char* name;
  std::size_t at;
  char kind;  // 'b' bits of a byte (shift, width below), 'u' unsigned, 'i' signed, 'd' double
  std::size_t bytes;
  int shift = 0, width = 8;
};

std::vector<LasField> fields_of(int format) {
  std::vector<LasField> f;
  if (format <= 5) {
    f = {{"intensity", 12, 'u', 2},        {"return_number", 14, 'b', 1, 0, 3},
         {"number_of_returns", 14, 'b', 1, 3, 3}, {"classification", 15, 'b', 1, 0, 5},
         {"scan_angle", 16, 'i', 1},       {"user_data", 17, 'u', 1},
         {"point_source_id", 18, 'u', 2}};
    if (format == 1 || format >= 3) f.push_back({"gps_time", 20, 'd', 8});
  } else {
    f = {{"intensity", 12, 'u', 2},        {"return_number", 14, 'b', 1, 0, 4},
         {"number_of_returns", 14, 'b', 1, 4, 4}, {"classification", 16, 'u', 1},
         {"user_data", 17, 'u', 1},        {"scan_angle", 18, 'i', 2},
         {"point_source_id", 20, 'u', 2},  {"gps_time", 22, 'd', 8}};
  }
  return f;
}

/// The least record length of each point format (LAS 1.4, table of formats).
std::size_t format_length(int format) {
  static const std::size_t len[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return len[format];
}

LasHeader parse_header(const std::string& path, const std::string& s) {
  if (s.size() < 227 || s.compare(0, 4, "LASF") != 0) fail(path, "not a LAS file (it does not start with LASF)");
  LasHeader h;
  h.major = static_cast<unsigned char>(s[24]);
  h.minor = static_cast<unsigned char>(s[25]);
  if (h.major != 1 || h.minor > 4)
    fail(path, "LAS version " + std::to_string(h.major) + "." + std::to_string(h.minor) + " is not supported (1.0 to 1.4)");
  const std::size_t header_size = le<std::uint16_t>(s, 94);
  h.offset = le<std::uint32_t>(s, 96);
  const int raw_format = static_cast<unsigned char>(s[104]);
  if (raw_format & 0xC0)
    fail(path, "LAZ (compressed LAS) is not supported: decompress it first (laszip -i in.laz -o out.las, or pdal "
               "translate in.laz out.las)");
  h.format = raw_format;
  if (h.format > 10) fail(path, "LAS point format " + std::to_string(h.format) + " is not defined (0 to 10)");
  h.record = le<std::uint16_t>(s, 105);
  if (h.record < format_length(h.format))
    fail(path, "LAS point records of " + std::to_string(h.record) + " bytes are shorter than format " +
                   std::to_string(h.format) + "'s " + std::to_string(format_length(h.format)));
  h.points = le<std::uint32_t>(s, 107);
  if (h.minor >= 4 && header_size >= 375 && s.size() >= 375) {
    const std::uint64_t wide = le<std::uint64_t>(s, 247);
    if (h.points == 0 || (wide != 0 && wide != h.points)) h.points = wide;  // the 1.4 count governs
  }
  for (int a = 0; a < 3; ++a) {
    h.scale[a] = le<double>(s, 131 + 8 * static_cast<std::size_t>(a));
    h.add[a] = le<double>(s, 155 + 8 * static_cast<std::size_t>(a));
    if (!(h.scale[a] != 0) || !std::isfinite(h.scale[a]) || !std::isfinite(h.add[a]))
      fail(path, std::string("LAS ") + "xyz"[a] + " scale and offset must be finite, the scale nonzero");
  }
  if (h.offset < header_size || h.offset > s.size())
    fail(path, "LAS offset to the point data (" + std::to_string(h.offset) + ") lies outside the file");
  // Refused before anything is sized by the count.
  if (h.points > (s.size() - h.offset) / h.record)
    fail(path, "LAS header gives " + std::to_string(h.points) + " points of " + std::to_string(h.record) +
                   " bytes, the file holds " + std::to_string((s.size() - h.offset) / h.record) +
                   " (data shorter than the header says)");
  return h;
}

/// A field name as compared: lower case, without underscores, so that PDAL's
/// and LAStools' spellings (Classification, ReturnNumber, ScanAngleRank) name
/// the same fields.
std::string folded(const std::string& name) {
  std::string out;
  for (const char c : name)
    if (c != '_') out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out == "scananglerank" ? "scanangle" : out;
}

std::string field_names(int format) {
  std::string names;
  for (const LasField& f : fields_of(format)) names += (names.empty() ? "'" : ", '") + std::string(f.name) + "'";
  return names;
}

/// The values of field `name` for every point; `is_float` where it holds
/// non-integers.
std::vector<double> field_values(const std::string& path, const std::string& s, const LasHeader& h,
                                 const std::string& name, bool& is_float) {
  for (const LasField& f : fields_of(h.format)) {
    if (folded(name) != folded(f.name)) continue;
    is_float = f.kind == 'd';
    std::vector<double> v(h.points);
    for (std::size_t i = 0; i < h.points; ++i) {
      const std::size_t at = h.offset + i * h.record + f.at;
      switch (f.kind) {
        case 'b': v[i] = (static_cast<unsigned char>(s[at]) >> f.shift) & ((1u << f.width) - 1); break;
        case 'u': v[i] = f.bytes == 1 ? static_cast<unsigned char>(s[at]) : le<std::uint16_t>(s, at); break;
        case 'i': v[i] = f.bytes == 1 ? static_cast<signed char>(s[at]) : le<std::int16_t>(s, at); break;
        default: v[i] = le<double>(s, at);
      }
    }
    return v;
  }
  fail(path, "no LAS field '" + name + "' (point format " + std::to_string(h.format) + " has " +
                 field_names(h.format) + ")");
}

}  // namespace

PointCloud read_las_points(const std::string& path, const ReadOptions& options, const std::string& label_field) {
  const std::string s = read_file_bytes(path);
  const LasHeader h = parse_header(path, s);
  const int dim = options.dim ? options.dim : 3;
  PointCloud pc;
  pc.dim = dim;
  pc.n = h.points;
  pc.coords.resize(h.points * static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < h.points; ++i)
    for (int a = 0; a < dim; ++a) {
      const std::int32_t x = le<std::int32_t>(s, h.offset + i * h.record + 4 * static_cast<std::size_t>(a));
      pc.coords[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(a)] =
          static_cast<double>(x) * h.scale[a] + h.add[a];
    }
  if (!label_field.empty()) {
    bool is_float = false;
    const std::vector<double> v = field_values(path, s, h, label_field, is_float);
    if (is_float) fail(path, "labels field '" + label_field + "' holds floating-point values, not integers");
    pc.labels = labels_from_values(path, label_field, v);
  }
  return pc;
}

std::vector<double> read_las_field(const std::string& path, const std::string& name) {
  const std::string s = read_file_bytes(path);
  const LasHeader h = parse_header(path, s);
  bool is_float = false;
  return field_values(path, s, h, name, is_float);
}

}  // namespace tessera::io::detail
