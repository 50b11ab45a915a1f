// PLY point reader: ascii, binary_little_endian and binary_big_endian. Only
// the `vertex` element is read: x, y (and z in 3D) plus an
// optional integer label property. Elements declared before `vertex` are
// skipped properly (including `property list` rows); elements after it are
// never looked at.
// Format: http://paulbourke.net/dataformats/ply/
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "io_detail.hpp"
#include "tessera/cells.hpp"

namespace tessera::io::detail {
namespace {

enum class Scalar { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };

struct Type {
  Scalar t = Scalar::f32;
  int size = 4;
  bool is_float() const { return t == Scalar::f32 || t == Scalar::f64; }
};

/// PLY type names, classic and sized aliases (int64/uint64 are non-standard but harmless).
bool lookup_type(std::string_view name, Type& type) {
  struct Entry {
    std::string_view name;
    Scalar t;
    int size;
  };
  static constexpr Entry kTypes[] = {
      {"char", Scalar::i8, 1},     {"int8", Scalar::i8, 1},    {"uchar", Scalar::u8, 1},
      {"uint8", Scalar::u8, 1},    {"short", Scalar::i16, 2},  {"int16", Scalar::i16, 2},
      {"ushort", Scalar::u16, 2},  {"uint16", Scalar::u16, 2}, {"int", Scalar::i32, 4},
      {"int32", Scalar::i32, 4},   {"uint", Scalar::u32, 4},   {"uint32", Scalar::u32, 4},
      {"int64", Scalar::i64, 8},   {"uint64", Scalar::u64, 8}, {"float", Scalar::f32, 4},
      {"float32", Scalar::f32, 4}, {"double", Scalar::f64, 8}, {"float64", Scalar::f64, 8},
  };
  for (const Entry& e : kTypes) {
    if (e.name == name) {
      type = Type{e.t, e.size};
      return true;
    }
  }
  return false;
}

struct Property {
  std::string name;
  bool is_list = false;
  Type type;        ///< scalar type, or the list item type
  Type count_type;  ///< list length type
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> props;
};

enum class Format { ascii, binary_le, binary_be };

struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  std::size_t data_start = 0;  ///< byte offset just past "end_header\n"
};

std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    std::size_t b = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
    if (i > b) out.push_back(s.substr(b, i - b));
  }
  return out;
}

Header parse_header(const std::string& path, std::string_view bytes) {
  Header h;
  std::size_t pos = 0;
  std::size_t line_no = 0;
  bool have_format = false;
  auto next_line = [&](std::string_view& line) {
    if (pos >= bytes.size()) return false;
    std::size_t nl = bytes.find('\n', pos);
    if (nl == std::string_view::npos) nl = bytes.size();
    line = bytes.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    return true;
  };
  std::string_view line;
  if (!next_line(line) || split_ws(line) != std::vector<std::string_view>{"ply"})
    fail(path, "not a PLY file (first line is not 'ply')");
  for (;;) {
    if (!next_line(line)) fail(path, "PLY header has no end_header");
    auto tok = split_ws(line);
    auto bad = [&](const std::string& what) {
      fail(path, "PLY header line " + std::to_string(line_no) + ": " + what);
    };
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") break;
    if (tok[0] == "format") {
      if (tok.size() < 2) bad("format line without a format");
      if (tok[1] == "ascii")
        h.format = Format::ascii;
      else if (tok[1] == "binary_little_endian")
        h.format = Format::binary_le;
      else if (tok[1] == "binary_big_endian")
        h.format = Format::binary_be;
      else
        bad("unknown format '" + std::string(tok[1]) + "'");
      have_format = true;
    } else if (tok[0] == "element") {
      if (tok.size() != 3) bad("expected 'element NAME COUNT'");
      Element e;
      e.name = std::string(tok[1]);
      auto [p, ec] = std::from_chars(tok[2].data(), tok[2].data() + tok[2].size(), e.count);
      if (ec != std::errc() || p != tok[2].data() + tok[2].size())
        bad("bad element count '" + std::string(tok[2]) + "'");
      h.elements.push_back(std::move(e));
    } else if (tok[0] == "property") {
      if (h.elements.empty()) bad("property before any element");
      Property prop;
      if (tok.size() == 5 && tok[1] == "list") {
        prop.is_list = true;
        if (!lookup_type(tok[2], prop.count_type) || prop.count_type.is_float())
          bad("bad list count type '" + std::string(tok[2]) + "'");
        if (!lookup_type(tok[3], prop.type)) bad("unknown type '" + std::string(tok[3]) + "'");
        prop.name = std::string(tok[4]);
      } else if (tok.size() == 3) {
        if (!lookup_type(tok[1], prop.type)) bad("unknown type '" + std::string(tok[1]) + "'");
        prop.name = std::string(tok[2]);
      } else {
        bad("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'");
      }
      h.elements.back().props.push_back(std::move(prop));
    } else {
      bad("unexpected keyword '" + std::string(tok[0]) + "'");
    }
  }
  if (!have_format) fail(path, "PLY header has no format line");
  h.data_start = std::min(pos, bytes.size());
  return h;
}

