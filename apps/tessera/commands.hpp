// The tessera subcommands. main.cpp parses the command line into these structs;
// each run_* returns the process exit code and reports bad input by throwing
// tessera::InputError (main turns it into "tessera: error: ..." and exit 2).
#pragma once

#include <cstdint>
#include <cstdio>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/image.hpp"
#include "tessera/prep/lloyd.hpp"
#include "tessera/surface_nets.hpp"
#include "tessera/io/points.hpp"

namespace CLI {
class App;
}

namespace tessera::cli {

/// Exit codes (documented in --help).
enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,      ///< internal error, or --validate found a problem
  kExitInputError = 2,   ///< bad command line or bad input data
  kExitInterrupted = 130 ///< Ctrl-C during the computation
};

/// Options shared by `voronoi` and `bench voronoi` (how to read and tessellate).
struct ComputeArgs {
  std::string input;
  int dim = 0;                  ///< 0: from the file
  std::string labels;           ///< "" | NAME | FILE.npy
  std::string radii;            ///< "" | NAME | FILE.npy: power cells (add_radii_option)
  std::vector<double> bounds;   ///< empty, 4 (2D) or 6 (3D) numbers: lo/hi per axis
  double padding = VoronoiOptions{}.padding;
  bool ignore_outside = false;
  int threads = 0;              ///< 0: TESSERA_NUM_THREADS, else all cores
  double bin_points = 0;        ///< 0: automatic
  std::string cell_method = "auto";  ///< auto | search | insertion (voronoi only; add_cell_method_option)
  std::string periodic;         ///< "" or periodic axes, e.g. "xyz" (voronoi only; add_periodic_option)
  std::vector<double> tilt;     ///< triclinic tilts: xy (2D), or xy xz yz (3D); empty: orthogonal
  /// --wall, each as given: NX NY D (2D) or NX NY NZ D (3D) (make_options
  /// checks the count against the dimension), from raw_walls' words
  /// (finish_compute_args: in 2D CLI11 also takes the next word, which may
  /// be INPUT, as for --bounds).
  std::vector<std::vector<double>> walls;
  std::vector<std::vector<std::string>> raw_walls;
  /// --walls FILE: more walls, read by make_options (walls_file.hpp).
  std::string walls_file;
  /// --hull-walls: the points' convex hull as walls too (tessera::hull_walls),
  /// pushed out by --hull-dilation.
  bool hull_walls = false;
  double hull_dilation = 0;
  /// Set where INPUT's own box (a LAMMPS dump's) gave the bounds
  /// (apply_file_box): what the summary says of it, e.g. "the box of
  /// run.dump (timestep 100)".
  std::string box_source;
  /// Whether the command line gave the domain (--bounds): otherwise each
  /// frame of a series takes its own file's box.
  bool domain_given = false;
  /// Whether the periodic axes, and the tilts, are the file's box's (not
  /// --periodic's and --tilt's): a series takes each frame's own.
  bool periodic_from_file = false, tilt_from_file = false;
  /// A series' frame after its first: the summary is one line
  /// (print_frame_line), where a trajectory of thousands of frames printed
  /// a dozen lines each.
  bool brief = false;
  /// --frame as given ("" when not): a trajectory's frame, 0 the first,
  /// negative from the end; finish_compute_args finds where it starts.
  std::string frame;
  io::FramePlace frame_place;  ///< where the frame read starts (the first by default)
  /// --frame all or A:B[:S] (a series: `voronoi` computes each, its output
  /// names carrying {frame}): the frames selected, in their order; empty
  /// for one INDEX.
  std::vector<io::FramePlace> frames;
};

struct VoronoiArgs {
  ComputeArgs compute;
  std::string output;       ///< .vtu (3D) / .vtp (2D), or empty
  std::string cell_table;   ///< .csv / .npy, or empty
  std::string neighbors;    ///< .npy, or empty
  std::string neighbor_shifts;  ///< .npy (periodic boxes), or empty
  bool validate = false;
  bool quiet = false;
};

struct BenchArgs {
  ComputeArgs compute;
  int repeat = 1;
  bool mesh = false;        ///< also build the merged mesh (what VTK output needs)
  double skip_cells = -1;   ///< bench delaunay: DelaunayOptions::skip_cells
  std::string method = "auto";  ///< bench delaunay: DelaunayOptions::method (auto|cells|insertion)
  std::optional<double> alpha;  ///< bench delaunay: also the alpha shape (op alpha2|alpha3)
};

