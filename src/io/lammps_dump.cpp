// LAMMPS dump files (`dump atom` and `dump custom`, text; .dump, .lammpstrj):
// the first frame's atoms, one of their columns (labels, radii), and the
// simulation box with its periodic axes. LIGGGHTS writes the same format.
//
// A frame, as LAMMPS writes it:
//   ITEM: TIMESTEP            then the step
//   ITEM: NUMBER OF ATOMS     then n
//   ITEM: BOX BOUNDS [xy xz yz] XX YY ZZ
//                             then one line per axis, "lo hi [tilt]"; XX..ZZ
//                             are the boundary flags, "pp" periodic, f/s/m
//                             walls (fixed, shrink-wrapped, with a minimum)
//   ITEM: ATOMS name name ... then n lines of values
// Other items (UNITS, TIME) may stand before ATOMS; they are skipped. A frame
// is read from where it starts (the first by default, find_frame's for the
// others): the frames after it are left alone, and those before it are
// skipped by their headers and line counts.
//
// A triclinic box's BOX BOUNDS are the bounding box of the tilted box; the
// box itself (LAMMPS's "Howto triclinic") has
//   xlo = xlo_bound - min(0, xy, xz, xy + xz), xhi = xhi_bound - max(0, xy, xz, xy + xz),
//   ylo = ylo_bound - min(0, yz),              yhi = yhi_bound - max(0, yz),
// and lattice vectors a = (xhi - xlo, 0, 0), b = (xy, yhi - ylo, 0),
// c = (xz, yz, zhi - zlo): tessera's --bounds and --tilt exactly.
//
// Coordinates: columns x y z (as written, wrapped or not), else xu yu zu
// (unwrapped), else xs ys zs or xsu ysu zsu (fractions of the box:
// x = xlo + xs Lx + ys xy + zs xz, y = ylo + ys Ly + zs yz, z = zlo + zs Lz).
// Atoms keep the file's order (LAMMPS writes them in processor order unless
// `dump_modify sort id`): point k is the k-th atom line, whatever its id.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
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

constexpr std::string_view item = "ITEM:";

/// What a frame's header says.
struct DumpHeader {
  std::int64_t timestep = 0;
  std::size_t atoms = 0;
  FileBox box;
  std::vector<std::string> columns;
};

bool starts_with(std::string_view s, std::string_view p) { return s.substr(0, p.size()) == p; }

std::string_view after_item(std::string_view line) { return trim(line.substr(item.size())); }

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> w;
  Fields fs(line, ' ');
  std::string_view f;
  while (fs.next(f)) w.push_back(f);
  return w;
}

/// The box from BOX BOUNDS' words (after "BOX BOUNDS") and its three lines.
FileBox parse_box(const std::string& path, const std::vector<std::string_view>& flags_words,
                  const std::string_view lines[3], const std::size_t numbers[3]) {
  FileBox b;
  std::size_t w = 0;
  b.triclinic = flags_words.size() >= 3 && flags_words[0] == "xy" && flags_words[1] == "xz" && flags_words[2] == "yz";
  if (b.triclinic) w = 3;
  const std::size_t flags = flags_words.size() - w;
  if (flags != 0 && flags != 3)
    fail(path, "ITEM: BOX BOUNDS: expected three boundary flags (such as pp pp pp), got " + std::to_string(flags));
  double lo[3], hi[3], tilt[3] = {0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    const std::vector<std::string_view> v = words(lines[a]);
    const std::size_t want = b.triclinic ? 3 : 2;
    double x[3] = {0, 0, 0};
    bool ok = v.size() == want;
    for (std::size_t k = 0; ok && k < want; ++k) ok = parse_double(v[k], x[k]) && std::isfinite(x[k]);
    if (!ok)
      fail(path, "line " + std::to_string(numbers[a]) + ": the box's " + "xyz"[a] + " bounds: expected " +
                     std::to_string(want) + " finite numbers (lo hi" + (b.triclinic ? " tilt)" : ")"));
    lo[a] = x[0];
    hi[a] = x[1];
    tilt[a] = x[2];  // xy, xz, yz in that order of lines
    // A flag is two letters, the lower and the upper side: pp periodic, or
    // f, s, m walls (fixed, shrink-wrapped, with a minimum); without flags
    // (old dumps) every axis is a wall.
    if (flags == 3) {
      const std::string_view f = flags_words[w + static_cast<std::size_t>(a)];
      const auto side = [](char c) { return c == 'f' || c == 's' || c == 'm'; };
      b.periodic[a] = f == "pp";
      if (!b.periodic[a] && !(f.size() == 2 && side(f[0]) && side(f[1])))
        fail(path, "ITEM: BOX BOUNDS: boundary flag '" + std::string(f) + "' along " + "xyz"[a] +
                       " is not pp, or two of f, s, m");
    }
  }
  if (b.triclinic) {
    const double xy = tilt[0], xz = tilt[1], yz = tilt[2];
    lo[0] -= std::min({0.0, xy, xz, xy + xz});
    hi[0] -= std::max({0.0, xy, xz, xy + xz});
    lo[1] -= std::min(0.0, yz);
    hi[1] -= std::max(0.0, yz);
    b.tilt = {xy, xz, yz};
  }
  for (int a = 0; a < 3; ++a) {
    if (!(hi[a] > lo[a])) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "[%.17g, %.17g]", lo[a], hi[a]);
      fail(path, std::string("ITEM: BOX BOUNDS: empty ") + "xyz"[a] + " range of the box " + buf);
    }
    b.lo[static_cast<std::size_t>(a)] = lo[a];
    b.hi[static_cast<std::size_t>(a)] = hi[a];
  }
  return b;
}

