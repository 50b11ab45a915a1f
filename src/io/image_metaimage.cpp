// MetaImage (.mha: header and data in one file; .mhd: header, data in the
// file named by ElementDataFile), the format of ITK's and VTK's MetaIO.
//
//   ObjectType = Image
//   NDims = 3
//   BinaryData = True
//   BinaryDataByteOrderMSB = False
//   CompressedData = True            zlib stream (CompressedDataSize bytes)
//   TransformMatrix = 1 0 0 0 1 0 0 0 1
//   Offset = 2 -2 5                  position of voxel (0,0,0)
//   ElementSpacing = 0.5 0.25 2
//   DimSize = 4 3 2                  x fastest
//   ElementType = MET_SHORT
//   ElementDataFile = LOCAL          always the last line; LOCAL: data follows
//
// Supported: 2D/3D, one channel, every MET_ integer and float type, binary
// (raw or zlib-compressed) and ascii data, HeaderSize for external files
// (-1: the data is at the end), a TransformMatrix that flips axes (read
// reversed). Rejected with a one-line error: several channels, a rotated or
// permuted TransformMatrix, file lists and patterns.
#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <string>
#include <string_view>

#include "image_detail.hpp"
#include "io_detail.hpp"

namespace tessera::io::detail {
namespace {

bool met_type(const std::string& name, ScalarType& t) {
  static const std::map<std::string, ScalarType> types = {
      {"MET_CHAR", ScalarType::i8},        {"MET_UCHAR", ScalarType::u8},      {"MET_SHORT", ScalarType::i16},
      {"MET_USHORT", ScalarType::u16},     {"MET_INT", ScalarType::i32},       {"MET_UINT", ScalarType::u32},
      {"MET_LONG", ScalarType::i32},       {"MET_ULONG", ScalarType::u32},     {"MET_LONG_LONG", ScalarType::i64},
      {"MET_ULONG_LONG", ScalarType::u64}, {"MET_FLOAT", ScalarType::f32},     {"MET_DOUBLE", ScalarType::f64},
  };
  auto it = types.find(name);
  if (it == types.end()) return false;
  t = it->second;
  return true;
}

bool parse_bool(const std::string& v, bool& out) {
  const std::string l = lower(v);
  if (l == "true" || l == "1") {
    out = true;
    return true;
  }
  if (l == "false" || l == "0") {
    out = false;
    return true;
  }
  return false;
}

}  // namespace

RawImage read_metaimage(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  std::map<std::string, std::string> fields;  // lower-cased keys
  std::size_t pos = 0, data_start = std::string::npos;
  bool first = true;
  while (pos < bytes.size()) {
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    std::string_view line = std::string_view(bytes).substr(pos, end - pos);
    pos = std::min(end + 1, bytes.size());
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (trim(line).empty()) continue;
    const std::size_t eq = line.find('=');
    if (eq == std::string_view::npos)
      fail(path, "malformed MetaImage header line '" + printable(line) + "' (expected 'Key = Value')");
    const std::string key = lower(trim(line.substr(0, eq)));
    if (first && key != "objecttype" && key != "ndims")
      fail(path, "not a MetaImage header (it must start with ObjectType or NDims)");
    first = false;
    if (fields.count(key)) fail(path, "MetaImage key '" + std::string(trim(line.substr(0, eq))) + "' given twice");
    fields[key] = std::string(trim(line.substr(eq + 1)));
    if (key == "elementdatafile") {
      data_start = pos;
      break;
    }
  }
  if (first) fail(path, "empty MetaImage header");
  auto field = [&](const char* name) -> const std::string* {
    auto it = fields.find(name);
    return it == fields.end() ? nullptr : &it->second;
  };
  if (data_start == std::string::npos) fail(path, "MetaImage header has no ElementDataFile line");
  if (const std::string* ot = field("objecttype"); ot && lower(*ot) != "image")
    fail(path, "MetaImage ObjectType is '" + *ot + "', expected Image");

  RawImage raw;
  ImageGeometry& g = raw.geometry;
  const std::string* nd = field("ndims");
  if (!nd) fail(path, "MetaImage header has no NDims");
  std::int64_t dim = 0;
  if (!parse_sizes(*nd, 1, &dim) || (dim != 2 && dim != 3))
    fail(path, "MetaImage NDims must be 2 or 3, got '" + *nd + "'");
  g.dim = static_cast<int>(dim);
  const std::size_t d = static_cast<std::size_t>(dim);
  const std::string* ds = field("dimsize");
  if (!ds) fail(path, "MetaImage header has no DimSize");
  if (!parse_sizes(*ds, d, g.size.data()))
    fail(path, "MetaImage DimSize must give " + std::to_string(dim) + " positive integers, got '" + *ds + "'");
  const std::string* sp = field("elementspacing");
  if (!sp) sp = field("elementsize");
  if (sp && !parse_doubles(*sp, d, g.spacing.data()))
    fail(path, "MetaImage ElementSpacing must give " + std::to_string(dim) + " numbers, got '" + *sp + "'");
  const std::string* org = field("offset");
  if (!org) org = field("origin");
  if (!org) org = field("position");
  if (org && !parse_doubles(*org, d, g.origin.data()))
    fail(path, "MetaImage Offset must give " + std::to_string(dim) + " numbers, got '" + *org + "'");
  const std::string* tm = field("transformmatrix");
  if (!tm) tm = field("rotation");
  if (!tm) tm = field("orientation");
  if (tm) {
    double m[9];
    if (!parse_doubles(*tm, d * d, m))
      fail(path, "MetaImage TransformMatrix must give " + std::to_string(d * d) + " numbers, got '" + *tm + "'");
    // The identity, up to axes stored flipped (a -1 on the diagonal: read
    // reversed, the origin moved to the lowest voxel once the sizes are known).
    for (std::size_t r = 0; r < d; ++r)
      for (std::size_t c = 0; c < d; ++c)
        if (std::abs(std::abs(m[r * d + c]) - (r == c ? 1.0 : 0.0)) > 1e-9)
          fail(path, "MetaImage TransformMatrix is not axis-aligned (rotated or permuted images are not supported; "
                     "resample first)");
    for (std::size_t a = 0; a < d; ++a) raw.flip[a] = m[a * d + a] < 0;
  }
  if (const std::string* ch = field("elementnumberofchannels"); ch && trim(*ch) != "1")
    fail(path, "MetaImage ElementNumberOfChannels = " + *ch + ": multi-component data is not supported");
  const std::string* et = field("elementtype");
  if (!et) fail(path, "MetaImage header has no ElementType");
  if (!met_type(*et, raw.type)) fail(path, "unsupported MetaImage ElementType '" + *et + "'");
  bool binary = true, compressed = false, msb = false;
  if (const std::string* b = field("binarydata"); b && !parse_bool(*b, binary))
    fail(path, "MetaImage BinaryData must be True or False, got '" + *b + "'");
  if (const std::string* c = field("compresseddata"); c && !parse_bool(*c, compressed))
    fail(path, "MetaImage CompressedData must be True or False, got '" + *c + "'");
  const std::string* bo = field("binarydatabyteordermsb");
  if (!bo) bo = field("elementbyteordermsb");
  if (bo && !parse_bool(*bo, msb)) fail(path, "MetaImage BinaryDataByteOrderMSB must be True or False, got '" + *bo + "'");
  raw.big_endian = msb;
  std::int64_t header_size = 0;
  if (const std::string* hs = field("headersize")) {
    auto t = trim(*hs);
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), header_size);
    if (t.empty() || ec != std::errc() || p != t.data() + t.size() || header_size < -1)
      fail(path, "MetaImage HeaderSize must be an integer >= -1, got '" + *hs + "'");
  }
  std::int64_t compressed_size = -1;
  if (const std::string* cs = field("compresseddatasize")) {
    auto t = trim(*cs);
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), compressed_size);
    if (t.empty() || ec != std::errc() || p != t.data() + t.size() || compressed_size < 0)
      fail(path, "MetaImage CompressedDataSize must be an integer >= 0, got '" + *cs + "'");
  }
  for (std::size_t a = 0; a < 3; ++a)  // Offset is voxel 0's place; a flipped axis runs down from it
    if (raw.flip[a]) g.origin[a] -= static_cast<double>(g.size[a] - 1) * g.spacing[a];
  check_geometry(path, g);
  const std::size_t n = g.n_voxels();
  const std::size_t need = data_bytes(g, raw.type);

  // The data: LOCAL (after the header) or an external file.
  const std::string file = *field("elementdatafile");
  std::string data_path = path, external;
  std::string_view data;
  if (file == "LOCAL" || file == "local") {
    data = std::string_view(bytes).substr(data_start);
  } else {
    if (file.rfind("LIST", 0) == 0 || file.find('%') != std::string::npos || file.find(' ') != std::string::npos)
      fail(path, "MetaImage ElementDataFile '" + file + "': file lists and patterns are not supported");
    data_path = (!file.empty() && file.front() == '/') ? file : directory_of(path) + file;
    external = read_detached(path, data_path);
    data = external;
    if (header_size > 0) {
      if (static_cast<std::size_t>(header_size) > data.size())
        fail(data_path, "data shorter than the HeaderSize of " + path);
      data.remove_prefix(static_cast<std::size_t>(header_size));
    }
  }

  if (!binary) {
    raw.bytes = parse_ascii_values(data_path, data, raw.type, n);
    raw.big_endian = std::endian::native == std::endian::big;
    return raw;
  }
  if (compressed) {
    if (compressed_size >= 0) {
      if (static_cast<std::size_t>(compressed_size) > data.size())
        fail(data_path, "compressed data is " + std::to_string(data.size()) + " bytes, shorter than the CompressedDataSize " +
                            std::to_string(compressed_size) + " of the header");
      data = data.substr(0, static_cast<std::size_t>(compressed_size));
    }
    raw.bytes = inflate_exact(data_path, "compressed data", data, need);
    return raw;
  }
  if (header_size == -1 && data.size() > need) data = data.substr(data.size() - need);
  if (data.size() < need)
    fail(data_path, "data is " + std::to_string(data.size()) + " bytes, shorter than the " + std::to_string(need) +
                        " the header gives (" + std::to_string(n) + " voxels of " + scalar_name(raw.type) + ")");
  if (data.size() > need)
    fail(data_path, "data is " + std::to_string(data.size()) + " bytes, more than the " + std::to_string(need) +
                        " the header gives (mismatched sizes)");
  raw.bytes.assign(data.data(), data.size());
  return raw;
}

}  // namespace tessera::io::detail
