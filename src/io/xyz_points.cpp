// XYZ files as chemistry and materials codes write them (ASE, OVITO, VMD,
// LAMMPS's `dump xyz`), and extended XYZ (ASE's and libAtoms' extxyz):
//
//   N                                   the number of atoms
//   comment                             free text, possibly empty; in
//                                       extended XYZ key=value pairs:
//                                       Lattice="ax ay az bx by bz cx cy cz"
//                                       Properties=species:S:1:pos:R:3:...
//                                       pbc="T T F", Origin="x y z"
//   N lines: species x y z [more]       (extended: the Properties' columns)
//
// A trajectory repeats the block; one frame is read (the first by default). Without
// Properties the columns are a species name and the position. Properties
// name each column group as name:type:count, type S (text), R (real),
// I (integer) or L (logical); pos (R:3) gives the position, an I:1 property
// can be labels and an R:1 or I:1 one scalars (radii).
//
// The box: Lattice's rows are the cell vectors a, b, c from Origin (0 when
// absent); pbc defaults to T T T where a Lattice is given (the extxyz
// convention). tessera's boxes are a = (Lx, 0, 0), b = (xy, Ly, 0),
// c = (xz, yz, Lz): a cell in another orientation would have to be rotated,
// points and all, and is refused with that said.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "io_detail.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/points.hpp"
#include "text_fields.hpp"

namespace tessera::io::detail {
namespace {

/// Raw lines, empty ones included (an XYZ comment may be empty); '\r' and a
/// UTF-8 BOM stripped.
class RawLines {
 public:
  explicit RawLines(std::string_view text, std::size_t first_line = 1)
      : begin_(text.data()), p_(text.data()), end_(text.data() + text.size()), number_(first_line - 1) {
    if (text.substr(0, 3) == "\xEF\xBB\xBF") p_ += 3;
  }
  std::size_t position() const { return static_cast<std::size_t>(p_ - begin_); }
  bool next(std::string_view& line) {
    if (p_ >= end_) return false;
    const char* nl = static_cast<const char*>(std::memchr(p_, '\n', static_cast<std::size_t>(end_ - p_)));
    const char* e = nl ? nl : end_;
    line = std::string_view(p_, static_cast<std::size_t>(e - p_));
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    p_ = nl ? nl + 1 : end_;
    ++number_;
    return true;
  }
  std::size_t number() const { return number_; }

 private:
  const char* begin_;
  const char* p_;
  const char* end_;
  std::size_t number_;
};

/// `line` as a lone count (an XYZ file's first line), if it is one.
std::optional<std::size_t> lone_count(std::string_view line) {
  const std::string_view t = trim(line);
  std::size_t n = 0;
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), n);
  if (t.empty() || ec != std::errc() || p != t.data() + t.size()) return std::nullopt;
  return n;
}

/// One column group of Properties: name, type letter, first column, count.
struct Property {
  std::string name;
  char type = 'R';
  std::size_t column = 0, count = 1;
};

struct XyzHeader {
  std::size_t atoms = 0;
  std::size_t comment_line = 2;  // its number in the file
  std::vector<Property> properties;
  std::size_t columns = 0;  // fields per atom line
  std::optional<FileBox> box;
  /// Why the Lattice is no box of ours (a cell in another orientation), or
  /// empty: said where the box is asked for (read_xyz_box, read_xyz_frame),
  /// not where only the atoms are, so that --bounds can stand in for it.
  std::string box_error;
};

/// The comment line's key=value pairs (values bare or in double quotes);
/// keys lowercased. A comment that is plain text gives pairs of nothing.
std::vector<std::pair<std::string, std::string>> key_values(std::string_view s) {
  std::vector<std::pair<std::string, std::string>> kv;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && is_blank(s[i])) ++i;
    const std::size_t k0 = i;
    while (i < s.size() && s[i] != '=' && !is_blank(s[i])) ++i;
    if (i >= s.size() || s[i] != '=') continue;  // a word with no value
    std::string key = lower(s.substr(k0, i - k0));
    ++i;
    std::string value;
    if (i < s.size() && s[i] == '"') {
      const std::size_t close = s.find('"', i + 1);
      const std::size_t e = close == std::string_view::npos ? s.size() : close;
      value = std::string(s.substr(i + 1, e - i - 1));
      i = e + 1;
    } else {
      const std::size_t v0 = i;
      while (i < s.size() && !is_blank(s[i])) ++i;
      value = std::string(s.substr(v0, i - v0));
    }
    kv.emplace_back(std::move(key), std::move(value));
  }
  return kv;
}