/// Reads the first frame's header; `lines` then stands at its first atom line.
DumpHeader read_header(const std::string& path, Lines& lines, bool whole) {
  DumpHeader h;
  std::string_view line;
  std::size_t number = 0;
  bool have_step = false, have_atoms = false, have_box = false, have_units = false, have_time = false;
  auto next = [&](const char* what) {
    if (!lines.next(line, number)) frame_ended(path, std::string("the file ends before ") + what, whole);
    return trim(line);
  };
  // Each item once before ATOMS: a second one means this frame's ATOMS line
  // is missing or corrupted, and reading on would take a later frame's
  // atoms for the first's.
  auto once = [&](bool& seen, const char* name) {
    if (seen) fail(path, "line " + std::to_string(number) + ": ITEM: " + name + " again before ITEM: ATOMS");
    seen = true;
  };
  if (!lines.next(line, number)) frame_ended(path, "not a LAMMPS dump: it is empty", whole);
  // LAMMPS writes UNITS and TIME (dump_modify units, time) before TIMESTEP.
  for (const char* first : {"ITEM: TIMESTEP", "ITEM: UNITS", "ITEM: TIME"})
    if (trim(line) == first) goto header;
  fail(path, "not a LAMMPS dump: its first line is not 'ITEM: TIMESTEP' (or UNITS, TIME)");
header:
  for (;;) {
    const std::string_view l = trim(line);
    if (!starts_with(l, item)) fail(path, "line " + std::to_string(number) + ": expected an 'ITEM:' line");
    const std::string_view what = after_item(l);
    if (what == "TIMESTEP") {
      once(have_step, "TIMESTEP");
      const std::string_view v = next("the timestep");
      auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), h.timestep);
      if (ec != std::errc() || p != v.data() + v.size())
        fail(path, "line " + std::to_string(number) + ": the timestep is not an integer");
    } else if (what == "NUMBER OF ATOMS") {
      once(have_atoms, "NUMBER OF ATOMS");
      const std::string_view v = next("the number of atoms");
      std::uint64_t n = 0;
      auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), n);
      if (ec != std::errc() || p != v.data() + v.size())
        fail(path, "line " + std::to_string(number) + ": the number of atoms is not a count");
      if (n > (std::uint64_t{1} << 31) - 1) fail(path, "more than 2^31 - 1 atoms (point ids are int32)");
      h.atoms = static_cast<std::size_t>(n);
    } else if (what == "BOX BOUNDS" || starts_with(what, "BOX BOUNDS ")) {
      once(have_box, "BOX BOUNDS");
      const std::vector<std::string_view> flags = words(what.substr(std::string_view("BOX BOUNDS").size()));
      std::string_view box_lines[3];
      std::size_t numbers[3];
      for (int a = 0; a < 3; ++a) {
        box_lines[a] = next("the box's three lines");
        numbers[a] = number;
      }
      h.box = parse_box(path, flags, box_lines, numbers);
    } else if (what == "ATOMS" || starts_with(what, "ATOMS ")) {
      if (!have_step || !have_atoms || !have_box)
        fail(path, std::string("ITEM: ATOMS before the frame's ") + (!have_atoms ? "NUMBER OF ATOMS"
                                                                     : !have_box ? "BOX BOUNDS"
                                                                                 : "TIMESTEP"));
      for (std::string_view w : words(what.substr(5))) h.columns.emplace_back(w);
      if (h.columns.empty()) fail(path, "ITEM: ATOMS names no columns");
      h.box.timestep = h.timestep;
      h.box.declared_by = "LAMMPS dump, timestep " + std::to_string(h.timestep);
      return h;
    } else if (what == "UNITS" || what == "TIME") {
      // LAMMPS's optional items: one line (the unit style, the time).
      once(what == "UNITS" ? have_units : have_time, what == "UNITS" ? "UNITS" : "TIME");
      next(what == "UNITS" ? "the unit style" : "the time");
    } else {
      // Any other name is a corrupted one, ATOMS perhaps, whose atoms would
      // be skipped as its lines.
      fail(path, "line " + std::to_string(number) + ": unknown item '" + std::string(what) +
                     "' (a dump frame has UNITS, TIME, TIMESTEP, NUMBER OF ATOMS, BOX BOUNDS and ATOMS)");
    }
    if (!lines.next(line, number)) frame_ended(path, "the file ends before ITEM: ATOMS", whole);
  }
}

