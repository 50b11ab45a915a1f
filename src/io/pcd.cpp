// PCD point reader: the Point Cloud Library's format (also Open3D's and ROS'
// tools'), after PCL's "The PCD (Point Cloud Data) file format":
//
//   # .PCD v0.7 - Point Cloud Data file format
//   VERSION 0.7
//   FIELDS x y z label
//   SIZE 4 4 4 4
//   TYPE F F F U           (F float, I signed, U unsigned)
//   COUNT 1 1 1 1          (values per field; optional, default 1)
//   WIDTH 640
//   HEIGHT 480             (an organized cloud: WIDTH x HEIGHT points)
//   VIEWPOINT 0 0 0 1 0 0 0
//   POINTS 307200          (optional before v0.7: WIDTH x HEIGHT)
//   DATA ascii | binary | binary_compressed
//
// ascii: one point per line; binary: the points' records, fields in order,
// little-endian; binary_compressed: uint32 compressed size, uint32 size,
// then the LZF-compressed data (Debian's liblzf), laid out field by field
// (all of field 0's values, then all of field 1's, ...).
//
// Coordinates come from the fields x, y (and z: 3D), labels from an integer
// field. Organized clouds mark missing returns with NaN points; those are
// refused with a hint, as the caller cannot drop points without renumbering
// them.
#include <lzf.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "io_detail.hpp"
#include "tessera/io/points.hpp"

namespace tessera::io::detail {
namespace {

enum class Encoding { ascii, binary, binary_compressed };

struct Field {
  std::string name;
  int size = 4;
  char type = 'F';
  std::size_t count = 1;
};

struct PcdHeader {
  std::vector<Field> fields;
  std::size_t points = 0;
  Encoding encoding = Encoding::ascii;
  std::size_t data_start = 0;  ///< offset of the byte after the DATA line
  std::size_t record = 0;      ///< bytes per point
};

/// The whitespace-separated words of `line` into `w` (reused: no allocation
/// per data line once it has grown).
void words(std::string_view line, std::vector<std::string_view>& w) {
  w.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t b = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > b) w.push_back(line.substr(b, i - b));
  }
}

bool parse_size(std::string_view s, std::size_t& v) {
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && p == s.data() + s.size();
}

