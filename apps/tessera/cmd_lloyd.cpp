// The `lloyd` subcommand (see commands.hpp): Lloyd relaxation of INPUT's
// points (tessera::lloyd). It checks its arguments and output path before
// reading anything, relaxes with a progress bar over all iterations and
// Ctrl-C cancellation, writes the moved points with their labels (and the
// radii, in .ply/.vtp) atomically, and prints a summary.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "commands.hpp"
#include "frame_series.hpp"
#include "progress.hpp"
#include "stdin_input.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/points.hpp"
#include "tessera/prep/lloyd.hpp"

namespace tessera::cli {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// The name the radii get in a .ply/.vtp output: --radii's own where it
/// named a field (so that `voronoi OUT --radii NAME` reads them back), else
/// "radius".
std::string radii_name(const std::string& radii) {
  if (extension(radii) == ".npy") return "radius";
  for (const char* taken : {"x", "y", "z", "label"})
    if (radii == taken) return "radius";
  return radii;
}

/// "[x0, x1] x [y0, y1]...", as the voronoi summary writes its domain.
std::string domain_text(const Bounds& b, int dim) {
  std::string s;
  for (int d = 0; d < dim; ++d) s += strf("%s[%.10g, %.10g]", d ? " x " : "", b.lo[d], b.hi[d]);
  return s;
}

/// "largest L (F of the spacing), rms R (G)": one iteration's displacements.
std::string displacement_text(const LloydResult& r, std::size_t k) {
  const double l = r.largest_displacement[k], m = r.rms_displacement[k], s = r.spacing;
  return strf("largest %.3g (%.3g of the spacing), rms %.3g (%.3g)", l, s > 0 ? l / s : 0.0, m, s > 0 ? m / s : 0.0);
}

void print_summary(const LloydArgs& a, const io::PointCloud& pc, const LloydResult& r, double read_s,
                   double compute_s, double write_s, const std::vector<std::string>& written) {
  if (a.compute.brief) {
    print_frame_line("lloyd", a.compute,
                     strf("%zu points, %d iterations%s", pc.n, r.iterations,
                          r.iterations == 0 ? "" : (", last: " + displacement_text(r, r.largest_displacement.size() - 1)).c_str()),
                     compute_s, written);
    return;
  }
  std::printf("tessera lloyd: %zu points (%dD) from %s\n", pc.n, pc.dim, shown_input(a.compute).c_str());
  if (r.iterations == 0) {
    std::printf("  %-18s 0: the points unchanged\n", "iterations");
  } else {
    const std::size_t last = r.largest_displacement.size() - 1;
    std::string done = strf("%d of %d", r.iterations, a.iterations);
    if (r.iterations < a.iterations)
      done += strf(" (stopped: the largest displacement is within --tolerance %g of the spacing)", a.tolerance);
    std::printf("  %-18s %s\n", "iterations", done.c_str());
    // (Counts change where duplicates separate, or power cells empty or fill.)
    const bool same = std::all_of(r.moved.begin(), r.moved.end(), [&](std::size_t m) { return m == r.moved[0]; });
    const std::string moved = same ? strf("%zu in every iteration", r.moved[0])
                                   : strf("%zu in the first iteration, %zu in the last", r.moved[0], r.moved[last]);
    std::printf("  %-18s %s (the points that own a cell; the others stay)\n", "moved", moved.c_str());
    std::printf("  %-18s %s\n", "first iteration", displacement_text(r, 0).c_str());
    if (last > 0) std::printf("  %-18s %s\n", "last iteration", displacement_text(r, last).c_str());
    std::printf("  %-18s %.6g ((domain volume / generators)^(1/%d))\n", "spacing", r.spacing, pc.dim);
    std::printf("  %-18s %s (every iteration's)\n", "domain", domain_text(*r.domain, pc.dim).c_str());
  }
  if (!a.compute.box_source.empty()) std::printf("  %-18s %s\n", "domain from", a.compute.box_source.c_str());
  if (!a.compute.periodic.empty()) {
    std::printf("  %-18s %s (each moved point wrapped back into the box)\n", "periodic", a.compute.periodic.c_str());
    if (!a.compute.tilt.empty()) {
      static const char* const name[3] = {"xy", "xz", "yz"};
      std::string t;
      for (std::size_t k = 0; k < a.compute.tilt.size() && k < 3; ++k)
        t += strf("%s%s %.10g", t.empty() ? "" : ", ", name[k], a.compute.tilt[k]);
      std::printf("  %-18s %s\n", "tilt (triclinic)", t.c_str());
    }
  }
  if (!pc.radii.empty()) {
    const auto [lo, hi] = std::minmax_element(pc.radii.begin(), pc.radii.end());
    std::printf("  %-18s radii %.10g to %.10g (each point moved to its power cell's centroid; radii unchanged)\n",
                "power cells", *lo, *hi);
  }
  const int threads = r.threads_used;
  if (r.iterations > 0)
    std::printf("  %-18s %.3f s on %d thread%s (%.3f s per iteration; read %.3f s, write %.3f s)\n", "compute",
                compute_s, threads, threads == 1 ? "" : "s", compute_s / r.iterations, read_s, write_s);
  std::printf("  %-18s %s\n", "wrote", written_list(written).c_str());
  std::fflush(stdout);
}

/// `lloyd` on one frame (any --frame: run_frames).
int run_lloyd_frame(const LloydArgs& a) {
  if (a.iterations < 0) throw InputError("--iterations must be >= 0, got " + std::to_string(a.iterations));
  if (!(a.tolerance >= 0) || !std::isfinite(a.tolerance)) throw InputError("--tolerance must be a finite number >= 0");
  check_bounds_arg(a.compute.bounds);
  if (a.compute.dim != 0 && !a.compute.bounds.empty() && int(a.compute.bounds.size()) != 2 * a.compute.dim)
    throw InputError(strf("--bounds has %zu numbers but --dim is %d (need %d)", a.compute.bounds.size(),
                          a.compute.dim, 2 * a.compute.dim));
  // Fail before the (possibly long) read and iterations, not after.
  check_prep_output(a.output);

  auto t0 = Clock::now();
  const io::PointCloud pc = read_input(a.compute);
  const double read_s = seconds_since(t0);

  LloydOptions o;
  o.voronoi = make_options(a.compute, pc.dim, pc.coords);
  o.voronoi.radii = pc.radii;
  o.iterations = a.iterations;
  o.tolerance = a.tolerance;
  double compute_s = 0;
  const LloydResult r =
      run_cancellable("tessera: Lloyd iterations", !a.quiet && stderr_is_terminal(), [&](auto progress) {
        o.voronoi.progress = progress;
        const auto t = Clock::now();
        LloydResult result = lloyd(pc.coords, pc.dim, pc.labels, o);
        compute_s = seconds_since(t);
        return result;
      });
  if (r.iterations > 0 && r.moved.front() == 0) {
    // No point owned a cell: say why, as voronoi does (a cells pass of the
    // same input, on this error path only).
    VoronoiOptions vo = o.voronoi;
    vo.progress = nullptr;
    vo.build_mesh = false;
    throw InputError(no_cells_reason(pc, voronoi(pc.coords, pc.dim, pc.labels, vo)));
  }

  t0 = Clock::now();
  LabelledPoints out;
  out.dim = pc.dim;
  out.coords = r.points;
  out.labels = pc.labels;
  io::WritePointsOptions wo;
  // The radii go along where the format holds them beside the points (a
  // .npy's radii are the file given, in the same order).
  if (!pc.radii.empty() && (a.output == "-" || extension(a.output) != ".npy"))
    wo.scalars.push_back({radii_name(a.compute.radii), std::span<const double>(pc.radii)});
  const std::vector<std::string> written = io::write_points(a.output, out, wo);
  const double write_s = seconds_since(t0);
  if (!a.quiet) print_summary(a, pc, r, read_s, compute_s, write_s, written);
  return kExitOk;
}

}  // namespace

int run_lloyd(const LloydArgs& a) { return run_frames(a, {{"-o", &LloydArgs::output}}, run_lloyd_frame); }

}  // namespace tessera::cli
