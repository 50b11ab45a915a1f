// Fields of text lines, shared by the text readers (text_points.cpp, lammps_dump.cpp):
// whitespace or delimiter splitting, numbers and labels parsed with std::from_chars,
// and a cursor over content lines. Private to src/io.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string_view>
#include <vector>

namespace tessera::io::detail {

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

/// Walks the fields of one line. delim is ',' or ';', or ' ' for whitespace runs.
class Fields {
 public:
  Fields(std::string_view line, char delim)
      : p_(line.data()), end_(line.data() + line.size()), delim_(delim) {}

  /// Next field into `f`; false when the line has no more fields.
  bool next(std::string_view& f) {
    if (delim_ == ' ') {
      while (p_ < end_ && is_blank(*p_)) ++p_;
      if (p_ == end_) return false;
      const char* b = p_;
      while (p_ < end_ && !is_blank(*p_)) ++p_;
      f = std::string_view(b, static_cast<std::size_t>(p_ - b));
      return true;
    }
    if (done_) return false;
    const char* b = p_;
    while (p_ < end_ && *p_ != delim_) ++p_;
    f = trim(std::string_view(b, static_cast<std::size_t>(p_ - b)));
    if (p_ == end_)
      done_ = true;
    else
      ++p_;
    return true;
  }

 private:
  const char* p_;
  const char* end_;
  char delim_;
  bool done_ = false;
};

/// The whitespace-separated fields of `line` into f[0..f.size()); returns
/// how many it has, counting to f.size() + 1 at most (one more says "too
/// many" without reading the rest).
inline std::size_t split_fields(std::string_view line, std::vector<std::string_view>& f) {
  Fields fs(line, ' ');
  std::size_t got = 0;
  std::string_view field;
  while (got <= f.size() && fs.next(field))
    if (got++ < f.size()) f[got - 1] = field;
  return got;
}

/// Parse a whole field as a double (a leading '+' is allowed). "nan"/"inf"
/// parse; the caller rejects them with the line number.
inline bool parse_double(std::string_view f, double& v) {
  const char* b = f.data();
  const char* e = b + f.size();
  if (b != e && *b == '+') ++b;
  if (b == e) return false;
  auto [p, ec] = std::from_chars(b, e, v);
  return ec == std::errc() && p == e;
}

/// Parse a label: an integer, or a decimal with an integral value ("3.0"), in int32 range.
inline bool parse_label(std::string_view f, std::int32_t& out) {
  const char* b = f.data();
  const char* e = b + f.size();
  if (b != e && *b == '+') ++b;
  std::int64_t iv = 0;
  auto [p, ec] = std::from_chars(b, e, iv);
  if (!(ec == std::errc() && p == e)) {
    double d = 0;
    if (!parse_double(f, d) || !std::isfinite(d) || d != std::floor(d) || std::abs(d) > 4e9) return false;
    iv = static_cast<std::int64_t>(d);
  }
  if (iv < std::numeric_limits<std::int32_t>::min() || iv > std::numeric_limits<std::int32_t>::max())
    return false;
  out = static_cast<std::int32_t>(iv);
  return true;
}

/// Cursor over the content lines (skips blank and '#' lines, strips '\r').
class Lines {
 public:
  /// `first_line`: the number of the text's first line (a frame of a
  /// trajectory read from its offset).
  explicit Lines(std::string_view text, std::size_t first_line = 1)
      : begin_(text.data()), p_(text.data()), end_(text.data() + text.size()), line_no_(first_line - 1) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") p_ += 3;
  }
  /// Bytes of the text consumed so far, and the number of the last line read.
  std::size_t position() const { return static_cast<std::size_t>(p_ - begin_); }
  std::size_t line_number() const { return line_no_; }
  /// Where a line that next() returned starts in the text.
  std::size_t offset_of(std::string_view line) const { return static_cast<std::size_t>(line.data() - begin_); }
  /// Next content line and its 1-based number; false at end of file.
  bool next(std::string_view& line, std::size_t& number) {
    while (p_ < end_) {
      const char* nl = static_cast<const char*>(std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_)));
      const char* e = nl ? nl : end_;
      std::string_view l(p_, static_cast<std::size_t>(e - p_));
      p_ = nl ? nl + 1 : end_;
      ++line_no_;
      if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
      std::size_t k = 0;
      while (k < l.size() && is_blank(l[k])) ++k;
      if (k == l.size() || l[k] == '#') continue;
      line = l;
      number = line_no_;
      return true;
    }
    return false;
  }

 private:
  const char* begin_;
  const char* p_;
  const char* end_;
  std::size_t line_no_;
};

}  // namespace tessera::io::detail
