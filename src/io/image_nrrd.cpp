// NRRD images (.nrrd with attached data, .nhdr with a detached data file),
// after the format definition at http://teem.sourceforge.net/nrrd/format.html.
//
//   NRRD0004                      magic (NRRD0001..NRRD0005)
//   # comment
//   type: short                   field "name: value" (names case-insensitive)
//   dimension: 3
//   sizes: 6 5 4                  x fastest
//   space directions: (0.5,0,0) (0,0.25,0) (0,0,2)   or  spacings: 0.5 0.25 2
//   space origin: (1,-2,3)
//   endian: little
//   encoding: raw | gzip | ascii
//   data file: other.raw          detached data (path relative to the header)
//   key:=value                    key/value pairs (ignored)
//   <blank line>                  attached data follows
//
// Supported: 2D/3D scalar images, every integer and float type, raw, gzip and
// ascii encodings, "line skip" and "byte skip" (-1 for raw: data at the end of
// the file), axis-aligned space directions (a negative step: the axis read
// reversed), or spacings
// with axis mins (and maxs) placed by their centering. Rejected with a
// one-line error: other encodings (hex, bzip2), multi-file data ("LIST",
// formats), non-spatial (vector, colour) axes, rotated or permuted directions,
// and fields NRRD does not define (a misspelt field was silently ignored).
#include <algorithm>
#include <bit>
#include <charconv>
#include <cctype>
#include <cmath>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "image_detail.hpp"
#include "io_detail.hpp"

namespace tessera::io::detail {
namespace {

/// NRRD type names (all the spellings the format allows).
bool nrrd_type(const std::string& name, ScalarType& t) {
  static const std::map<std::string, ScalarType> types = {
      {"signed char", ScalarType::i8},
      {"int8", ScalarType::i8},
      {"int8_t", ScalarType::i8},
      {"uchar", ScalarType::u8},
      {"unsigned char", ScalarType::u8},
      {"uint8", ScalarType::u8},
      {"uint8_t", ScalarType::u8},
      {"short", ScalarType::i16},
      {"short int", ScalarType::i16},
      {"signed short", ScalarType::i16},
      {"signed short int", ScalarType::i16},
      {"int16", ScalarType::i16},
      {"int16_t", ScalarType::i16},
      {"ushort", ScalarType::u16},
      {"unsigned short", ScalarType::u16},
      {"unsigned short int", ScalarType::u16},
      {"uint16", ScalarType::u16},
      {"uint16_t", ScalarType::u16},
      {"int", ScalarType::i32},
      {"signed int", ScalarType::i32},
      {"int32", ScalarType::i32},
      {"int32_t", ScalarType::i32},
      {"uint", ScalarType::u32},
      {"unsigned int", ScalarType::u32},
      {"uint32", ScalarType::u32},
      {"uint32_t", ScalarType::u32},
      {"longlong", ScalarType::i64},
      {"long long", ScalarType::i64},
      {"long long int", ScalarType::i64},
      {"signed long long", ScalarType::i64},
      {"signed long long int", ScalarType::i64},
      {"int64", ScalarType::i64},
      {"int64_t", ScalarType::i64},
      {"ulonglong", ScalarType::u64},
      {"unsigned long long", ScalarType::u64},
      {"unsigned long long int", ScalarType::u64},
      {"uint64", ScalarType::u64},
      {"uint64_t", ScalarType::u64},
      {"float", ScalarType::f32},
      {"double", ScalarType::f64},
  };
  auto it = types.find(name);
  if (it == types.end()) return false;
  t = it->second;
  return true;
}

/// Splits "(1,0,0) none (0,1,0)" into its vectors; "none" gives an empty
/// vector. Returns false on bad syntax.
bool parse_vectors(std::string_view s, std::vector<std::vector<double>>& out) {
  out.clear();
  std::size_t i = 0;
  for (;;) {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
    if (i >= s.size()) return true;
    if (s.substr(i, 4) == "none") {
      out.emplace_back();
      i += 4;
      continue;
    }
    if (s[i] != '(') return false;
    const std::size_t close = s.find(')', i);
    if (close == std::string_view::npos) return false;
    std::string inner(s.substr(i + 1, close - i - 1));
    std::replace(inner.begin(), inner.end(), ',', ' ');
    std::size_t count = 0;
    bool in_token = false;
    for (char c : inner) {
      const bool ws = std::isspace(static_cast<unsigned char>(c)) != 0;
      if (!ws && !in_token) ++count;
      in_token = !ws;
    }
    if (count == 0) return false;
    std::vector<double> v(count);
    if (!parse_doubles(inner, count, v.data())) return false;
    out.push_back(std::move(v));
    i = close + 1;
  }
}

struct Header {
  std::string magic;
  std::map<std::string, std::string> fields;  // lower-cased names
  std::size_t data_start = 0;                 // attached: offset of the data in the file
  bool attached = false;
};

Header parse_header(const std::string& path, const std::string& bytes) {
  Header h;
  std::size_t pos = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= bytes.size()) return false;
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    line = std::string_view(bytes).substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = std::min(end + 1, bytes.size());
    return true;
  };
  std::string_view line;
  if (!next_line(line) || line.size() != 8 || line.substr(0, 7) != "NRRD000" || line[7] < '1' || line[7] > '5')
    fail(path, "not a NRRD file (the first line must be NRRD0001 .. NRRD0005)");
  h.magic = std::string(line);
  while (next_line(line)) {
    if (line.empty()) {
      h.attached = true;
      h.data_start = pos;
      return h;
    }
    if (line.front() == '#') continue;
    const std::size_t kv = line.find(":=");
    const std::size_t colon = line.find(": ");
    if (kv != std::string_view::npos && (colon == std::string_view::npos || kv < colon)) continue;  // key/value
    if (colon == std::string_view::npos) {
      // A line without "field: value" is where binary data (with no blank
      // line before it) or garbage begins.
      fail(path, "malformed NRRD header line '" + printable(line) + "' (expected 'field: value')");
    }
    std::string name = lower(trim(line.substr(0, colon)));
    if (name == "datafile") name = "data file";
    if (name == "centerings") name = "centers";
    if (name == "byteskip") name = "byte skip";
    if (name == "lineskip") name = "line skip";
    if (name == "blocksize") name = "block size";
    // teem refuses what it does not know; so do we, as a misspelt
    // "spacing" or "space orign" silently left a unit grid at 0.
    static const char* const known[] = {
        "dimension", "type",       "encoding",    "endian",        "content",          "min",
        "max",       "old min",    "old max",     "sizes",         "spacings",         "thicknesses",
        "axis mins", "axis maxs",  "centers",     "labels",        "units",            "kinds",
        "space",     "space dimension", "space units", "space origin", "space directions", "measurement frame",
        "block size", "data file", "line skip",   "byte skip",     "sample units",     "number"};
    if (std::find(std::begin(known), std::end(known), name) == std::end(known))
      fail(path, "unknown NRRD field '" + name + "' (a misspelling?)");
    if (h.fields.count(name)) fail(path, "NRRD field '" + name + "' given twice");
    h.fields[name] = std::string(trim(line.substr(colon + 2)));
  }
  return h;  // header ran to the end of the file: detached data only
}