std::vector<double> numbers(const std::string& path, const std::string& where, const std::string& what,
                            const std::string& value, std::size_t want) {
  std::vector<double> v;
  Fields fs(value, ' ');
  std::string_view f;
  double x = 0;
  while (fs.next(f)) {
    if (!parse_double(f, x) || !std::isfinite(x))
      fail(path, where + what + " holds '" + std::string(f) + "', not a finite number");
    v.push_back(x);
  }
  if (v.size() != want)
    fail(path, where + what + " needs " + std::to_string(want) + " numbers, got " + std::to_string(v.size()));
  return v;
}

XyzHeader read_header(const std::string& path, RawLines& lines, bool whole) {
  XyzHeader h;
  std::string_view line;
  if (!lines.next(line)) frame_ended(path, "no points", whole);
  const std::optional<std::size_t> n = lone_count(line);
  if (!n) fail(path, "not an XYZ file: its first line is not the number of atoms");
  // (A frame of 0 atoms is a frame, as a dump's: read_points refuses it as
  // "no points", a trajectory's walk goes past it.)
  if (*n > (std::size_t{1} << 31) - 1) fail(path, "more than 2^31 - 1 atoms (point ids are int32)");
  h.atoms = *n;
  if (!lines.next(line)) frame_ended(path, "the file ends before the comment line", whole);
  h.comment_line = lines.number();
  const std::string where = "line " + std::to_string(h.comment_line) + ": ";
  const auto kv = key_values(line);
  auto find = [&](const char* key) -> const std::string* {
    for (const auto& [k, v] : kv)
      if (k == key) return &v;
    return nullptr;
  };
  // Columns: Properties, or a species name and the position.
  if (const std::string* props = find("properties")) {
    std::vector<std::string> parts;
    std::size_t from = 0;
    for (std::size_t c = 0; c <= props->size(); ++c)
      if (c == props->size() || (*props)[c] == ':') {
        parts.push_back(props->substr(from, c - from));
        from = c + 1;
      }
    if (parts.size() % 3 != 0) fail(path, where + "Properties must be name:type:count triples, got '" + *props + "'");
    for (std::size_t k = 0; k < parts.size(); k += 3) {
      Property p;
      p.name = parts[k];
      const std::string type = parts[k + 1];
      std::size_t count = 0;
      const std::string& cs = parts[k + 2];
      auto [q, ec] = std::from_chars(cs.data(), cs.data() + cs.size(), count);
      if (type.size() != 1 || std::string("SRIL").find(type[0]) == std::string::npos || ec != std::errc() ||
          q != cs.data() + cs.size() || count == 0 || count > 1000)
        fail(path, where + "Properties entry '" + p.name + ":" + type + ":" + cs + "' is not name:S|R|I|L:count");
      p.type = type[0];
      p.count = count;
      p.column = h.columns;
      h.columns += count;
      h.properties.push_back(p);
    }
  } else {
    h.properties = {{"species", 'S', 0, 1}, {"pos", 'R', 1, 3}};
    h.columns = 4;
  }
  if (const std::string* lattice = find("lattice")) {
    const std::vector<double> v = numbers(path, where, "Lattice", *lattice, 9);
    FileBox b;
    if (v[1] != 0 || v[2] != 0 || v[5] != 0 || !(v[0] > 0 && v[4] > 0 && v[8] > 0)) {
      h.box_error = where +
                    "the Lattice's cell must have a along +x and b in the xy plane (ay = az = bz = 0, and "
                    "ax, by, cz > 0), as LAMMPS's and tessera's boxes; rotate the cell and the atoms to that "
                    "orientation, or give --bounds";
      return h;
    }
    std::vector<double> origin = {0, 0, 0};
    if (const std::string* o = find("origin")) origin = numbers(path, where, "Origin", *o, 3);
    b.periodic = {true, true, true};
    if (const std::string* pbc = find("pbc")) {
      Fields fs(*pbc, ' ');
      std::string_view f;
      std::size_t a = 0;
      for (; fs.next(f); ++a) {
        const std::string w = lower(f);
        const bool t = w == "t" || w == "true" || w == "1", no = w == "f" || w == "false" || w == "0";
        if (a >= 3 || (!t && !no)) fail(path, where + "pbc must be three of T and F, got '" + *pbc + "'");
        b.periodic[a] = t;
      }
      if (a != 3) fail(path, where + "pbc must be three of T and F, got '" + *pbc + "'");
    }
    for (std::size_t a = 0; a < 3; ++a) {
      b.lo[a] = origin[a];
      b.hi[a] = origin[a] + v[a * 4];  // the diagonal: ax, by, cz
    }
    b.tilt = {v[3], v[6], v[7]};  // bx, cx, cy
    b.triclinic = v[3] != 0 || v[6] != 0 || v[7] != 0;
    b.declared_by = "extended XYZ Lattice";
    h.box = b;
  }
  return h;
}

