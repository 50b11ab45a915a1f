// `tessera delaunay` and `tessera bench delaunay` (see commands.hpp).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <cstdio>
#include <string>
#include <vector>

#include "commands.hpp"
#include "frame_series.hpp"
#include "progress.hpp"
#include "tessera/alpha_shape.hpp"
#include "tessera/delaunay.hpp"
#include "tessera/io/alpha_shape.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/vtk_simplices.hpp"

namespace tessera::cli {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

DelaunayOptions delaunay_options(const ComputeArgs& c, int dim, bool complete_hull) {
  // A dump's box with walls: say where the periodic axes came from.
  if (c.periodic_from_file && !c.periodic.empty() && c.periodic.size() != static_cast<std::size_t>(dim))
    throw InputError(c.box_source + " is periodic along " + c.periodic +
                     " only, and a periodic triangulation needs every axis periodic: give --bounds (walls "
                     "everywhere) for the triangulation of the points as they lie");
  DelaunayOptions o;
  static_cast<VoronoiOptions&>(o) = make_options(c, dim, {});  // (no --hull-walls here)
  o.complete_hull = complete_hull;
  return o;
}

/// tessera::delaunay with a progress bar and Ctrl-C cancellation (as compute()).
DelaunayMethod delaunay_method(const std::string& name) {
  if (name == "cells") return DelaunayMethod::cells;
  if (name == "insertion") return DelaunayMethod::insertion;
  return DelaunayMethod::automatic;  // CLI11 admits only auto|cells|insertion
}

Delaunay triangulate(const io::PointCloud& pc, DelaunayOptions opt, bool show_progress, double& seconds) {
  opt.radii = pc.radii;
  return run_cancellable("tessera: computing the triangulation", show_progress, [&](auto progress) {
    opt.progress = progress;
    const auto t0 = Clock::now();
    Delaunay dt = delaunay(pc.coords, pc.dim, pc.labels, opt);
    seconds = seconds_since(t0);
    return dt;
  });
}

/// --alpha R (delaunay, bench delaunay): a radius >= 0 or inf, before any work.
void check_alpha(const std::optional<double>& alpha) {
  if (alpha && !(*alpha >= 0))
    throw InputError("--alpha " + strf("%g", *alpha) + ": must be a radius >= 0 (inf keeps every simplex)");
}

void check_delaunay_outputs(const DelaunayArgs& a) {
  if (a.output == "-") throw InputError("-o: the triangulation is written to a .vtu or .vtp file, not to standard output");
  if (!a.output.empty()) {
    const std::string e = extension(a.output);
    if (e != ".vtu" && e != ".vtp")
      throw InputError("output " + a.output + ": unknown extension '" + e + "' (use .vtu, or .vtp for 2D)");
  }
  if (!a.simplices.empty() && a.simplices != "-" && extension(a.simplices) != ".npy")
    throw InputError("--simplices " + a.simplices + ": must be a .npy file");
  if (!a.simplex_shifts.empty()) {
    if (a.simplex_shifts != "-" && extension(a.simplex_shifts) != ".npy")
      throw InputError("--simplex-shifts " + a.simplex_shifts + ": must be a .npy file");
    if (a.compute.periodic.empty())
      throw InputError("--simplex-shifts: only with --periodic (without it every vertex is the point itself)");
  }
  if (!a.compute.periodic.empty() && (a.no_hull_completion || a.skip_cells >= 0 || a.method != "auto"))
    throw InputError("--periodic: a periodic triangulation has no hull (--no-hull-completion, --skip-cells and "
                     "--method do not apply)");
  if (!a.boundary.empty() && a.boundary != "-") {
    const std::string e = extension(a.boundary);
    if (e != ".vtp" && e != ".npy" && e != ".geojson")
      throw InputError("--boundary " + a.boundary + ": unknown extension '" + e + "' (use .vtp, .npy or, in 2D, .geojson)");
  }
  check_alpha(a.alpha);
  if (a.regularized && (a.boundary.empty() || !a.alpha))
    throw InputError("--regularized: only with --alpha and --boundary (it leaves the alpha complex's singular facets "
                     "out of the boundary)");
  if (!a.compute.periodic.empty() && !a.boundary.empty())
    throw InputError("--boundary: not written with --periodic (its facets meet images; --alpha's summary gives the "
                     "boundary's area, and -o / --simplices / --simplex-shifts the kept simplices)");
  if (a.method == "insertion" && a.no_hull_completion)
    throw InputError("--method insertion triangulates the whole convex hull: it cannot be combined with "
                     "--no-hull-completion");
  if (a.output.empty() && a.simplices.empty() && a.simplex_shifts.empty() && a.boundary.empty() && !a.validate)
    throw InputError("nothing to do: give -o OUTPUT.vtu|.vtp, --simplices FILE.npy, --boundary FILE or --validate");
  for (const std::string* p : {&a.output, &a.simplices, &a.simplex_shifts, &a.boundary})
    if (!p->empty()) io::check_writable(*p);
  check_distinct_outputs({{"-o", &a.output},
                          {"--simplices", &a.simplices},
                          {"--simplex-shifts", &a.simplex_shifts},
                          {"--boundary", &a.boundary}});
  route_standard_output({&a.simplices, &a.simplex_shifts, &a.boundary});
}

/// The triangulation of the rows kept (what -o and --simplices write with --alpha).
Delaunay simplices_kept(const Delaunay& dt, const std::vector<std::int32_t>& rows) {
  Delaunay k;
  k.dim = dt.dim;
  k.n_points = dt.n_points;
  k.bounds = dt.bounds;
  k.power = dt.power;
  k.periodic = dt.periodic;
  k.tilt = dt.tilt;
  k.periodic_points = dt.periodic_points;
  const std::size_t w = static_cast<std::size_t>(dt.dim + 1), ws = dt.is_periodic() ? w * static_cast<std::size_t>(dt.dim) : 0;
  k.simplices.resize(rows.size() * w);
  k.simplex_shifts.resize(rows.size() * ws);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::copy_n(dt.simplices.data() + static_cast<std::size_t>(rows[i]) * w, w, k.simplices.data() + i * w);
    std::copy_n(dt.simplex_shifts.data() + static_cast<std::size_t>(rows[i]) * ws, ws, k.simplex_shifts.data() + i * ws);
  }
  return k;
}

