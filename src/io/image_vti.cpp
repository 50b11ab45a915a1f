// VTK XML ImageData (.vti), after VTK's "VTK File Formats" (XML section).
//
//   <VTKFile type="ImageData" byte_order="LittleEndian" header_type="UInt32"
//            compressor="vtkZLibDataCompressor">
//     <ImageData WholeExtent="x0 x1 y0 y1 z0 z1" Origin="..." Spacing="..." Direction="1 0 0 0 1 0 0 0 1">
//       <Piece Extent="...">
//         <PointData Scalars="name">
//           <DataArray type="Int32" Name="name" format="ascii|binary|appended" offset="0">...</DataArray>
//     ...
//     <AppendedData encoding="raw|base64">_DATA</AppendedData>
//
// Binary data (inline base64, appended raw or base64) is a header of
// header_type integers then the bytes: uncompressed [nbytes] + data;
// zlib-compressed [nblocks, block size, last block size (0: full), compressed
// size of each block] + the blocks, each a zlib stream. VTK base64-encodes the
// header and the data either as one stream or as two (each padded), so the
// decoder below restarts after every padded quantum.
//
// Voxel (i, j, k) of extent [x0..x1]x[y0..y1]x[z0..z1] sits at Origin +
// (i, j, k) * Spacing, so the geometry's origin (voxel of index 0) is
// Origin + (x0, y0, z0) * Spacing: cropped extents keep their true positions.
// An image with one slice along z is 2D. Several pieces are assembled into
// the whole extent (they may share their boundary layer, as VTK's do).
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "image_detail.hpp"
#include "io_detail.hpp"

namespace tessera::io::detail {
namespace {

// ------------------------------------------------------------ a small XML scanner

struct Element {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::vector<std::size_t> children;  // indices into the element list
  std::size_t content_begin = 0, content_end = 0;  // text between the tags
};

std::string decode_entities(std::string_view s) {
  std::string r;
  r.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '&') {
      r += s[i];
      continue;
    }
    static constexpr std::pair<std::string_view, char> ents[] = {
        {"&quot;", '"'}, {"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&apos;", '\''}};
    bool done = false;
    for (auto [e, c] : ents)
      if (s.substr(i, e.size()) == e) {
        r += c;
        i += e.size() - 1;
        done = true;
        break;
      }
    if (!done) r += '&';
  }
  return r;
}

bool name_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == ':' || c == '.';
}

/// Parses the XML part of a .vti file into elements (element 0 is a virtual
/// root). Stops at <AppendedData>: what follows its '_' is data, not XML.
class XmlScanner {
 public:
  XmlScanner(const std::string& path, const std::string& text) : path_(path), s_(text) {}

  std::vector<Element> elements;
  std::size_t appended = std::string::npos;  ///< element index of AppendedData
  std::size_t appended_start = 0;            ///< offset of the byte after '_'