struct DemoArgs {
  std::string out_dir = "out";
  std::size_t n = 1000000;
  std::uint64_t seed = 12345;
  int threads = 0;
  bool quiet = false;
};

/// `graph`, `faces`, `flower`: products read off the merged cells (cmd_dual.cpp).
struct GraphArgs {
  ComputeArgs compute;
  std::string output;          ///< .vtp lines, or empty
  std::string csr;             ///< .npy wheels (layout of --neighbors), or empty
  std::string spoke_classes;   ///< .npy uint8 class per spoke, or empty
  std::string spoke_measures;  ///< .npy float64 face area (2D: length) per spoke, or empty
  std::string spoke_shifts;    ///< .npy int8 (spokes, D) image shifts (periodic boxes), or empty
  double prune_tolerance = 0;
  bool quiet = false;
};

struct FacesArgs {
  ComputeArgs compute;
  std::string output;          ///< .vtp
  std::string kind;            ///< boundary | complex | surface-net
  bool capping = false;
  bool quiet = false;
};

struct FlowerArgs {
  ComputeArgs compute;
  std::string output;          ///< .vtp
  std::vector<std::int64_t> points;  ///< ids of the cells to show
  bool glyphs = false;
  bool quiet = false;
};

/// `delaunay` (cmd_delaunay.cpp).
struct DelaunayArgs {
  ComputeArgs compute;
  std::string output;          ///< .vtu (VTK_TETRA / VTK_TRIANGLE) or .vtp (2D), or empty
  std::string simplices;       ///< .npy int64 (M, D+1), or empty
  std::string simplex_shifts;  ///< .npy int8 (M, D+1, D) image shifts (periodic boxes), or empty
  bool no_hull_completion = false;
  double skip_cells = -1;      ///< DelaunayOptions::skip_cells (negative: automatic)
  std::string method = "auto"; ///< DelaunayOptions::method: auto|cells|insertion
  std::optional<double> alpha; ///< keep the simplices of circumradius <= alpha (tessera::alpha_shape)
  std::string boundary;        ///< .vtp or .npy int64 (B, D): the boundary of the simplices written, or empty
  bool regularized = false;    ///< --boundary without the alpha complex's singular facets
  bool validate = false;
  bool quiet = false;
};

/// Point preparation (cmd_prep.cpp): each reads points (+ labels) and writes
/// labelled points (.npy + _labels.npy sidecar, .ply, .vtp) via io::write_points.
struct PrepInput {
  std::string input;
  std::string output;          ///< .npy / .ply / .vtp
  int dim = 0;                 ///< 0: from the file
  std::string labels;          ///< "" | NAME | FILE.npy
  bool quiet = false;
  bool keep_non_finite = false;  ///< points with a NaN or infinite coordinate kept, untouched
};

struct JoggleArgs {
  PrepInput io;
  double radius = 1e-4;        ///< fraction of the bounding-box diagonal, or absolute
  bool absolute = false;
  std::string mode = "ball";   ///< ball | xy | xz | yz
  std::string mask;            ///< .npy, one value per point (nonzero = move), or empty
  std::uint64_t seed = 0;
  int threads = 0;
};

struct FillArgs {
  PrepInput io;
  std::string strategy = "uniform";  ///< uniform | adaptive
  std::int32_t background_label = -1;
  std::int32_t in_label = 0;
  double bin_points = 2.0;
  std::vector<std::string> bounds;  ///< none, or the words of x0 x1 y0 y1 [z0 z1] (or comma-separated)
  double joggle = 0.0;         ///< fraction of the bin edge, <= 0.5
  std::uint64_t seed = 0;
  int threads = 0;
};

struct ThresholdArgs {
  PrepInput io;
  std::string scalars;                 ///< S.npy, or a .ply property / .csv column name
  std::vector<std::string> intervals;  ///< "lo,hi,label" each
  std::int32_t background_label = -1;
};