void print_alpha_line(const AlphaShape& s, bool filtered, std::size_t all) {
  const bool d3 = s.dim == 3;
  const std::string kept =
      filtered ? strf("alpha %.17g: %zu of %zu %s kept", s.alpha, s.n_simplices(), all, d3 ? "tetrahedra" : "triangles")
               : strf("%zu %s", s.n_simplices(), d3 ? "tetrahedra" : "triangles");
  std::fprintf(stderr,
               "tessera: %s, %s %.17g; boundary %zu %s, %s %.17g; %zu piece%s, %zu non-manifold %s%s%s\n",
               kept.c_str(), d3 ? "volume" : "area", s.volume, s.n_boundary(), d3 ? "triangles" : "segments",
               d3 ? "area" : "length", s.boundary_measure, s.components, s.components == 1 ? "" : "s",
               s.nonmanifold_ridges, d3 ? (s.nonmanifold_ridges == 1 ? "edge" : "edges")
                                        : (s.nonmanifold_ridges == 1 ? "vertex" : "vertices"),
               filtered ? strf("; %zu singular %s", s.n_singular(), d3 ? "triangles" : "segments").c_str() : "",
               s.exact_tests == 0 ? "" : strf("; %zu tests exact", s.exact_tests).c_str());
}

}  // namespace

