// Legacy VTK files (.vtk): point sets, as VTK's legacy writers, ParaView,
// LAMMPS's and LIGGGHTS's `dump vtk`, OpenFOAM's foamToVTK and CloudCompare
// save them, and images (STRUCTURED_POINTS, as ITK's VTKImageIO writes them):
//
//   # vtk DataFile Version 3.0        (2.0 to 5.1)
//   any title
//   ASCII | BINARY                    (binary data is big-endian)
//   DATASET POLYDATA | UNSTRUCTURED_GRID | STRUCTURED_GRID | STRUCTURED_POINTS
//   POINTS n float|double|int|...     then 3n values
//   DIMENSIONS, SPACING (ASPECT_RATIO), ORIGIN: an image's grid
//   VERTICES/LINES/POLYGONS/TRIANGLE_STRIPS, CELLS, CELL_TYPES, METADATA: skipped
//   POINT_DATA n                      SCALARS name type [components]
//                                     [LOOKUP_TABLE table], or FIELD name k
//                                     with arrays "name components tuples type"
//   CELL_DATA n                       skipped
//
// The points are the input (cells are not read); labels and per-point
// scalars come from a named one-component POINT_DATA attribute: a SCALARS
// attribute or an array of a FIELD (string arrays are stepped over). An
// image's voxels are such an attribute, the one named or the first of one
// component. Images are no points, points no image, and rectilinear grids
// are refused: one-line errors.
//
// Written here (not VTK's reader): the core does not link VTK, and what is
// read is small (docs/design.md, "Input files from users' tools").
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "../message_text.hpp"
#include "image_detail.hpp"  // printable, trim
#include "io_detail.hpp"
#include "tessera/io/points.hpp"

namespace tessera::io::detail {
namespace {

/// A name as VTK's writer encodes it: "%20" for a space, "%25" for '%', and
/// so for any byte that is not printable or would split the line.
std::string decoded(std::string_view s) {
  std::string out;
  for (std::size_t k = 0; k < s.size(); ++k) {
    auto hex = [](char c) {
      return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
    };
    if (s[k] == '%' && k + 2 < s.size() && hex(s[k + 1]) >= 0 && hex(s[k + 2]) >= 0) {
      out += static_cast<char>(16 * hex(s[k + 1]) + hex(s[k + 2]));
      k += 2;
    } else {
      out += s[k];
    }
  }
  return out;
}

/// A data type of the legacy format: its size in binary files and whether
/// it holds integers. `bit` packs eight values in a byte.
struct LegacyType {
  std::size_t bytes = 0;  // 0: bit
  bool integer = true;
  bool is_signed = true;
  bool string = false;    // strings: skipped, never numbers
  std::string name;       // as the file spells it, for messages
};

/// A type of no name (the name is set where the file names one).
LegacyType type_of(std::size_t bytes, bool integer, bool is_signed, bool string = false) {
  LegacyType t;
  t.bytes = bytes;
  t.integer = integer;
  t.is_signed = is_signed;
  t.string = string;
  return t;
}

bool legacy_type(const std::string& name, LegacyType& t) {
  const std::string n = lower(name);
  if (n == "bit") t = type_of(0, true, false);
  else if (n == "unsigned_char" || n == "vtktypeuint8") t = type_of(1, true, false);
  else if (n == "char" || n == "signed_char" || n == "vtktypeint8") t = type_of(1, true, true);
  else if (n == "unsigned_short" || n == "vtktypeuint16") t = type_of(2, true, false);
  else if (n == "short" || n == "vtktypeint16") t = type_of(2, true, true);
  else if (n == "unsigned_int" || n == "vtktypeuint32") t = type_of(4, true, false);
  else if (n == "int" || n == "vtktypeint32") t = type_of(4, true, true);
  // VTK writes `long` with the writer's sizeof(long): 8 on the 64-bit
  // systems that write such files today; `vtkIdType` as 4-byte ints (its
  // legacy writer narrows ids, and its reader reads them so).
  else if (n == "unsigned_long" || n == "unsigned_long_long" || n == "vtktypeuint64") t = type_of(8, true, false);
  else if (n == "long" || n == "long_long" || n == "vtktypeint64") t = type_of(8, true, true);
  else if (n == "vtkidtype") t = type_of(4, true, true);
  else if (n == "float" || n == "vtktypefloat32") t = type_of(4, false, true);
  else if (n == "string" || n == "utf8_string") t = type_of(0, false, false, true);
  else if (n == "double" || n == "vtktypefloat64") t = type_of(8, false, true);
  else return false;
  t.name = n;
  return true;
}

/// The file, walked by words (ASCII) and by blocks of bytes (BINARY).
class Legacy {
 public:
  Legacy(const std::string& path, std::string text) : path_(path), s_(std::move(text)) {
    std::string_view line = next_line();
    if (lower(line.substr(0, 22)) != "# vtk datafile version")
      fail(path_, "not a legacy VTK file (the first line must be '# vtk DataFile Version ...')");
    next_line();  // the title
    const std::string mode = lower(trim(next_line()));
    if (mode != "ascii" && mode != "binary")
      fail(path_, "legacy VTK line 3 must be ASCII or BINARY, got '" + printable(mode) + "'");
    binary_ = mode == "binary";
  }