const Property* find_property(const XyzHeader& h, const std::string& name) {
  for (const Property& p : h.properties)
    if (p.name == name) return &p;
  return nullptr;
}

/// The column of the one-value property `name` of a type in `types`.
std::size_t property_column(const std::string& path, const XyzHeader& h, const std::string& name, const char* types,
                            const char* what) {
  const Property* p = find_property(h, name);
  if (p == nullptr) {
    std::vector<std::string> names;
    for (const Property& q : h.properties) names.push_back(q.name);
    fail(path, "no property '" + name + "' for " + what + " (properties: " + quoted_list(names) + ")");
  }
  if (p->count != 1 || std::string(types).find(p->type) == std::string::npos)
    fail(path, "property '" + name + "' for " + what + " is " + std::string(1, p->type) + ":" +
                   std::to_string(p->count) + "; need " +
                   (std::string(types) == "I" ? "I:1 (integers)" : "R:1 or I:1"));
  return p->column;
}

/// The atom lines' values of `cols`, atoms × cols; no columns: the lines
/// are only counted (a frame skipped).
std::vector<double> atom_values(const std::string& path, RawLines& lines, std::size_t text_size, const XyzHeader& h,
                                const std::vector<std::size_t>& cols, std::optional<std::string_view> tail,
                                FrameEnd* end = nullptr) {
  const bool whole = !tail;
  // Sized by the lines the text can hold, not by the count the file claims.
  std::vector<double> out;
  out.reserve(std::min(h.atoms, text_size / 2) * cols.size());
  std::vector<std::string_view> f(h.columns);
  std::string_view line;
  // Plain XYZ lines may carry more columns (velocities) than the four read.
  const bool plain = h.properties.size() == 2 && h.properties[0].name == "species" && h.columns == 4;
  for (std::size_t k = 0; k < h.atoms; ++k) {
    if (!lines.next(line))
      atoms_ended(path, lines.number(), k, h.atoms, whole);
    if (cols.empty()) continue;  // a frame skipped (find_frame): its lines counted, not split
    out.resize(out.size() + cols.size());
    const std::size_t got = split_fields(line, f);
    if (got < f.size() || (got > f.size() && !plain))
      fail(path, "line " + std::to_string(lines.number()) + ": expected " + std::to_string(f.size()) +
                     " values per atom, got " + std::to_string(got));
    for (std::size_t c = 0; c < cols.size(); ++c)
      if (!parse_double(f[cols[c]], out[k * cols.size() + c]))
        fail(path, "line " + std::to_string(lines.number()) + ": '" + std::string(f[cols[c]]) + "' is not a number");
  }
  // The frame ends at the next frame's count line or at the end of the file
  // (blank lines aside): another line is an atom the count did not count.
  const std::size_t last = lines.number();
  for (std::size_t at = lines.position(); lines.next(line); at = lines.position())
    if (!trim(line).empty()) {
      if (!lone_count(line))
        fail(path, "line " + std::to_string(lines.number()) + ": more atom lines than the frame's count (" +
                       std::to_string(h.atoms) + ")");
      if (end != nullptr) *end = FrameEnd{at, lines.number(), false};
      return out;
    }
  if (tail) {  // the next line starts in the bytes past the prefix
    const std::string_view t = trim(*tail);
    if (t.empty()) throw FrameCut{};
    if (t[0] < '0' || t[0] > '9')
      fail(path, "after line " + std::to_string(last) + ": more atom lines than the frame's count (" +
                     std::to_string(h.atoms) + ")");
    if (end != nullptr) *end = FrameEnd{lines.position(), lines.number() + 1, false};
    return out;
  }
  if (end != nullptr) *end = FrameEnd{lines.position(), lines.number() + 1, true};
  return out;
}

}  // namespace

bool looks_like_xyz(std::string_view text) {
  // A lone count, any comment, then an atom line of a position at least (a
  // column of single numbers is a one-column point file, refused as such).
  // A second count is Qhull's header (dimension, then count: rbox's output).
  RawLines lines(text);
  std::string_view first, comment, atom;
  if (!lines.next(first) || !lone_count(first) || !lines.next(comment)) return false;
  // Frames of no atoms (a trajectory of a group empty at first) lead straight
  // to the next frame's count (a fuzz found such a file taken for no XYZ).
  for (int empty = 0; *lone_count(first) == 0; ++empty)
    if (empty == 64 || !lines.next(first) || !lone_count(first) || !lines.next(comment)) return false;
  if (!lines.next(atom)) return false;
  Fields fs(atom, ' ');
  std::string_view f;
  std::size_t fields = 0;
  while (fields < 5 && fs.next(f)) ++fields;
  // Two counts are also Qhull's header (dimension and count, either first:
  // rbox's output), whose points have as many coordinates as the smaller.
  if (fields < 3) return false;
  if (const auto second = lone_count(comment)) return fields != std::min(*lone_count(first), *second);
  return true;
}