/// `lloyd` (cmd_lloyd.cpp): Lloyd relaxation of INPUT's points, which are
/// written moved (labelled points, io::write_points). main.cpp registers its
/// options: the compute options, --method, --radii, --periodic/--tilt and
/// these.
struct LloydArgs {
  ComputeArgs compute;
  std::string output;                              ///< .npy / .ply / .vtp, or - (.ply on standard output)
  int iterations = LloydOptions{}.iterations;
  double tolerance = LloydOptions{}.tolerance;     ///< relative to the mean spacing; 0: every iteration
  bool quiet = false;
};

int run_voronoi(const VoronoiArgs& args);
int run_delaunay(const DelaunayArgs& args);
int run_bench_delaunay(const BenchArgs& args);
int run_bench_voronoi(const BenchArgs& args);
int run_default(const DemoArgs& args);
int run_graph(const GraphArgs& args);
int run_faces(const FacesArgs& args);
int run_flower(const FlowerArgs& args);
int run_joggle(const JoggleArgs& args);
int run_fill(const FillArgs& args);
int run_threshold(const ThresholdArgs& args);
int run_lloyd(const LloydArgs& args);
/// A command that writes points (joggle, fill, threshold, lloyd) checks its
/// output path before any work: a points extension (.npy, .ply, .vtp) and a
/// writable directory, or "-" (binary .ply on standard output; the summary
/// then goes to standard error). InputError otherwise (cmd_prep.cpp).
void check_prep_output(const std::string& path);
/// `joggle`, `fill`, `threshold` with their options (cmd_prep.cpp); main.cpp
/// calls add_prep_commands before parsing and run_prep_command after it
/// (-1: none of them was given).
struct PrepCommands {
  JoggleArgs joggle;
  FillArgs fill;
  ThresholdArgs threshold;
  CLI::App* joggle_app = nullptr;
  CLI::App* fill_app = nullptr;
  CLI::App* threshold_app = nullptr;
};
void add_prep_commands(CLI::App& app, PrepCommands& commands);
int run_prep_command(const PrepCommands& commands);

/// Image commands (cmd_image.cpp): `sample-image` and `probe`.
/// How to read an image: geometry overrides and the .vti array.
struct ImageReadArgs {
  std::vector<double> spacing;  ///< empty, or 2/3 numbers (x, y[, z])
  std::vector<double> origin;   ///< empty, or 2/3 numbers
  std::string array;            ///< .vti point-data array ("" = active scalars)
};

/// The sampler's options; also what `surface-nets` takes for an image input
/// (add_sampler_options registers them on any subcommand).
struct SamplerArgs {
  ImageReadArgs read;
  std::vector<std::int32_t> select;       ///< empty: every label >= 0
  std::string schedule = "exponential";   ///< exponential | linear
  int step = 2;
  bool no_randomize = false;
  std::vector<double> probability;        ///< empty or lo,hi
  std::uint64_t seed = 0;
  std::string output = "all";             ///< all | labelled | background
  std::string background_label;           ///< "" or an integer < 0
  double joggle = 0;
  int threads = 0;
};

struct SampleImageArgs {
  std::string image;
  std::string output;  ///< .npy / .ply / .vtp
  SamplerArgs sampler;
  bool quiet = false;
};

struct ProbeArgs {
  std::string image;
  std::string points;
  std::string output;                 ///< .npy (the values, (n,) float64) / .ply / .vtp
  ImageReadArgs read;
  std::string labels;                 ///< carried to .ply/.vtp output: NAME | FILE.npy
  std::string outside_value = "nan";  ///< a number, nan, inf, -inf
  int threads = 0;
  bool quiet = false;
  bool keep_non_finite = false;       ///< points with a NaN coordinate are outside, not refused
};