std::int64_t parse_int(const std::string& path, const std::string& field, const std::string& v) {
  std::string_view s = trim(v);
  std::int64_t x = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
  if (s.empty() || ec != std::errc() || p != s.data() + s.size())
    fail(path, "NRRD field '" + field + "': '" + v + "' is not an integer");
  return x;
}

}  // namespace

RawImage read_nrrd_image(const std::string& path) {
  const std::string bytes = read_file_bytes(path);
  Header h = parse_header(path, bytes);
  auto field = [&](const char* name) -> const std::string* {
    auto it = h.fields.find(name);
    return it == h.fields.end() ? nullptr : &it->second;
  };
  auto require = [&](const char* name) -> const std::string& {
    const std::string* v = field(name);
    if (!v) fail(path, std::string("NRRD header has no '") + name + "' field");
    return *v;
  };

  RawImage raw;
  const std::string type_name = lower(require("type"));
  if (!nrrd_type(type_name, raw.type)) fail(path, "unsupported NRRD type '" + type_name + "'");
  const std::int64_t dim = parse_int(path, "dimension", require("dimension"));
  if (dim != 2 && dim != 3)
    fail(path, "NRRD dimension " + std::to_string(dim) + " is not supported (2D or 3D scalar images only)");
  ImageGeometry& g = raw.geometry;
  g.dim = static_cast<int>(dim);
  if (!parse_sizes(require("sizes"), static_cast<std::size_t>(dim), g.size.data()))
    fail(path, "NRRD field 'sizes' must give " + std::to_string(dim) + " positive integers, got '" +
                   require("sizes") + "'");
  if (const std::string* kinds = field("kinds")) {
    std::string_view rest = *kinds;
    std::size_t p = 0;
    int axis = 0;
    while (true) {
      while (p < rest.size() && rest[p] == ' ') ++p;
      if (p >= rest.size()) break;
      std::size_t e = rest.find(' ', p);
      if (e == std::string_view::npos) e = rest.size();
      const std::string k = lower(rest.substr(p, e - p));
      if (k != "domain" && k != "space" && k != "time" && k != "???" && k != "none")
        fail(path, "NRRD axis " + std::to_string(axis) + " has kind '" + k +
                       "': multi-component (vector, colour) data is not supported");
      ++axis;
      p = e;
    }
  }

  // Geometry: space directions (+ space origin), or spacings.
  const std::string* dirs = field("space directions");
  if (dirs) {
    std::vector<std::vector<double>> vs;
    if (!parse_vectors(*dirs, vs) || vs.size() != static_cast<std::size_t>(dim))
      fail(path, "NRRD field 'space directions' must give " + std::to_string(dim) + " vectors like (1,0,0), got '" +
                     *dirs + "'");
    const std::size_t sdim = vs[0].size();
    for (std::size_t a = 0; a < vs.size(); ++a) {
      if (vs[a].empty())
        fail(path, "NRRD axis " + std::to_string(a) + " is not spatial ('none'): multi-component data is not supported");
      if (vs[a].size() != sdim || sdim < static_cast<std::size_t>(dim) || sdim > 3)
        fail(path, "NRRD 'space directions' vectors have inconsistent lengths");
      for (std::size_t c = 0; c < sdim; ++c) {
        const double x = vs[a][c];
        if ((c == a && !(x != 0)) || (c != a && x != 0))
          fail(path, "NRRD 'space directions' are not axis-aligned (rotated or permuted images are not supported; "
                     "resample first)");
      }
      // A negative step: the axis is stored flipped, and read reversed.
      raw.flip[a] = vs[a][a] < 0;
      g.spacing[a] = std::fabs(vs[a][a]);
    }
    if (const std::string* org = field("space origin")) {
      std::vector<std::vector<double>> o;
      if (!parse_vectors(*org, o) || o.size() != 1 || o[0].size() != sdim)
        fail(path, "NRRD field 'space origin' must be one vector of " + std::to_string(sdim) + " numbers, got '" +
                       *org + "'");
      for (std::size_t c = 0; c < sdim; ++c) g.origin[c] = o[0][c];
    }
    for (std::size_t a = 0; a < static_cast<std::size_t>(dim); ++a)
      if (raw.flip[a]) g.origin[a] += static_cast<double>(g.size[a] - 1) * vs[a][a];
    if (field("spacings")) fail(path, "NRRD header gives both 'spacings' and 'space directions'");
    if (field("axis mins") || field("axis maxs"))
      fail(path, "NRRD header gives both 'axis mins' or 'axis maxs' and 'space directions'");
  } else {
    if (field("space origin")) fail(path, "NRRD header gives 'space origin' without 'space directions'");
    const std::size_t d = static_cast<std::size_t>(dim);
    if (const std::string* sp = field("spacings")) {
      if (!parse_doubles(*sp, d, g.spacing.data()))
        fail(path, "NRRD field 'spacings' must give " + std::to_string(dim) + " finite numbers, got '" + *sp + "'");
    }
    // Axis mins place the grid as teem does: a cell-centred axis (teem's
    // default) has its first sample half a spacing above its min, a
    // node-centred one at it; without spacings, axis maxs give them.
    if (const std::string* mins = field("axis mins")) {
      double lo[3], hi[3];
      if (!parse_doubles(*mins, d, lo))
        fail(path, "NRRD field 'axis mins' must give " + std::to_string(dim) + " finite numbers, got '" + *mins + "'");
      const std::string* maxs = field("axis maxs");
      if (maxs && !parse_doubles(*maxs, d, hi))
        fail(path, "NRRD field 'axis maxs' must give " + std::to_string(dim) + " finite numbers, got '" + *maxs + "'");
      std::vector<std::string> centers(d, "cell");
      if (const std::string* c = field("centers")) {
        std::vector<std::string> words;
        for (std::string_view rest = *c; !trim(rest).empty();) {
          rest = trim(rest);
          const std::size_t e = std::min(rest.find(' '), rest.size());
          words.push_back(lower(rest.substr(0, e)));
          rest.remove_prefix(e);
        }
        if (words.size() != d) fail(path, "NRRD field 'centers' must give " + std::to_string(dim) + " centerings");
        for (std::size_t a = 0; a < d; ++a) {
          if (words[a] != "cell" && words[a] != "node" && words[a] != "???" && words[a] != "none")
            fail(path, "NRRD axis " + std::to_string(a) + " has centering '" + words[a] + "' (cell or node)");
          if (words[a] == "node") centers[a] = "node";
        }
      }
      for (std::size_t a = 0; a < d; ++a) {
        const bool cell = centers[a] == "cell";
        if (!field("spacings") && maxs) {
          const double steps = static_cast<double>(cell ? g.size[a] : g.size[a] - 1);
          g.spacing[a] = steps > 0 ? (hi[a] - lo[a]) / steps : 1;
        }
        g.origin[a] = lo[a] + (cell ? 0.5 * g.spacing[a] : 0.0);
      }
    } else if (field("axis maxs")) {
      fail(path, "NRRD header gives 'axis maxs' without 'axis mins' (give both, or 'space origin' with 'space "
                 "directions')");
    }
  }

  // Encoding and the data bytes.
  std::string enc = lower(field("encoding") ? *field("encoding") : std::string());
  if (enc.empty()) fail(path, "NRRD header has no 'encoding' field");
  if (enc == "gz") enc = "gzip";
  if (enc == "txt" || enc == "text") enc = "ascii";
  if (enc != "raw" && enc != "gzip" && enc != "ascii")
    fail(path, "unsupported NRRD encoding '" + enc + "' (expected raw, gzip or ascii)");
  const std::size_t item = scalar_size(raw.type);
  if (enc != "ascii" && item > 1) {
    const std::string* endian = field("endian");
    if (!endian) fail(path, "NRRD header has no 'endian' field (needed for " + type_name + " data)");
    const std::string e = lower(*endian);
    if (e != "little" && e != "big") fail(path, "NRRD field 'endian' must be little or big, got '" + *endian + "'");
    raw.big_endian = e == "big";
  }
  const std::int64_t line_skip = field("line skip") ? parse_int(path, "line skip", *field("line skip")) : 0;
  const std::int64_t byte_skip = field("byte skip") ? parse_int(path, "byte skip", *field("byte skip")) : 0;
  if (line_skip < 0) fail(path, "NRRD 'line skip' must be >= 0");
  if (byte_skip < -1) fail(path, "NRRD 'byte skip' must be >= -1");
  if (byte_skip == -1 && enc != "raw") fail(path, "NRRD 'byte skip: -1' is only allowed with raw encoding");

  check_geometry(path, g);
  const std::size_t n = g.n_voxels();
  const std::size_t need = data_bytes(g, raw.type);

  std::string data_path = path;
  std::string detached;
  std::string_view data;
  if (const std::string* df = field("data file")) {
    const std::string name(trim(*df));
    if (name.rfind("LIST", 0) == 0 || name.find(' ') != std::string::npos || name.find('%') != std::string::npos)
      fail(path, "NRRD multi-file data ('data file: " + name + "') is not supported");
    data_path = (!name.empty() && name.front() == '/') ? name : directory_of(path) + name;
    detached = read_detached(path, data_path);
    data = detached;
  } else {
    if (!h.attached) fail(path, "NRRD header has no 'data file' field and no blank line before attached data");
    data = std::string_view(bytes).substr(h.data_start);
  }
  for (std::int64_t l = 0; l < line_skip; ++l) {
    const std::size_t nl = data.find('\n');
    if (nl == std::string_view::npos) fail(data_path, "data shorter than the NRRD 'line skip' of the header " + path);
    data.remove_prefix(nl + 1);
  }

  if (enc == "ascii") {
    // (teem skips the bytes in every encoding but the compressed ones)
    const std::size_t skip = static_cast<std::size_t>(byte_skip);
    if (data.size() < skip) fail(data_path, "data shorter than the NRRD 'byte skip' of the header " + path);
    data.remove_prefix(skip);
    raw.bytes = parse_ascii_values(data_path, data, raw.type, n);
    raw.big_endian = std::endian::native == std::endian::big;
    return raw;
  }
  if (enc == "gzip") {
    const std::size_t skip = static_cast<std::size_t>(byte_skip);
    std::string full = inflate_exact(data_path, "gzip data", data, skip + need);
    raw.bytes = full.substr(skip);
    return raw;
  }
  // raw
  if (byte_skip == -1) {
    if (data.size() < need)
      fail(data_path, "data is " + std::to_string(data.size()) + " bytes, shorter than the " + std::to_string(need) +
                          " the header gives (" + std::to_string(n) + " voxels of " + type_name + ")");
    data = data.substr(data.size() - need);
  } else {
    const std::size_t skip = static_cast<std::size_t>(byte_skip);
    if (data.size() < skip + need)
      fail(data_path, "data is " + std::to_string(data.size() > skip ? data.size() - skip : 0) +
                          " bytes, shorter than the " + std::to_string(need) + " the header gives (" +
                          std::to_string(n) + " voxels of " + type_name + ")");
    if (data.size() > skip + need)
      fail(data_path, "data is " + std::to_string(data.size() - skip) + " bytes, more than the " +
                          std::to_string(need) + " the header gives (mismatched sizes)");
    data = data.substr(skip);
  }
  raw.bytes.assign(data.data(), data.size());
  return raw;
}

}  // namespace tessera::io::detail