  const std::string& path() const { return path_; }
  bool at_end() {
    skip_space();
    return i_ >= s_.size();
  }

  /// The next word (empty at the end of the file).
  std::string_view word() {
    skip_space();
    const std::size_t b = i_;
    while (i_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
    return std::string_view(s_).substr(b, i_ - b);
  }
  std::string keyword() { return lower(word()); }
  /// The rest of the current line (a name may hold spaces in no writer we
  /// know; a FIELD array's line is split by words).
  std::string_view rest_of_line() {
    const std::size_t b = i_;
    while (i_ < s_.size() && s_[i_] != '\n') ++i_;
    std::string_view r = std::string_view(s_).substr(b, i_ - b);
    if (i_ < s_.size()) ++i_;
    return trim(r);
  }
  std::string peek_keyword() {
    const std::size_t at = i_;
    std::string k = keyword();
    i_ = at;
    return k;
  }

  /// A finite number, named `what` in the message.
  double number(const std::string& what) {
    const std::string_view w = word();
    double v = 0;
    if (!parse_number(w, v) || !std::isfinite(v)) fail(path_, what + ": expected a number, got '" + printable(w) + "'");
    return v;
  }

  /// A non-negative count, named `what` in the message.
  std::size_t count(const std::string& what) {
    const std::string_view w = word();
    std::uint64_t v = 0;
    const auto [p, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (w.empty() || ec != std::errc() || p != w.data() + w.size() || v > (std::uint64_t(1) << 40))
      fail(path_, what + ": expected a count, got '" + printable(w) + "'");
    return static_cast<std::size_t>(v);
  }

  LegacyType type(const std::string& what) {
    const std::string_view w = word();
    LegacyType t;
    if (lower(w) == "variant") fail(path_, what + ": variant arrays are not supported");
    if (!legacy_type(std::string(w), t)) fail(path_, what + ": unknown data type '" + printable(w) + "'");
    return t;
  }
  bool binary() const { return binary_; }

  /// `n` strings skipped: a line each in ASCII; in BINARY each after its
  /// length, whose first byte's two high bits say how many bytes hold it
  /// (11: one, 10: two, 01: four, 00: eight; big-endian, VTK's writer).
  void skip_strings(std::size_t n, const std::string& what) {
    if (!binary_) {
      rest_of_line();
      for (std::size_t k = 0; k < n; ++k) {
        if (i_ >= s_.size()) fail(path_, what + ": the file ends after " + std::to_string(k) + " of " +
                                             std::to_string(n) + " strings");
        rest_of_line();
      }
      return;
    }
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t')) ++i_;
    if (i_ < s_.size() && s_[i_] == '\r') ++i_;
    if (i_ < s_.size() && s_[i_] == '\n') ++i_;
    for (std::size_t k = 0; k < n; ++k) {
      if (i_ >= s_.size()) fail(path_, what + ": the file ends inside its strings");
      const unsigned char b0 = static_cast<unsigned char>(s_[i_]);
      const std::size_t width = (b0 >> 6) == 3 ? 1 : (b0 >> 6) == 2 ? 2 : (b0 >> 6) == 1 ? 4 : 8;
      if (width > s_.size() - i_) fail(path_, what + ": the file ends inside its strings");
      std::uint64_t len = b0 & (width == 8 ? 0xFF : 0x3F);
      for (std::size_t b = 1; b < width; ++b) len = (len << 8) | static_cast<unsigned char>(s_[i_ + b]);
      i_ += width;
      if (len > s_.size() - i_) fail(path_, what + ": the file ends inside its strings");
      i_ += static_cast<std::size_t>(len);
    }
  }

  /// `n` values of type `t` as doubles (`keep` false: skipped).
  std::vector<double> values(std::size_t n, const LegacyType& t, const std::string& what, bool keep) {
    std::vector<double> out;
    if (!binary_) {
      // Each value takes at least two characters: a count the rest of the
      // file cannot hold is refused before anything is sized by it.
      if (n > (s_.size() - i_ + 1) / 2) fail(path_, what + ": the file ends before its " + std::to_string(n) + " values");
      if (keep) out.reserve(n);
      for (std::size_t k = 0; k < n; ++k) {
        const std::string_view w = word();
        if (w.empty())
          fail(path_, what + ": the file ends after " + std::to_string(k) + " of " + std::to_string(n) + " values");
        if (!keep && t.integer) continue;  // (floats are parsed: a word that is no number is an error anyway)
        double v = 0;
        if (t.integer) {
          // A whole number in the type's range: "2.5" or "nan" in an int
          // array was truncated, 300 in an unsigned_char taken as is.
          if (!integer_text(w, t, v))
            fail(path_, what + ": '" + printable(w) + "' is not a value of its type (" + t.name + ")");
          out.push_back(v);
          continue;
        }
        if (!parse_number(w, v)) fail(path_, what + ": '" + printable(w) + "' is not a number");
        // A float array's text is rounded to float, as its binary twin and
        // VTK's reader hold it.
        if (keep) out.push_back(!t.integer && t.bytes == 4 ? static_cast<double>(static_cast<float>(v)) : v);
      }
      return out;
    }
    // Binary: the block starts after the header line's newline.
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t')) ++i_;
    if (i_ < s_.size() && s_[i_] == '\r') ++i_;
    if (i_ < s_.size() && s_[i_] == '\n') ++i_;
    const std::size_t bytes = t.bytes == 0 ? (n + 7) / 8 : n * t.bytes;
    if (bytes > s_.size() - i_)
      fail(path_, what + ": the file ends before its " + std::to_string(n) + " values (" + std::to_string(bytes) +
                      " bytes, " + std::to_string(s_.size() - i_) + " left)");
    const unsigned char* p = reinterpret_cast<const unsigned char*>(s_.data() + i_);
    i_ += bytes;
    if (!keep) return out;
    out.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      if (t.bytes == 0) {
        out[k] = (p[k / 8] >> (7 - k % 8)) & 1;
        continue;
      }
      std::uint64_t u = 0;
      for (std::size_t b = 0; b < t.bytes; ++b) u = (u << 8) | p[k * t.bytes + b];  // big-endian
      if (!t.integer) {
        if (t.bytes == 4) {
          float f;
          const std::uint32_t u32 = static_cast<std::uint32_t>(u);
          std::memcpy(&f, &u32, 4);
          out[k] = f;
        } else {
          std::memcpy(&out[k], &u, 8);
        }
      } else if (t.is_signed && t.bytes < 8 && (u >> (8 * t.bytes - 1)) != 0) {
        out[k] = static_cast<double>(static_cast<std::int64_t>(u) - (std::int64_t(1) << (8 * t.bytes)));
      } else {
        out[k] = t.is_signed ? static_cast<double>(static_cast<std::int64_t>(u)) : static_cast<double>(u);
      }
    }
    return out;
  }

  /// METADATA: lines up to a blank one.
  void skip_metadata() {
    rest_of_line();
    while (i_ < s_.size()) {
      if (trim(rest_of_line()).empty()) return;
    }
  }

 private:
  void skip_space() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  std::string_view next_line() {
    if (i_ >= s_.size()) fail(path_, "not a legacy VTK file (it ends within its first three lines)");
    return rest_of_line();
  }
  /// An integer type's word: whole, and within the type's range (`bit`: 0 or 1).
  static bool integer_text(std::string_view w, const LegacyType& t, double& v) {
    if (!w.empty() && w.front() == '+') w.remove_prefix(1);
    const unsigned bits = t.bytes == 0 ? 1 : static_cast<unsigned>(8 * t.bytes);
    if (t.is_signed) {
      std::int64_t x = 0;
      const auto [p, ec] = std::from_chars(w.data(), w.data() + w.size(), x);
      if (w.empty() || ec != std::errc() || p != w.data() + w.size()) return false;
      if (bits < 64 && (x < -(std::int64_t(1) << (bits - 1)) || x >= (std::int64_t(1) << (bits - 1)))) return false;
      v = static_cast<double>(x);
      return true;
    }
    std::uint64_t x = 0;
    const auto [p, ec] = std::from_chars(w.data(), w.data() + w.size(), x);
    if (w.empty() || ec != std::errc() || p != w.data() + w.size()) return false;
    if (bits < 64 && x >= (std::uint64_t(1) << bits)) return false;
    v = static_cast<double>(x);
    return true;
  }

  static bool parse_number(std::string_view w, double& v) {
    if (w.size() > 1 && w.front() == '+') w.remove_prefix(1);  // (VTK's reader takes a sign)
    const auto [p, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
    if (ec == std::errc() && p == w.data() + w.size()) return true;
    // VTK writes non-finite values as nan, inf, -inf (and some writers 1.#INF).
    const std::string l = lower(w);
    if (l == "nan" || l == "-nan") return v = std::nan(""), true;
    if (l == "inf" || l == "infinity") return v = HUGE_VAL, true;
    if (l == "-inf" || l == "-infinity") return v = -HUGE_VAL, true;
    return false;
  }

  std::string path_;
  std::string s_;
  std::size_t i_ = 0;
  bool binary_ = false;
};

/// What the walk keeps: the points, and one POINT_DATA attribute by name
/// (or, `take_first`, the first of one component: an image's default).
struct LegacyPoints {
  bool take_first = false;
  std::size_t n = 0;
  std::vector<double> xyz;  // 3n
  bool found = false;       // the attribute named
  bool is_float = false;
  std::size_t type_bytes = 0;  // of the attribute named
  std::vector<double> values;
  std::vector<std::string> names;  // POINT_DATA attributes, for the message
  // STRUCTURED_POINTS (an image): its grid
  std::int64_t dims[3] = {0, 0, 0};
  double spacing[3] = {1, 1, 1}, origin[3] = {0, 0, 0};
};

/// Cells of the 5.1 format (OFFSETS and CONNECTIVITY blocks) or of the
/// older ones (one block of `size` ints).
void skip_cells(Legacy& f, const std::string& section) {
  const std::size_t a = f.count(section);
  const std::size_t b = f.count(section);
  if (f.peek_keyword() == "offsets") {
    for (const char* block : {"offsets", "connectivity"}) {
      if (f.keyword() != block) fail(f.path(), section + ": expected " + lower(block) + " data");
      const LegacyType t = f.type(section);
      f.values(std::string(block) == "offsets" ? a : b, t, section, false);
    }
    return;
  }
  f.values(b, type_of(4, true, true), section, false);
}

/// One attribute of POINT_DATA or CELL_DATA over `n` tuples; kept where it
/// is `wanted` (a POINT_DATA attribute of one component).
void read_attribute(Legacy& f, const std::string& kw, std::size_t n, bool point_data, const std::string& wanted,
                    LegacyPoints& out) {
  const std::string name = decoded(f.word());
  auto take = [&](const std::string& array, std::size_t components, std::size_t tuples, const LegacyType& t) {
    // Of arrays sharing the name asked for, the last: VTK's legacy readers
    // add each array to the point data, where one of the same name replaces
    // the one before (its XML readers keep the first). take_first: the first
    // of one component.
    const bool keep = point_data && (out.take_first ? !out.found && components == 1 && tuples == n && !t.string
                                                    : !wanted.empty() && array == wanted);
    if (point_data) out.names.push_back(array);
    if (t.string) {
      if (keep) fail(f.path(), "point data '" + array + "' holds strings, not numbers");
      f.skip_strings(components * tuples, "array '" + array + "'");
      return;
    }
    if (keep && components != 1)
      fail(f.path(), "point data '" + array + "' has " + std::to_string(components) + " components, expected 1");
    if (keep && tuples != n)
      fail(f.path(), "point data '" + array + "' has " + std::to_string(tuples) + " values for " +
                         std::to_string(n) + " points");
    std::vector<double> v = f.values(components * tuples, t, "array '" + array + "'", keep);
    if (keep) {
      out.found = true;
      out.is_float = !t.integer;
      out.type_bytes = t.bytes;
      out.values = std::move(v);
    }
  };
  if (kw == "scalars") {
    const LegacyType t = f.type("SCALARS " + name);
    std::size_t components = 1;
    const std::string_view more = f.rest_of_line();
    if (!more.empty()) {
      std::uint64_t c = 0;
      const auto [p, ec] = std::from_chars(more.data(), more.data() + more.size(), c);
      if (ec != std::errc() || p != more.data() + more.size() || c < 1 || c > 4)
        fail(f.path(), "SCALARS " + name + ": components must be 1 to 4, got '" + printable(more) + "'");
      components = static_cast<std::size_t>(c);
    }
    if (f.peek_keyword() == "lookup_table") {
      f.word();
      f.word();  // its name
    }
    take(name, components, n, t);
  } else if (kw == "color_scalars") {
    // Bytes in BINARY files; in ASCII each byte written as byte / 255, which
    // VTK's reader turns back into the byte.
    const std::size_t components = f.count("COLOR_SCALARS " + name);
    const bool found_before = out.found;
    take(name, components, n, f.binary() ? type_of(1, true, false) : type_of(8, false, true));
    if (!found_before && out.found && !f.binary()) {
      for (double& v : out.values) v = std::floor(255.0 * v + 0.5);
      out.is_float = false;
    }
  } else if (kw == "lookup_table") {
    const std::size_t size = f.count("LOOKUP_TABLE " + name);
    f.values(4 * size, type_of(1, true, false), "LOOKUP_TABLE " + name, false);
  } else if (kw == "vectors" || kw == "normals") {
    take(name, 3, n, f.type(kw + " " + name));
  } else if (kw == "texture_coordinates") {
    const std::size_t d = f.count("TEXTURE_COORDINATES " + name);
    if (d < 1 || d > 3) fail(f.path(), "TEXTURE_COORDINATES " + name + ": dimension must be 1 to 3");
    take(name, d, n, f.type(kw + " " + name));
  } else if (kw == "tensors" || kw == "tensors6") {
    take(name, kw == "tensors" ? 9 : 6, n, f.type(kw + " " + name));
  } else if (kw == "global_ids" || kw == "pedigree_ids" || kw == "edge_flags") {
    take(name, 1, n, f.type(kw + " " + name));
  } else if (kw == "field") {
    const std::size_t arrays = f.count("FIELD " + name);
    for (std::size_t k = 0; k < arrays; ++k) {
      const std::string array = decoded(f.word());
      if (lower(array) == "null_array") continue;
      const std::size_t components = f.count("array '" + array + "'");
      const std::size_t tuples = f.count("array '" + array + "'");
      const LegacyType t = f.type("array '" + array + "'");
      take(array, components, tuples, t);
      if (f.peek_keyword() == "metadata") f.skip_metadata();
    }
    return;
  } else {
    fail(f.path(), std::string(point_data ? "POINT_DATA" : "CELL_DATA") + ": unknown attribute '" + kw + "'");
  }
  if (f.peek_keyword() == "metadata") f.skip_metadata();
}

[[noreturn]] void no_array(const std::string& path, const std::string& name, const LegacyPoints& lp) {
  std::string names;
  for (const std::string& n : lp.names) names += (names.empty() ? "'" : ", '") + n + "'";
  fail(path, "no point data array '" + name + "'" +
                 (names.empty() ? std::string(" (the file has none)") : " (arrays: " + names + ")"));
}

/// The file's points (`image` false) or its image (STRUCTURED_POINTS: `image`
/// true), with the POINT_DATA attribute `wanted` where named (an image
/// without a name: its first attribute of one component).
LegacyPoints walk(const std::string& path, const std::string& wanted, bool image = false) {
  Legacy f(path, read_file_bytes(path));
  if (f.keyword() != "dataset") fail(path, "legacy VTK: expected DATASET after the file's header");
  const std::string ds = f.keyword();
  if (ds == "structured_points" && !image)
    fail(path, "a legacy VTK image (STRUCTURED_POINTS) holds no point set: give it to `sample-image` (or "
               "`surface-nets --image`), or its voxel centres as points");
  std::string upper = ds;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  if (image && ds != "structured_points")
    fail(path, "a legacy VTK " + upper + " is not an image (images are STRUCTURED_POINTS)");
  if (!image && ds != "polydata" && ds != "unstructured_grid" && ds != "structured_grid")
    fail(path, "legacy VTK DATASET '" + upper + "' is not supported (POLYDATA, UNSTRUCTURED_GRID or STRUCTURED_GRID)");
  LegacyPoints out;
  out.take_first = image && wanted.empty();
  bool have_points = false;
  bool in_data = false;    // after a POINT_DATA or CELL_DATA header
  bool in_points = false;  // inside POINT_DATA (or CELL_DATA: false)
  std::size_t tuples = 0;  // of the current POINT_DATA / CELL_DATA
  while (!f.at_end()) {
    const std::string kw = f.keyword();
    if (kw == "points") {
      if (have_points) fail(path, "legacy VTK: POINTS given twice");
      out.n = f.count("POINTS");
      out.xyz = f.values(3 * out.n, f.type("POINTS"), "POINTS", true);
      have_points = true;
    } else if (kw == "dimensions") {
      for (int k = 0; k < 3; ++k) out.dims[k] = static_cast<std::int64_t>(f.count("DIMENSIONS"));
    } else if (image && (kw == "spacing" || kw == "aspect_ratio" || kw == "origin")) {
      double* to = kw == "origin" ? out.origin : out.spacing;
      for (int k = 0; k < 3; ++k) to[k] = f.number(kw);
    } else if (kw == "vertices" || kw == "lines" || kw == "polygons" || kw == "triangle_strips" || kw == "cells") {
      skip_cells(f, kw);
    } else if (kw == "cell_types") {
      f.values(f.count("CELL_TYPES"), type_of(4, true, true), "CELL_TYPES", false);
    } else if (kw == "metadata") {
      f.skip_metadata();
    } else if (kw == "point_data" || kw == "cell_data") {
      in_data = true;
      in_points = kw == "point_data";
      tuples = f.count(kw);
      if (in_points && have_points && tuples != out.n)
        fail(path, "POINT_DATA has " + std::to_string(tuples) + " values for " + std::to_string(out.n) + " points");
      const std::uint64_t voxels = static_cast<std::uint64_t>(out.dims[0]) * static_cast<std::uint64_t>(out.dims[1]) *
                                   static_cast<std::uint64_t>(out.dims[2]);
      if (in_points && image && tuples != voxels)
        fail(path, "POINT_DATA has " + std::to_string(tuples) + " values for DIMENSIONS of " + std::to_string(voxels) +
                       " voxels");
    } else if (kw == "field" && !in_data) {
      // Field data of the whole dataset (a TIME, a CYCLE), not per point.
      read_attribute(f, kw, 0, false, std::string(), out);
    } else if (in_data) {
      read_attribute(f, kw, tuples, in_points, wanted, out);
    } else {
      fail(path, "legacy VTK: unexpected keyword '" + printable(kw) + "'");
    }
  }
  if (!have_points && !image) fail(path, "legacy VTK file without POINTS");
  if (image && (out.dims[0] == 0 || out.dims[1] == 0 || out.dims[2] == 0))
    fail(path, "legacy VTK image without DIMENSIONS (or with a dimension of 0)");
  return out;
}

}  // namespace

bool looks_like_legacy_vtk(std::string_view head) {
  return lower(head.substr(0, 22)) == "# vtk datafile version";
}

PointCloud read_vtk_legacy_points(const std::string& path, const ReadOptions& options,
                                  const std::string& label_array) {
  const LegacyPoints lp = walk(path, label_array);
  const int dim = options.dim ? options.dim : 3;
  PointCloud pc;
  pc.dim = dim;
  pc.n = lp.n;
  pc.coords.reserve(lp.n * static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < lp.n; ++i)
    for (int d = 0; d < dim; ++d) pc.coords.push_back(lp.xyz[3 * i + static_cast<std::size_t>(d)]);
  if (!label_array.empty()) {
    if (!lp.found) no_array(path, label_array, lp);
    if (lp.is_float) fail(path, "labels array '" + label_array + "' holds floating-point values, not integers");
    pc.labels = labels_from_values(path, label_array, lp.values);
  }
  return pc;
}

RawImage read_vtk_legacy_image(const std::string& path, const std::string& array) {
  // The array asked for, else the first of one component (VTK writes the
  // active scalars first).
  const LegacyPoints lp = walk(path, array, true);
  if (!lp.found && array.empty()) fail(path, "a legacy VTK image without point data of one component");
  if (!lp.found) no_array(path, array, lp);
  RawImage raw;
  ImageGeometry& g = raw.geometry;
  for (std::size_t a = 0; a < 3; ++a) {
    g.size[a] = lp.dims[a];
    g.spacing[a] = lp.spacing[a];
    g.origin[a] = lp.origin[a];
    // Voxel i lies at ORIGIN + i SPACING: a negative spacing is an axis
    // stored flipped (VTK's writers keep it so), read reversed from the
    // lowest voxel, as the other formats' flips are.
    if (g.spacing[a] < 0) {
      raw.flip[a] = true;
      g.origin[a] += static_cast<double>(g.size[a] - 1) * g.spacing[a];
      g.spacing[a] = -g.spacing[a];
    }
  }
  g.dim = g.size[2] == 1 ? 2 : 3;  // one slice: a 2D image, as a .vti's
  check_geometry(path, g);
  raw.converted = true;
  if (lp.is_float) {
    raw.type = lp.type_bytes == 4 ? ScalarType::f32 : ScalarType::f64;  // (named so in messages)
    raw.doubles = lp.values;
  } else {
    raw.type = ScalarType::i64;
    raw.ints.reserve(lp.values.size());
    for (std::size_t k = 0; k < lp.values.size(); ++k) {
      const double v = lp.values[k];
      if (!(v >= -0x1p63 && v < 0x1p63))  // (an unsigned 64-bit value past int64: the cast would wrap)
        fail(path, "voxel " + std::to_string(k) + " holds " + tessera::detail::number_text(v) +
                       ", beyond 64-bit signed integers");
      raw.ints.push_back(static_cast<std::int64_t>(v));
    }
  }
  return raw;
}

std::vector<double> read_vtk_legacy_point_array(const std::string& path, const std::string& name) {
  LegacyPoints lp = walk(path, name);
  if (!lp.found) no_array(path, name, lp);
  return std::move(lp.values);
}

}  // namespace tessera::io::detail
