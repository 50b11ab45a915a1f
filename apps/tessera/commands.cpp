// Implementation of the tessera subcommands (see commands.hpp).
#include "commands.hpp"
#include "walls_file.hpp"
#include "frame_series.hpp"
#include "stdin_input.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <system_error>
#include <vector>

#include "progress.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"
#include "tessera/io/tables.hpp"
#include "tessera/io/vtk_xml.hpp"

namespace tessera::cli {

std::string strf(const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  va_list ap2;
  va_copy(ap2, ap);
  const int n = std::vsnprintf(nullptr, 0, fmt, ap);
  va_end(ap);
  std::string s(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(s.data(), s.size() + 1, fmt, ap2);
  va_end(ap2);
  return s;
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

// Shared with the other subcommand files (declared in commands.hpp).

/// Lower-cased extension including the dot ("" when there is none).
std::string extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext;
}

void route_standard_output(std::initializer_list<const std::string*> outputs) {
  int to_stdout = 0;
  for (const std::string* p : outputs) to_stdout += *p == "-";
  if (to_stdout > 1) throw InputError("only one output can go to standard output ('-')");
  if (to_stdout == 0) return;
  // glibc's stdout is a variable: the summaries' printf calls now write to
  // standard error, while file descriptor 1 carries the output alone.
  std::fflush(stdout);
  stdout = stderr;
}

void check_distinct_outputs(std::initializer_list<std::pair<const char*, const std::string*>> outputs) {
  // The same file by another spelling (./a.npy, dir/../a.npy, a link to it)
  // is the same output: compared as the paths resolve, made absolute first
  // (weakly_canonical left a bare name of a file not there yet relative,
  // "x.npy", and resolved "./x.npy": a fuzz found them taken for two files).
  auto resolved = [](const std::string& p) {
    std::error_code ec;
    const std::filesystem::path a = std::filesystem::absolute(p, ec);
    if (ec) return std::filesystem::path(p).lexically_normal();
    const std::filesystem::path r = std::filesystem::weakly_canonical(a, ec);
    return ec ? a.lexically_normal() : r;
  };
  std::vector<std::pair<const char*, std::filesystem::path>> seen;
  for (const auto& [option, path] : outputs) {
    if (path->empty() || *path == "-") continue;
    const std::filesystem::path r = resolved(*path);
    for (const auto& [other, before] : seen)
      if (before == r)
        throw InputError(std::string(other) + " and " + option + " name the same file, " + *path +
                         ": each output needs its own");
    seen.emplace_back(option, r);
  }
}

namespace {

const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

// ---------------------------------------------------------------- validation

/// Output names are checked before anything is read or computed, so a typo
/// does not cost a long run.
void check_output_names(const VoronoiArgs& a) {
  if (a.output == "-") throw InputError("-o: cells are written to a .vtu or .vtp file, not to standard output");
  if (!a.output.empty()) {
    const std::string e = extension(a.output);
    if (e != ".vtu" && e != ".vtp")
      throw InputError("output " + a.output + ": unknown extension '" + e +
                       "' (use .vtu for 3D cells, .vtp for 2D cells)");
  }
  if (!a.cell_table.empty() && a.cell_table != "-") {  // "-": the CSV on standard output
    const std::string e = extension(a.cell_table);
    if (e != ".csv" && e != ".npy")
      throw InputError("--cell-table " + a.cell_table + ": unknown extension '" + e + "' (use .csv or .npy)");
  }
  if (!a.neighbors.empty() && a.neighbors != "-" && extension(a.neighbors) != ".npy")
    throw InputError("--neighbors " + a.neighbors + ": must be a .npy file");
  if (!a.neighbor_shifts.empty() && extension(a.neighbor_shifts) != ".npy")
    throw InputError("--neighbor-shifts " + a.neighbor_shifts + ": must be a .npy file");
  if (!a.neighbor_shifts.empty() && a.compute.periodic.empty())
    throw InputError("--neighbor-shifts: only with --periodic (without it every neighbour is the point itself)");
  if (a.output.empty() && a.cell_table.empty() && a.neighbors.empty() && a.neighbor_shifts.empty() && !a.validate)
    throw InputError("nothing to do: give -o OUTPUT.vtu|.vtp, --cell-table, --neighbors or --validate");
}

}  // namespace

/// --bounds: 4 or 6 finite numbers with hi > lo on every axis.
void check_bounds_arg(const std::vector<double>& b) {
  if (b.empty()) return;
  if (b.size() != 4 && b.size() != 6)
    throw InputError(strf("--bounds needs 4 numbers (X0 X1 Y0 Y1) in 2D or 6 (X0 X1 Y0 Y1 Z0 Z1) in 3D, got %zu",
                          b.size()));
  for (std::size_t axis = 0; axis < b.size() / 2; ++axis) {
    const double lo = b[2 * axis], hi = b[2 * axis + 1];
    if (!std::isfinite(lo) || !std::isfinite(hi))
      throw InputError(strf("--bounds: %s range must be finite", axis_name(int(axis))));
    if (!(hi > lo))
      throw InputError(strf("--bounds: empty %s range [%.17g, %.17g] (need %s1 > %s0)", axis_name(int(axis)),
                            lo, hi, axis_name(int(axis)), axis_name(int(axis))));
  }
}

namespace {

/// Checks that need the data: bounds arity vs dimension, and inputs whose
/// default (padded bounding-box) domain would be degenerate or meaningless.
void check_against_input(const ComputeArgs& a, const io::PointCloud& pc) {
  const int dim = pc.dim;
  if (!a.bounds.empty() && static_cast<int>(a.bounds.size()) != 2 * dim) {
    if (dim == 3)
      throw InputError("--bounds has 4 numbers (a 2D box) but the input is 3D; add --dim 2 to use x,y only");
    throw InputError("--bounds has 6 numbers (a 3D box) but the input is 2D");
  }
  if (!a.bounds.empty() || pc.n == 0) return;  // the reader reports empty input
  const std::string box_hint = dim == 3 ? "--bounds X0 X1 Y0 Y1 Z0 Z1" : "--bounds X0 X1 Y0 Y1";
  // Over the finite points: with --ignore-outside the others are set aside
  // (the library says so where none is left).
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  std::size_t finite = 0;
  for (std::size_t i = 0; i < pc.n; ++i) {
    bool ok = true;
    for (int d = 0; d < dim; ++d) ok = ok && std::isfinite(pc.coords[i * dim + d]);
    if (!ok) continue;
    ++finite;
    for (int d = 0; d < dim; ++d) {
      const double v = pc.coords[i * dim + d];
      lo[d] = std::min(lo[d], v);
      hi[d] = std::max(hi[d], v);
    }
  }
  if (finite == 0) return;
  if (finite == 1) throw InputError("only one point: give " + box_hint + " to define the domain around it");
  int flat = 0, flat_axis = -1;
  for (int d = 0; d < dim; ++d)
    if (lo[d] == hi[d]) {
      ++flat;
      if (flat_axis < 0) flat_axis = d;
    }
  if (flat == 0) return;
  if (flat == dim) throw InputError(strf("all %zu points coincide: give %s", finite, box_hint.c_str()));
  const std::string where = strf("all %zu points have %s = %.17g", finite, axis_name(flat_axis), lo[flat_axis]);
  if (dim == 2) throw InputError(where + " (collinear input): give " + box_hint + " for a 2D domain");
  if (flat_axis == 2)
    throw InputError(where + " (planar input): use --dim 2 to tessellate x,y, or give " + box_hint +
                     " for a 3D domain");
  throw InputError(where + " (planar input): for a 2D tessellation drop that column and use --dim 2, or give " +
                   box_hint + " for a 3D domain");
}

/// One part of a --frame slice: empty (the default), else a whole number.
std::optional<std::int64_t> slice_part(const std::string& frame, const std::string& part) {
  if (part.empty()) return std::nullopt;
  std::int64_t v = 0;
  const char* end = part.data() + part.size();
  const auto [p, ec] = std::from_chars(part.data(), end, v);
  if (ec != std::errc() || p != end)
    throw InputError("--frame: '" + frame +
                     "' is not a frame's index or a series (all, or START:STOP[:STEP] as Python's slices)");
  return v;
}

/// The frame indices of the slice A:B[:S] over n frames, as Python's
/// range(*slice(A, B, S).indices(n)): B excluded, negatives from the end.
std::vector<std::size_t> slice_indices(const std::string& frame, std::int64_t n) {
  if (frame == "all") return slice_indices(":", n);
  std::vector<std::string> parts(1);
  for (const char c : frame) {
    if (c == ':')
      parts.emplace_back();
    else
      parts.back() += c;
  }
  if (parts.size() < 2 || parts.size() > 3)
    throw InputError("--frame: '" + frame + "' is not START:STOP or START:STOP:STEP");
  const std::optional<std::int64_t> a = slice_part(frame, parts[0]), b = slice_part(frame, parts[1]);
  const std::int64_t step = parts.size() == 3 ? slice_part(frame, parts[2]).value_or(1) : 1;
  if (step == 0) throw InputError("--frame: '" + frame + "': the step is 0");
  // Out-of-range ends are clamped to the frames there are, as Python does.
  auto clamp_end = [&](std::optional<std::int64_t> v, std::int64_t absent) {
    if (!v) return absent;
    const std::int64_t lo = step > 0 ? 0 : -1, hi = step > 0 ? n : n - 1;
    return std::clamp(*v < 0 ? (*v < -n ? (step > 0 ? 0 : -1) : *v + n) : *v, lo, hi);
  };
  const std::int64_t start = clamp_end(a, step > 0 ? 0 : n - 1), stop = clamp_end(b, step > 0 ? n : -1);
  std::vector<std::size_t> out;
  // (step's magnitude may be near INT64_MAX: no overflow past stop)
  for (std::int64_t k = start; step > 0 ? k < stop : k > stop;) {
    out.push_back(static_cast<std::size_t>(k));
    if (step > 0 ? stop - k <= step : k - stop <= -step) break;
    k += step;
  }
  return out;
}

}  // namespace

bool is_frame_series(const std::string& frame) { return frame == "all" || frame.find(':') != std::string::npos; }

void find_input_frame(ComputeArgs& a) {
  if (a.frame.empty()) return;  // (CLI11 refuses an empty --frame)
  try {
    if (is_frame_series(a.frame)) {
      const std::vector<io::FramePlace> all = io::find_frames(a.input);
      for (const std::size_t k : slice_indices(a.frame, static_cast<std::int64_t>(all.size())))
        a.frames.push_back(all[k]);
      if (a.frames.empty())
        throw InputError(strf("'%s' selects none of the %zu frames of %s", a.frame.c_str(), all.size(),
                              shown_path(a.input).c_str()));
      a.frame_place = a.frames.front();
      return;
    }
    const std::optional<std::int64_t> index = slice_part(a.frame, a.frame);
    a.frame_place = io::find_frame(a.input, *index);
  } catch (const InputError& e) {
    const std::string m = e.what();
    throw InputError(m.rfind("--frame", 0) == 0 ? m : "--frame: " + m);
  }
}

std::string shown_input(const ComputeArgs& a) {
  const std::string path = shown_path(a.input);
  if (a.frame.empty()) return path;
  return strf("%s, frame %zu (from line %zu)", path.c_str(), a.frame_place.index, a.frame_place.line);
}

void apply_file_box(ComputeArgs& a) {
  // --bounds makes the domain the command line's, whole. --periodic and
  // --tilt alone take the file's box with their own axes and tilts: a user
  // restating a dump's periodicity, or choosing other axes, means that box.
  a.domain_given = !a.bounds.empty();
  if (a.domain_given) return;
  const std::optional<io::FileBox> box = io::read_file_box(a.input, a.frame_place);
  if (!box) return;  // (make_options then asks --periodic for --bounds)
  const int dim = a.dim == 0 ? 3 : a.dim;
  a.periodic_from_file = a.periodic.empty();
  for (int d = 0; d < dim; ++d) {
    const auto k = static_cast<std::size_t>(d);
    a.bounds.push_back(box->lo[k]);
    a.bounds.push_back(box->hi[k]);
    if (a.periodic_from_file && box->periodic[k]) a.periodic += "xyz"[d];
  }
  a.tilt_from_file = a.tilt.empty();
  a.box_source = "the box of " + (a.frame.empty() ? "" : strf("frame %zu of ", a.frame_place.index)) +
                 shown_path(a.input) + " (" + box->declared_by + ")";
  if (!a.periodic_from_file) a.box_source += ", periodic along --periodic's axes";
  // A tilt along a wall, where the file decided either: the file's tilt
  // against its own or --periodic's walls, or --tilt against the file's
  // walls (--tilt against --periodic is the library's to refuse).
  static const char* const tilt_name[3] = {"xy", "xz", "yz"};
  static const int tilt_axes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  const int tilts = dim == 3 ? 3 : 1;
  if (a.tilt_from_file || a.periodic_from_file)
    for (int t = 0; t < tilts; ++t) {
      const auto k = static_cast<std::size_t>(t);
      const double v = a.tilt_from_file ? box->tilt[k] : k < a.tilt.size() ? a.tilt[k] : 0.0;
      for (const int axis : tilt_axes[t]) {
        if (v == 0 || a.periodic.find("xyz"[axis]) != std::string::npos) continue;
        if (!a.tilt_from_file)
          throw InputError(strf("--tilt: %s needs %s periodic, and %s has a wall there; give --periodic",
                                tilt_name[t], axis_name(axis), a.box_source.c_str()));
        throw InputError(strf("%s: the box tilts by %s = %.17g, but %s is a wall there%s; give the domain yourself "
                              "(--bounds, with --periodic and --tilt)",
                              shown_path(a.input).c_str(), tilt_name[t], v, axis_name(axis),
                              a.periodic_from_file ? "" : (" (--periodic " + a.periodic + ")").c_str()));
      }
    }
  if (!a.tilt_from_file) {
    a.box_source += ", tilted by --tilt";
    return;
  }
  const auto used = box->tilt.begin() + tilts;  // (2D: xy alone)
  if (std::any_of(box->tilt.begin(), used, [](double v) { return v != 0; })) a.tilt.assign(box->tilt.begin(), used);
}

std::string tilt_text(const ComputeArgs& a, const std::array<double, 3>& used, const Bounds& box, int dim) {
  // Tilts of more than a box length are reduced by whole lengths (the same
  // lattice): say so, since the shifts then count that basis.
  bool reduced = false;
  for (std::size_t t = 0; t < a.tilt.size() && t < 3; ++t) {
    const std::size_t lo = t == 2 ? 1 : 0;  // xy, xz along x; yz along y
    reduced |= std::fabs(a.tilt[t] - used[t]) > 0.5 * (box.hi[lo] - box.lo[lo]);
  }
  if (!reduced && used[0] == 0 && used[1] == 0 && used[2] == 0) return "";
  std::string s = dim == 2 ? strf("xy %.17g", used[0]) : strf("xy %.17g, xz %.17g, yz %.17g", used[0], used[1], used[2]);
  if (reduced) s += " (the given tilts reduced by whole box lengths: the same lattice, and the basis the shifts count)";
  return s;
}

void print_frame_line(const char* command, const ComputeArgs& a, const std::string& what, double seconds,
                      const std::vector<std::string>& written, std::FILE* to) {
  const std::string files = written_list(written);
  std::fprintf(to, "tessera %s: %s: %s; %.3f s; wrote %s\n", command, shown_input(a).c_str(), what.c_str(), seconds,
               files.empty() ? "(nothing)" : files.c_str());
  std::fflush(to);
}

io::PointCloud read_input(const ComputeArgs& a) {
  io::ReadOptions ro;
  ro.dim = a.dim;
  ro.labels = a.labels;
  ro.keep_non_finite = a.ignore_outside;  // set aside by the computation, as points outside --bounds
  ro.non_finite_hint = "--ignore-outside sets such points aside";
  ro.frame = a.frame_place;
  // One frame asked for by --frame: its errors say which (a series' wrapper,
  // run_frames, says it for all of a frame's errors).
  const std::string which =
      a.frame.empty() || is_frame_series(a.frame) ? "" : strf("frame %zu: ", a.frame_place.index);
  io::PointCloud pc;
  try {
    pc = io::read_points(a.input, ro);
  } catch (const InputError& e) {
    if (which.empty()) throw;
    throw InputError(which + e.what());
  }
  if (!a.radii.empty()) {
    try {
      pc.radii = io::read_point_scalars(a.input, a.radii, a.frame_place);
    } catch (const InputError& e) {  // its words are for any scalars: name the option
      throw InputError(which + "--radii: " + e.what());
    }
    if (pc.radii.size() != pc.n)
      throw InputError("--radii " + a.radii + ": " + std::to_string(pc.radii.size()) + " values for " +
                       std::to_string(pc.n) + " points");
  }
  check_against_input(a, pc);
  return pc;
}

VoronoiOptions make_options(const ComputeArgs& a, int dim, std::span<const double> points) {
  VoronoiOptions o;
  o.dim = dim;
  if (!a.bounds.empty()) {
    Bounds b;
    for (int d = 0; d < dim; ++d) {
      b.lo[d] = a.bounds[2 * d];
      b.hi[d] = a.bounds[2 * d + 1];
    }
    o.bounds = b;
  }
  o.padding = a.padding;
  o.ignore_outside_points = a.ignore_outside;
  o.threads = a.threads;
  o.points_per_bin = a.bin_points;
  // CLI11 admits only these three (add_cell_method_option).
  o.cell_method = a.cell_method == "search"      ? CellMethod::search
                  : a.cell_method == "insertion" ? CellMethod::insertion
                                                 : CellMethod::automatic;
  for (const char axis : a.periodic) {
    const std::size_t k = axis == 'x' ? 0 : axis == 'y' ? 1 : axis == 'z' ? 2 : 3;
    if (k == 3 || o.periodic[k])
      throw InputError("--periodic '" + a.periodic + "': expected axes x, y, z, each at most once (e.g. xyz)");
    if (static_cast<int>(k) >= dim) throw InputError("--periodic " + a.periodic + ": 2D points have no z axis");
    o.periodic[k] = true;
  }
  if (!a.periodic.empty() && a.bounds.empty())
    throw InputError("--periodic needs --bounds: the box that repeats");
  auto add_wall = [&](const std::vector<double>& w, const std::string& what) {
    if (w.size() != static_cast<std::size_t>(dim + 1))
      throw InputError(what + (dim == 3 ? ": expected four values, NX NY NZ D, for 3D points"
                                        : ": expected three values, NX NY D, for 2D points"));
    Wall wall;
    for (int d = 0; d < dim; ++d) wall.normal[static_cast<std::size_t>(d)] = w[static_cast<std::size_t>(d)];
    wall.offset = w.back();
    o.walls.push_back(wall);
  };
  for (const auto& w : a.walls) add_wall(w, "--wall");
  if (!a.walls_file.empty())
    for (const auto& w : read_walls_file(a.walls_file)) add_wall(w, "--walls " + a.walls_file);
  if (a.hull_walls) {
    // A dilated hull reaches past the default box (the points' bounding box
    // grown by --padding): the box grows by the dilation too.
    if (!o.bounds && a.hull_dilation > 0) {
      Bounds b;
      for (int d = 0; d < dim; ++d) {
        double lo = INFINITY, hi = -INFINITY;
        for (std::size_t i = static_cast<std::size_t>(d); i < points.size(); i += static_cast<std::size_t>(dim))
          if (std::isfinite(points[i])) lo = std::min(lo, points[i]), hi = std::max(hi, points[i]);
        b.lo[static_cast<std::size_t>(d)] = lo, b.hi[static_cast<std::size_t>(d)] = hi;
      }
      double extent = 0;
      for (int d = 0; d < dim; ++d) extent = std::max(extent, b.hi[static_cast<std::size_t>(d)] - b.lo[static_cast<std::size_t>(d)]);
      const double grow = a.padding * extent + 2 * a.hull_dilation;
      for (int d = 0; d < dim; ++d) b.lo[static_cast<std::size_t>(d)] -= grow, b.hi[static_cast<std::size_t>(d)] += grow;
      if (std::isfinite(grow) && extent > 0) o.bounds = b;
    }
    std::vector<double> finite;  // (--ignore-outside keeps points with a NaN, to drop them)
    for (std::size_t i = 0; i + static_cast<std::size_t>(dim) <= points.size(); i += static_cast<std::size_t>(dim))
      if (std::all_of(&points[i], &points[i] + dim, [](double v) { return std::isfinite(v); }))
        finite.insert(finite.end(), &points[i], &points[i] + dim);
    try {
      for (const Wall& w : hull_walls(finite, dim, a.hull_dilation, a.threads)) o.walls.push_back(w);
    } catch (const InputError& e) {
      std::string m = e.what();
      if (m.rfind("hull_walls: ", 0) == 0) m = m.substr(12);
      throw InputError("--hull-walls: " + m);
    }
  }
  if (!a.tilt.empty()) {
    if (a.periodic.empty()) throw InputError("--tilt needs --periodic (a triclinic box repeats along its tilted axes)");
    if (a.tilt.size() != (dim == 3 ? 3u : 1u))
      throw InputError(dim == 3 ? "--tilt: expected three values, XY XZ YZ, for 3D points"
                                : "--tilt: expected one value, XY, for 2D points");
    for (std::size_t t = 0; t < a.tilt.size(); ++t) o.tilt[t] = a.tilt[t];
  }
  return o;
}

namespace {

/// "radii LO to HI; WHAT N (points a, b, ...)": the radii's range and the
/// count of `ids` with the first five (the power cells' and regular
/// triangulations' summary lines).
std::string radii_and_points(const io::PointCloud& pc, const char* what, const std::vector<std::int32_t>& ids) {
  const auto [lo, hi] = std::minmax_element(pc.radii.begin(), pc.radii.end());
  std::string line = strf("radii %.10g to %.10g; %s %zu", *lo, *hi, what, ids.size());
  for (std::size_t i = 0; i < std::min<std::size_t>(ids.size(), 5); ++i) line += strf("%s%d", i ? ", " : " (points ", ids[i]);
  if (!ids.empty()) line += ids.size() > 5 ? ", ...)" : ")";
  return line;
}

}  // namespace

/// Power cells: the radii's range and the points whose cells are empty.
void print_power_line(const io::PointCloud& pc, const Cells& c) {
  std::printf("  %-18s %s\n", "power cells", radii_and_points(pc, "empty cells", c.empty_cells).c_str());
}

/// A regular triangulation: the radii's range and its hidden points.
void print_regular_line(const io::PointCloud& pc, const Delaunay& dt) {
  std::fprintf(stderr, "tessera: regular triangulation: %s\n", radii_and_points(pc, "hidden points", dt.hidden).c_str());
}

std::string no_cells_reason(const io::PointCloud& pc, const Cells& c) {
  if (!c.empty_cells.empty())
    return strf("no cells: every point that could own one (%zu%s) has an empty power cell: other spheres' powers "
                "are less everywhere",
                c.empty_cells.size(), pc.labels.empty() ? "" : ", label >= 0");
  // An inside point (label >= 0) duplicating an outside one, which owns their place.
  const auto inside_under_outside = [&](const std::pair<std::int32_t, std::int32_t>& d) {
    return pc.labels[static_cast<std::size_t>(d.first)] >= 0 && pc.labels[static_cast<std::size_t>(d.second)] < 0;
  };
  if (!pc.labels.empty() && std::any_of(c.duplicates.begin(), c.duplicates.end(), inside_under_outside))
    return strf("no cells: of the %zu points, those inside the domain with a label >= 0 all duplicate an outside "
                "point (label < 0), which owns their place (the lowest id of coincident points does)",
                pc.n);
  return strf("no cells: none of the %zu points is inside the domain%s", pc.n,
              pc.labels.empty() ? "" : " with a label >= 0");
}

/// Runs the engine with a progress bar (when wanted) and Ctrl-C cancellation
/// (run_cancellable).
Cells compute(const io::PointCloud& pc, VoronoiOptions opt, bool show_progress, double& seconds) {
  opt.radii = pc.radii;
  return run_cancellable("tessera: computing cells", show_progress, [&](auto progress) {
    opt.progress = progress;
    const auto t0 = Clock::now();
    Cells cells = voronoi(pc.coords, pc.dim, pc.labels, opt);
    seconds = seconds_since(t0);
    return cells;
  });
}

namespace {

/// Sum with Neumaier compensation: the volume check compares against the
/// domain at ~1e-15, which plain summation of 1e6 terms can miss.
double accurate_sum(std::span<const double> v) {
  double s = 0, c = 0;
  for (double x : v) {
    const double t = s + x;
    c += std::fabs(s) >= std::fabs(x) ? (s - t) + x : (x - t) + s;
    s = t;
  }
  // An infinite term (a cell whose volume overflows: an outlier near 1e200)
  // makes the compensation inf - inf; the plain sum is then the answer.
  return std::isfinite(s) ? s + c : s;
}

std::uint64_t total_faces(const Cells& c) {
  std::uint64_t f = 0;
  for (std::int32_t k : c.num_faces) f += static_cast<std::uint64_t>(k);
  return f;
}

std::string domain_string(const Cells& c) {
  std::string s;
  for (int d = 0; d < c.dim; ++d)
    s += strf("%s[%.10g, %.10g]", d ? " x " : "", c.bounds.lo[d], c.bounds.hi[d]);
  if (!c.walls.empty()) s += strf(", inside %zu wall%s", c.walls.size(), c.walls.size() == 1 ? "" : "s");
  return s;
}

void print_volume_line(const Cells& c, const char* name) {
  const double sum = accurate_sum(c.volume), dom = domain_volume(c.bounds, c.walls, c.dim, c.threads_used);
  // Beyond the validator's rule the volumes in the input's units over- or
  // underflow, and comparing them says nothing.
  if (!volumes_representable(dom, c.n_cells()))
    std::printf("  %-18s %.17g (domain %.17g: outside double's range at this scale, not compared)\n", name, sum, dom);
  else
    std::printf("  %-18s %.17g (domain %.17g, relative difference %.2g)\n", name, sum, dom, std::fabs(sum - dom) / dom);
}

// ------------------------------------------------------------------ summary


void print_summary(const VoronoiArgs& a, const io::PointCloud& pc, const Cells& c, double read_s,
                   double compute_s, double write_s, const std::vector<std::string>& written) {
  if (a.compute.brief) {
    print_frame_line("voronoi", a.compute, strf("%zu points, %zu cells", pc.n, c.n_cells()), compute_s, written);
    return;
  }
  const bool d3 = c.dim == 3;
  std::printf("tessera voronoi: %zu points (%dD) from %s\n", pc.n, c.dim, shown_input(a.compute).c_str());
  std::printf("  %-18s %zu\n", "cells", c.n_cells());
  if (!pc.labels.empty()) {
    const auto outside = std::count_if(pc.labels.begin(), pc.labels.end(), [](std::int32_t l) { return l < 0; });
    std::printf("  %-18s %td (label < 0: no cell, they clip their neighbours)\n", "outside points", outside);
  }
  std::string dup = std::to_string(c.duplicates.size());
  for (std::size_t i = 0; i < std::min<std::size_t>(c.duplicates.size(), 5); ++i)
    dup += strf("%s point %d duplicates point %d", i ? ";" : ":", c.duplicates[i].first, c.duplicates[i].second);
  if (c.duplicates.size() > 5) dup += "; ...";
  std::printf("  %-18s %s\n", "duplicates", dup.c_str());
  if (c.power) print_power_line(pc, c);
  if (a.compute.ignore_outside || !c.ignored_outside_bounds.empty()) {
    std::string ign = std::to_string(c.ignored_outside_bounds.size());
    for (std::size_t i = 0; i < std::min<std::size_t>(c.ignored_outside_bounds.size(), 5); ++i)
      ign += strf("%s%d", i ? ", " : " (points ", c.ignored_outside_bounds[i]);
    if (!c.ignored_outside_bounds.empty()) ign += c.ignored_outside_bounds.size() > 5 ? ", ...)" : ")";
    std::printf("  %-18s %s\n", "ignored (outside)", ign.c_str());  // (or not finite)
  }
  std::printf("  %-18s %s\n", "domain", domain_string(c).c_str());
  if (!a.compute.box_source.empty()) std::printf("  %-18s %s\n", "domain from", a.compute.box_source.c_str());
  if (c.is_periodic()) {
    std::string axes, reach;
    for (int a = 0; a < c.dim; ++a)
      if (c.periodic[static_cast<std::size_t>(a)]) {
        axes += "xyz"[a];
        reach += strf("%s%.6g", reach.empty() ? "" : ", ", c.image_reach[static_cast<std::size_t>(a)]);
      }
    std::printf("  %-18s %s (%zu images of points, within %s beyond the box)\n", "periodic", axes.c_str(),
                c.periodic_images, reach.c_str());
    if (const std::string t = tilt_text(a.compute, c.tilt, c.bounds, c.dim); !t.empty())
      std::printf("  %-18s %s\n", "tilt (triclinic)", t.c_str());
  }
  if (c.far_points != 0)
    std::printf("  %-18s %zu (beyond the bulk of the points; they stretch the default domain: outliers?)\n",
                "far points", c.far_points);
  const std::uint64_t faces = total_faces(c);
  std::printf("  %-18s %llu (%.2f per cell, box faces included)\n", d3 ? "faces" : "edges",
              static_cast<unsigned long long>(faces), c.n_cells() ? double(faces) / double(c.n_cells()) : 0.0);
  std::printf("  %-18s %zu\n", "neighbour entries", c.neighbors.size());
  print_volume_line(c, d3 ? "volume sum" : "area sum");
  std::printf("  %-18s %.3f s on %d thread%s (read %.3f s, write %.3f s)\n", "compute", compute_s,
              c.threads_used, c.threads_used == 1 ? "" : "s", read_s, write_s);
  if (c.from_insertion)
    std::printf("  %-18s insertion (%zu cells assembled from their Delaunay stars, %zu clipped by their Delaunay "
                "neighbours)\n",
                "method", c.assembled_from_stars, c.n_cells() - c.assembled_from_stars);
  // Lattices tie often but cheaply (tens of exact calls per cell, on the
  // integer path); thousands per cell mean a many-fold near-degenerate vertex
  // (points on one sphere, searched with --method search: docs/design.md,
  // "Cells from Delaunay neighbours"): quadratic work.
  const bool tie_heavy = c.exact_predicate_calls > 1000 * static_cast<std::uint64_t>(c.n_cells());
  std::printf("  %-18s %llu%s\n", "exact predicates", static_cast<unsigned long long>(c.exact_predicate_calls),
              tie_heavy ? " (over 1000 per cell: near-degenerate input, e.g. points on one sphere; "
                          "`--method insertion` avoids the search, `tessera joggle` removes such ties)"
                        : "");
  const std::string out = written_list(written);
  std::printf("  %-18s %s\n", "wrote", out.empty() ? "(nothing)" : out.c_str());
  std::fflush(stdout);
}

bool report_validation(const Cells& c, const io::PointCloud& pc, bool quiet) {
  const ValidationReport r = validate(c, pc.labels, pc.coords, pc.radii);
  if (!quiet) {
    std::printf("validation: %s\n", r.ok ? "OK" : "FAILED");
    if (r.volumes_checked)
      std::printf("  %-18s %.17g of %.17g (relative error %.2g)\n", "volume sum", r.volume_sum, r.domain_volume,
                  r.volume_rel_error);
    else
      std::printf("  %-18s not checked: the domain volume %.17g is outside double's range for %s at this scale\n",
                  "volume sum", r.domain_volume, c.dim == 3 ? "cell volumes" : "cell areas");
    std::printf("  %-18s %zu\n", "asymmetric spokes", r.asymmetric_spokes);
    if (c.is_periodic() && c.vertex_key_shifts.empty())
      std::printf("  %-18s not checked without the mesh's key shifts\n", "bad vertex degree");
    else
      std::printf("  %-18s %zu%s\n", "bad vertex degree", r.bad_vertex_degree,
                  c.is_periodic() ? " (by the cells of each key's points at shift 0)" : "");
    if (c.dim == 3) std::printf("  %-18s %zu\n", "bad Euler", r.bad_euler);
    if (r.underflowed_volumes)
      std::printf("  %-18s %zu (below the smallest double, reported as 0)\n", "tiny cells", r.underflowed_volumes);
    if (r.measures_checked)
      std::printf("  %-18s %zu sampled cells against exact arithmetic: largest relative %s error %.2g (point %d)\n",
                  "exact measures", r.measures_checked, c.dim == 3 ? "volume" : "area", r.measure_rel_error,
                  r.measure_worst);
    if (r.measures_checked)
      std::printf("  %-18s their merged vertices against exact positions: largest offset %.2g of the cell radius (vertex %d)\n",
                  "exact corners", r.vertex_rel_error, r.vertex_worst);
    for (const auto& m : r.messages) std::printf("  %s\n", m.c_str());
    std::fflush(stdout);
  }
  if (!r.ok)
    std::fprintf(stderr, "tessera: error: validation failed%s%s\n", r.messages.empty() ? "" : ": ",
                 r.messages.empty() ? "" : r.messages.front().c_str());
  return r.ok;
}

}  // namespace

Usage usage_now() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  auto tv = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  // ru_maxrss is in KiB on Linux.
  return {tv(ru.ru_utime), tv(ru.ru_stime), static_cast<long long>(ru.ru_minflt),
          static_cast<long long>(ru.ru_maxrss) * 1024};
}

// ---------------------------------------------------------------- voronoi

namespace {

/// `voronoi` on one frame (any --frame: run_frames).
int run_voronoi_frame(const VoronoiArgs& a) {
  check_output_names(a);
  check_bounds_arg(a.compute.bounds);
  if (a.compute.dim != 0 && !a.compute.bounds.empty() && int(a.compute.bounds.size()) != 2 * a.compute.dim)
    throw InputError(strf("--bounds has %zu numbers but --dim is %d (need %d)", a.compute.bounds.size(),
                          a.compute.dim, 2 * a.compute.dim));
  // Fail before the (possibly long) read and computation, not after.
  for (const std::string* p : {&a.output, &a.cell_table, &a.neighbors, &a.neighbor_shifts})
    if (!p->empty()) io::check_writable(*p);
  check_distinct_outputs({{"-o", &a.output},
                          {"--cell-table", &a.cell_table},
                          {"--neighbors", &a.neighbors},
                          {"--neighbor-shifts", &a.neighbor_shifts}});
  route_standard_output({&a.cell_table, &a.neighbors});

  auto t0 = Clock::now();
  const io::PointCloud pc = read_input(a.compute);
  const double read_s = seconds_since(t0);

  if (!a.output.empty()) {
    const std::string e = extension(a.output);
    if (pc.dim == 3 && e != ".vtu")
      throw InputError("output " + a.output + ": 3D cells are written as .vtu (use --dim 2 for a 2D tessellation)");
    if (pc.dim == 2 && e != ".vtp") throw InputError("output " + a.output + ": 2D cells are written as .vtp");
  }

  VoronoiOptions opt = make_options(a.compute, pc.dim, pc.coords);
  opt.build_mesh = !a.output.empty() || a.validate;
  double compute_s = 0;
  const Cells cells = compute(pc, opt, !a.quiet && stderr_is_terminal(), compute_s);
  if (cells.n_cells() == 0) throw InputError(no_cells_reason(pc, cells));

  t0 = Clock::now();
  std::vector<std::string> written;
  if (!a.output.empty()) {
    io::write_cells_vtk(a.output, cells);
    written.push_back(a.output);
  }
  if (!a.cell_table.empty()) {
    io::write_cell_table(a.cell_table, cells);
    written.push_back(shown_output(a.cell_table));
  }
  if (!a.neighbors.empty()) {
    io::write_neighbors_npy(a.neighbors, cells);
    written.push_back(shown_output(a.neighbors));
  }
  if (!a.neighbor_shifts.empty()) {
    io::write_file_atomic(a.neighbor_shifts,
                          io::npy_bytes(cells.neighbor_shifts.data(),
                                        {cells.neighbors.size(), static_cast<std::size_t>(cells.dim)}));
    written.push_back(a.neighbor_shifts);
  }
  const double write_s = seconds_since(t0);

  if (!a.quiet) print_summary(a, pc, cells, read_s, compute_s, write_s, written);
  // (A series' later frames report a failed validation only, as -q does.)
  if (a.validate && !report_validation(cells, pc, a.quiet || a.compute.brief)) return kExitFailure;
  return kExitOk;
}

}  // namespace

int run_voronoi(const VoronoiArgs& a) {
  return run_frames(a,
                    {{"-o", &VoronoiArgs::output},
                     {"--cell-table", &VoronoiArgs::cell_table},
                     {"--neighbors", &VoronoiArgs::neighbors},
                     {"--neighbor-shifts", &VoronoiArgs::neighbor_shifts}},
                    run_voronoi_frame);
}

// ------------------------------------------------------------------ bench

int run_bench_voronoi(const BenchArgs& a) {
  check_bounds_arg(a.compute.bounds);
  if (a.repeat < 1) throw InputError("--repeat must be at least 1");
  const io::PointCloud pc = read_input(a.compute);
  VoronoiOptions opt = make_options(a.compute, pc.dim, pc.coords);
  opt.build_mesh = a.mesh;
  opt.radii = pc.radii;
  const char* op = pc.dim == 3 ? (a.mesh ? "voronoi3_mesh" : "voronoi3") : (a.mesh ? "voronoi2_mesh" : "voronoi2");

  for (int rep = 0; rep < a.repeat; ++rep) {
    // Timed region: the library call only (no I/O, no teardown), as the peers do.
    const Usage u0 = usage_now();
    const auto t0 = Clock::now();
    Cells cells = voronoi(pc.coords, pc.dim, pc.labels, opt);
    const double secs = seconds_since(t0);
    const Usage u1 = usage_now();
    std::printf(
        "{\"tool\":\"tessera\",\"op\":\"%s\",\"n\":%zu,\"threads\":%d,\"seconds\":%.6f,\"simplices\":%zu,"
        "\"extra\":{\"cpu_user_s\":%.6f,\"cpu_sys_s\":%.6f,\"minflt\":%lld,\"peak_rss_bytes\":%lld,"
        "\"neighbors\":%zu,\"empty_cells\":%zu,\"from_insertion\":%s,\"assembled\":%zu,\"from_pilot\":%zu,\"exact_calls\":%llu,\"volume_sum\":%.17g,\"repeat\":%d}}\n",
        op, pc.n, cells.threads_used, secs, cells.n_cells(), u1.user_s - u0.user_s, u1.sys_s - u0.sys_s,
        u1.minflt - u0.minflt, u1.maxrss_bytes, cells.neighbors.size(), cells.empty_cells.size(), cells.from_insertion ? "true" : "false",
        cells.assembled_from_stars, cells.cells_from_pilot, static_cast<unsigned long long>(cells.exact_predicate_calls),
        accurate_sum(cells.volume), rep);
    std::fflush(stdout);
  }
  return kExitOk;
}

// ------------------------------------------------------------ run-default

int run_default(const DemoArgs& a) {
  if (a.n < 2) throw InputError("--points must be at least 2");
  std::error_code ec;
  std::filesystem::create_directories(a.out_dir, ec);
  if (ec) throw InputError("cannot create directory " + a.out_dir + ": " + ec.message());
  const std::string vtu = (std::filesystem::path(a.out_dir) / "cells.vtu").string();
  const std::string csv = (std::filesystem::path(a.out_dir) / "cells.csv").string();
  io::check_writable(vtu);
  io::check_writable(csv);

  // Uniform points in the unit cube. The 53-bit mapping of mt19937_64's output
  // (whose sequence the standard fixes) makes the set identical on every
  // platform, unlike std::uniform_real_distribution.
  io::PointCloud pc;
  pc.dim = 3;
  pc.n = a.n;
  pc.coords.resize(a.n * 3);
  std::mt19937_64 rng(a.seed);
  for (double& x : pc.coords) x = static_cast<double>(rng() >> 11) * 0x1.0p-53;

  VoronoiOptions opt;
  opt.dim = 3;
  opt.bounds = Bounds{{0, 0, 0}, {1, 1, 1}};
  opt.threads = a.threads;
  opt.build_mesh = true;
  double compute_s = 0;
  const Cells cells = compute(pc, opt, !a.quiet && stderr_is_terminal(), compute_s);

  const auto t0 = Clock::now();
  {
    io::OutputGroup outputs;  // both or neither
    io::write_cells_vtk(vtu, cells);
    io::write_cell_table(csv, cells);
    outputs.commit();
  }
  const double write_s = seconds_since(t0);

  if (!a.quiet) {
    std::printf("tessera run-default: %zu uniform random points in the unit cube (seed %llu)\n", a.n,
                static_cast<unsigned long long>(a.seed));
    std::printf("  %-18s %zu\n", "cells", cells.n_cells());
    std::printf("  %-18s %llu\n", "faces", static_cast<unsigned long long>(total_faces(cells)));
    std::printf("  %-18s %zu\n", "neighbour entries", cells.neighbors.size());
    std::printf("  %-18s %zu\n", "vertices", cells.n_vertices());
    print_volume_line(cells, "volume sum");
    std::printf("  %-18s %.3f s on %d thread%s (write %.3f s)\n", "compute", compute_s, cells.threads_used,
                cells.threads_used == 1 ? "" : "s", write_s);
    std::printf("  %-18s %s, %s\n", "wrote", vtu.c_str(), csv.c_str());
    std::fflush(stdout);
  }
  return kExitOk;
}

bool whole_number(const std::string& word, double& value) {
  if (word.empty() || std::isspace(static_cast<unsigned char>(word.front()))) return false;
  char* end = nullptr;
  value = std::strtod(word.c_str(), &end);
  return end == word.c_str() + word.size();
}

bool beyond_range(const std::string& word, double value) {
  if (!std::isinf(value)) return false;
  std::string lower(word);
  for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return lower.find("inf") == std::string::npos;
}

double parse_number(const std::string& word, const std::string& what, bool allow_inf) {
  double v = 0;
  const bool whole = whole_number(word, v);
  if (whole && beyond_range(word, v)) throw InputError(what + ": '" + word + "' is beyond double's range");
  if (!whole || std::isnan(v) || (!allow_inf && !std::isfinite(v)))
    throw InputError(what + ": '" + word + "' is not a " + (allow_inf ? "number" : "finite number"));
  return v;
}

std::vector<std::string> split_commas(const std::string& s) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == ',')
      out.emplace_back();
    else if (c != ' ')
      out.back() += c;
  }
  return out;
}

}  // namespace tessera::cli