TrajectoryFrame read_xyz_frame(const std::string& path, std::uint64_t offset, std::size_t line,
                               const ReadOptions& options, const std::string& label_column, bool with_box) {
  const int dim = options.dim == 0 ? 3 : options.dim;
  XyzHeader h;
  std::vector<std::size_t> cols;
  FrameEnd end;
  const std::vector<double> v =
      frame_at(path, offset, [&](std::string_view text, std::optional<std::string_view> tail) {
        RawLines lines(text, line);
        h = read_header(path, lines, !tail);
        const Property* pos = find_property(h, "pos");
        if (pos == nullptr || pos->type != 'R' || pos->count != 3)
          fail(path, "line " + std::to_string(h.comment_line) + ": Properties has no pos:R:3 (the positions)");
        cols.clear();
        for (int a = 0; a < dim; ++a) cols.push_back(pos->column + static_cast<std::size_t>(a));
        if (!label_column.empty()) cols.push_back(property_column(path, h, label_column, "I", "labels"));
        if (dim == 2 && h.box && (h.box->tilt[1] != 0 || h.box->tilt[2] != 0))
          fail(path, "--dim 2: the Lattice tilts along z (cx, cy not 0); a 2D box has the xy tilt only");
        return atom_values(path, lines, text.size(), h, cols, tail, &end);
      });
  if (with_box && !h.box_error.empty()) fail(path, h.box_error);  // no box would be a wrong one
  TrajectoryFrame frame;
  frame.box = h.box;
  frame.next_offset = offset + end.bytes;
  frame.next_line = end.next_line;
  frame.last = end.last;
  PointCloud& pc = frame.points;
  pc.dim = dim;
  pc.n = h.atoms;
  pc.coords.resize(pc.n * static_cast<std::size_t>(dim));
  for (std::size_t k = 0; k < pc.n; ++k)
    for (int a = 0; a < dim; ++a)
      pc.coords[k * static_cast<std::size_t>(dim) + static_cast<std::size_t>(a)] =
          v[k * cols.size() + static_cast<std::size_t>(a)];
  if (!label_column.empty()) pc.labels = atom_labels(path, label_column, v, cols.size(), static_cast<std::size_t>(dim));
  return frame;
}

PointCloud read_xyz_points(const std::string& path, const ReadOptions& options, const std::string& label_column) {
  return read_xyz_frame(path, options.frame.offset, options.frame.line, options, label_column, false).points;
}

std::vector<double> read_xyz_column(const std::string& path, const std::string& name, const FramePlace& frame) {
  return frame_at(path, frame.offset, [&](std::string_view text, std::optional<std::string_view> tail) {
    RawLines lines(text, frame.line);
    const XyzHeader h = read_header(path, lines, !tail);
    return atom_values(path, lines, text.size(), h, {property_column(path, h, name, "RI", "scalars")}, tail);
  });
}

std::optional<FileBox> read_xyz_box(const std::string& path, const FramePlace& frame) {
  return frame_at(path, frame.offset, [&](std::string_view text, std::optional<std::string_view> tail) {
    RawLines lines(text, frame.line);
    const XyzHeader h = read_header(path, lines, !tail);
    if (!h.box_error.empty()) fail(path, h.box_error);
    return h.box;
  });
}

FrameEnd skip_xyz_frame(const std::string& path, std::uint64_t offset, std::size_t line) {
  return frame_at(path, offset, [&](std::string_view text, std::optional<std::string_view> tail) {
    RawLines lines(text, line);
    FrameEnd end;
    const auto header = read_header(path, lines, !tail);
    atom_values(path, lines, text.size(), header, {}, tail, &end);
    end.atoms = header.atoms;
    return end;
  });
}

bool is_xyz_file(const std::string& path) {
  // Its first three lines, however long the comment (extended XYZ's can be);
  // a first line that is no lone count settles it without more.
  return first_frame(path, [&](std::string_view text, std::optional<std::string_view> tail) {
    RawLines lines(text);
    std::string_view first;
    if (lines.next(first) && !lone_count(first)) return false;
    // (Three lines, or past empty frames two more for each, up to 64 of them.)
    if (tail && std::count(text.begin(), text.end(), '\n') < 3 + 2 * 64 && !looks_like_xyz(text)) throw FrameCut{};
    return looks_like_xyz(text);
  });
}

}  // namespace tessera::io::detail
