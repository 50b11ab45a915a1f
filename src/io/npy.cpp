// NumPy .npy reader (versions 1.0, 2.0, 3.0) and writer (version 1.0).
//
// File layout: "\x93NUMPY", major, minor, header length (uint16 LE for 1.x,
// uint32 LE for 2.x/3.x), then an ASCII (3.x: UTF-8) Python dict literal
//   {'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }
// padded with spaces and ended by '\n', then the raw array data.
#include "tessera/io/npy.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <string_view>
#include <type_traits>

#include "io_detail.hpp"
#include "tessera/cells.hpp"

namespace tessera::io {
namespace {

constexpr std::string_view kMagic = "\x93NUMPY";
/// Headers larger than this are not something NumPy writes; refuse them
/// rather than allocate whatever a corrupt length field says.
constexpr std::uint32_t kMaxHeaderLen = 1u << 20;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

/// What the header says about the array.
struct Header {
  bool big_endian = false;  ///< data byte order ('>' in descr)
  char kind = 'f';          ///< 'f', 'i', 'u' or 'b'
  int item_size = 8;
  std::string descr;  ///< as written, for messages
  bool fortran_order = false;
  std::vector<std::size_t> shape;
  std::size_t count = 1;  ///< product of shape
  /// A structured dtype's fields (descr a list), in record order; empty for
  /// a plain array. item_size is then the record's size.
  struct Field {
    std::string name;
    std::string descr;     ///< as written
    char kind = 'V';       ///< 'f', 'i', 'u', 'b'; 'V' for void (padding, raw bytes)
    int item_size = 0;
    bool big_endian = false;
    std::size_t count = 1;  ///< values per record (a sub-array field: more)
    std::size_t offset = 0;
  };
  std::vector<Field> fields;
  bool structured() const { return !fields.empty(); }
};

/// Parser for the subset of Python literals NumPy writes in the header:
/// a dict with string keys 'descr' (str), 'fortran_order' (bool), 'shape'
/// (tuple of ints). Anything else is an error, as in numpy.lib.format.
class HeaderParser {
 public:
  HeaderParser(const std::string& path, std::string_view text) : path_(path), s_(text) {}

  Header parse() {
    Header h;
    bool have_descr = false, have_fortran = false, have_shape = false;
    expect('{');
    for (;;) {
      skip_ws();
      if (peek() == '}') break;
      std::string key = parse_string();
      expect(':');
      skip_ws();
      if (key == "descr") {
        if (peek() == '[')
          parse_fields(h);
        else
          h.descr = parse_string();
        have_descr = true;
      } else if (key == "fortran_order") {
        h.fortran_order = parse_bool();
        have_fortran = true;
      } else if (key == "shape") {
        h.shape = parse_shape();
        have_shape = true;
      } else {
        bad("unexpected key '" + key + "'");
      }
      skip_ws();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      skip_ws();
      if (peek() != '}') bad("expected ',' or '}'");
    }
    if (!have_descr || !have_fortran || !have_shape) bad("missing 'descr', 'fortran_order' or 'shape'");
    decode_descr(h);
    return h;
  }

