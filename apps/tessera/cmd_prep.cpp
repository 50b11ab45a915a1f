// The point-preparation subcommands `joggle`, `fill` and `threshold` (see
// commands.hpp). Each checks its arguments and output path before reading
// anything, then reads the points, runs the library function, writes labelled
// points with io::write_points (atomically) and prints a one-line summary.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "stdin_input.hpp"
#include "option_checks.hpp"
#include "tessera/finite_points.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"
#include "tessera/prep/fill.hpp"
#include "tessera/prep/joggle.hpp"
#include "tessera/prep/threshold.hpp"

namespace tessera::cli {
namespace {

constexpr const char* kOutputHelp =
    "Output points with labels: .npy (float64 (N, D); labels in OUT_labels.npy, int32), .ply (binary, double x y z, "
    "int property 'label') or .vtp (VTK vertices, point data 'label'). 2D points get z = 0 in .ply/.vtp. - writes "
    "the .ply to standard output (rbox 1000 D3 | tessera joggle - -o - | tessera voronoi - --cell-table -)";

/// The flag's help, per command: what it does to those points there.
/// `input_required` false: the command checks INPUT itself (fill, whose
/// --bounds may have taken it: "--bounds 0 1 0 1 pts.npy").
void add_input_options(CLI::App* app, PrepInput& p, bool labels, const char* keep_help, bool input_required = true) {
  CLI::Option* input = app->add_option("INPUT", p.input, "Point file: .npy, .csv/.xyz/.txt (or Qhull's format), .ply, .vtp/.vtu, .vtk (legacy VTK), .pcd, .las or .dump/.lammpstrj (as for `voronoi`); - reads standard input");
  if (input_required) input->required();
  app->add_option("-o,--output", p.output, kOutputHelp)->required();
  app->add_option("--dim", p.dim, "Dimension: 2 or 3 (default: the number of columns or fields; .ply, .vtp and .vtu are 3D)")
      ->check(CLI::IsMember({2, 3}));
  if (labels)
    app->add_option("--labels", p.labels,
                    "Per-point integer labels, carried to the output: FILE.npy, or the name of an integer .ply "
                    "vertex property / .csv column / .vtp, .vtu or .vtk point data array / LAMMPS dump column / .pcd, .las or structured .npy field");
  app->add_flag("--keep-non-finite", p.keep_non_finite, keep_help);
  app->add_flag("-q,--quiet", p.quiet, "No summary line");
}

/// The summary's note on kept non-finite points ("" when there are none).
std::string non_finite_note(std::size_t count) {
  return count == 0 ? std::string() : ", " + std::to_string(count) + " with a non-finite coordinate kept in place";
}

io::PointCloud read_prep_input(const PrepInput& p, bool with_labels) {
  io::ReadOptions ro;
  ro.dim = p.dim;
  ro.keep_non_finite = p.keep_non_finite;
  ro.non_finite_hint = "--keep-non-finite keeps such points in place";
  if (with_labels) ro.labels = p.labels;
  return io::read_points(input_path(p.input), ro);
}

std::int32_t parse_label(const std::string& word, const std::string& what) {
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(word.c_str(), &end, 10);
  if (word.empty() || end != word.c_str() + word.size() || errno == ERANGE || v < INT32_MIN || v > INT32_MAX)
    throw InputError(what + ": '" + word + "' is not a 32-bit integer label");
  return static_cast<std::int32_t>(v);
}

}  // namespace

void check_prep_output(const std::string& path) {
  if (path == "-") {
    route_standard_output({&path});
    return;
  }
  const std::string e = extension(path);
  if (e != ".npy" && e != ".ply" && e != ".vtp")
    throw InputError("output " + path + ": points are written as .npy, .ply or .vtp (got '" + e + "')");
  io::check_writable(path);
}

// ------------------------------------------------------------------ registration

void add_prep_commands(CLI::App& app, PrepCommands& c) {
  c.joggle_app = app.add_subcommand(
      "joggle", "Move points by a small deterministic random displacement (seeded per point id)");
  CLI::App* j = c.joggle_app;
  add_input_options(j, c.joggle.io, true,
                    "Points with a NaN or infinite coordinate (an organized cloud's missing returns) are copied "
                    "through unmoved instead of refused, so ids stay; the diagonal is the finite points' box. "
                    "`voronoi --ignore-outside` sets them aside");
  j->add_option("--radius", c.joggle.radius,
                "Largest displacement: a fraction of the bounding-box diagonal, or a length with --absolute")
      ->check(NonNegative)
      ->capture_default_str();
  j->add_flag("--absolute", c.joggle.absolute, "--radius is a length, not a fraction of the diagonal");
  j->add_option("--mode", c.joggle.mode,
                "ball: uniform in the ball (disk in 2D); xy, xz, yz: in a disk of that plane (3D), the third "
                "coordinate kept exactly")
      ->check(CLI::IsMember({"ball", "xy", "xz", "yz"}))
      ->capture_default_str();
  j->add_option("--mask", c.joggle.mask,
                "MASK.npy: one integer/bool per point; only points with a nonzero value move, the others are "
                "copied exactly");
  j->add_option("--seed", c.joggle.seed, "Random seed (each point's displacement depends on seed and id only)")
      ->capture_default_str();
  j->add_option("--threads", c.joggle.threads, "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores)")
      ->check(NonNegative);
  j->footer("Examples:\n  tessera joggle lattice.npy -o jittered.npy --radius 1e-6\n"
            "  tessera joggle slab.ply --mode xy --radius 0.01 --absolute -o out.ply");

  c.fill_app = app.add_subcommand(
      "fill", "Add background points (label < 0) in the empty bins of a point cloud, so outside regions carve "
              "concave shapes");
  CLI::App* f = c.fill_app;
  add_input_options(f, c.fill.io, true,
                    "Points with a NaN or infinite coordinate (an organized cloud's missing returns) are kept in "
                    "place with their labels instead of refused; they mark no bin, and the box is the finite "
                    "points'. `voronoi --ignore-outside` sets them aside",
                    false);
  f->add_option("--strategy", c.fill.strategy,
                "uniform: one point at the centre of every empty bin; adaptive: every empty bin next to the "
                "data, sparser (exponentially) further away")
      ->check(CLI::IsMember({"uniform", "adaptive"}))
      ->capture_default_str();
  f->add_option("--background-label", c.fill.background_label, "Label of the added points (must be < 0)")
      ->capture_default_str();
  f->add_option("--in-label", c.fill.in_label, "Label of the input points when --labels is not given")
      ->capture_default_str();
  f->add_option("--bin-points", c.fill.bin_points, "Average input points per bin (> 0): sets the bin size")
      ->capture_default_str();
  f->add_option("--bounds", c.fill.bounds,
                "Region to fill, X0 X1 Y0 Y1 [Z0 Z1] or X0,X1,Y0,Y1[,Z0,Z1] (default: the bounding box of the "
                "points); must contain every point")
      ->expected(4, 6)
      ->allow_extra_args(false)
      ->delimiter(',')
      ->type_name("X0 X1 Y0 Y1 [Z0 Z1]");
  f->add_option("--joggle", c.fill.joggle,
                "Joggle of the added points, a fraction (<= 0.5) of the smallest bin edge (default 0: exact bin "
                "centres)")
      ->capture_default_str();
  f->add_option("--seed", c.fill.seed, "Random seed (joggle; adaptive sampling)")->capture_default_str();
  f->add_option("--threads", c.fill.threads, "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores)")
      ->check(NonNegative);
  f->footer("The input points come first, unchanged, with their labels (or --in-label); the added points follow.\n"
            "Examples:\n  tessera fill grains.ply --labels grain --bin-points 4 -o filled.ply\n"
            "  tessera fill pts.csv --dim 2 --strategy adaptive --bounds 0,1,0,1 -o filled.npy");

  c.threshold_app = app.add_subcommand(
      "threshold", "Label points by a scalar per point in half-open intervals [lo, hi); the rest get the "
                   "background label");
  CLI::App* t = c.threshold_app;
  add_input_options(t, c.threshold.io, false,
                    "Points with a NaN or infinite coordinate (an organized cloud's missing returns) are read and "
                    "labelled by their scalar as any other, instead of refused. `voronoi --ignore-outside` sets "
                    "them aside");
  t->add_option("--scalars", c.threshold.scalars,
                "S.npy (one number per point), or the name of a .ply vertex property / .csv column / .vtp, .vtu or .vtk "
                "point data array / LAMMPS dump column / .pcd, .las or structured .npy field of INPUT "
                "(with a .csv whose header does not name x,y[,z], use --dim so that the column is not taken "
                "as a coordinate)")
      ->required();
  t->add_option("--interval", c.threshold.intervals,
                "lo,hi,label: points with lo <= s < hi get label (repeat; lo may be -inf, hi inf; intervals must "
                "not overlap)")
      ->required()
      ->allow_extra_args(false)
      ->type_name("LO,HI,LABEL");
  t->add_option("--background-label", c.threshold.background_label,
                "Label of points in no interval (and NaN scalars)")
      ->capture_default_str();
  t->footer("Examples:\n  tessera threshold pts.npy --scalars density.npy --interval 0.5,inf,1 -o labelled.npy\n"
            "  tessera threshold scan.ply --scalars intensity --interval 0,10,1 --interval 10,20,2 -o out.vtp");
}

/// No output may replace a file the command reads (io::protect_from_writes):
/// `joggle p.npy -o p.npy` replaced the points it read.
void protect_inputs(const PrepInput& p) {
  io::protect_from_writes(p.input, "the INPUT");
  io::protect_from_writes(p.labels, "--labels");
}

int run_prep_command(const PrepCommands& c) {
  if (c.joggle_app && c.joggle_app->parsed()) {
    protect_inputs(c.joggle.io);
    io::protect_from_writes(c.joggle.mask, "--mask");
  }
  if (c.fill_app && c.fill_app->parsed()) protect_inputs(c.fill.io);
  if (c.threshold_app && c.threshold_app->parsed()) {
    protect_inputs(c.threshold.io);
    io::protect_from_writes(c.threshold.scalars, "--scalars");
  }
  if (c.joggle_app && c.joggle_app->parsed()) return run_joggle(c.joggle);
  if (c.fill_app && c.fill_app->parsed()) return run_fill(c.fill);
  if (c.threshold_app && c.threshold_app->parsed()) return run_threshold(c.threshold);
  return -1;
}

// ------------------------------------------------------------------ joggle

int run_joggle(const JoggleArgs& a) {
  JoggleOptions o;
  if (!(a.radius >= 0) || !std::isfinite(a.radius)) throw InputError("--radius must be a finite number >= 0");
  o.radius = a.radius;
  o.absolute = a.absolute;
  o.mode = a.mode == "xy"   ? JoggleMode::xy
           : a.mode == "xz" ? JoggleMode::xz
           : a.mode == "yz" ? JoggleMode::yz
                            : JoggleMode::ball;
  o.seed = a.seed;
  o.threads = a.threads;
  o.keep_non_finite = a.io.keep_non_finite;
  check_prep_output(a.io.output);

  const io::PointCloud pc = read_prep_input(a.io, true);
  if (o.mode != JoggleMode::ball && pc.dim != 3)
    throw InputError("--mode " + a.mode + " needs 3D points (2D points joggle in their plane: --mode ball)");
  std::vector<std::uint8_t> mask;
  std::size_t moving = pc.n;
  const std::size_t non_finite = a.io.keep_non_finite ? count_non_finite(pc.coords, pc.dim) : 0;
  if (!a.mask.empty()) {
    const io::NpyArray m = io::read_npy_int(a.mask);
    if (!(m.shape.size() == 1 || (m.shape.size() == 2 && m.shape[1] == 1)) || m.as_int.size() != pc.n)
      throw InputError(a.mask + ": mask must be a 1-D array of " + std::to_string(pc.n) + " values (one per point), "
                       "found " + std::to_string(m.as_int.size()));
    mask.resize(pc.n);
    for (std::size_t i = 0; i < pc.n; ++i) mask[i] = m.as_int[i] != 0 ? 1 : 0;
  }
  if (!mask.empty() || non_finite != 0) {
    // What joggle() moves: the masked points with finite coordinates.
    moving = 0;
    for (std::size_t i = 0; i < pc.n; ++i) moving += (mask.empty() || mask[i] != 0) && finite_point(pc.coords, i, pc.dim);
  }

  LabelledPoints out;
  out.dim = pc.dim;
  out.coords = joggle(pc.coords, pc.dim, o, mask);
  out.labels = pc.labels;
  double largest = 0;
  for (std::size_t i = 0; i < pc.n; ++i) {
    // std::hypot: squares of displacements below ~1e-154 underflow (the
    // summary said 0 for points that moved).
    double dx[3] = {0, 0, 0};
    for (int d = 0; d < pc.dim; ++d)
      if (std::isfinite(pc.coords[i * pc.dim + d])) dx[d] = out.coords[i * pc.dim + d] - pc.coords[i * pc.dim + d];
    largest = std::max(largest, std::hypot(dx[0], dx[1], dx[2]));
  }
  const std::vector<std::string> written = io::write_points(a.io.output, out);
  if (!a.io.quiet)
    std::printf("tessera joggle: %zu points (%dD) from %s, %zu moved (%s, radius %g%s), largest displacement %.3g%s; "
                "wrote %s\n",
                pc.n, pc.dim, shown_path(a.io.input).c_str(), moving, a.mode.c_str(), a.radius,
                a.absolute ? "" : " of the bounding-box diagonal", largest, non_finite_note(non_finite).c_str(),
                written_list(written).c_str());
  return kExitOk;
}

// ------------------------------------------------------------------ fill

int run_fill(const FillArgs& a) {
  FillOptions o;
  o.strategy = a.strategy == "adaptive" ? FillStrategy::adaptive : FillStrategy::uniform;
  if (a.background_label >= 0)
    throw InputError("--background-label must be < 0 (added points are outside points), got " +
                     std::to_string(a.background_label));
  o.background_label = a.background_label;
  o.in_label = a.in_label;
  if (!(a.bin_points > 0) || !std::isfinite(a.bin_points)) throw InputError("--bin-points must be a number > 0");
  o.points_per_bin = a.bin_points;
  if (!(a.joggle >= 0 && a.joggle <= 0.5)) throw InputError("--joggle must be between 0 and 0.5 (of the bin edge)");
  o.joggle = a.joggle;
  o.seed = a.seed;
  o.threads = a.threads;
  o.keep_non_finite = a.io.keep_non_finite;
  // "--bounds 0 1 0 1 pts.npy": --bounds (up to six words) took INPUT, and gives it back.
  PrepInput io = a.io;
  std::vector<std::string> words = a.bounds;
  if (io.input.empty() && !words.empty()) {  // (any count: an odd one is then refused by its count)
    try {
      parse_number(words.back(), "--bounds", false);
    } catch (const InputError&) {
      io.input = words.back();
      words.pop_back();
    }
  }
  if (io.input.empty()) throw InputError("INPUT is required: the point file to fill");
  std::vector<double> bounds;
  for (const std::string& w : words) bounds.push_back(parse_number(w, "--bounds", false));
  if (!bounds.empty() && bounds.size() != 4 && bounds.size() != 6)
    throw InputError("--bounds needs x0 x1 y0 y1 (2D) or x0 x1 y0 y1 z0 z1 (3D), got " +
                     std::to_string(bounds.size()) + " numbers");
  check_prep_output(io.output);

  const io::PointCloud pc = read_prep_input(io, true);
  if (!bounds.empty()) {
    if (static_cast<int>(bounds.size()) != 2 * pc.dim)
      throw InputError("--bounds has " + std::to_string(bounds.size()) + " numbers but the points are " +
                       std::to_string(pc.dim) + "D" + (pc.dim == 3 ? " (use --dim 2 for 2D)" : ""));
    Bounds b;
    for (int d = 0; d < pc.dim; ++d) {
      b.lo[d] = bounds[2 * d];
      b.hi[d] = bounds[2 * d + 1];
    }
    o.bounds = b;
  }
  const LabelledPoints out = fill(pc.coords, pc.dim, pc.labels, o);
  const std::vector<std::string> written = io::write_points(io.output, out);
  if (!io.quiet)
    std::printf("tessera fill: %zu points (%dD) from %s, %zu background points added (%s, label %d)%s; wrote %s\n",
                pc.n, pc.dim, shown_path(io.input).c_str(), out.size() - pc.n, a.strategy.c_str(),
                static_cast<int>(a.background_label),
                non_finite_note(a.io.keep_non_finite ? count_non_finite(pc.coords, pc.dim) : 0).c_str(), written_list(written).c_str());
  return kExitOk;
}

// ------------------------------------------------------------------ threshold

int run_threshold(const ThresholdArgs& a) {
  ThresholdOptions o;
  o.background_label = a.background_label;
  for (const std::string& spec : a.intervals) {
    const std::vector<std::string> w = split_commas(spec);
    if (w.size() != 3) throw InputError("--interval '" + spec + "': expected lo,hi,label");
    ThresholdInterval iv;
    iv.lo = parse_number(w[0], "--interval '" + spec + "'", true);
    iv.hi = parse_number(w[1], "--interval '" + spec + "'", true);
    iv.label = parse_label(w[2], "--interval '" + spec + "'");
    if (!(iv.lo < iv.hi)) throw InputError("--interval '" + spec + "': needs lo < hi");
    o.intervals.push_back(iv);
  }
  // Overlaps and the rest are checked once more by the library; check them
  // here too so that bad intervals fail before reading the input.
  (void)threshold({}, o);
  check_prep_output(a.io.output);

  const io::PointCloud pc = read_prep_input(a.io, false);
  const std::vector<double> s = io::read_point_scalars(input_path(a.io.input), a.scalars);
  if (s.size() != pc.n)
    throw InputError("--scalars " + a.scalars + ": " + std::to_string(s.size()) + " values for " +
                     std::to_string(pc.n) + " points");
  LabelledPoints out;
  out.dim = pc.dim;
  out.coords = pc.coords;
  out.labels = threshold(s, o);
  io::WritePointsOptions wo;
  // .ply/.vtp carry the scalars along for viewing; .npy would need another file.
  if (extension(a.io.output) != ".npy") wo.scalars.push_back({"scalars", std::span<const double>(s)});
  const std::vector<std::string> written = io::write_points(a.io.output, out, wo);
  if (!a.io.quiet) {
    std::map<std::int32_t, std::size_t> count;
    for (std::int32_t l : out.labels) ++count[l];
    std::string parts;
    for (const auto& [label, k] : count)
      parts += (parts.empty() ? "" : ", ") + std::string(label == a.background_label ? "background " : "label ") +
               std::to_string(label) + ": " + std::to_string(k);
    std::printf("tessera threshold: %zu points (%dD) from %s (%s)%s; wrote %s\n", pc.n, pc.dim,
                shown_path(a.io.input).c_str(), parts.c_str(),
                non_finite_note(a.io.keep_non_finite ? count_non_finite(pc.coords, pc.dim) : 0).c_str(), written_list(written).c_str());
  }
  return kExitOk;
}

}  // namespace tessera::cli