PcdHeader parse_header(const std::string& path, std::string_view bytes) {
  PcdHeader h;
  std::size_t pos = 0, line_no = 0, width = 0, height = 1;
  std::vector<std::string_view> w;
  bool have_fields = false, have_size = false, have_type = false, have_points = false, have_width = false;
  for (;;) {
    if (pos >= bytes.size()) fail(path, "PCD header has no DATA line");
    const std::size_t nl = bytes.find('\n', pos);
    const std::string_view line = bytes.substr(pos, (nl == std::string_view::npos ? bytes.size() : nl) - pos);
    pos = nl == std::string_view::npos ? bytes.size() : nl + 1;
    ++line_no;
    words(line, w);
    if (w.empty() || w[0][0] == '#') continue;
    auto bad = [&](const std::string& what) { fail(path, "PCD header line " + std::to_string(line_no) + ": " + what); };
    const std::string key = lower(w[0]);
    if (key == "version" || key == "viewpoint") continue;
    if (key == "fields") {
      if (w.size() < 2) bad("FIELDS names no field");
      h.fields.resize(w.size() - 1);
      for (std::size_t k = 1; k < w.size(); ++k) h.fields[k - 1].name = std::string(w[k]);
      have_fields = true;
    } else if (key == "size" || key == "type" || key == "count") {
      if (!have_fields) bad(std::string(w[0]) + " before FIELDS");
      if (w.size() != h.fields.size() + 1)
        bad(std::string(w[0]) + " gives " + std::to_string(w.size() - 1) + " values for " +
            std::to_string(h.fields.size()) + " fields");
      for (std::size_t k = 1; k < w.size(); ++k) {
        Field& f = h.fields[k - 1];
        if (key == "type") {
          if (w[k].size() != 1 || (w[k][0] != 'F' && w[k][0] != 'I' && w[k][0] != 'U'))
            bad("unknown TYPE '" + std::string(w[k]) + "' (expected F, I or U)");
          f.type = w[k][0];
        } else {
          std::size_t v = 0;
          if (!parse_size(w[k], v) || v == 0 || v > (1u << 20)) bad("bad " + std::string(w[0]) + " '" + std::string(w[k]) + "'");
          if (key == "size") {
            if (v != 1 && v != 2 && v != 4 && v != 8) bad("bad SIZE '" + std::string(w[k]) + "' (expected 1, 2, 4 or 8)");
            f.size = static_cast<int>(v);
          } else {
            f.count = v;
          }
        }
      }
      have_size |= key == "size";
      have_type |= key == "type";
    } else if (key == "width" || key == "height" || key == "points") {
      std::size_t v = 0;
      if (w.size() != 2 || !parse_size(w[1], v) || v > (std::size_t{1} << 40)) bad("bad " + std::string(w[0]));
      if (key == "width") {
        width = v;
        have_width = true;
      } else if (key == "height") {
        height = v;
      } else {
        h.points = v;
        have_points = true;
      }
    } else if (key == "data") {
      if (w.size() != 2) bad("expected 'DATA ascii|binary|binary_compressed'");
      const std::string e = lower(w[1]);
      if (e == "ascii")
        h.encoding = Encoding::ascii;
      else if (e == "binary")
        h.encoding = Encoding::binary;
      else if (e == "binary_compressed")
        h.encoding = Encoding::binary_compressed;
      else
        bad("unknown DATA '" + std::string(w[1]) + "' (expected ascii, binary or binary_compressed)");
      h.data_start = pos;
      break;
    } else {
      bad("unexpected keyword '" + std::string(w[0]) + "'");
    }
  }
  if (!have_fields || !have_size || !have_type) fail(path, "PCD header lacks FIELDS, SIZE or TYPE");
  if (!have_points) {
    if (!have_width) fail(path, "PCD header gives neither POINTS nor WIDTH");
    h.points = width * height;
  }
  for (const Field& f : h.fields) {
    if (f.type == 'F' && f.size != 4 && f.size != 8) fail(path, "field '" + f.name + "': float of " + std::to_string(f.size) + " bytes");
    h.record += static_cast<std::size_t>(f.size) * f.count;
  }
  return h;
}

double load(const unsigned char* p, const Field& f) {
  auto get = [p](auto tag) {
    decltype(tag) v;
    std::memcpy(&v, p, sizeof v);
    if constexpr (std::endian::native == std::endian::big && sizeof v > 1) {
      unsigned char b[sizeof v];
      std::memcpy(b, &v, sizeof v);
      std::reverse(b, b + sizeof v);
      std::memcpy(&v, b, sizeof v);
    }
    return static_cast<double>(v);
  };
  if (f.type == 'F') return f.size == 4 ? get(float{}) : get(double{});
  if (f.type == 'I') {
    switch (f.size) {
      case 1: return get(std::int8_t{});
      case 2: return get(std::int16_t{});
      case 4: return get(std::int32_t{});
      default: return get(std::int64_t{});
    }
  }
  switch (f.size) {
    case 1: return get(std::uint8_t{});
    case 2: return get(std::uint16_t{});
    case 4: return get(std::uint32_t{});
    default: return get(std::uint64_t{});
  }
}