  void run() {
    elements.emplace_back();  // virtual root
    std::vector<std::size_t> stack{0};
    std::size_t i = 0;
    while (i < s_.size()) {
      const std::size_t lt = s_.find('<', i);
      if (lt == std::string::npos) break;
      if (s_.compare(lt, 4, "<!--") == 0) {
        const std::size_t e = s_.find("-->", lt + 4);
        if (e == std::string::npos) bad("unterminated comment");
        i = e + 3;
        continue;
      }
      if (s_.compare(lt, 2, "<?") == 0 || s_.compare(lt, 2, "<!") == 0) {
        const std::size_t e = s_.find('>', lt);
        if (e == std::string::npos) bad("unterminated declaration");
        i = e + 1;
        continue;
      }
      if (s_.compare(lt, 2, "</") == 0) {
        std::size_t p = lt + 2;
        const std::size_t start = p;
        while (p < s_.size() && name_char(s_[p])) ++p;
        const std::string name = s_.substr(start, p - start);
        const std::size_t gt = s_.find('>', p);
        if (gt == std::string::npos) bad("unterminated end tag </" + name + ">");
        if (stack.size() < 2 || elements[stack.back()].name != name)
          bad("unexpected end tag </" + name + ">");
        elements[stack.back()].content_end = lt;
        stack.pop_back();
        i = gt + 1;
        continue;
      }
      // start tag
      std::size_t p = lt + 1;
      const std::size_t start = p;
      while (p < s_.size() && name_char(s_[p])) ++p;
      if (p == start) bad("malformed tag");
      Element el;
      el.name = s_.substr(start, p - start);
      bool self_closing = false;
      for (;;) {
        while (p < s_.size() && std::isspace(static_cast<unsigned char>(s_[p]))) ++p;
        if (p >= s_.size()) bad("unterminated tag <" + el.name + ">");
        if (s_[p] == '/') {
          if (p + 1 >= s_.size() || s_[p + 1] != '>') bad("malformed tag <" + el.name + ">");
          self_closing = true;
          p += 2;
          break;
        }
        if (s_[p] == '>') {
          ++p;
          break;
        }
        const std::size_t an = p;
        while (p < s_.size() && name_char(s_[p])) ++p;
        if (p == an) bad("malformed attribute in <" + el.name + ">");
        const std::string aname = s_.substr(an, p - an);
        while (p < s_.size() && std::isspace(static_cast<unsigned char>(s_[p]))) ++p;
        if (p >= s_.size() || s_[p] != '=') bad("attribute " + aname + " of <" + el.name + "> has no value");
        ++p;
        while (p < s_.size() && std::isspace(static_cast<unsigned char>(s_[p]))) ++p;
        if (p >= s_.size() || (s_[p] != '"' && s_[p] != '\'')) bad("attribute " + aname + " is not quoted");
        const char q = s_[p++];
        const std::size_t close = s_.find(q, p);
        if (close == std::string::npos) bad("unterminated attribute " + aname);
        el.attrs[aname] = decode_entities(std::string_view(s_).substr(p, close - p));
        p = close + 1;
      }
      el.content_begin = el.content_end = p;
      const std::size_t idx = elements.size();
      elements[stack.back()].children.push_back(idx);
      const bool is_appended = el.name == "AppendedData";
      elements.push_back(std::move(el));
      if (is_appended) {
        if (self_closing) bad("empty <AppendedData/>");
        appended = idx;
        while (p < s_.size() && std::isspace(static_cast<unsigned char>(s_[p]))) ++p;
        if (p >= s_.size() || s_[p] != '_') bad("<AppendedData> does not start with '_'");
        appended_start = p + 1;
        return;  // the rest is data
      }
      if (!self_closing) stack.push_back(idx);
      i = p;
    }
    if (stack.size() > 1) bad("unterminated element <" + elements[stack.back()].name + ">");
  }

 private:
  [[noreturn]] void bad(const std::string& what) const { fail(path_, "malformed XML: " + what); }
  const std::string& path_;
  const std::string& s_;
};

// ------------------------------------------------------------ byte sources

/// Base64 text decoded on demand. Padding ('=') ends a quantum; decoding
/// then goes on with the next one (VTK pads the header and the data
/// separately). Whitespace is skipped.
class Base64Source {
 public:
  Base64Source(const std::string& path, std::string_view text) : path_(path), s_(text) {}