struct ImageCommands {
  SampleImageArgs sample;
  ProbeArgs probe;
  CLI::App* sample_app = nullptr;
  CLI::App* probe_app = nullptr;
};
/// Registers `sample-image` and `probe` (main.cpp, before parsing).
void add_image_commands(CLI::App& app, ImageCommands& commands);
/// Runs the one given, or returns -1 when neither was.
int run_image_command(const ImageCommands& commands);
int run_sample_image(const SampleImageArgs& args);
int run_probe(const ProbeArgs& args);
/// The sampler's own options on `app`: --spacing, --origin, --array,
/// --schedule, --step, --no-randomize, --probability, --seed,
/// --background-label, --joggle. Not --select, --threads (a command that
/// samples an image has its own; fill SamplerArgs::select / threads from
/// them) nor the output mode (SamplerArgs::output stays "all").
void add_sampler_options(CLI::App* app, SamplerArgs& s);
/// True for the image extensions that are never point files (.nrrd, .nhdr, .mha, .mhd, .vti).
bool is_image_path(const std::string& path);
/// Reads a label image and samples it with `s` (InputError on bad options or input).
LabelledPoints sample_image_file(const std::string& image, const SamplerArgs& s);
/// The two halves of sample_image_file (surface-nets needs the geometry and
/// times the sampling alone): read (options checked first), then sample.
LabelImage read_label_image_file(const std::string& image, const SamplerArgs& s);
LabelledPoints sample_label_image(const std::string& image, const LabelImage& img, const SamplerArgs& s);

/// `surface-nets` and `bench surface-nets` (cmd_surface_nets.cpp). INPUT is
/// labelled points (compute.input, compute.labels) or a label image (by
/// extension, or .npy with --image), sampled first with `sampler`.
struct SurfaceNetsArgs {
  ComputeArgs compute;
  std::string output;                  ///< .vtp
  std::vector<std::int32_t> select;    ///< empty: every label >= 0
  std::int32_t background_label = -1;  ///< BoundaryLabels value of the domain box
  bool capping = false;
  int smooth = SmoothingOptions{}.iterations;  ///< smoothing iterations (0 = none)
  double relax = SmoothingOptions{}.relaxation;
  double constraint = SmoothingOptions{}.constraint;  ///< x petal radius, or absolute
  bool absolute_constraint = false;
  bool triangles = false;
  bool image = false;                  ///< .npy INPUT is a label image
  SamplerArgs sampler;                 ///< select / threads come from the fields above
  bool quiet = false;
  int repeat = 1;                      ///< bench only
};
/// Registers the surface-nets options other than the compute options (main.cpp
/// adds those) on `app`; `bench` adds --repeat and leaves out -o/--quiet.
void add_surface_nets_options(CLI::App* app, SurfaceNetsArgs& args, bool bench);
int run_surface_nets(const SurfaceNetsArgs& args);
int run_bench_surface_nets(const SurfaceNetsArgs& args);

/// `sphere` and `bench sphere` (cmd_sphere.cpp): Voronoi cells on a sphere.
struct SphereArgs {
  std::string input;
  bool lonlat = false;              ///< INPUT's first two columns are longitude, latitude (degrees)
  std::vector<double> center;       ///< empty or X Y Z
  double radius = 0;                ///< 0: the points' mean distance (with --lonlat: 1)
  double tolerance = 1e-6;          ///< SphericalVoronoiOptions::tolerance
  int threads = 0;
  std::string output;               ///< .vtp cells, or empty
  std::string triangles;            ///< .vtp / .npy, or empty
  std::string cell_table;           ///< .csv / .npy, or empty
  std::string neighbors;            ///< .npy, or empty
  bool validate = false;            ///< validate_spherical_voronoi
  bool quiet = false;
  int repeat = 1;                   ///< bench only
};
struct SphereCommands {
  SphereArgs run, bench;
  CLI::App* run_app = nullptr;
  CLI::App* bench_app = nullptr;
};
/// Registers `sphere` on `app` and `sphere` on `bench` (main.cpp, before parsing).
void add_sphere_commands(CLI::App& app, CLI::App& bench, SphereCommands& commands);
/// Runs the one given, or returns -1 when neither was.
int run_sphere_command(const SphereCommands& commands);
int run_sphere(const SphereArgs& args);
int run_bench_sphere(const SphereArgs& args);

// Shared by the subcommand files (defined in commands.cpp).
/// Resource usage of this process so far (bench JSON lines).
struct Usage {
  double user_s, sys_s;
  long long minflt;
  long long maxrss_bytes;
};
Usage usage_now();
std::string extension(const std::string& path);  ///< lower-cased, with the dot; "" if none

/// Outputs named "-" go to standard output (io::write_file_atomic writes
/// them in place): at most one per command (InputError otherwise), and the
/// command's summary then goes to standard error instead.
void route_standard_output(std::initializer_list<const std::string*> outputs);