/// The values of the fields `want` (indices into h.fields; each of count 1),
/// one column per wanted field.
std::vector<std::vector<double>> read_columns(const std::string& path, std::string_view bytes, const PcdHeader& h,
                                              const std::vector<std::size_t>& want) {
  const std::string_view data = bytes.substr(std::min(h.data_start, bytes.size()));
  // The data must be able to hold the points before anything is sized by
  // the header: n ascii points take at least 2n - 1 characters, binary ones
  // their records, LZF expands at most ~100 times.
  const std::size_t need = h.points * h.record;
  if (h.record != 0 && need / h.record != h.points) fail(path, "PCD POINTS too large");
  if (h.encoding == Encoding::ascii && h.points > data.size() / 2 + 1)
    fail(path, "PCD data ends before " + std::to_string(h.points) + " points");
  if (h.encoding == Encoding::binary && data.size() < need)
    fail(path, "PCD data ends after " + std::to_string(data.size()) + " of " + std::to_string(need) + " bytes (" +
                   std::to_string(h.points) + " points)");
  if (h.encoding == Encoding::binary_compressed && need / 128 > data.size())
    fail(path, "PCD compressed data is shorter than " + std::to_string(h.points) + " points can compress to");
  std::vector<std::vector<double>> cols(want.size(), std::vector<double>(h.points));
  std::vector<std::size_t> offset(h.fields.size());  // within a record
  for (std::size_t k = 1; k < h.fields.size(); ++k)
    offset[k] = offset[k - 1] + static_cast<std::size_t>(h.fields[k - 1].size) * h.fields[k - 1].count;
  if (h.encoding == Encoding::ascii) {
    // Values per point: the fields' counts; the wanted ones at their index.
    std::vector<std::size_t> at(h.fields.size());
    std::size_t per = 0;
    for (std::size_t k = 0; k < h.fields.size(); ++k) {
      at[k] = per;
      per += h.fields[k].count;
    }
    std::size_t pos = 0;
    std::vector<std::string_view> w;
    for (std::size_t i = 0; i < h.points;) {
      if (pos >= data.size())
        fail(path, "PCD data ends after " + std::to_string(i) + " of " + std::to_string(h.points) + " points");
      const std::size_t nl = data.find('\n', pos);
      const std::string_view l = data.substr(pos, (nl == std::string_view::npos ? data.size() : nl) - pos);
      pos = nl == std::string_view::npos ? data.size() : nl + 1;
      words(l, w);
      if (w.empty()) continue;
      if (w.size() != per)
        fail(path, "PCD point " + std::to_string(i) + " has " + std::to_string(w.size()) + " values, expected " +
                       std::to_string(per));
      for (std::size_t c = 0; c < want.size(); ++c) {
        std::string_view t = w[at[want[c]]];
        double v = 0;  // (from_chars reads "nan", an organized cloud's missing return, in any case)
        if (!t.empty() && t[0] == '+') t.remove_prefix(1);
        auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (ec != std::errc() || p != t.data() + t.size())
          fail(path, "PCD point " + std::to_string(i) + ": cannot parse '" + std::string(w[at[want[c]]]) + "' as a number");
        cols[c][i] = v;
      }
      ++i;
    }
    return cols;
  }
  const unsigned char* src = reinterpret_cast<const unsigned char*>(data.data());
  std::vector<unsigned char> plain;
  if (h.encoding == Encoding::binary_compressed) {
    if (data.size() < 8) fail(path, "PCD compressed data ends before its sizes");
    std::uint32_t csize = 0, usize = 0;
    std::memcpy(&csize, src, 4);
    std::memcpy(&usize, src + 4, 4);
    if constexpr (std::endian::native == std::endian::big) {
      csize = __builtin_bswap32(csize);
      usize = __builtin_bswap32(usize);
    }
    if (usize != need)
      fail(path, "PCD compressed data holds " + std::to_string(usize) + " bytes, the header's points need " +
                     std::to_string(need) + " (mismatched sizes)");
    if (csize > data.size() - 8)
      fail(path, "PCD compressed data ends after " + std::to_string(data.size() - 8) + " of " + std::to_string(csize) + " bytes");
    plain.resize(std::max<std::size_t>(need, 1));
    const unsigned got = need == 0 ? 0 : lzf_decompress(src + 8, csize, plain.data(), static_cast<unsigned>(need));
    if (got != need) fail(path, "PCD compressed data is corrupt (LZF)");
    // Field by field: field k's values start at points * (its record offset).
    for (std::size_t c = 0; c < want.size(); ++c) {
      const Field& f = h.fields[want[c]];
      const unsigned char* base = plain.data() + h.points * offset[want[c]];
      for (std::size_t i = 0; i < h.points; ++i) cols[c][i] = load(base + i * static_cast<std::size_t>(f.size), f);
    }
    return cols;
  }
  for (std::size_t c = 0; c < want.size(); ++c) {
    const Field& f = h.fields[want[c]];
    for (std::size_t i = 0; i < h.points; ++i) cols[c][i] = load(src + i * h.record + offset[want[c]], f);
  }
  return cols;
}