std::size_t column_index(const std::string& path, const DumpHeader& h, const std::string& name, const char* what) {
  const auto it = std::find(h.columns.begin(), h.columns.end(), name);
  if (it == h.columns.end())
    fail(path, "no column '" + name + "' for " + what + " (columns: " + quoted_list(h.columns) + ")");
  return static_cast<std::size_t>(it - h.columns.begin());
}

/// The atom lines' values of `cols` (columns of the header), atoms × cols,
/// row-major. Every line must have one field per column; the wanted ones
/// must be numbers (others, such as an element name, are not read). No
/// columns: the lines are only counted (a frame skipped; ~4x faster).
std::vector<double> atom_values(const std::string& path, Lines& lines, std::size_t text_size, const DumpHeader& h,
                                const std::vector<std::size_t>& cols, std::optional<std::string_view> tail,
                                FrameEnd* end = nullptr) {
  const bool whole = !tail;
  // Sized by the lines the text can hold, not by the count the header
  // claims (2^31 - 1 atoms in a 150-byte file asked for 48 GB).
  std::vector<double> out;
  out.reserve(std::min(h.atoms, text_size / 2) * cols.size());
  std::vector<std::string_view> f(h.columns.size());
  std::string_view line;
  std::size_t number = 0;
  for (std::size_t k = 0; k < h.atoms; ++k) {
    if (!lines.next(line, number))
      atoms_ended(path, lines.line_number(), k, h.atoms, whole);
    if (cols.empty()) {  // a frame skipped (find_frame): its lines counted, not split
      if (starts_with(trim(line), item))
        fail(path, "line " + std::to_string(number) + ": found the next item: fewer atoms than NUMBER OF ATOMS");
      continue;
    }
    out.resize(out.size() + cols.size());
    const std::size_t got = split_fields(line, f);
    if (got != f.size())
      fail(path, "line " + std::to_string(number) + ": expected " + std::to_string(f.size()) +
                     " values (the columns of ITEM: ATOMS)" +
                     (starts_with(trim(line), item) ? ", found the next item: fewer atoms than NUMBER OF ATOMS" : ""));
    for (std::size_t c = 0; c < cols.size(); ++c)
      if (!parse_double(f[cols[c]], out[k * cols.size() + c]))
        fail(path, "line " + std::to_string(number) + ": column '" + h.columns[cols[c]] + "' is not a number: '" +
                       std::string(f[cols[c]]) + "'");
  }
  // The frame ends at the next frame's first item or at the end of the
  // file: another line is an atom NUMBER OF ATOMS did not count.
  if (end != nullptr) *end = FrameEnd{lines.position(), lines.line_number() + 1, true};
  const std::size_t last = lines.line_number();
  const bool more = lines.next(line, number);
  if (more ? !starts_with(trim(line), item) : !frame_follows(tail, item))
    fail(path, (more ? "line " + std::to_string(number) : "after line " + std::to_string(last)) +
                   ": more atom lines than NUMBER OF ATOMS (" + std::to_string(h.atoms) + ")");
  if (end != nullptr) {
    end->last = !more && !tail;
    if (more) *end = FrameEnd{lines.offset_of(line), number, false};  // the next frame's first item, past blank lines
  }
  return out;
}

/// Which columns hold the coordinates, and whether they are box fractions.
struct CoordinateColumns {
  std::size_t col[3] = {0, 0, 0};
  bool scaled = false;
};

