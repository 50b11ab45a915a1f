// The tessera subcommands. main.cpp parses the command line into these structs;
// each run_* returns the process exit code and reports bad input by throwing
// tessera::InputError (main turns it into "tessera: error: ..." and exit 2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/io/points.hpp"

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
  std::vector<double> bounds;   ///< empty, 4 (2D) or 6 (3D) numbers: lo/hi per axis
  double padding = VoronoiOptions{}.padding;
  bool ignore_outside = false;
  int threads = 0;              ///< 0: TESSERA_NUM_THREADS, else all cores
  double bin_points = 0;        ///< 0: automatic
};

struct VoronoiArgs {
  ComputeArgs compute;
  std::string output;       ///< .vtu (3D) / .vtp (2D), or empty
  std::string cell_table;   ///< .csv / .npy, or empty
  std::string neighbors;    ///< .npy, or empty
  bool validate = false;
  bool quiet = false;
};

struct BenchArgs {
  ComputeArgs compute;
  int repeat = 1;
  bool mesh = false;        ///< also build the merged mesh (what VTK output needs)
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
  bool no_hull_completion = false;
  bool validate = false;
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

// Shared by the subcommand files (defined in commands.cpp).
/// Resource usage of this process so far (bench JSON lines).
struct Usage {
  double user_s, sys_s;
  long long minflt;
  long long maxrss_bytes;
};
Usage usage_now();
std::string extension(const std::string& path);  ///< lower-cased, with the dot; "" if none
void check_bounds_arg(const std::vector<double>& bounds);  ///< InputError unless 4 or 6 valid numbers
io::PointCloud read_input(const ComputeArgs& args);        ///< read and check INPUT (InputError)
VoronoiOptions make_options(const ComputeArgs& args, int dim);
/// tessera::voronoi with a progress bar (when `show_progress`) and Ctrl-C cancellation.
Cells compute(const io::PointCloud& pc, VoronoiOptions options, bool show_progress, double& seconds);

}  // namespace tessera::cli
