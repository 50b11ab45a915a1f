// tessera: command-line front end (argument parsing, dispatch, error reporting).
//
// Contract with the user: every failure prints exactly one line
// "tessera: error: MESSAGE" on stderr and exits non-zero (2: bad command line
// or input, 1: anything else or a failed --validate, 130: Ctrl-C). Outputs are
// written atomically by the IO layer, so a failed run leaves no partial file.
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "commands.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "stdin_input.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/atomic_file.hpp"

namespace {

using namespace tessera::cli;

/// One line of valid UTF-8, whatever the message contains: control
/// characters (a newline, or a form feed quoted from a file's header) become
/// spaces, and bytes that are not UTF-8 (a corrupt file's header quoted) '?'.
/// Valid multi-byte characters (a file name's) are kept.
void print_error(const std::string& message) {
  const std::string msg = name_stdin(message);
  std::string line;
  line.reserve(msg.size());
  for (std::size_t i = 0; i < msg.size();) {
    const auto c = static_cast<unsigned char>(msg[i]);
    if (c < 0x80) {
      line += c < 0x20 || c == 0x7f ? ' ' : static_cast<char>(c);
      ++i;
      continue;
    }
    // A lead byte and its continuation bytes (no overlong 2-byte forms).
    const std::size_t len = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
    bool ok = len != 0 && i + len <= msg.size();
    for (std::size_t k = 1; ok && k < len; ++k) ok = (static_cast<unsigned char>(msg[i + k]) & 0xc0) == 0x80;
    if (ok) {
      line.append(msg, i, len);
      i += len;
    } else {
      line += '?';
      ++i;
    }
  }
  std::fprintf(stderr, "tessera: error: %s\n", line.c_str());
}

/// The first option of the command run that was given an empty value
/// (-o "", --cell-table ""), or "". Such an option was taken as not given:
/// `--cell-table "" --neighbors nb.npy` wrote the neighbours alone, exit 0.
std::string option_given_empty(const CLI::App& app) {
  for (const CLI::App* sub : app.get_subcommands()) {
    for (const CLI::Option* o : sub->get_options())
      // (not a flag; nor --wall, whose repeats CLI11 keeps apart by empty entries)
      if (o->count() > 0 && o->get_expected_min() > 0 && o->get_name() != "--wall")
        for (const std::string& r : o->results())
          if (r.empty()) return o->get_name();
    if (std::string inner = option_given_empty(*sub); !inner.empty()) return inner;
  }
  return "";
}

constexpr const char* kExitCodes =
    "Exit status: 0 success; 1 failure (an internal error, or a failed --validate where the command has one);\n"
    "2 bad command line or bad input; 130 interrupted (Ctrl-C during the computation: nothing written).\n"
    "Ctrl-C while writing (or a second one), SIGTERM or SIGHUP remove the outputs being written and end\n"
    "it by that signal. Signals ignored where it starts (nohup, a background job) stay ignored.\n"
    "Environment: TESSERA_NUM_THREADS sets the thread count when --threads is not given.";

/// Options shared by the commands that compute cells (`voronoi`, `bench voronoi`, `graph`, ...).
void add_compute_options(CLI::App* app, ComputeArgs& c, std::vector<std::string>& raw_bounds) {
  // INPUT is checked after parsing (finish_compute_args), not ->required():
  // "--bounds 0 1 0 1 pts.npy" hands pts.npy to --bounds, which gives it back.
  const CLI::App* parent = app->get_parent();
  const std::string command = (parent && parent->get_parent() ? parent->get_name() + " " : "") + app->get_name();
  app->add_option("INPUT", c.input,
                  "Point file (required): .npy (float array, shape (N,2) or (N,3), or records with fields "
                  "x,y[,z]), .csv/.xyz/.txt (the columns a header names x,y[,z], else the first 2 or 3 "
                  "numeric columns; also Qhull's format, as rbox writes it, and XYZ: a count, a comment, then species x y z; "
                  "extended XYZ's Lattice and pbc are the domain as a dump's box), .ply (vertex x,y,z), .vtp/.vtu (VTK XML "
                  "points, as ParaView saves them), .vtk (legacy VTK: the POINTS of PolyData, an unstructured or a structured grid, "
                  "ASCII or binary), .pcd (PCL's point clouds), .las (lidar: LAS 1.0-1.4, point formats 0-10; fields such as "
                  "classification for --labels; LAZ refused) or .dump/.lammpstrj (a LAMMPS dump's first "
                  "frame, or --frame's: x y z, xu yu zu or scaled xs ys zs, atoms in file order; its box and periodic axes are the "
                  "domain unless --bounds is given; --periodic and --tilt replace its axes and tilts); - reads standard input, in any of these "
                  "formats (rbox 1000 D3 | tessera " + command + " - ...)");
  app->add_option("--frame", c.frame,
                  "Of a trajectory (a LAMMPS dump, an XYZ file): the frame to read, 0 the first (default), 1 the "
                  "next; negative counts from the end, -1 the last. Its box is the domain, as the first frame's "
                  "would be; --labels and --radii columns are read from it (a .npy file serves every frame). Also "
                  "a series (not in bench), all or START:STOP[:STEP] as Python's slices (-10: the last ten, ::5 "
                  "every fifth): each frame is computed in turn, and every output's name must hold {frame}, "
                  "replaced by the frame's index (-o cells_{frame}.vtu, a series ParaView opens as one), and a "
                  "frame of no atoms is skipped with a note; with one INDEX, {frame} in a name is replaced alike")
      ->type_name("INDEX")
      ->check(CLI::Validator(
          [](std::string& v) {
            return v.empty() ? std::string("expected a frame's index (0 the first, -1 the last), got ''") : "";
          },
          "", "frame"));
  app->add_option("--dim", c.dim,
                  "Dimension: 2 or 3 (default: the number of columns or fields; .ply, .vtp and .vtu are 3D). --dim 2 "
                  "on 3-column input keeps x,y")
      ->check(CLI::IsMember({2, 3}));
  app->add_option("--labels", c.labels,
                  "Per-point integer labels: FILE.npy (length N), or the name of an integer .ply vertex "
                  "property / .csv column / .vtp, .vtu or .vtk point data array / LAMMPS dump column / .pcd, .las or structured .npy field. Cells get "
                  "their point's label as Region; points labelled < 0 own no cell and clip their neighbours");
  // Collected as text: CLI11 cannot know whether 4 (2D) or 6 (3D) numbers
  // follow, so in 2D it also takes the next word; finish_compute_args sorts it out.
  app->add_option("--bounds", raw_bounds,
                  "Domain box: X0 X1 Y0 Y1 in 2D, X0 X1 Y0 Y1 Z0 Z1 in 3D (default: the bounding box of "
                  "the points grown by --padding); also X0,X1,Y0,Y1[,Z0,Z1]")
      ->expected(4, 6)
      ->allow_extra_args(false)  // never more than 6 values
      ->delimiter(',')
      ->type_name("X0 X1 Y0 Y1 [Z0 Z1]");
  app->add_option("--padding", c.padding,
                  "Margin of the default domain, as a fraction of the largest extent of the points")
      ->check(NonNegative)
      ->capture_default_str();
  app->add_flag("--ignore-outside", c.ignore_outside,
                "Drop points outside --bounds (listed in the summary) instead of failing; also points with a NaN or "
                "infinite coordinate (an organized point cloud's missing returns), with or without --bounds (the "
                "default domain then comes from the others). Point ids stay those of the input");
  app->add_option("--threads", c.threads,
                  "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores; at most " +
                      std::to_string(tessera::max_threads) +
                      ", more than the cores run oversubscribed). Results are identical for any thread count")
      ->check(NonNegative);
  app->add_option("--bin-points", c.bin_points,
                  "Tuning: mean points per bin of the point locator (default 0: automatic)")
      ->check(NonNegative);
}

/// --method of the commands whose product is the cells themselves.
void add_cell_method_option(CLI::App* app, ComputeArgs& c) {
  app->add_option("--method", c.cell_method,
                  "How each cell finds the points that clip it. search: the bins around it (the meshless "
                  "method); insertion: the Delaunay triangulation by incremental insertion, each cell assembled "
                  "from its Delaunay star, or clipped by its Delaunay neighbours where the box or an "
                  "ill-conditioned vertex needs the exact clips; faster where cells reach far (points nearly "
                  "on a sphere or circle, surface samples, dense clusters, 2D curves); "
                  "auto: insertion where a sample of cells costs far more than on uniform points, else search. "
                  "Same cells")
      ->check(CLI::IsMember({"auto", "search", "insertion"}))
      ->capture_default_str();
}

/// --radii of the commands that take power cells (`with_method`: the
/// command has --method).
void add_radii_option(CLI::App* app, ComputeArgs& c, bool with_method) {
  app->add_option("--radii", c.radii,
                  "Sphere radii for power cells (the radical tessellation of polydisperse spheres, as Voro++'s "
                  "container_poly): FILE.npy (float array, length N) or the name of a numeric .ply vertex property / "
                  ".csv column / .vtp, .vtu or .vtk point data array / LAMMPS dump column / .pcd, .las or structured .npy field. Each cell is where "
                  "its point's power |x-p|^2 - r^2 is the least; a point may own no cell (listed as empty), and of "
                  "coincident points the largest radius owns it. Radii must be finite and >= 0" +
                      std::string(with_method ? "; either --method (the search, or the regular triangulation's stars)"
                                              : "") +
                      "; with --periodic every image has its point's radius")
      ->type_name("FILE|NAME");
}

/// --radii of `delaunay` and `bench delaunay`: the regular triangulation.
void add_regular_radii_option(CLI::App* app, ComputeArgs& c) {
  app->add_option("--radii", c.radii,
                  "Sphere radii for the regular (weighted Delaunay) triangulation, the dual of the power cells "
                  "(weights r^2, as CGAL's Regular_triangulation): FILE.npy (float array, length N) or the name of "
                  "a numeric .ply vertex property / .csv column / .vtp, .vtu or .vtk point data array / LAMMPS dump "
                  "column / .pcd, .las or structured .npy field. A simplex is regular when no point's power |x-p|^2 - r^2 at its "
                  "orthocentre is below its vertices'; a point whose power cell is empty is hidden (in no "
                  "simplex), and of coincident points the largest radius is the vertex. Radii must be finite and "
                  ">= 0; either --method gives the same simplices; with --periodic every image has its point's "
                  "radius")
      ->type_name("FILE|NAME");
}

constexpr const char* kAnyAxes = "e.g. xyz (a simulation's or a crystal's periodic box), xy or x";
constexpr const char* kEveryAxis = "every axis: xyz (xy in 2D)";
constexpr const char* kPeriodicTriangulation =
    "The triangulation of the points among all their images, each simplex once (delaunay --simplex-shifts: its "
    "vertices' images); walls on some axes are refused (the periodic cells with walls serve such boxes)";

/// --periodic and --tilt. `images`: where the command's output names the
/// images a cell meets across the box (e.g. "neighbours may be images
/// (--neighbor-shifts)"), or what it says of them.
void add_periodic_option(CLI::App* app, ComputeArgs& c, const std::string& images, const char* axes_example) {
  app->add_option("--periodic", c.periodic,
                  std::string("Periodic axes, ") + axes_example +
                      ": --bounds is the box (else the box a LAMMPS dump or extended XYZ INPUT declares), which repeats along them, with no walls there; points outside it are "
                      "wrapped in. The box and the coordinates along those axes are rounded to the spacing of "
                      "doubles at a few box lengths (2^-51 for a unit box) so that every image is exact. " +
                      images)
      ->type_name("AXES");
  app->add_option("--tilt", c.tilt,
                  "With --periodic: a triclinic (sheared) box's tilt factors as lengths, as LAMMPS and Voro++ give "
                  "them: XY in 2D, XY XZ YZ in 3D. The box is the parallelepiped spanned from --bounds' lower "
                  "corner by a = (Lx,0,0), b = (XY,Ly,0), c = (XZ,YZ,Lz), L the extents of --bounds; a tilt needs "
                  "both its axes periodic. A tilt of more than one box length is reduced by whole lengths (XY by Lx; YZ by "
                  "Ly, moving XZ by as many XY; XZ by Lx): the same lattice, in a box that is not thin; the summary "
                  "then gives the tilts used. Points are wrapped into the box of the tilts used, and shifts count "
                  "its a, b, c")
      ->type_name("XY [XZ YZ]")
      ->expected(1, 3);
}

/// --wall, repeatable, of the commands whose cells may lie in a convex domain.
void add_walls_option(CLI::App* app, ComputeArgs& c) {
  app->add_option("--wall", c.raw_walls,
                  "A wall: the half-space NX*x + NY*y (+ NZ*z) <= D, which cuts the domain box (--bounds, or the "
                  "default) down to a convex polygon or polyhedron; repeat it, one per side (e.g. --wall 1,1,1.5 "
                  "keeps x + y <= 1.5). Cells are cut exactly where they cross it; a face on wall k is listed as "
                  "spoke -7-k, below the box planes' -1..-6. Every point must lie inside every wall (or "
                  "--ignore-outside drops it). Not with --periodic")
      ->type_name("NX NY [NZ] D")
      ->expected(3, 4)
      ->allow_extra_args(false)
      ->delimiter(',');
  app->add_option("--walls", c.walls_file,
                  "Walls from a file, as --wall gives one (both may be used): a .npy array of shape (k, 3) in 2D or "
                  "(k, 4) in 3D (NX NY [NZ] D per row; tessera.hull_walls' output, saved), or text with one wall "
                  "a line (numbers separated by commas or spaces; '#' lines skipped)")
      ->type_name("FILE");
  CLI::Option* hull = app->add_flag("--hull-walls", c.hull_walls,
                                    "The points' convex hull as walls (one per hull facet, facets in one plane merged): "
                                    "cells bounded by the hull instead of the box (the box and any --wall cut too). "
                                    "Every point lies inside it exactly; hull points sit on it (lattices) or within ~1e-14 of the "
                                    "coordinates' size inside");
  app->add_option("--hull-dilation", c.hull_dilation,
                  "With --hull-walls: push each hull wall out by this distance (>= 0), a dilated hull (the default box grows to hold it)")
      ->check(NonNegative)
      ->needs(hull);
}

/// Converts the --bounds words to numbers. A fifth word that is not a number
/// is the INPUT that CLI11 attached to a 2D --bounds (when INPUT is otherwise
/// missing). Throws InputError for anything else that is not a number, and
/// for a series of frames (--frame all, A:B) where `series` is false.
void finish_compute_args(ComputeArgs& c, const std::vector<std::string>& raw_bounds, bool series = false) {
  // strtod's ERANGE means overflow (inf) or underflow: a subnormal such as
  // 1e-310 (a domain Python takes, and the default domain may be) or 0, as
  // Python's float() reads them too; only overflow is refused.
  // (A word that is not wholly a number may have set ERANGE on its numeric
  // prefix: `1e-400.npy` is the INPUT, not an overflow.)
  auto parse = [](const std::string& w, double& v, bool& overflow) {
    errno = 0;
    const bool whole = whole_number(w, v);
    overflow = whole && errno == ERANGE && std::isinf(v);
    return whole && !overflow;
  };
  c.bounds.clear();
  for (std::size_t i = 0; i < raw_bounds.size(); ++i) {
    double v = 0;
    bool overflow = false;
    if (parse(raw_bounds[i], v, overflow)) {
      c.bounds.push_back(v);
      continue;
    }
    if (overflow) throw tessera::InputError("--bounds: '" + raw_bounds[i] + "' is beyond double's range");
    if (i == 4 && c.input.empty() && raw_bounds.size() == 5) {
      c.input = raw_bounds[i];
      break;
    }
    throw tessera::InputError("--bounds: '" + raw_bounds[i] + "' is not a number" +
                              (i >= 4 ? " (put INPUT before --bounds)" : ""));
  }
  c.walls.clear();
  for (const auto& words : c.raw_walls) {
    std::vector<double>& wall = c.walls.emplace_back();
    for (std::size_t i = 0; i < words.size(); ++i) {
      double v = 0;
      bool overflow = false;
      if (parse(words[i], v, overflow)) {
        wall.push_back(v);
        continue;
      }
      if (overflow) throw tessera::InputError("--wall: '" + words[i] + "' is beyond double's range");
      if (i == 3 && c.input.empty()) {  // a 2D wall's three numbers, then INPUT
        c.input = words[i];
        break;
      }
      throw tessera::InputError("--wall: '" + words[i] + "' is not a number" + (i == 3 ? " (put INPUT before --wall)" : ""));
    }
  }
  if (c.input.empty()) throw tessera::InputError("INPUT is required (run with --help for usage)");
  // No output may replace a file the command reads (a slip such as
  // `voronoi p.npy --cell-table p.npy` replaced the points); `-` is the file
  // standard input comes from, if it is one.
  tessera::io::protect_from_writes(c.input, "the INPUT");
  c.input = input_path(c.input);
  tessera::io::protect_from_writes(c.labels, "--labels");
  tessera::io::protect_from_writes(c.radii, "--radii");
  tessera::io::protect_from_writes(c.walls_file, "--walls");
  if (!series && is_frame_series(c.frame))
    throw tessera::InputError("--frame " + c.frame + ": a bench runs on one frame; give its INDEX");
  find_input_frame(c);
  try {
    apply_file_box(c);
  } catch (const tessera::InputError& e) {  // a frame's box: say which frame, as its other errors do
    if (c.frame.empty()) throw;
    throw tessera::InputError("frame " + std::to_string(c.frame_place.index) + ": " + e.what());
  }
}

/// The value of --threads of the command that ran (its deepest parsed
/// subcommand), 0 when not given or when it has none.
int threads_given(const CLI::App& app) {
  const CLI::App* command = &app;
  while (!command->get_subcommands().empty()) command = command->get_subcommands().front();
  const CLI::Option* o = command->get_option_no_throw("--threads");
  return o != nullptr && o->count() > 0 ? o->as<int>() : 0;
}

}  // namespace