std::vector<std::string> field_names(const PcdHeader& h) {
  std::vector<std::string> names;
  for (const Field& f : h.fields) names.push_back(f.name);
  return names;
}

/// Index of the field `name`, which must hold one value per point;
/// h.fields.size() when absent.
std::size_t find_field(const std::string& path, const PcdHeader& h, const std::string& name) {
  for (std::size_t k = 0; k < h.fields.size(); ++k)
    if (h.fields[k].name == name) {
      if (h.fields[k].count != 1)
        fail(path, "field '" + name + "' holds " + std::to_string(h.fields[k].count) + " values per point, expected 1");
      return k;
    }
  return h.fields.size();
}

}  // namespace

PointCloud read_pcd_points(const std::string& path, const ReadOptions& options, const std::string& label_field) {
  const std::string bytes = read_file_bytes(path);
  const PcdHeader h = parse_header(path, bytes);
  const std::size_t none = h.fields.size();
  const NamedAxes axes = named_axes(path, field_names(h), label_field, options.dim, "field");
  if (!axes.found) fail(path, "PCD fields need x and y (fields: " + quoted_list(field_names(h)) + ")");
  const int dim = axes.dim;
  std::vector<std::size_t> want(axes.col, axes.col + dim);
  for (const std::size_t k : want)
    if (h.fields[k].count != 1)
      fail(path, "field '" + h.fields[k].name + "' holds " + std::to_string(h.fields[k].count) +
                     " values per point, expected 1");
  std::size_t label = none;
  if (!label_field.empty()) {
    label = find_field(path, h, label_field);
    if (label == none)
      fail(path, "no field '" + label_field + "' for labels (fields: " + quoted_list(field_names(h)) + ")");
    if (h.fields[label].type == 'F') fail(path, "labels field '" + label_field + "' holds floating-point values, not integers");
    want.push_back(label);
  }
  const auto cols = read_columns(path, bytes, h, want);
  PointCloud pc;
  pc.dim = dim;
  pc.n = h.points;
  pc.coords.resize(h.points * static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < h.points; ++i)
    for (int d = 0; d < dim; ++d) {
      const double v = cols[static_cast<std::size_t>(d)][i];
      if (std::isnan(v) && !options.keep_non_finite)
        fail(path, "point " + std::to_string(i) + " has a NaN coordinate (organized clouds mark missing returns so: "
                   "remove them first, e.g. pcl::removeNaNFromPointCloud; or " + non_finite_hint(options) + ")");
      pc.coords[i * static_cast<std::size_t>(dim) + static_cast<std::size_t>(d)] = v;
    }
  if (label != none) pc.labels = labels_from_values(path, label_field, cols.back());
  return pc;
}

std::vector<double> read_pcd_field(const std::string& path, const std::string& name) {
  const std::string bytes = read_file_bytes(path);
  const PcdHeader h = parse_header(path, bytes);
  const std::size_t k = find_field(path, h, name);
  if (k == h.fields.size()) fail(path, "no field '" + name + "' for scalars (fields: " + quoted_list(field_names(h)) + ")");
  return std::move(read_columns(path, bytes, h, {k})[0]);
}

}  // namespace tessera::io::detail