  std::string read(std::size_t n) {
    std::string out;
    out.reserve(n);
    while (out.size() < n && pend_pos_ < pending_.size()) out += pending_[pend_pos_++];
    while (out.size() < n) {
      int v[4];
      int pad = 0;
      for (int k = 0; k < 4; ++k) {
        char c;
        do {
          if (i_ >= s_.size())
            fail(path_, "base64 data ends after " + std::to_string(out.size()) + " of " + std::to_string(n) +
                            " bytes (data shorter than the header says)");
          c = s_[i_++];
        } while (c == ' ' || c == '\n' || c == '\r' || c == '\t');
        if (c == '=') {
          if (k < 2) fail(path_, "malformed base64 data (misplaced '=')");
          v[k] = 0;
          ++pad;
        } else {
          if (pad) fail(path_, "malformed base64 data (misplaced '=')");
          const int d = digit(c);
          if (d < 0) fail(path_, std::string("malformed base64 data (character '") + c + "')");
          v[k] = d;
        }
      }
      const unsigned bits = (unsigned(v[0]) << 18) | (unsigned(v[1]) << 12) | (unsigned(v[2]) << 6) | unsigned(v[3]);
      const char b[3] = {static_cast<char>(bits >> 16), static_cast<char>((bits >> 8) & 0xff),
                         static_cast<char>(bits & 0xff)};
      const int got = 3 - pad;
      for (int k = 0; k < got; ++k) {
        if (out.size() < n)
          out += b[k];
        else
          pending_ += b[k];
      }
    }
    return out;
  }

 private:
  static int digit(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  }
  const std::string& path_;
  std::string_view s_;
  std::size_t i_ = 0;
  std::string pending_;
  std::size_t pend_pos_ = 0;
};

/// Raw bytes (appended raw data).
class RawSource {
 public:
  RawSource(const std::string& path, std::string_view bytes) : path_(path), s_(bytes) {}
  std::string read(std::size_t n) {
    if (n > s_.size() - i_)
      fail(path_, "appended data ends after " + std::to_string(s_.size() - i_) + " of " + std::to_string(n) +
                      " bytes (data shorter than the header says)");
    std::string out(s_.substr(i_, n));
    i_ += n;
    return out;
  }

 private:
  const std::string& path_;
  std::string_view s_;
  std::size_t i_ = 0;
};

struct BinaryLayout {
  std::size_t header_size = 4;  // UInt32 or UInt64
  bool big_endian = false;      // of the header integers (and the data)
  bool compressed = false;
};

std::uint64_t header_int(const std::string& b, std::size_t k, const BinaryLayout& l) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < l.header_size; ++i) {
    const std::size_t byte = l.big_endian ? i : l.header_size - 1 - i;
    v = (v << 8) | static_cast<unsigned char>(b[k * l.header_size + byte]);
  }
  return v;
}

/// One array's bytes (exactly `need`) from a binary source.
template <class Source>
std::string read_binary(const std::string& path, Source& src, const BinaryLayout& l, std::size_t need,
                        const std::string& array) {
  if (!l.compressed) {
    const std::uint64_t nbytes = header_int(src.read(l.header_size), 0, l);
    if (nbytes != need)
      fail(path, "array '" + array + "' has " + std::to_string(nbytes) + " bytes of data, the extent needs " +
                     std::to_string(need) + " (mismatched sizes)");
    return src.read(need);
  }
  const std::string h3 = src.read(3 * l.header_size);
  const std::uint64_t nblocks = header_int(h3, 0, l), block = header_int(h3, 1, l), last = header_int(h3, 2, l);
  if (nblocks > need + 1 || (nblocks > 0 && block == 0) || last > block)
    fail(path, "array '" + array + "': malformed compressed-data header");
  const std::uint64_t total = nblocks == 0 ? 0 : (nblocks - 1) * block + (last ? last : block);
  if (total != need)
    fail(path, "array '" + array + "' has " + std::to_string(total) + " bytes of data, the extent needs " +
                   std::to_string(need) + " (mismatched sizes)");
  const std::string sizes = src.read(static_cast<std::size_t>(nblocks) * l.header_size);
  std::string out;
  out.reserve(need);
  for (std::uint64_t b = 0; b < nblocks; ++b) {
    const std::uint64_t csize = header_int(sizes, static_cast<std::size_t>(b), l);
    if (csize > (std::uint64_t(1) << 40)) fail(path, "array '" + array + "': malformed compressed-data header");
    const std::string comp = src.read(static_cast<std::size_t>(csize));
    const std::uint64_t usize = (b + 1 == nblocks && last) ? last : block;
    out += inflate_exact(path, "array '" + array + "' compressed block " + std::to_string(b), comp,
                         static_cast<std::size_t>(usize));
  }
  return out;
}