namespace {

/// `delaunay` on one frame (any --frame: run_frames).
int run_delaunay_frame(const DelaunayArgs& a) {
  check_delaunay_outputs(a);
  check_bounds_arg(a.compute.bounds);
  auto t0 = Clock::now();
  const io::PointCloud pc = read_input(a.compute);
  const double read_s = seconds_since(t0);
  if (!a.output.empty() && pc.dim == 3 && extension(a.output) != ".vtu")
    throw InputError("output " + a.output + ": a 3D triangulation is written as .vtu");
  if (!a.boundary.empty() && pc.dim == 3 && a.boundary != "-" && extension(a.boundary) == ".geojson")
    throw InputError("--boundary " + a.boundary + ": GeoJSON polygons are for a 2D shape (use .vtp or .npy in 3D)");

  double compute_s = 0;
  DelaunayOptions opt = delaunay_options(a.compute, pc.dim, !a.no_hull_completion);
  opt.skip_cells = a.skip_cells;
  opt.method = delaunay_method(a.method);
  const Delaunay dt = triangulate(pc, opt,
                                  !a.quiet && stderr_is_terminal(), compute_s);

  // A regular triangulation's radii (equal radii gave an ordinary one).
  const std::span<const double> radii = dt.power ? std::span<const double>(pc.radii) : std::span<const double>();
  // The alpha shape, where asked for (alpha_s: its time), and the
  // triangulation of its simplices that -o and --simplices write.
  std::optional<AlphaShape> shape;
  std::optional<Delaunay> kept;
  double alpha_s = 0;
  if (a.alpha || !a.boundary.empty()) {
    t0 = Clock::now();
    shape = alpha_shape(dt, pc.coords, a.alpha.value_or(std::numeric_limits<double>::infinity()), radii);
    if (a.alpha) kept = simplices_kept(dt, shape->simplex_rows);
    alpha_s = seconds_since(t0);
  }
  const Delaunay& out = kept ? *kept : dt;

  t0 = Clock::now();
  std::vector<std::string> written;
  if (!a.output.empty()) {
    io::write_simplices_vtk(a.output, out, pc.coords, radii);
    written.push_back(a.output);
  }
  if (!a.simplices.empty()) {
    // int64 (M, D+1), as scipy.spatial.Delaunay.simplices.
    std::vector<std::int64_t> s(out.simplices.begin(), out.simplices.end());
    io::write_file_atomic(a.simplices, io::npy_bytes(s.data(), {out.n_simplices(), std::size_t(pc.dim + 1)}));
    written.push_back(shown_output(a.simplices));
  }
  if (!a.boundary.empty()) {
    // SimplexId: the row of what --simplices writes (the kept ones' order with --alpha).
    io::write_alpha_boundary(a.boundary, dt, *shape, pc.coords, !a.regularized, a.alpha.has_value());
    written.push_back(shown_output(a.boundary));
  }
  if (!a.simplex_shifts.empty()) {
    const auto d = static_cast<std::size_t>(pc.dim);
    io::write_file_atomic(a.simplex_shifts, io::npy_bytes(out.simplex_shifts.data(), {out.n_simplices(), d + 1, d}));
    written.push_back(shown_output(a.simplex_shifts));
  }
  const double write_s = seconds_since(t0);

  if (!a.quiet && a.compute.brief) {
    print_frame_line("delaunay", a.compute,
                     strf("%zu points, %zu %s", pc.n, dt.n_simplices(), pc.dim == 3 ? "tetrahedra" : "triangles"),
                     compute_s, written, stderr);
  } else if (!a.quiet) {
    // With labels, where the whole triangulation was built, the counts by
    // method are of it (Delaunay::outside_simplices).
    const std::string outside =
        dt.outside_simplices == 0 ? std::string()
                                  : "; " + std::to_string(dt.outside_simplices) + " with an outside vertex left out";
    if (!a.compute.frame.empty()) std::fprintf(stderr, "tessera: points from %s\n", shown_input(a.compute).c_str());
    if (!a.compute.box_source.empty()) std::fprintf(stderr, "tessera: domain from %s\n", a.compute.box_source.c_str());
    if (dt.is_periodic()) {
      std::fprintf(stderr, "tessera: %zu points (%dD) -> %zu %s of the periodic box%s (each once, with its images)\n",
                   pc.n, pc.dim, dt.n_simplices(), pc.dim == 3 ? "tetrahedra" : "triangles",
                   dt.tilt[0] != 0 || dt.tilt[1] != 0 || dt.tilt[2] != 0 ? " (triclinic)" : "");
      if (const std::string t = tilt_text(a.compute, dt.tilt, dt.bounds, dt.dim); !t.empty())
        std::fprintf(stderr, "tessera: tilts %s\n", t.c_str());
    } else if (dt.from_insertion > 0) {
      std::fprintf(stderr, "tessera: %zu points (%dD) -> %zu %s (by incremental insertion%s)\n", pc.n, pc.dim,
                   dt.n_simplices(), pc.dim == 3 ? "tetrahedra" : "triangles", outside.c_str());
    } else {
      std::fprintf(stderr, "tessera: %zu points (%dD) -> %zu %s (%zu from the cells, %zu by hull completion%s%s)\n",
                   pc.n, pc.dim, dt.n_simplices(), pc.dim == 3 ? "tetrahedra" : "triangles", dt.from_cells,
                   dt.from_hull_completion, a.no_hull_completion ? ": off" : "", outside.c_str());
    }
    if (dt.n_simplices() == 0) {
      // Only with hull completion and no labels does an empty result mean
      // flat input; otherwise say what else leaves none.
      const char* flat =
          pc.dim == 3 ? "coplanar or collinear (for a 2D triangulation use --dim 2 on in-plane coordinates)"
                      : "collinear";
      if (a.no_hull_completion)
        std::fprintf(stderr,
                     "tessera: no simplices: none has its circumcentre in the domain box (hull completion is off), "
                     "or the points are %s\n",
                     flat);
      else if (dt.outside_simplices > 0)
        std::fprintf(stderr, "tessera: no simplices: each of the triangulation's %zu has an outside vertex (label < 0)\n",
                     dt.outside_simplices);
      else if (dt.power && !dt.hidden.empty())
        std::fprintf(stderr, "tessera: no simplices: %zu points are hidden, and the rest are %s\n", dt.hidden.size(),
                     pc.dim == 3 ? "at most three or coplanar" : "at most two or collinear");
      else if (!pc.labels.empty())
        std::fprintf(stderr, "tessera: no simplices: none has all its vertices inside (label >= 0), or the points are %s\n",
                     flat);
      else
        std::fprintf(stderr, "tessera: no simplices: the points are %s\n", flat);
    }
    if (!dt.duplicates.empty())
      std::fprintf(stderr, "tessera: %zu duplicate points are not vertices (first: %d = %d)\n", dt.duplicates.size(),
                   dt.duplicates.front().first, dt.duplicates.front().second);
    if (dt.power) print_regular_line(pc, dt);
    if (!dt.ignored_outside_bounds.empty())
      std::fprintf(stderr, "tessera: %zu points outside --bounds (or not finite) ignored\n",
                   dt.ignored_outside_bounds.size());
    if (shape) print_alpha_line(*shape, a.alpha.has_value(), dt.n_simplices());
    std::fprintf(stderr, "tessera: read %.3f s, triangulate %.3f s (%d thread%s), %swrite %.3f s\n", read_s,
                 compute_s, dt.threads_used, dt.threads_used == 1 ? "" : "s",
                 shape ? strf("alpha shape %.3f s, ", alpha_s).c_str() : "", write_s);
    for (const auto& w : written) std::fprintf(stderr, "tessera: wrote %s\n", w.c_str());
  }
  if (a.validate) {
    const DelaunayReport r = validate(dt, pc.coords, pc.labels, radii);
    if ((!a.quiet && !a.compute.brief) || !r.ok) {  // a series' later frames: failures only, as -q
      const std::string hidden =
          dt.power ? ", " + std::to_string(dt.hidden.size()) + " hidden points (" + std::to_string(r.hidden_in_conflict) +
                         " in conflict)"
                   : std::string();
      std::fprintf(stderr,
                   "tessera: validation %s: %zu simplices, %zu flat/inverted, %zu non-manifold facets, %zu boundary "
                   "facets, %zu open ridges, %zu non-convex ridges, %zu missing points%s, %zu non-%s facets, "
                   "volume %.17g (%s %.17g; they agree within %.3g)\n",
                   r.ok ? "passed" : "FAILED", r.simplices, r.flat_or_inverted, r.nonmanifold_facets,
                   r.boundary_facets, r.open_boundary_ridges, r.nonconvex_boundary, r.missing_points, hidden.c_str(),
                   r.local_delaunay_violations, dt.power ? "regular" : "Delaunay", r.volume_sum,
                   dt.is_periodic() ? "the periodic box holds" : "boundary encloses", r.enclosed_volume,
                   r.volume_tolerance);
      for (const auto& m : r.messages) std::fprintf(stderr, "tessera: validation: %s\n", m.c_str());
    }
    if (!r.ok) {
      std::fprintf(stderr, "tessera: error: validation failed: %s\n", r.messages.front().c_str());
      return kExitFailure;
    }
  }
  return kExitOk;
}

}  // namespace