/// A scalar stored big-endian (`big`) or little-endian at `p`.
template <class T>
T load_binary(const unsigned char* p, bool big) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (big != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// A binary scalar of type `t` at `p`, as double (exact for all but 64-bit
/// integers beyond 2^53, which are not coordinates or labels anyway).
double load_value(const unsigned char* p, Scalar t, bool big) {
  switch (t) {
    case Scalar::i8:
      return static_cast<std::int8_t>(p[0]);
    case Scalar::u8:
      return p[0];
    case Scalar::i16:
      return load_binary<std::int16_t>(p, big);
    case Scalar::u16:
      return load_binary<std::uint16_t>(p, big);
    case Scalar::i32:
      return load_binary<std::int32_t>(p, big);
    case Scalar::u32:
      return load_binary<std::uint32_t>(p, big);
    case Scalar::i64:
      return static_cast<double>(load_binary<std::int64_t>(p, big));
    case Scalar::u64:
      return static_cast<double>(load_binary<std::uint64_t>(p, big));
    case Scalar::f32:
      return load_binary<float>(p, big);
    case Scalar::f64:
      return load_binary<double>(p, big);
  }
  return 0;
}

/// Where each vertex property goes: 0..2 a coordinate, 3 the label, -1 nowhere.
constexpr int kLabelSlot = 3;

/// Reads element rows from the data section, in either encoding.
class DataReader {
 public:
  DataReader(const std::string& path, const Header& h, std::string_view bytes)
      : path_(path),
        format_(h.format),
        p_(reinterpret_cast<const unsigned char*>(bytes.data()) + h.data_start),
        end_(reinterpret_cast<const unsigned char*>(bytes.data()) + bytes.size()) {}

  /// Skip every row of `e`.
  void skip(const Element& e) {
    if (format_ != Format::ascii) {
      bool fixed = std::none_of(e.props.begin(), e.props.end(), [](const Property& p) { return p.is_list; });
      if (fixed) {
        std::size_t stride = 0;
        for (const Property& p : e.props) stride += static_cast<std::size_t>(p.type.size);
        if (stride && e.count > static_cast<std::size_t>(end_ - p_) / stride) truncated(e, 0);
        p_ += stride * e.count;
        return;
      }
    }
    const std::vector<int> none(e.props.size(), -1);
    double sink[4];
    for (std::size_t r = 0; r < e.count; ++r) row(e, r, none, sink);
  }

  /// Read row `r` of `e`: the property with slot s >= 0 is stored in out[s].
  void row(const Element& e, std::size_t r, const std::vector<int>& slot, double* out) {
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const Property& prop = e.props[k];
      if (prop.is_list) {
        const double n = value(e, r, prop.count_type);
        if (n < 0 || n != std::floor(n))
          fail(path_, "bad list length in element '" + e.name + "' row " + std::to_string(r));
        skip_values(e, r, prop.type, static_cast<std::size_t>(n));
      } else if (slot[k] >= 0) {
        out[slot[k]] = value(e, r, prop.type);
      } else {
        skip_values(e, r, prop.type, 1);
      }
    }
  }

 private:
  [[noreturn]] void truncated(const Element& e, std::size_t r) const {
    fail(path_, "PLY data ends early in element '" + e.name + "' (row " + std::to_string(r) + " of " +
                    std::to_string(e.count) + ")");
  }

  /// ASCII: the next whitespace-separated token, or an error at end of data.
  std::string_view token(const Element& e, std::size_t r) {
    while (p_ < end_ && (*p_ == ' ' || *p_ == '\t' || *p_ == '\n' || *p_ == '\r')) ++p_;
    if (p_ == end_) truncated(e, r);
    const unsigned char* b = p_;
    while (p_ < end_ && !(*p_ == ' ' || *p_ == '\t' || *p_ == '\n' || *p_ == '\r')) ++p_;
    return std::string_view(reinterpret_cast<const char*>(b), static_cast<std::size_t>(p_ - b));
  }

  double value(const Element& e, std::size_t r, const Type& t) {
    if (format_ != Format::ascii) {
      if (static_cast<std::size_t>(end_ - p_) < static_cast<std::size_t>(t.size)) truncated(e, r);
      double v = load_value(p_, t.t, format_ == Format::binary_be);
      p_ += t.size;
      return v;
    }
    std::string_view tok = token(e, r);
    const char* b = tok.data();
    const char* end = b + tok.size();
    if (b != end && *b == '+') ++b;
    double v = 0;
    auto [q, ec] = std::from_chars(b, end, v);
    if (ec != std::errc() || q != end)
      fail(path_, "cannot parse '" + std::string(tok) + "' as a number in element '" + e.name + "' row " +
                      std::to_string(r));
    return v;
  }

  void skip_values(const Element& e, std::size_t r, const Type& t, std::size_t n) {
    if (format_ != Format::ascii) {
      if (n > static_cast<std::size_t>(end_ - p_) / static_cast<std::size_t>(t.size)) truncated(e, r);
      p_ += n * static_cast<std::size_t>(t.size);
      return;
    }
    for (std::size_t k = 0; k < n; ++k) token(e, r);
  }

  const std::string& path_;
  Format format_;
  const unsigned char* p_;
  const unsigned char* end_;
};