int main(int argc, char** argv) {
  install_fatal_signal_cleanup();
  CLI::App app{"tessera: Voronoi tessellations of 2D/3D point clouds, clipped to a box, with exact topology.",
               "tessera"};
  app.require_subcommand(1);
  app.footer(kExitCodes);

  VoronoiArgs va;
  CLI::App* vor = app.add_subcommand("voronoi", "Compute the Voronoi cells of a point cloud and write them");
  std::vector<std::string> vor_bounds, bench_bounds;
  add_compute_options(vor, va.compute, vor_bounds);
  add_cell_method_option(vor, va.compute);
  add_radii_option(vor, va.compute, true);
  add_periodic_option(vor, va.compute, "Cells keep their shape across the box's faces; neighbours may be images (--neighbor-shifts)", kAnyAxes);
  add_walls_option(vor, va.compute);
  vor->add_option("-o,--output", va.output,
                  "Cells as VTK XML: .vtu (3D, one polyhedron per cell) or .vtp (2D, one polygon per cell), "
                  "with cell data GeneratorId, Region, Volume/Area, NumberOfFaces/Edges, NumberOfNeighbors");
  vor->add_option("--cell-table", va.cell_table,
                  "Per-cell table, one row per cell in point order: .csv (id,region,volume,cx,cy,cz,faces,"
                  "neighbors; 2D: id,region,area,cx,cy,edges,neighbors) or .npy (float64, same columns); - writes "
                  "the CSV to standard output (the summary then goes to standard error)");
  vor->add_option("--neighbors", va.neighbors,
                  "Neighbour lists as one int64 .npy array: [n_cells, offsets (n_cells+1), ids...]; the "
                  "neighbours of cell c are ids[offsets[c]:offsets[c+1]] (point ids). Cells are numbered as the "
                  "--cell-table rows (point order; outside points and duplicates own none); - writes it to standard "
                  "output");
  vor->add_option("--neighbor-shifts", va.neighbor_shifts,
                  "With --periodic: which image each --neighbors entry is, as an int8 .npy array of shape (entries, "
                  "dim): the neighbour's point moved by that many box lengths along each axis (a point may be "
                  "listed once per image that shares a face, itself included)");
  vor->add_flag("--validate", va.validate,
                "Check the result (volume sum, neighbour symmetry, vertex degrees, Euler characteristic, and "
                "the volumes and centroids of up to 128 sampled cells against exact arithmetic), print the report, "
                "exit 1 if a check fails");
  vor->add_flag("-q,--quiet", va.quiet, "No summary, no progress bar and no --validate report (a failed check still prints its error line)");
  vor->footer(
      "At least one of -o, --cell-table, --neighbors or --validate is required. Output paths are checked\n"
      "before computing; files are written atomically (never partially).\n"
      "Examples:\n"
      "  tessera voronoi points.npy -o cells.vtu --cell-table cells.csv\n"
      "  tessera voronoi points.csv --dim 2 --bounds 0 1 0 1 -o cells.vtp\n"
      "  tessera voronoi grains.ply --labels grain --neighbors nb.npy --validate\n"
      "  tessera voronoi frame.npy --bounds 0 10 0 10 0 10 --periodic xyz --cell-table cells.csv --neighbors nb.npy "
      "--neighbor-shifts shifts.npy\n" +
      std::string(kExitCodes));

  DelaunayArgs dla;
  std::vector<std::string> del_bounds, bench_del_bounds;
  CLI::App* del = app.add_subcommand(
      "delaunay", "The Delaunay triangulation (tetrahedra in 3D, triangles in 2D), dual of the cells");
  add_compute_options(del, dla.compute, del_bounds);
  del->add_option("-o,--output", dla.output,
                  "Triangulation as VTK: .vtu (VTK_TETRA / VTK_TRIANGLE over the input points) or, in 2D, .vtp; "
                  "with --radii point data Radius (for sphere glyphs in ParaView)");
  del->add_option("--simplices", dla.simplices,
                  "Simplices as an int64 .npy array of shape (M, D+1), point ids; tetrahedra positively oriented, "
                  "triangles counter-clockwise; - writes it to standard output");
  add_periodic_option(del, dla.compute, kPeriodicTriangulation, kEveryAxis);
  add_regular_radii_option(del, dla.compute);
  del->add_option("--simplex-shifts", dla.simplex_shifts,
                  "With --periodic (every axis): which image each vertex of --simplices is, as an int8 .npy array "
                  "of shape (M, D+1, D) in box lengths (lattice vectors with --tilt). Each simplex of the periodic "
                  "triangulation is listed once, translated so that its least (id, shift) vertex is at shift 0");
  del->add_flag("--no-hull-completion", dla.no_hull_completion,
                "Keep only the simplices whose circumcentre lies in the domain box (skip closing the triangulation "
                "up to the convex hull)");
  del->add_option("--skip-cells", dla.skip_cells,
                  "Fraction of the points (ranked by a hash of their id among their neighbours) whose cells are not "
                  "built: their simplices come from their neighbours' cells, and gift wrapping closes the cavities "
                  "between skipped points. Same result. Default from 20,000 points, by what a sample of cells costs: "
                  "in 3D 0.35 to 0.9 (more on surface samples, whose cells are needles), in 2D 0 on uniform points "
                  "and 0.3 to 0.6 on clustered ones; else 0. Ignored with --no-hull-completion")
      ->check(CLI::Range(0.0, 0.99));
  del->add_option("--method", dla.method,
                  "cells: the cells pass and hull completion; insertion: incremental insertion (with hull "
                  "completion; parallel by phases); auto (without --skip-cells): insertion below 20,000 "
                  "points, and from there where a sample of cells costs far more than it finds (surface samples, "
                  "2D curves and circles) or meets no ties on 1-2 threads (uniform points), or "
                  "where 3D hull completion stalls; else the cells (lattices). Same result")
      ->check(CLI::IsMember({"auto", "cells", "insertion"}))
      ->capture_default_str();
  del->add_option("--alpha", dla.alpha,
                  "Alpha shape: keep only the simplices whose circumsphere's radius is at most R (with --radii: "
                  "whose orthosphere's squared radius |c-p|^2-r^2 is at most R^2, the dual of the balls grown by R). "
                  "The union of those simplices is the regularized alpha shape (CGAL's REGULARIZED mode at its "
                  "alpha = R^2; VTK's Alpha without its leftover triangles, edges and vertices): -o and --simplices "
                  "hold the kept simplices, --boundary its surface. Decided exactly (lattices' equal radii all one "
                  "way); inf keeps every simplex. With --periodic the kept simplices of the periodic triangulation "
                  "(--simplex-shifts theirs), their volume, boundary area and pieces");
  del->add_option("--boundary", dla.boundary,
                  "The boundary of the simplices written (the alpha shape's with --alpha; else the convex hull, or "
                  "with --labels the inside region's): 3D triangles counter-clockwise seen from outside, 2D "
                  "segments with the shape on their left; then, with --alpha, the alpha complex's singular facets "
                  "(small, empty-sphere triangles or segments no kept simplex holds: a surface scan's reconstructed "
                  "surface, a curve's samples), unoriented. .vtp (point data PointId; cell data SimplexId: the row "
                  "of --simplices a facet bounds, -1 for singular ones, and Singular 0/1), .npy (int64 (B, D) point "
                  "ids, in that order; - writes it to standard output) or, in 2D, .geojson (a MultiPolygon, one "
                  "polygon per piece: its outer ring counter-clockwise, then its holes; the singular segments as a "
                  "MultiLineString)");
  del->add_flag("--regularized", dla.regularized,
                "--boundary without the singular facets: the closed, oriented boundary of the kept simplices only "
                "(CGAL's REGULARIZED mode)");
  del->add_flag("--validate", dla.validate,
                "Check the triangulation (orientation, conformity, closed convex hull, every point used, local "
                "Delaunay, volumes), print the report, exit 1 if a check fails");
  del->add_flag("-q,--quiet", dla.quiet, "No summary, no progress bar and no --validate report (a failed check still prints its error line)");
  del->footer(
      "Without labels the triangulation covers the convex hull (CGAL's on points in general position; a valid\n"
      "one chosen by symbolic perturbation on degenerate input). With --labels: that triangulation's simplices\n"
      "whose vertices all have labels >= 0 (concave results allowed; with --no-hull-completion, only those\n"
      "whose circumcentre lies in the domain box). With --periodic (every axis periodic, --bounds the box,\n"
      "--tilt for a triclinic one) the triangulation of the points among all their images: each simplex once,\n"
      "with its vertices' images in --simplex-shifts; -o writes the points as wrapped into the box and one more\n"
      "point at each image a simplex uses (point data PointId: whose image). With --radii the regular\n"
      "triangulation (CGAL's Regular_triangulation on points in general position), its hidden points listed.\n"
      "With --alpha R the simplices of circumradius <= R (the alpha shape; --validate checks the whole\n"
      "triangulation), and --boundary its surface (a concave hull in 2D).\n"
      "Examples:\n"
      "  tessera delaunay points.npy -o tets.vtu --simplices tets.npy\n"
      "  tessera delaunay scan.ply --alpha 0.05 --boundary surface.vtp\n"
      "  tessera delaunay points.csv --dim 2 -o triangles.vtp --validate\n"
      "  tessera delaunay spheres.ply --radii radius --simplices tets.npy --validate\n" +
      std::string(kExitCodes));

  // Products read off the merged cells (cmd_dual.cpp).
  GraphArgs ga;
  std::vector<std::string> graph_bounds, faces_bounds, flower_bounds;
  CLI::App* graph = app.add_subcommand(
      "graph", "The adjacency graph: each generator's face neighbours (wheels and spokes) with spoke classes");
  add_compute_options(graph, ga.compute, graph_bounds);
  add_radii_option(graph, ga.compute, false);
  graph->add_option("-o,--output", ga.output,
                    "Graph as VTK PolyData lines (.vtp): points = input points, one line per undirected edge, "
                    "cell data SpokeClass (0 same region, 1 region boundary, 3 outside) and FaceArea/FaceLength. "
                    "With --periodic the points are wrapped into the box, and an edge to an image ends at an extra "
                    "point there (point data PointId: whose image)");
  graph->add_option("--csr", ga.csr,
                    "Wheels as one int64 .npy array: [n_points, offsets (n_points+1), spokes...]; spokes of point "
                    "p are ids[offsets[p]:offsets[p+1]], ascending, box planes negative (x0=-1 .. z1=-6)");
  graph->add_option("--spoke-classes", ga.spoke_classes,
                    "Class of every spoke of --csr as a uint8 .npy array (0 same region, 1 region boundary, "
                    "2 domain boundary, 3 outside)");
  graph->add_option("--spoke-measures", ga.spoke_measures,
                    "Area (3D) or length (2D) of the face behind every spoke of --csr, as a float64 .npy array: "
                    "face-area weights for neighbour statistics; both directions of a face get the same value");
  add_periodic_option(graph, ga.compute, "Cells keep their shape across the box's faces; a spoke may lead to an image (--spoke-shifts)", kAnyAxes);
  add_walls_option(graph, ga.compute);
  graph->add_option("--spoke-shifts", ga.spoke_shifts,
                    "With --periodic: which image every spoke of --csr leads to, as an int8 .npy array of shape "
                    "(spokes, D) in box lengths (lattice vectors with --tilt); the twin of i -> (j, s) is j -> (i, -s)");
  graph->add_option("--prune-tolerance", ga.prune_tolerance,
                    "Drop spokes whose face area (length in 2D) is below F * (mean cell volume)^((D-1)/D), both "
                    "directions together (VTK parity; default 0: keep all)")
      ->check(NonNegative);
  graph->add_flag("-q,--quiet", ga.quiet, "No summary and no progress bar");

  FacesArgs fa;
  CLI::App* faces = app.add_subcommand(
      "faces", "Voronoi faces (3D polygons, 2D segments), each once, oriented, with BoundaryLabels per face");
  add_compute_options(faces, fa.compute, faces_bounds);
  add_radii_option(faces, fa.compute, false);
  faces->add_option("-o,--output", fa.output,
                    "Faces as VTK PolyData (.vtp), cell data BoundaryLabels, Sides, SpokeClass; with --periodic "
                    "also SideShift (which image of side 1 the face meets; each face lies where side 0's cell "
                    "is, so faces fit together across the box's faces by lattice translations)");
  faces->add_option("--kind", fa.kind,
                    "boundary: faces on the box or against outside points; complex: every face once; "
                    "surface-net: faces between different regions")
      ->required();
  faces->add_flag("--capping", fa.capping, "surface-net: also the boundary faces, closing every region");
  add_periodic_option(faces, fa.compute, "Cells keep their shape across the box's faces; a face is placed where its side-0 cell is, and side 1 may be an image (cell data SideShift)", kAnyAxes);
  add_walls_option(faces, fa.compute);
  faces->add_flag("-q,--quiet", fa.quiet, "No summary and no progress bar");

  FlowerArgs wa;
  CLI::App* flower = app.add_subcommand(
      "flower", "A cell with its petals (vertices, radius to the generator), circumflower and clipping neighbours");
  add_compute_options(flower, wa.compute, flower_bounds);
  flower->add_option("--point", wa.points, "Point id whose cell to show (repeat for several)")
      ->required()
      ->allow_extra_args(false)
      ->delimiter(',');
  flower->add_option("-o,--output", wa.output,
                     "Flower as VTK PolyData (.vtp): point data Radius, Role, GeneratorId, PointId; with --periodic "
                     "the cell lies where its point is wrapped to, and each neighbour is drawn at the image across "
                     "its face");
  flower->add_flag("--glyphs", wa.glyphs, "Also draw each petal and the circumflower as a circle (2D) / sphere (3D)");
  add_periodic_option(flower, wa.compute, "Cells keep their shape across the box's faces; the site is the point as wrapped, each neighbour at its image across the face", kAnyAxes);
  add_walls_option(flower, wa.compute);
  flower->add_flag("-q,--quiet", wa.quiet, "No summary and no progress bar");

  // Generalized surface nets (cmd_surface_nets.cpp).
  SurfaceNetsArgs sna;
  std::vector<std::string> sn_bounds;
  CLI::App* snets = app.add_subcommand(
      "surface-nets",
      "Smooth, watertight surfaces between labelled regions (generalized surface nets) from labelled points or a "
      "label image");
  add_compute_options(snets, sna.compute, sn_bounds);
  add_surface_nets_options(snets, sna, false);
  add_periodic_option(snets, sna.compute, "Cells keep their shape across the box's faces; the surfaces close up across the box (their pieces fit by lattice translations; an image's default box is its voxels)", kAnyAxes);
  add_walls_option(snets, sna.compute);

  BenchArgs ba;
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks printing one JSON line per run on stdout");
  bench->require_subcommand(1);
  CLI::App* bench_vor = bench->add_subcommand(
      "voronoi",
      "Time tessera::voronoi (cells, volumes and neighbour lists; no mesh, no output files) K times. "
      "Each run prints {\"tool\":\"tessera\",\"op\":\"voronoi3\"|\"voronoi2\",\"n\",\"threads\",\"seconds\","
      "\"simplices\" (= cells),\"extra\":{cpu_user_s,cpu_sys_s,minflt,peak_rss_bytes,neighbors,empty_cells (power "
      "cells),from_insertion,assembled (cells from their Delaunay stars),from_pilot (the method's sample, kept),"
      "exact_calls,volume_sum,repeat}}; seconds is wall time of the computation only");
  add_compute_options(bench_vor, ba.compute, bench_bounds);
  add_cell_method_option(bench_vor, ba.compute);
  add_radii_option(bench_vor, ba.compute, true);
  add_periodic_option(bench_vor, ba.compute, "Cells keep their shape across the box's faces", kAnyAxes);
  add_walls_option(bench_vor, ba.compute);
  bench_vor->add_option("--repeat", ba.repeat, "Number of timed runs")
      ->check(Positive)
      ->capture_default_str();
  bench_vor->add_flag("--mesh", ba.mesh,
                      "Also build the merged mesh (what VTK output needs); op becomes voronoi3_mesh/voronoi2_mesh");

  BenchArgs bda;
  CLI::App* bench_del = bench->add_subcommand(
      "delaunay",
      "Time tessera::delaunay (hull completion included; no output files) K times. Each run prints "
      "{\"tool\":\"tessera\",\"op\":\"delaunay3\"|\"delaunay2\",\"n\",\"threads\",\"seconds\",\"simplices\","
      "\"extra\":{cpu_user_s,cpu_sys_s,minflt,peak_rss_bytes,from_cells,from_hull_completion,from_insertion,skipped_cells,hidden,exact_calls,repeat}}");
  add_compute_options(bench_del, bda.compute, bench_del_bounds);
  add_periodic_option(bench_del, bda.compute, kPeriodicTriangulation, kEveryAxis);
  add_regular_radii_option(bench_del, bda.compute);
  bench_del->add_option("--repeat", bda.repeat, "Number of timed runs")
      ->check(Positive)
      ->capture_default_str();
  bench_del->add_option("--skip-cells", bda.skip_cells, "As for `tessera delaunay --skip-cells`")
      ->check(CLI::Range(0.0, 0.99));
  bench_del->add_option("--method", bda.method, "As for `tessera delaunay --method`")
      ->check(CLI::IsMember({"auto", "cells", "insertion"}))
      ->capture_default_str();
  bench_del->add_option("--alpha", bda.alpha,
                        "Also the alpha shape of radius R (tessera::alpha_shape: kept simplices, boundary, singular "
                        "facets, pieces): op alpha3|alpha2, seconds the triangulation and the shape, simplices the "
                        "kept ones; extra adds triangulate_s, alpha_s, boundary, singular");

  SurfaceNetsArgs bsna;
  std::vector<std::string> bench_sn_bounds;
  CLI::App* bench_sn = bench->add_subcommand(
      "surface-nets",
      "Time the surface-nets pipeline (image sampling + cells + faces + smoothing [+ triangles]; no output files) "
      "K times. Each run prints {\"tool\":\"tessera\",\"op\":\"surface-nets\",\"n\" (points),\"threads\","
      "\"seconds\",\"simplices\" (= output faces),\"extra\":{cpu_user_s,cpu_sys_s,minflt,peak_rss_bytes,voxels,"
      "points,cells,polygons,triangles (those of --triangles, or that the polygons would make),vertices,labels,"
      "watertight,open_labels,boundary_edges,nonmanifold_edges,sample_s,cells_s,faces_s,smoothing_s,"
      "triangulation_s,smooth (iterations),capping,repeat}}");
  add_compute_options(bench_sn, bsna.compute, bench_sn_bounds);
  add_surface_nets_options(bench_sn, bsna, true);
  add_periodic_option(bench_sn, bsna.compute, "Cells keep their shape across the box's faces", kAnyAxes);

  DemoArgs da;
  CLI::App* demo = app.add_subcommand(
      "run-default",
      "The default job: 1,000,000 uniform random 3D points (fixed seed) in the unit cube, computed in "
      "memory; writes DIR/cells.vtu and DIR/cells.csv and prints a summary");
  demo->add_option("-o,--output-dir", da.out_dir, "Output directory (created if missing)")->capture_default_str();
  demo->add_option("--points", da.n, "Number of points")->check(Positive)->capture_default_str();
  demo->add_option("--seed", da.seed, "Random seed (std::mt19937_64)")->capture_default_str();
  demo->add_option("--threads", da.threads, "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores)")
      ->check(NonNegative);
  demo->add_flag("-q,--quiet", da.quiet, "No summary and no progress bar");

  PrepCommands prep;  // joggle, fill, threshold (cmd_prep.cpp)
  add_prep_commands(app, prep);

  // Lloyd relaxation (cmd_lloyd.cpp): a point tool that computes cells.
  LloydArgs la;
  std::vector<std::string> lloyd_bounds;
  CLI::App* lloyd_app = app.add_subcommand(
      "lloyd", "Lloyd relaxation: move every point to its cell's centroid, iteration after iteration (towards a "
               "centroidal Voronoi tessellation)");
  add_compute_options(lloyd_app, la.compute, lloyd_bounds);
  add_cell_method_option(lloyd_app, la.compute);
  add_radii_option(lloyd_app, la.compute, true);
  add_periodic_option(lloyd_app, la.compute,
                      "Each cell is its point's periodic cell, whose centroid may lie across a face: the moved point "
                      "is wrapped back into the box",
                      kAnyAxes);
  add_walls_option(lloyd_app, la.compute);
  lloyd_app->add_option("-o,--output", la.output,
                        "The moved points, in input order, with their labels: .npy (float64 (N, D); labels in "
                        "OUT_labels.npy), .ply (binary, double x y z, int property 'label') or .vtp (VTK vertices, "
                        "point data 'label'); with --radii, .ply and .vtp also hold the radii, unchanged (named as "
                        "--radii names its field, else 'radius'). 2D points get z = 0 in .ply/.vtp. - writes the "
                        ".ply to standard output")
      ->required();
  lloyd_app->add_option("--iterations", la.iterations,
                        "Lloyd iterations: each computes the cells (no mesh) and moves every point that owns a cell "
                        "to its centroid; 0 writes the points unchanged")
      ->check(NonNegative)
      ->capture_default_str();
  lloyd_app->add_option("--tolerance", la.tolerance,
                        "Stop after the first iteration whose largest displacement is at most T times the mean "
                        "spacing, (domain volume / generators)^(1/D); 0: run every iteration")
      ->check(NonNegative)
      ->capture_default_str();
  lloyd_app->add_flag("-q,--quiet", la.quiet, "No summary and no progress bar");
  lloyd_app->footer(
      "Lloyd's method (Lloyd 1982; Du, Faber and Gunzburger 1999): each iteration lowers the energy\n"
      "sum over cells of the integral of |x - p|^2, within one domain. The domain is fixed: --bounds (or the\n"
      "periodic box), else the padded bounding box of the points as the first iteration computes it, kept\n"
      "for every later one. Points that own no cell stay where they are, bit for bit: outside points (label\n"
      "< 0), the copies of exact duplicates that do not own their cell (the owner moves, which separates\n"
      "them), points set aside by --ignore-outside, and points whose power cell is empty (--radii: each\n"
      "point moves to its power cell's centroid). With --periodic each moved point is wrapped back into\n"
      "the box and rounded to its grid. The result is identical for any thread count; the output is written\n"
      "atomically, once the iterations are done.\n"
      "Examples:\n"
      "  tessera lloyd points.npy -o relaxed.npy --iterations 50 --tolerance 1e-4\n"
      "  tessera lloyd points.csv --dim 2 --bounds 0 1 0 1 -o relaxed.ply\n"
      "  tessera lloyd grains.ply --labels grain --bounds 0 10 0 10 0 10 --periodic xyz -o relaxed.ply\n" +
      std::string(kExitCodes));

  ImageCommands image_cmds;  // sample-image, probe (cmd_image.cpp)
  add_image_commands(app, image_cmds);
  SphereCommands sphere_cmds;
  add_sphere_commands(app, *bench, sphere_cmds);
  require_number_syntax(app);

  // "--radii=" with nothing after '=' makes CLI11 take the next word as the
  // value, and the error then names another problem: refused as empty here.
  for (int k = 1; k < argc; ++k) {
    const std::string_view w = argv[k];
    if (w == "--") break;
    if (w.size() > 3 && w.substr(0, 2) == "--" && w.back() == '=' && w.find('=') == w.size() - 1) {
      print_error(std::string(w.substr(0, w.size() - 1)) + ": an empty value (a file name, a number or a list was "
                  "expected)");
      return kExitInputError;
    }
  }
  // sample-image chose its points with --output until stop 83 (-o was the
  // file): the old spelling, where CLI11 would report -o and --output given
  // together ("At Most 1 required"), names the option it now is.
  if (argc > 1 && std::string_view(argv[1]) == "sample-image")
    for (int k = 2; k < argc; ++k) {
      const std::string_view w = argv[k];
      if (w == "--") break;
      const std::string_view v = w == "--output" && k + 1 < argc ? std::string_view(argv[k + 1])
                                 : w.substr(0, 9) == "--output="  ? w.substr(9)
                                                                  : std::string_view();
      if (v == "all" || v == "labelled" || v == "background") {
        print_error("--output is the output file; which points to keep is --output-type " + std::string(v));
        return kExitInputError;
      }
    }
  // Files that readers open beyond those named (an image header's data file)
  // are protected from outputs, as the named inputs are.
  tessera::io::protect_files_read(true);
  // A number such as -.5 is taken by CLI11 for an option (`--bounds -.5 1
  // ...` said "At least 4 required but received 2"), where -0.5 is a
  // value: written so before parsing. No option begins with "-.".
  std::vector<std::string> words(argv, argv + argc);
  for (std::string& w : words)
    if (w.size() > 2 && w[0] == '-' && w[1] == '.' && std::isdigit(static_cast<unsigned char>(w[2])))
      w.insert(1, "0");
  std::vector<const char*> word_ptrs;
  for (const std::string& w : words) word_ptrs.push_back(w.c_str());
  try {
    app.parse(argc, word_ptrs.data());
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    print_error(std::string(e.what()) + " (run with --help for usage)");
    return kExitInputError;
  }
  if (const std::string empty = option_given_empty(app); !empty.empty()) {
    print_error(empty + ": an empty value (a file name, a number or a list was expected)");
    return kExitInputError;
  }

  try {
    // --threads (or TESSERA_NUM_THREADS) bounds every parallel loop of the
    // command, the writers' included, which run outside the library's
    // arenas (a .vtu written with --threads 1 used both cores).
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                      static_cast<std::size_t>(tessera::resolve_threads(threads_given(app))));
    if (vor->parsed()) {
      finish_compute_args(va.compute, vor_bounds, true);
      return run_voronoi(va);
    }
    if (bench_vor->parsed()) {
      finish_compute_args(ba.compute, bench_bounds);
      return run_bench_voronoi(ba);
    }
    if (graph->parsed()) {
      finish_compute_args(ga.compute, graph_bounds, true);
      return run_graph(ga);
    }
    if (faces->parsed()) {
      finish_compute_args(fa.compute, faces_bounds, true);
      return run_faces(fa);
    }
    if (flower->parsed()) {
      finish_compute_args(wa.compute, flower_bounds, true);
      return run_flower(wa);
    }
    if (del->parsed()) {
      finish_compute_args(dla.compute, del_bounds, true);
      return run_delaunay(dla);
    }
    if (snets->parsed()) {
      finish_compute_args(sna.compute, sn_bounds, true);
      return run_surface_nets(sna);
    }
    if (bench_sn->parsed()) {
      finish_compute_args(bsna.compute, bench_sn_bounds);
      return run_bench_surface_nets(bsna);
    }
    if (bench_del->parsed()) {
      finish_compute_args(bda.compute, bench_del_bounds);
      return run_bench_delaunay(bda);
    }
    if (lloyd_app->parsed()) {
      finish_compute_args(la.compute, lloyd_bounds, true);
      return run_lloyd(la);
    }
    if (demo->parsed()) return run_default(da);
    if (const int rc = run_prep_command(prep); rc >= 0) return rc;
    if (const int rc = run_image_command(image_cmds); rc >= 0) return rc;
    if (const int rc = run_sphere_command(sphere_cmds); rc >= 0) return rc;
    print_error("no command given (see tessera --help)");
    return kExitInputError;
  } catch (const tessera::InputError& e) {
    print_error(e.what());
    return kExitInputError;
  } catch (const tessera::Cancelled&) {
    print_error("interrupted; nothing was written");
    return kExitInterrupted;
  } catch (const std::bad_alloc&) {
    print_error("out of memory");
    return kExitFailure;
  } catch (const std::exception& e) {
    print_error(e.what());
    return kExitFailure;
  }
}