int run_delaunay(const DelaunayArgs& a) {
  return run_frames(a,
                    {{"-o", &DelaunayArgs::output},
                     {"--simplices", &DelaunayArgs::simplices},
                     {"--simplex-shifts", &DelaunayArgs::simplex_shifts},
                     {"--boundary", &DelaunayArgs::boundary}},
                    run_delaunay_frame);
}

int run_bench_delaunay(const BenchArgs& a) {
  check_bounds_arg(a.compute.bounds);
  if (a.repeat < 1) throw InputError("--repeat must be at least 1");
  if (!a.compute.periodic.empty() && (a.skip_cells >= 0 || a.method != "auto"))
    throw InputError("--periodic: a periodic triangulation has no hull (--skip-cells and --method do not apply)");
  const io::PointCloud pc = read_input(a.compute);
  DelaunayOptions opt = delaunay_options(a.compute, pc.dim, true);
  opt.skip_cells = a.skip_cells;
  opt.method = delaunay_method(a.method);
  opt.radii = pc.radii;
  check_alpha(a.alpha);
  const std::span<const double> radii(pc.radii);
  for (int rep = 0; rep < a.repeat; ++rep) {
    // Timed region: the library calls only (no I/O), as the peers do.
    const Usage u0 = usage_now();
    const auto t0 = Clock::now();
    const Delaunay dt = delaunay(pc.coords, pc.dim, pc.labels, opt);
    const double tri_s = seconds_since(t0);
    std::optional<AlphaShape> shape;
    if (a.alpha) shape = alpha_shape(dt, pc.coords, *a.alpha, dt.power ? radii : std::span<const double>());
    const double secs = seconds_since(t0);
    const Usage u1 = usage_now();
    const std::string alpha_extra =
        shape ? strf("\"triangulate_s\":%.6f,\"alpha_s\":%.6f,\"alpha\":%.17g,\"boundary\":%zu,\"singular\":%zu,"
                     "\"components\":%zu,\"exact_tests\":%zu,\"triangulation_simplices\":%zu,",
                     tri_s, secs - tri_s, shape->alpha, shape->n_boundary(), shape->n_singular(), shape->components,
                     shape->exact_tests, dt.n_simplices())
              : std::string();
    std::printf(
        "{\"tool\":\"tessera\",\"op\":\"%s%d\",\"n\":%zu,\"threads\":%d,\"seconds\":%.6f,\"simplices\":%zu,"
        "\"extra\":{%s\"cpu_user_s\":%.6f,\"cpu_sys_s\":%.6f,\"minflt\":%lld,\"peak_rss_bytes\":%lld,"
        "\"from_cells\":%zu,\"from_hull_completion\":%zu,\"from_insertion\":%zu,\"skipped_cells\":%zu,\"hidden\":%zu,\"exact_calls\":%llu,\"repeat\":%d}}\n",
        shape ? "alpha" : "delaunay", pc.dim, pc.n, dt.threads_used, secs,
        shape ? shape->n_simplices() : dt.n_simplices(), alpha_extra.c_str(), u1.user_s - u0.user_s,
        u1.sys_s - u0.sys_s, u1.minflt - u0.minflt, u1.maxrss_bytes, dt.from_cells, dt.from_hull_completion,
        dt.from_insertion, dt.skipped_cells, dt.hidden.size(), static_cast<unsigned long long>(dt.exact_predicate_calls),
        rep);
    std::fflush(stdout);
  }
  return kExitOk;
}

}  // namespace tessera::cli
