// VtkXmlFile (vtk_xml_read.hpp): the XML scanner, the base64 and raw byte
// sources, and the binary arrays' headers and zlib blocks.
#include "vtk_xml_read.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>

#include "io_detail.hpp"

namespace tessera::io::detail {
namespace {

// ------------------------------------------------------------ a small XML scanner


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

/// Parses the XML part of a VTK XML file into elements (element 0 is a virtual
/// root). Stops at <AppendedData>: what follows its '_' is data, not XML.
class XmlScanner {
 public:
  XmlScanner(const std::string& path, const std::string& text) : path_(path), s_(text) {}

  std::vector<XmlElement> elements;
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
      XmlElement el;
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

  /// At most this many bytes are left to read (four characters give at most three).
  std::size_t most_left() const { return (s_.size() - i_) / 4 * 3 + 3 + (pending_.size() - pend_pos_); }

  std::string read(std::size_t n) {
    // A size the text cannot hold is refused before anything is sized by it.
    if (n > most_left())
      fail(path_, "base64 data ends before the " + std::to_string(n) +
                      " bytes the header gives (data shorter than the header says)");
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
  std::size_t most_left() const { return s_.size() - i_; }
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
      fail(path, "array '" + array + "' has " + std::to_string(nbytes) + " bytes of data, its size needs " +
                     std::to_string(need) + " (mismatched sizes)");
    return src.read(need);
  }
  const std::string h3 = src.read(3 * l.header_size);
  const std::uint64_t nblocks = header_int(h3, 0, l), block = header_int(h3, 1, l), last = header_int(h3, 2, l);
  if (nblocks > need + 1 || (nblocks > 0 && block == 0) || last > block)
    fail(path, "array '" + array + "': malformed compressed-data header");
  const std::uint64_t total = nblocks == 0 ? 0 : (nblocks - 1) * block + (last ? last : block);
  if (total != need)
    fail(path, "array '" + array + "' has " + std::to_string(total) + " bytes of data, its size needs " +
                   std::to_string(need) + " (mismatched sizes)");
  const std::string sizes = src.read(static_cast<std::size_t>(nblocks) * l.header_size);
  // zlib inflates at most ~1032 times: blocks claiming more are corrupt,
  // and are refused before anything is sized by them, as are blocks
  // longer than the data left (a header claiming 10^11 bytes in a file of
  // 500 reserved them: "out of memory").
  std::uint64_t compressed = 0;
  for (std::uint64_t b = 0; b < nblocks; ++b) {
    compressed += std::min<std::uint64_t>(header_int(sizes, static_cast<std::size_t>(b), l), std::uint64_t(1) << 40);
    if (compressed > src.most_left())  // (checked per block: the sum stays far from overflow)
      fail(path, "array '" + array + "': its compressed blocks take more than the " +
                     std::to_string(src.most_left()) + " bytes left (data shorter than the header says)");
  }
  if (need / 1100 > compressed + 64)
    fail(path, "array '" + array + "': malformed compressed-data header (more data than its blocks can hold)");
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

}  // namespace

VtkXmlFile::VtkXmlFile(const std::string& path, std::initializer_list<std::string_view> types)
    : path_(path), text_(read_file_bytes(path)) {
  XmlScanner xml(path_, text_);
  xml.run();
  elements_ = std::move(xml.elements);
  appended_ = xml.appended;
  appended_start_ = xml.appended_start;
  root_ = child(0, "VTKFile");
  if (!root_) fail(path_, "not a VTK XML file (no <VTKFile> element)");
  const std::string* t = attr(root_, "type");
  type_ = t ? *t : std::string();
  if (std::find(types.begin(), types.end(), std::string_view(type_)) == types.end()) {
    std::string expected;
    for (std::string_view e : types) expected += (expected.empty() ? "" : " or ") + std::string(e);
    fail(path_, "VTK XML file of type '" + type_ + "', expected " + expected);
  }
  if (const std::string* bo = attr(root_, "byte_order")) {
    if (*bo == "BigEndian")
      layout_.big_endian = true;
    else if (*bo != "LittleEndian")
      fail(path_, "unknown byte_order '" + *bo + "'");
  }
  if (const std::string* ht = attr(root_, "header_type")) {
    if (*ht == "UInt64")
      layout_.header_size = 8;
    else if (*ht != "UInt32")
      fail(path_, "unknown header_type '" + *ht + "' (expected UInt32 or UInt64)");
  }
  if (const std::string* c = attr(root_, "compressor"); c && !c->empty()) {
    if (*c != "vtkZLibDataCompressor")
      fail(path_, "unsupported compressor '" + *c + "' (only vtkZLibDataCompressor; rewrite with zlib or none)");
    layout_.compressed = true;
  }
}

std::size_t VtkXmlFile::child(std::size_t parent, std::string_view name) const {
  for (std::size_t c : elements_[parent].children)
    if (elements_[c].name == name) return c;
  return 0;
}

std::vector<std::size_t> VtkXmlFile::children(std::size_t parent, std::string_view name) const {
  std::vector<std::size_t> r;
  for (std::size_t c : elements_[parent].children)
    if (elements_[c].name == name) r.push_back(c);
  return r;
}

const std::string* VtkXmlFile::attr(std::size_t e, const char* name) const {
  auto it = elements_[e].attrs.find(name);
  return it == elements_[e].attrs.end() ? nullptr : &it->second;
}

ScalarType VtkXmlFile::array_type(std::size_t da, const std::string& array) const {
  ScalarType t{};
  const std::string* ty = attr(da, "type");
  if (!ty || !vtk_type(*ty, t))
    fail(path_, "array '" + array + "' has unsupported type '" + (ty ? *ty : std::string()) + "'");
  return t;
}

std::string VtkXmlFile::array_bytes(std::size_t da, std::size_t count, const std::string& array, bool& big) const {
  const ScalarType t = array_type(da, array);
  const std::string format = attr(da, "format") ? *attr(da, "format") : std::string();
  const std::size_t need = count * scalar_size(t);
  big = layout_.big_endian;
  const XmlElement& e = elements_[da];
  // The values are the element's text up to its first child: VTK writes
  // <InformationKey> elements (a multi-component array's norm range) after them.
  std::string_view content = std::string_view(text_).substr(e.content_begin, e.content_end - e.content_begin);
  content = content.substr(0, std::min(content.size(), content.find('<')));
  if (format == "ascii") {
    big = std::endian::native == std::endian::big;
    return parse_ascii_values(path_, content, t, count);
  }
  if (format == "binary") {
    Base64Source src(path_, content);
    return read_binary(path_, src, layout_, need, array);
  }
  if (format != "appended") fail(path_, "array '" + array + "' has unknown format '" + format + "'");
  if (appended_ == std::string::npos) fail(path_, "array '" + array + "' is appended but there is no <AppendedData>");
  const std::string* off = attr(da, "offset");
  double offd = 0;
  if (!off || !parse_doubles(*off, 1, &offd) || offd < 0 || offd != std::floor(offd))
    fail(path_, "array '" + array + "' has a missing or malformed offset");
  const std::size_t o = static_cast<std::size_t>(offd);
  const std::string* enc = attr(appended_, "encoding");
  const std::string encoding = enc ? *enc : std::string("raw");
  if (o > text_.size() - appended_start_)
    fail(path_, "array '" + array + "' offset lies beyond the end of the file (data shorter than the header says)");
  std::string_view rest = std::string_view(text_).substr(appended_start_ + o);
  if (encoding == "raw") {
    RawSource src(path_, rest);
    return read_binary(path_, src, layout_, need, array);
  }
  if (encoding == "base64") {
    const std::size_t end = rest.find('<');
    Base64Source src(path_, rest.substr(0, end == std::string_view::npos ? rest.size() : end));
    return read_binary(path_, src, layout_, need, array);
  }
  fail(path_, "unknown AppendedData encoding '" + encoding + "'");
}

std::vector<double> values_as_double(std::string_view bytes, ScalarType t, bool big_endian) {
  const std::size_t size = scalar_size(t);
  const std::size_t n = bytes.size() / size;
  const bool swap = size > 1 && big_endian != (std::endian::native == std::endian::big);
  std::vector<double> out(n);
  auto each = [&](auto tag) {
    using T = decltype(tag);
    for (std::size_t k = 0; k < n; ++k) out[k] = static_cast<double>(load_item<T>(bytes.data() + k * size, swap));
  };
  switch (t) {
    case ScalarType::i8: each(std::int8_t{}); break;
    case ScalarType::u8: each(std::uint8_t{}); break;
    case ScalarType::i16: each(std::int16_t{}); break;
    case ScalarType::u16: each(std::uint16_t{}); break;
    case ScalarType::i32: each(std::int32_t{}); break;
    case ScalarType::u32: each(std::uint32_t{}); break;
    case ScalarType::i64: each(std::int64_t{}); break;
    case ScalarType::u64: each(std::uint64_t{}); break;
    case ScalarType::f32: each(float{}); break;
    case ScalarType::f64: each(double{}); break;
  }
  return out;
}

}  // namespace tessera::io::detail