/// A command's output files (option as the messages name it, path; empty
/// and "-" skipped) must be distinct files: two options naming one file
/// would leave only the one written last. InputError naming both options.
void check_distinct_outputs(std::initializer_list<std::pair<const char*, const std::string*>> outputs);

/// How to name output `path` in a summary: "stdout" for "-".
inline std::string shown_output(const std::string& path) { return path == "-" ? "stdout" : path; }
/// The outputs written, as the summaries list them: "a.vtu, stdout".
inline std::string written_list(const std::vector<std::string>& written) {
  std::string s;
  for (const auto& w : written) s += (s.empty() ? "" : ", ") + shown_output(w);
  return s;
}

/// Whether `word` is one whole number in strtod's syntax (no leading space,
/// nothing after it; "inf" and "nan" included), and its value. Every reader
/// of a number from the command line goes through this.
bool whole_number(const std::string& word, double& value);
/// Whether `value`, read from `word`, is an infinity the word does not spell
/// (1e400): strtod's overflow, which an option should refuse, not take as inf.
bool beyond_range(const std::string& word, double value);
/// A number as the user wrote it ("inf", "-inf" allowed when `allow_inf`);
/// InputError("WHAT: 'WORD' is not a ...", or "... is beyond double's
/// range" for an overflowing one) otherwise.
double parse_number(const std::string& word, const std::string& what, bool allow_inf);
/// The comma-separated words of `s`, spaces dropped ("" gives one empty word).
std::vector<std::string> split_commas(const std::string& s);
void check_bounds_arg(const std::vector<double>& bounds);  ///< InputError unless 4 or 6 valid numbers
/// Where INPUT declares its box (a LAMMPS dump) and the command line gives no
/// --bounds: the bounds from the file's box, and its periodic axes and tilts
/// where --periodic and --tilt do not give them.
void apply_file_box(ComputeArgs& args);

/// Whether --frame's text asks for a series (all, START:STOP[:STEP]), not
/// one frame's index.
bool is_frame_series(const std::string& frame);

/// --frame: where the frame asked for starts (args.frame_place), or nothing
/// where --frame was not given; for a series (all, A:B[:S]) every frame
/// selected (args.frames; frame_place is the first). InputError for a file
/// that is no trajectory, a frame it does not have, or a series that
/// selects none.
void find_input_frame(ComputeArgs& args);

/// printf into a std::string (g++ 12's libstdc++ has no <format>).
[[gnu::format(printf, 1, 2)]] std::string strf(const char* fmt, ...);

/// INPUT as the summaries name it: "stdin" for standard input, and the frame
/// read where --frame was given ("run.dump, frame 3 (from line 4017)").
std::string shown_input(const ComputeArgs& args);
/// The tilts used ("xy A, xz B, yz C"), with a note where the given ones
/// (args.tilt) were reduced by whole box lengths; "" for an orthogonal box
/// given as one.
std::string tilt_text(const ComputeArgs& args, const std::array<double, 3>& used, const Bounds& box, int dim);
/// A series' later frame's summary, one line: "tessera COMMAND: INPUT, frame
/// K (from line L): WHAT; T s; wrote A, B" (to `to`: delaunay's summary is
/// on standard error).
void print_frame_line(const char* command, const ComputeArgs& args, const std::string& what, double seconds,
                      const std::vector<std::string>& written, std::FILE* to = stdout);
io::PointCloud read_input(const ComputeArgs& args);        ///< read and check INPUT (InputError)
/// The options of a cells pass over `points` (n x dim), whose convex hull
/// --hull-walls adds as walls (its finite points').
VoronoiOptions make_options(const ComputeArgs& args, int dim, std::span<const double> points);
/// tessera::voronoi with a progress bar (when `show_progress`) and Ctrl-C cancellation.
Cells compute(const io::PointCloud& pc, VoronoiOptions options, bool show_progress, double& seconds);
/// Why a computation gave no cells, as an error line (points outside, or every power cell empty).
std::string no_cells_reason(const io::PointCloud& pc, const Cells& c);
/// The summary's line on power cells (Cells::power): the radii's range and the empty cells.
void print_power_line(const io::PointCloud& pc, const Cells& c);
/// The delaunay summary's line (stderr) on a regular triangulation (Delaunay::power): radii and hidden points.
void print_regular_line(const io::PointCloud& pc, const Delaunay& dt);

}  // namespace tessera::cli