std::string property_names(const Element& e) {
  std::string s;
  for (std::size_t k = 0; k < e.props.size(); ++k) s += (k ? ", " : "") + e.props[k].name;
  return s.empty() ? "none" : s;
}

}  // namespace

PointCloud read_ply_points(const std::string& path, const ReadOptions& options,
                           const std::string& label_property) {
  const std::string bytes = read_file_bytes(path);
  const Header h = parse_header(path, bytes);

  auto vit =
      std::find_if(h.elements.begin(), h.elements.end(), [](const Element& e) { return e.name == "vertex"; });
  if (vit == h.elements.end()) fail(path, "PLY file has no 'vertex' element");
  const Element& vertex = *vit;

  // PLY is 3D unless 2D is forced, in which case z is not needed.
  const int dim = options.dim == 2 ? 2 : 3;
  std::vector<int> slot(vertex.props.size(), -1);
  const char* axes[3] = {"x", "y", "z"};
  for (int a = 0; a < dim; ++a) {
    auto it = std::find_if(vertex.props.begin(), vertex.props.end(),
                           [&](const Property& p) { return p.name == axes[a]; });
    if (it == vertex.props.end() || it->is_list)
      fail(path, std::string("vertex element has no scalar '") + axes[a] +
                     "' property (properties: " + property_names(vertex) + ")");
    slot[static_cast<std::size_t>(it - vertex.props.begin())] = a;
  }
  const bool want_labels = !label_property.empty();
  if (want_labels) {
    auto it = std::find_if(vertex.props.begin(), vertex.props.end(),
                           [&](const Property& p) { return p.name == label_property; });
    if (it == vertex.props.end())
      fail(path, "no vertex property '" + label_property +
                     "' for labels (properties: " + property_names(vertex) + ")");
    if (it->is_list || it->type.is_float())
      fail(path, "vertex property '" + label_property + "' must be an integer scalar to serve as labels");
    slot[static_cast<std::size_t>(it - vertex.props.begin())] = kLabelSlot;
  }

  DataReader reader(path, h, bytes);
  for (auto it = h.elements.begin(); it != vit; ++it) reader.skip(*it);

  PointCloud pc;
  pc.dim = dim;
  pc.n = vertex.count;
  // Every vertex takes at least one byte, so a count beyond the file size is
  // corrupt; don't let it drive a huge allocation before the truncation error.
  const std::size_t reserve = std::min(vertex.count, bytes.size());
  pc.coords.reserve(reserve * static_cast<std::size_t>(dim));
  if (want_labels) pc.labels.reserve(reserve);
  double v[4] = {0, 0, 0, 0};
  for (std::size_t r = 0; r < vertex.count; ++r) {
    reader.row(vertex, r, slot, v);
    pc.coords.insert(pc.coords.end(), v, v + dim);
    if (want_labels) {
      if (v[kLabelSlot] != std::floor(v[kLabelSlot]) ||
          v[kLabelSlot] < std::numeric_limits<std::int32_t>::min() ||
          v[kLabelSlot] > std::numeric_limits<std::int32_t>::max())
        fail(path, "vertex " + std::to_string(r) + ": label " + std::to_string(v[kLabelSlot]) +
                       " is not a 32-bit integer");
      pc.labels.push_back(static_cast<std::int32_t>(v[kLabelSlot]));
    }
  }
  return pc;
}

std::vector<double> read_ply_property(const std::string& path, const std::string& name) {
  const std::string bytes = read_file_bytes(path);
  const Header h = parse_header(path, bytes);
  auto vit =
      std::find_if(h.elements.begin(), h.elements.end(), [](const Element& e) { return e.name == "vertex"; });
  if (vit == h.elements.end()) fail(path, "PLY file has no 'vertex' element");
  const Element& vertex = *vit;
  auto it = std::find_if(vertex.props.begin(), vertex.props.end(), [&](const Property& p) { return p.name == name; });
  if (it == vertex.props.end())
    fail(path, "no vertex property '" + name + "' (properties: " + property_names(vertex) + ")");
  if (it->is_list) fail(path, "vertex property '" + name + "' is a list, not a scalar");
  std::vector<int> slot(vertex.props.size(), -1);
  slot[static_cast<std::size_t>(it - vertex.props.begin())] = 0;

  DataReader reader(path, h, bytes);
  for (auto e = h.elements.begin(); e != vit; ++e) reader.skip(*e);
  std::vector<double> values;
  values.reserve(std::min(vertex.count, bytes.size()));
  double v[4] = {0, 0, 0, 0};
  for (std::size_t r = 0; r < vertex.count; ++r) {
    reader.row(vertex, r, slot, v);
    values.push_back(v[0]);
  }
  return values;
}

}  // namespace tessera::io::detail