bool vtk_type(const std::string& name, ScalarType& t) {
  static const std::map<std::string, ScalarType> types = {
      {"Int8", ScalarType::i8},      {"Char", ScalarType::i8},      {"UInt8", ScalarType::u8},
      {"Int16", ScalarType::i16},    {"UInt16", ScalarType::u16},   {"Int32", ScalarType::i32},
      {"UInt32", ScalarType::u32},   {"Int64", ScalarType::i64},    {"UInt64", ScalarType::u64},
      {"Float32", ScalarType::f32},  {"Float64", ScalarType::f64},
  };
  auto it = types.find(name);
  if (it == types.end()) return false;
  t = it->second;
  return true;
}

bool parse_extent(std::string_view s, std::array<std::int64_t, 6>& e) {
  double d[6];
  if (!parse_doubles(s, 6, d)) return false;
  for (int k = 0; k < 6; ++k) {
    if (d[k] != std::floor(d[k]) || std::abs(d[k]) > 1e15) return false;
    e[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(d[k]);
  }
  for (int a = 0; a < 3; ++a)
    if (e[static_cast<std::size_t>(2 * a + 1)] < e[static_cast<std::size_t>(2 * a)]) return false;
  return true;
}

}  // namespace

RawImage read_vti_image(const std::string& path, const std::string& array) {
  const std::string text = read_file_bytes(path);
  XmlScanner xml(path, text);
  xml.run();
  const auto& els = xml.elements;
  auto child = [&](std::size_t parent, const char* name) -> std::size_t {
    for (std::size_t c : els[parent].children)
      if (els[c].name == name) return c;
    return 0;
  };
  auto attr = [&](std::size_t e, const char* name) -> const std::string* {
    auto it = els[e].attrs.find(name);
    return it == els[e].attrs.end() ? nullptr : &it->second;
  };

  const std::size_t root = child(0, "VTKFile");
  if (!root) fail(path, "not a VTK XML file (no <VTKFile> element)");
  if (const std::string* t = attr(root, "type"); !t || *t != "ImageData")
    fail(path, "VTK XML file of type '" + (t ? *t : std::string()) + "', expected ImageData");
  BinaryLayout layout;
  if (const std::string* bo = attr(root, "byte_order")) {
    if (*bo == "BigEndian")
      layout.big_endian = true;
    else if (*bo != "LittleEndian")
      fail(path, "unknown byte_order '" + *bo + "'");
  }
  if (const std::string* ht = attr(root, "header_type")) {
    if (*ht == "UInt64")
      layout.header_size = 8;
    else if (*ht != "UInt32")
      fail(path, "unknown header_type '" + *ht + "' (expected UInt32 or UInt64)");
  }
  if (const std::string* c = attr(root, "compressor"); c && !c->empty()) {
    if (*c != "vtkZLibDataCompressor")
      fail(path, "unsupported compressor '" + *c + "' (only vtkZLibDataCompressor; rewrite with zlib or none)");
    layout.compressed = true;
  }

  const std::size_t id = child(root, "ImageData");
  if (!id) fail(path, "no <ImageData> element");
  std::array<std::int64_t, 6> whole{};
  const std::string* we = attr(id, "WholeExtent");
  if (!we || !parse_extent(*we, whole)) fail(path, "missing or malformed WholeExtent");
  RawImage raw;
  ImageGeometry& g = raw.geometry;
  std::array<double, 3> origin{0, 0, 0};
  if (const std::string* o = attr(id, "Origin"); o && !parse_doubles(*o, 3, origin.data()))
    fail(path, "malformed Origin '" + *o + "'");
  if (const std::string* s = attr(id, "Spacing"); s && !parse_doubles(*s, 3, g.spacing.data()))
    fail(path, "malformed Spacing '" + *s + "'");
  if (const std::string* d = attr(id, "Direction")) {
    double m[9];
    if (!parse_doubles(*d, 9, m)) fail(path, "malformed Direction '" + *d + "'");
    for (int k = 0; k < 9; ++k)
      if (std::abs(m[k] - (k % 4 == 0 ? 1.0 : 0.0)) > 1e-9)
        fail(path, "Direction is not the identity (rotated or flipped images are not supported; resample first)");
  }
  for (std::size_t a = 0; a < 3; ++a) {
    g.size[a] = whole[2 * a + 1] - whole[2 * a] + 1;
    g.origin[a] = origin[a] + static_cast<double>(whole[2 * a]) * g.spacing[a];
  }
  g.dim = g.size[2] == 1 ? 2 : 3;
  check_geometry(path, g);

  std::vector<std::size_t> pieces;
  for (std::size_t c : els[id].children)
    if (els[c].name == "Piece") pieces.push_back(c);
  if (pieces.empty()) fail(path, "no <Piece> in <ImageData>");

  std::string chosen;  // the array name, fixed by the first piece
  const std::size_t n = g.n_voxels();
  std::vector<std::uint8_t> covered(pieces.size() > 1 ? n : 0);
  bool type_set = false;

  for (std::size_t piece : pieces) {
    std::array<std::int64_t, 6> ext{};
    const std::string* pe = attr(piece, "Extent");
    if (!pe || !parse_extent(*pe, ext)) fail(path, "missing or malformed Piece Extent");
    for (std::size_t a = 0; a < 3; ++a)
      if (ext[2 * a] < whole[2 * a] || ext[2 * a + 1] > whole[2 * a + 1])
        fail(path, "Piece Extent '" + *pe + "' lies outside WholeExtent '" + *we + "'");
    const std::size_t pd = child(piece, "PointData");
    std::vector<std::size_t> arrays;
    if (pd)
      for (std::size_t c : els[pd].children)
        if (els[c].name == "DataArray") arrays.push_back(c);
    if (arrays.empty()) {
      const bool cells = child(piece, "CellData") && !els[child(piece, "CellData")].children.empty();
      fail(path, std::string("no point data array") + (cells ? " (cell data is not supported)" : ""));
    }
    if (chosen.empty()) {
      if (!array.empty())
        chosen = array;
      else if (const std::string* sc = attr(pd, "Scalars"); sc && !sc->empty())
        chosen = *sc;
      else
        chosen = attr(arrays[0], "Name") ? *attr(arrays[0], "Name") : std::string();
    }
    std::size_t da = 0;
    for (std::size_t c : arrays) {
      const std::string* nm = attr(c, "Name");
      if ((nm ? *nm : std::string()) == chosen) {
        da = c;
        break;
      }
    }
    if (!da) {
      std::string names;
      for (std::size_t c : arrays) names += (names.empty() ? "" : ", ") + (attr(c, "Name") ? *attr(c, "Name") : "?");
      fail(path, "no point data array named '" + chosen + "' (arrays: " + names + ")");
    }
    ScalarType t{};
    const std::string* ty = attr(da, "type");
    if (!ty || !vtk_type(*ty, t))
      fail(path, "array '" + chosen + "' has unsupported type '" + (ty ? *ty : std::string()) + "'");
    if (type_set && t != raw.type) fail(path, "array '" + chosen + "' changes type between pieces");
    raw.type = t;
    type_set = true;
    if (const std::string* nc = attr(da, "NumberOfComponents"); nc && trim(*nc) != "1")
      fail(path, "array '" + chosen + "' has " + *nc + " components: multi-component data is not supported");
    const std::string format = attr(da, "format") ? *attr(da, "format") : std::string();

    std::array<std::int64_t, 3> psize{};
    for (std::size_t a = 0; a < 3; ++a) psize[a] = ext[2 * a + 1] - ext[2 * a] + 1;
    const std::size_t pn = static_cast<std::size_t>(psize[0] * psize[1] * psize[2]);
    const std::size_t item = scalar_size(t);
    const std::size_t need = pn * item;
    std::string bytes;
    bool big = layout.big_endian;
    if (format == "ascii") {
      const Element& e = els[da];
      bytes = parse_ascii_values(path, std::string_view(text).substr(e.content_begin, e.content_end - e.content_begin),
                                 t, pn);
      big = std::endian::native == std::endian::big;
    } else if (format == "binary") {
      const Element& e = els[da];
      Base64Source src(path, std::string_view(text).substr(e.content_begin, e.content_end - e.content_begin));
      bytes = read_binary(path, src, layout, need, chosen);
    } else if (format == "appended") {
      if (xml.appended == std::string::npos) fail(path, "array '" + chosen + "' is appended but there is no <AppendedData>");
      const std::string* off = attr(da, "offset");
      double offd = 0;
      if (!off || !parse_doubles(*off, 1, &offd) || offd < 0 || offd != std::floor(offd))
        fail(path, "array '" + chosen + "' has a missing or malformed offset");
      const std::size_t o = static_cast<std::size_t>(offd);
      const std::string* enc = attr(xml.appended, "encoding");
      const std::string encoding = enc ? *enc : std::string("raw");
      if (o > text.size() - xml.appended_start)
        fail(path, "array '" + chosen + "' offset lies beyond the end of the file (data shorter than the header says)");
      std::string_view rest = std::string_view(text).substr(xml.appended_start + o);
      if (encoding == "raw") {
        RawSource src(path, rest);
        bytes = read_binary(path, src, layout, need, chosen);
      } else if (encoding == "base64") {
        const std::size_t end = rest.find('<');
        Base64Source src(path, rest.substr(0, end == std::string_view::npos ? rest.size() : end));
        bytes = read_binary(path, src, layout, need, chosen);
      } else {
        fail(path, "unknown AppendedData encoding '" + encoding + "'");
      }
    } else {
      fail(path, "array '" + chosen + "' has unknown format '" + format + "'");
    }

    // Place the piece into the whole image.
    if (pieces.size() == 1) {
      if (psize[0] != g.size[0] || psize[1] != g.size[1] || psize[2] != g.size[2])
        fail(path, "the only Piece's Extent does not cover WholeExtent");
      raw.bytes = std::move(bytes);
      raw.big_endian = big;
      break;
    }
    if (raw.bytes.empty()) {
      raw.bytes.assign(n * item, '\0');
      raw.big_endian = layout.big_endian;
    }
    if (big != raw.big_endian)  // ascii piece among binary ones: swap to the common order
      for (std::size_t k = 0; k < pn; ++k) std::reverse(bytes.begin() + k * item, bytes.begin() + (k + 1) * item);
    const std::size_t row = static_cast<std::size_t>(psize[0]) * item;
    for (std::int64_t z = 0; z < psize[2]; ++z)
      for (std::int64_t y = 0; y < psize[1]; ++y) {
        const std::size_t dst = g.index(ext[0] - whole[0], ext[2] - whole[2] + y, ext[4] - whole[4] + z);
        std::memcpy(raw.bytes.data() + dst * item,
                    bytes.data() + static_cast<std::size_t>(y + psize[1] * z) * row, row);
        std::fill_n(covered.begin() + static_cast<std::ptrdiff_t>(dst), psize[0], std::uint8_t{1});
      }
  }
  if (pieces.size() > 1 && std::find(covered.begin(), covered.end(), std::uint8_t{0}) != covered.end())
    fail(path, "the Pieces do not cover WholeExtent");
  return raw;
}

}  // namespace tessera::io::detail