 private:
  [[noreturn]] void bad(const std::string& what) const { detail::fail(path_, "bad .npy header: " + what); }
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void skip_ws() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  void expect(char c) {
    skip_ws();
    if (peek() != c) bad(std::string("expected '") + c + "'");
    ++i_;
  }
  std::string parse_string() {
    skip_ws();
    char q = peek();
    if (q != '\'' && q != '"') bad("expected a string");
    std::size_t start = ++i_;
    while (i_ < s_.size() && s_[i_] != q) ++i_;
    if (i_ >= s_.size()) bad("unterminated string");
    return std::string(s_.substr(start, i_++ - start));
  }
  bool parse_bool() {
    if (s_.substr(i_, 4) == "True") {
      i_ += 4;
      return true;
    }
    if (s_.substr(i_, 5) == "False") {
      i_ += 5;
      return false;
    }
    bad("fortran_order must be True or False");
  }
  std::vector<std::size_t> parse_shape() {
    std::vector<std::size_t> shape;
    expect('(');
    for (;;) {
      skip_ws();
      if (peek() == ')') {
        ++i_;
        return shape;
      }
      std::size_t v = 0;
      auto [p, ec] = std::from_chars(s_.data() + i_, s_.data() + s_.size(), v);
      if (ec != std::errc()) bad("shape must be a tuple of non-negative integers");
      i_ = static_cast<std::size_t>(p - s_.data());
      // Python 2 era writers may append 'L' to longs.
      if (peek() == 'L') ++i_;
      shape.push_back(v);
      skip_ws();
      if (peek() == ',')
        ++i_;
      else if (peek() != ')')
        bad("expected ',' or ')' in shape");
    }
  }
  /// A structured dtype: a list of fields (name, dtype[, shape]), packed as
  /// numpy writes them (alignment padding appears as void fields named '').
  void parse_fields(Header& h) {
    expect('[');
    std::size_t offset = 0;
    h.descr = "structured";
    for (;;) {
      skip_ws();
      if (peek() == ']') {
        ++i_;
        break;
      }
      expect('(');
      skip_ws();
      if (peek() == '(') bad("structured dtype with field titles is not supported");
      Header::Field f;
      f.name = parse_string();
      expect(',');
      skip_ws();
      if (peek() == '[') bad("nested structured dtype (field '" + f.name + "') is not supported");
      f.descr = parse_string();
      skip_ws();
      if (peek() == ',') {
        ++i_;
        skip_ws();
        if (peek() == '(')
          for (std::size_t d : parse_shape()) {
            if (d != 0 && f.count > (std::size_t{1} << 32) / d) bad("field '" + f.name + "' too large");
            f.count *= d;
          }
      }
      expect(')');
      if (f.descr.size() >= 3 && (f.descr[0] == '|' || f.descr[0] == '<' || f.descr[0] == '>') && f.descr[1] == 'V') {
        auto [p, ec] = std::from_chars(f.descr.data() + 2, f.descr.data() + f.descr.size(), f.item_size);
        if (ec != std::errc() || p != f.descr.data() + f.descr.size() || f.item_size < 0 || f.item_size > (1 << 20))
          bad("unsupported dtype '" + f.descr + "' of field '" + f.name + "'");
      } else {
        decode_scalar(f.descr, f.kind, f.item_size, f.big_endian, "field '" + f.name + "': ");
      }
      f.offset = offset;
      offset += f.count * static_cast<std::size_t>(f.item_size);
      h.fields.push_back(std::move(f));
      skip_ws();
      if (peek() == ',') ++i_;
    }
    if (h.fields.empty()) bad("structured dtype without fields");
    if (offset == 0 || offset > (std::size_t{1} << 24)) bad("implausible record size");
  }

  /// A scalar dtype: byte order + kind + size, e.g. '<f8', '|u1', '>i4', '|b1'.
  void decode_scalar(const std::string& d, char& kind, int& item_size, bool& big_endian,
                     const std::string& what = "") const {
    if (d.size() < 3) bad(what + "unsupported dtype '" + d + "'");
    char order = d[0];
    if (order != '<' && order != '>' && order != '|' && order != '=') bad(what + "unsupported dtype '" + d + "'");
    big_endian = order == '>' || (order == '=' && std::endian::native == std::endian::big);
    kind = d[1];
    int size = 0;
    auto [p, ec] = std::from_chars(d.data() + 2, d.data() + d.size(), size);
    if (ec != std::errc() || p != d.data() + d.size()) bad(what + "unsupported dtype '" + d + "'");
    item_size = size;
    bool ok = false;
    switch (kind) {
      case 'f':
        ok = size == 4 || size == 8;
        break;
      case 'i':
      case 'u':
        ok = size == 1 || size == 2 || size == 4 || size == 8;
        break;
      case 'b':
        ok = size == 1;
        break;
      default:
        ok = false;
    }
    if (!ok)
      bad(what + "unsupported dtype '" + d + "' (expected float32/float64, int8..int64, uint8..uint64 or bool)");
    // Single-byte data has no byte order.
    if (size == 1) big_endian = false;
  }

  void decode_descr(Header& h) const {
    if (h.structured()) {
      h.kind = 'V';
      std::size_t record = 0;
      for (const Header::Field& f : h.fields) record += f.count * static_cast<std::size_t>(f.item_size);
      h.item_size = static_cast<int>(record);
    } else {
      decode_scalar(h.descr, h.kind, h.item_size, h.big_endian);
    }
    h.count = 1;
    for (std::size_t dim : h.shape) {
      if (dim != 0 && h.count > std::numeric_limits<std::size_t>::max() / dim / static_cast<std::size_t>(std::max(8, h.item_size)))
        bad("shape too large");
      h.count *= dim;
    }
  }