CoordinateColumns coordinate_columns(const std::string& path, const DumpHeader& h, int dim) {
  static const char* const sets[4][3] = {
      {"x", "y", "z"}, {"xu", "yu", "zu"}, {"xs", "ys", "zs"}, {"xsu", "ysu", "zsu"}};
  for (int s = 0; s < 4; ++s) {
    CoordinateColumns c;
    c.scaled = s >= 2;
    bool all = true;
    // A scaled x needs every fraction: y and z move it in a triclinic box.
    const int needed = c.scaled ? 3 : dim;
    for (int a = 0; a < needed && all; ++a) {
      const auto it = std::find(h.columns.begin(), h.columns.end(), sets[s][a]);
      all = it != h.columns.end();
      if (all) c.col[a] = static_cast<std::size_t>(it - h.columns.begin());
    }
    if (all) return c;
  }
  fail(path,
       "no coordinate columns: expected x y z, xu yu zu, xs ys zs or xsu ysu zsu among " + quoted_list(h.columns));
}

}  // namespace

TrajectoryFrame read_dump_frame(const std::string& path, std::uint64_t offset, std::size_t line,
                                const ReadOptions& options, const std::string& label_column) {
  const int dim = options.dim == 0 ? 3 : options.dim;
  DumpHeader h;
  CoordinateColumns cc;
  std::vector<std::size_t> cols;
  FrameEnd end;
  const std::vector<double> v =
      frame_at(path, offset, [&](std::string_view text, std::optional<std::string_view> tail) {
        Lines lines(text, line);
        h = read_header(path, lines, !tail);
        if (dim == 2 && (h.box.tilt[1] != 0 || h.box.tilt[2] != 0))
          fail(path, "--dim 2: the box tilts along z (xz, yz not 0); a 2D box has the xy tilt only");
        cc = coordinate_columns(path, h, dim);
        cols.assign(cc.col, cc.col + (cc.scaled ? 3 : dim));
        if (!label_column.empty()) cols.push_back(column_index(path, h, label_column, "labels"));
        return atom_values(path, lines, text.size(), h, cols, tail, &end);
      });
  const std::size_t coords = cc.scaled ? 3 : static_cast<std::size_t>(dim);

  TrajectoryFrame frame;
  frame.box = h.box;
  frame.next_offset = offset + end.bytes;
  frame.next_line = end.next_line;
  frame.last = end.last;
  PointCloud& pc = frame.points;
  pc.dim = dim;
  pc.n = h.atoms;
  pc.coords.resize(pc.n * static_cast<std::size_t>(dim));
  const FileBox& b = h.box;
  for (std::size_t k = 0; k < pc.n; ++k) {
    const double* r = &v[k * cols.size()];
    double* x = &pc.coords[k * static_cast<std::size_t>(dim)];
    if (cc.scaled) {
      const double L[3] = {b.hi[0] - b.lo[0], b.hi[1] - b.lo[1], b.hi[2] - b.lo[2]};
      const double full[3] = {b.lo[0] + r[0] * L[0] + r[1] * b.tilt[0] + r[2] * b.tilt[1],
                              b.lo[1] + r[1] * L[1] + r[2] * b.tilt[2], b.lo[2] + r[2] * L[2]};
      for (int a = 0; a < dim; ++a) x[a] = full[a];
    } else {
      for (int a = 0; a < dim; ++a) x[a] = r[a];
    }
  }
  if (!label_column.empty()) pc.labels = atom_labels(path, label_column, v, cols.size(), coords);
  return frame;
}

PointCloud read_dump_points(const std::string& path, const ReadOptions& options, const std::string& label_column) {
  return read_dump_frame(path, options.frame.offset, options.frame.line, options, label_column).points;
}

std::vector<double> read_dump_column(const std::string& path, const std::string& name, const FramePlace& frame) {
  return frame_at(path, frame.offset, [&](std::string_view text, std::optional<std::string_view> tail) {
    Lines lines(text, frame.line);
    const DumpHeader h = read_header(path, lines, !tail);
    return atom_values(path, lines, text.size(), h, {column_index(path, h, name, "scalars")}, tail);
  });
}

FileBox read_dump_box(const std::string& path, const FramePlace& frame) {
  return frame_at(path, frame.offset, [&](std::string_view text, std::optional<std::string_view> tail) {
    Lines lines(text, frame.line);
    return read_header(path, lines, !tail).box;
  });
}

FrameEnd skip_dump_frame(const std::string& path, std::uint64_t offset, std::size_t line) {
  return frame_at(path, offset, [&](std::string_view text, std::optional<std::string_view> tail) {
    Lines lines(text, line);
    FrameEnd end;
    const auto header = read_header(path, lines, !tail);
    atom_values(path, lines, text.size(), header, {}, tail, &end);
    end.atoms = header.atoms;
    return end;
  });
}

}  // namespace tessera::io::detail
