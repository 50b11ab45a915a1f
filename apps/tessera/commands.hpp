// The tessera subcommands. main.cpp parses the command line into these structs;
// each run_* returns the process exit code and reports bad input by throwing
// tessera::InputError (main turns it into "tessera: error: ..." and exit 2).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tessera/cells.hpp"

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

int run_voronoi(const VoronoiArgs& args);
int run_bench_voronoi(const BenchArgs& args);
int run_default(const DemoArgs& args);

}  // namespace tessera::cli