  const std::string& path_;
  std::string_view s_;
  std::size_t i_ = 0;
};

std::string shape_string(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k) {
    if (k) s += ", ";
    s += std::to_string(shape[k]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

/// Open `path`, read and check the header; leaves the file positioned at the data.
File open_npy(const std::string& path, Header& h) {
  detail::check_readable(path);
  File f(std::fopen(path.c_str(), "rb"));
  if (!f) throw InputError("cannot open " + path + ": " + std::strerror(errno));
  unsigned char pre[12];
  if (std::fread(pre, 1, 8, f.get()) != 8 || std::memcmp(pre, kMagic.data(), kMagic.size()) != 0)
    detail::fail(path, "not a .npy file (bad magic)");
  const int major = pre[6], minor = pre[7];
  std::uint32_t header_len = 0;
  if (major == 1) {
    if (std::fread(pre + 8, 1, 2, f.get()) != 2) detail::fail(path, "truncated .npy header");
    header_len = pre[8] | (std::uint32_t(pre[9]) << 8);
  } else if (major == 2 || major == 3) {
    if (std::fread(pre + 8, 1, 4, f.get()) != 4) detail::fail(path, "truncated .npy header");
    header_len = pre[8] | (std::uint32_t(pre[9]) << 8) | (std::uint32_t(pre[10]) << 16) |
                 (std::uint32_t(pre[11]) << 24);
  } else {
    detail::fail(path, "unsupported .npy version " + std::to_string(major) + "." + std::to_string(minor) +
                           " (expected 1.0, 2.0 or 3.0)");
  }
  if (header_len > kMaxHeaderLen) detail::fail(path, "bad .npy header: implausible length");
  std::string text(header_len, '\0');
  if (std::fread(text.data(), 1, header_len, f.get()) != header_len)
    detail::fail(path, "truncated .npy header");
  h = HeaderParser(path, text).parse();
  return f;
}

/// Reorder an array read in Fortran order (first index fastest) into C order
/// (last index fastest), in place through one copy. NumPy saves any
/// F-contiguous array so: a transposed array, or a pandas DataFrame's
/// to_numpy(), whose columns are stored one after another. Fortran order of
/// a 1-D array is C order.
template <class T>
void fortran_to_c_order(std::vector<T>& data, const std::vector<std::size_t>& shape) {
  const std::size_t rank = shape.size();
  if (rank < 2 || data.empty()) return;
  const std::vector<T> f(data);
  if (rank == 2) {  // (rows, columns): the points' case
    const std::size_t rows = shape[0], cols = shape[1];
    for (std::size_t c = 0; c < cols; ++c)
      for (std::size_t r = 0; r < rows; ++r) data[r * cols + c] = f[c * rows + r];
    return;
  }
  // C index walked in order; its Fortran offset kept by an odometer over
  // the axes (Fortran stride of axis a: the product of the axes before it).
  std::vector<std::size_t> stride(rank, 1), index(rank, 0);
  for (std::size_t a = 1; a < rank; ++a) stride[a] = stride[a - 1] * shape[a - 1];
  std::size_t off = 0;
  for (std::size_t c = 0; c < data.size(); ++c) {
    data[c] = f[off];
    for (std::size_t a = rank; a-- > 0;) {
      if (++index[a] < shape[a]) {
        off += stride[a];
        break;
      }
      off -= (shape[a] - 1) * stride[a];
      index[a] = 0;
    }
  }
}


/// Reverse the bytes of each of `n` items of `size` bytes at `data`.
void byteswap_in_place(void* data, std::size_t n, std::size_t size) {
  auto* b = static_cast<unsigned char*>(data);
  for (std::size_t k = 0; k < n; ++k) std::reverse(b + k * size, b + (k + 1) * size);
}

/// Convert `n` items of the header's dtype at `src` into `dst`. For int64
/// output, uint64 values beyond INT64_MAX are an error.
template <class Out>
void convert(const std::string& path, const Header& h, const unsigned char* src, std::size_t n, Out* dst) {
  const bool swap = h.big_endian != (std::endian::native == std::endian::big);
  const int sz = h.item_size;
  auto each = [&](auto tag) {
    using T = decltype(tag);
    for (std::size_t k = 0; k < n; ++k) dst[k] = static_cast<Out>(detail::load_item<T>(src + k * sz, swap));
  };
  switch (h.kind) {
    case 'f':
      if (sz == 4)
        each(float{});
      else
        each(double{});
      break;
    case 'i':
      if (sz == 1)
        each(std::int8_t{});
      else if (sz == 2)
        each(std::int16_t{});
      else if (sz == 4)
        each(std::int32_t{});
      else
        each(std::int64_t{});
      break;
    case 'u':
      if (sz == 1)
        each(std::uint8_t{});
      else if (sz == 2)
        each(std::uint16_t{});
      else if (sz == 4)
        each(std::uint32_t{});
      else {
        for (std::size_t k = 0; k < n; ++k) {
          auto v = detail::load_item<std::uint64_t>(src + k * sz, swap);
          if constexpr (std::is_integral_v<Out>) {
            if (v > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
              detail::fail(path, "uint64 value " + std::to_string(v) + " does not fit in int64");
          }
          dst[k] = static_cast<Out>(v);
        }
      }
      break;
    case 'b':
      for (std::size_t k = 0; k < n; ++k) dst[k] = src[k] != 0 ? Out(1) : Out(0);
      break;
  }
}

/// Read the data into `out` (h.count items). Same-type native data is read
/// straight into `out`; other dtypes go through a bounded conversion buffer.
template <class Out>
void read_data(const std::string& path, std::FILE* f, const Header& h, std::vector<Out>& out) {
  const std::size_t total_bytes = h.count * static_cast<std::size_t>(h.item_size);
  auto truncated = [&](std::size_t got) {
    detail::fail(path, "truncated data: expected " + std::to_string(total_bytes) + " bytes for shape " +
                           shape_string(h.shape) + " " + h.descr + ", found " + std::to_string(got));
  };
  // A header may claim any shape: check that the file holds the data before
  // allocating for it (a claim of 2^31 x 2 items otherwise ended in "out of
  // memory").
  struct stat st;
  const long pos = std::ftell(f);
  if (pos >= 0 && ::fstat(::fileno(f), &st) == 0 && S_ISREG(st.st_mode)) {
    const std::size_t avail = st.st_size > pos ? static_cast<std::size_t>(st.st_size - pos) : 0;
    if (avail < total_bytes) truncated(avail);
  }
  out.resize(h.count);
  const bool same_type = sizeof(Out) == static_cast<std::size_t>(h.item_size) &&
                         ((std::is_floating_point_v<Out> && h.kind == 'f') ||
                          (std::is_signed_v<Out> && std::is_integral_v<Out> && h.kind == 'i'));
  if (same_type) {
    std::size_t got = std::fread(out.data(), 1, total_bytes, f);
    if (got != total_bytes) truncated(got);
    if (h.big_endian != (std::endian::native == std::endian::big))
      byteswap_in_place(out.data(), h.count, sizeof(Out));
    return;
  }
  constexpr std::size_t kChunkItems = 1 << 16;
  std::vector<unsigned char> buf(kChunkItems * static_cast<std::size_t>(h.item_size));
  std::size_t done = 0;
  while (done < h.count) {
    const std::size_t items = std::min(kChunkItems, h.count - done);
    const std::size_t bytes = items * static_cast<std::size_t>(h.item_size);
    std::size_t got = std::fread(buf.data(), 1, bytes, f);
    if (got != bytes) truncated(done * static_cast<std::size_t>(h.item_size) + got);
    convert(path, h, buf.data(), items, out.data() + done);
    done += items;
  }
}

NpyArray make_array(const Header& h) {
  NpyArray a;
  a.shape = h.shape;
  a.kind = h.kind;
  a.item_size = h.item_size;
  return a;
}

template <class T>
std::string npy_bytes_impl(const T* data, const std::vector<std::size_t>& shape, const char* descr) {
  std::size_t count = 1;
  for (std::size_t d : shape) count *= d;
  std::string dict = std::string("{'descr': '") + descr +
                     "', 'fortran_order': False, 'shape': " + shape_string(shape) + ", }";
  // magic(6) + version(2) + length(2) + dict + padding + '\n' must be a multiple of 64.
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string out;
  out.reserve(10 + dict.size() + count * sizeof(T));
  out.append(kMagic);
  out += char(1);
  out += char(0);
  out += static_cast<char>(dict.size() & 0xff);
  out += static_cast<char>((dict.size() >> 8) & 0xff);
  out += dict;
  const std::size_t start = out.size();
  if (count) out.append(reinterpret_cast<const char*>(data), count * sizeof(T));
  // The data is written little-endian whatever the host.
  if constexpr (std::endian::native == std::endian::big)
    byteswap_in_place(out.data() + start, count, sizeof(T));
  return out;
}

}  // namespace

namespace {

std::string field_list(const Header& h) {
  std::string s;
  for (const Header::Field& f : h.fields)
    if (!f.name.empty()) s += (s.empty() ? "'" : ", '") + f.name + "'";
  return s;
}

void refuse_structured(const std::string& path, const Header& h) {
  if (h.structured())
    detail::fail(path, "a structured array (fields " + field_list(h) + ") where a plain numeric array was expected");
}

}  // namespace

NpyRecords read_npy_records(const std::string& path, const std::function<bool(const std::string&)>& take) {
  Header h;
  File f = open_npy(path, h);
  NpyRecords r;
  if (!h.structured()) return r;
  r.structured = true;
  if (h.shape.size() != 1)
    detail::fail(path, "a structured array must be 1-D (one record per point), found shape " + shape_string(h.shape));
  r.n = h.shape[0];
  // The file must hold the records before anything is sized by the header.
  const std::size_t record = static_cast<std::size_t>(h.item_size);
  struct stat st;
  const long pos = std::ftell(f.get());
  if (pos >= 0 && ::fstat(::fileno(f.get()), &st) == 0 && S_ISREG(st.st_mode)) {
    const std::size_t avail = st.st_size > pos ? static_cast<std::size_t>(st.st_size - pos) : 0;
    if (avail / record < r.n)
      detail::fail(path, "truncated data: expected " + std::to_string(r.n) + " records of " + std::to_string(record) +
                             " bytes, found " + std::to_string(avail) + " bytes");
  }
  std::vector<std::size_t> taken;
  for (const Header::Field& fd : h.fields) {
    NpyRecords::Field out;
    out.name = fd.name;
    out.kind = fd.kind;
    if (!fd.name.empty() && take(fd.name)) {
      if (fd.kind == 'V' || fd.count != 1)
        detail::fail(path, "field '" + fd.name + "' is not a number (dtype '" + fd.descr + "'" +
                               (fd.count != 1 ? ", " + std::to_string(fd.count) + " values per record" : "") + ")");
      out.taken = true;
      out.values.resize(r.n);
      taken.push_back(r.fields.size());
    }
    r.fields.push_back(std::move(out));
  }
  // Records in chunks; each taken field converted to double.
  const std::size_t chunk = std::max<std::size_t>(1, (std::size_t{1} << 22) / record);
  std::vector<unsigned char> buf(chunk * record);
  for (std::size_t done = 0; done < r.n;) {
    const std::size_t items = std::min(chunk, r.n - done);
    const std::size_t got = std::fread(buf.data(), 1, items * record, f.get());
    if (got != items * record)
      detail::fail(path, "truncated data: records end at record " + std::to_string(done + got / record) + " of " +
                             std::to_string(r.n));
    for (const std::size_t k : taken) {
      const Header::Field& fd = h.fields[k];
      Header one;
      one.kind = fd.kind;
      one.item_size = fd.item_size;
      one.big_endian = fd.big_endian;
      double* dst = r.fields[k].values.data() + done;
      // One value at a time: the field's values are `record` bytes apart.
      for (std::size_t i = 0; i < items; ++i) convert(path, one, buf.data() + i * record + fd.offset, 1, dst + i);
    }
    done += items;
  }
  return r;
}

NpyArray read_npy_double(const std::string& path) {
  Header h;
  File f = open_npy(path, h);
  refuse_structured(path, h);
  NpyArray a = make_array(h);
  read_data(path, f.get(), h, a.as_double);
  if (h.fortran_order) fortran_to_c_order(a.as_double, h.shape);
  return a;
}

NpyArray read_npy_int(const std::string& path) {
  Header h;
  File f = open_npy(path, h);
  refuse_structured(path, h);
  if (h.kind == 'f') detail::fail(path, "expected an integer array, found dtype '" + h.descr + "'");
  NpyArray a = make_array(h);
  read_data(path, f.get(), h, a.as_int);
  if (h.fortran_order) fortran_to_c_order(a.as_int, h.shape);
  return a;
}

std::string npy_bytes(const double* data, const std::vector<std::size_t>& shape) {
  return npy_bytes_impl(data, shape, "<f8");
}
std::string npy_bytes(const std::uint8_t* data, const std::vector<std::size_t>& shape) {
  return npy_bytes_impl(data, shape, "|u1");
}
std::string npy_bytes(const std::int8_t* data, const std::vector<std::size_t>& shape) {
  return npy_bytes_impl(data, shape, "|i1");
}
std::string npy_bytes(const std::int32_t* data, const std::vector<std::size_t>& shape) {
  return npy_bytes_impl(data, shape, "<i4");
}
std::string npy_bytes(const std::int64_t* data, const std::vector<std::size_t>& shape) {
  return npy_bytes_impl(data, shape, "<i8");
}

}  // namespace tessera::io
