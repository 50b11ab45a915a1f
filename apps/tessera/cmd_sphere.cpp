// `sphere` and `bench sphere` (see commands.hpp): Voronoi cells on a sphere
// (tessera::spherical_voronoi). Outputs are checked before reading INPUT,
// written atomically, and all or none: a failure while writing one removes
// those written before it (io::OutputGroup).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "stdin_input.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/points.hpp"
#include "tessera/io/spherical.hpp"
#include "tessera/spherical_voronoi.hpp"

namespace tessera::cli {
namespace {

using Clock = std::chrono::steady_clock;

SphericalVoronoiOptions options_of(const SphereArgs& a) {
  SphericalVoronoiOptions o;
  if (!a.center.empty()) o.center = {a.center[0], a.center[1], a.center[2]};
  o.radius = a.radius;
  o.tolerance = a.tolerance;
  o.threads = a.threads;
  return o;
}

/// INPUT's points as 3D points on the sphere: x y z, or with --lonlat the
/// first two columns as longitude and latitude in degrees.
std::vector<double> read_sphere_points(const SphereArgs& a) {
  if (a.center.size() != 0 && a.center.size() != 3) throw InputError("--center takes three numbers: X Y Z");
  for (double c : a.center)
    if (!std::isfinite(c)) throw InputError("--center: the coordinates must be finite");
  if (!(a.radius >= 0) || !std::isfinite(a.radius)) throw InputError("--radius must be positive and finite");
  if (!(a.tolerance >= 0)) throw InputError("--tolerance must be >= 0 (inf: no check)");
  io::ReadOptions ro;
  ro.dim = a.lonlat ? 2 : 0;
  io::PointCloud pc = io::read_points(input_path(a.input), ro);
  if (a.lonlat) {
    const auto o = options_of(a);
    return lonlat_to_points(pc.coords, a.radius > 0 ? a.radius : 1.0, o.center);
  }
  if (pc.dim != 3)
    throw InputError(shown_path(a.input) + ": " + std::to_string(pc.dim) +
                     "D points; the sphere needs x y z (or --lonlat for longitudes and latitudes in degrees)");
  return std::move(pc.coords);
}

void check_outputs(const SphereArgs& a) {
  auto ext_is = [](const std::string& path, std::initializer_list<const char*> allowed, const char* option) {
    if (path.empty()) return;
    const std::string e = extension(path);
    for (const char* x : allowed)
      if (e == x) return;
    std::string list;
    for (const char* x : allowed) list += (list.empty() ? "" : " or ") + std::string(x);
    throw InputError(std::string(option) + " " + path + ": unknown extension '" + e + "' (expected " + list + ")");
  };
  ext_is(a.output, {".vtp"}, "-o");
  ext_is(a.triangles, {".vtp", ".npy"}, "--triangles");
  // `--cell-table -`: the CSV on standard output, the summary on standard error.
  if (a.cell_table != "-") ext_is(a.cell_table, {".csv", ".npy"}, "--cell-table");
  route_standard_output({&a.cell_table});
  ext_is(a.neighbors, {".npy"}, "--neighbors");
  check_distinct_outputs({{"-o", &a.output}, {"--triangles", &a.triangles}, {"--cell-table", &a.cell_table},
                          {"--neighbors", &a.neighbors}});
  for (const std::string* p : {&a.output, &a.triangles, &a.cell_table, &a.neighbors})
    if (!p->empty()) io::check_writable(*p);
}

}  // namespace

int run_sphere(const SphereArgs& a) {
  check_outputs(a);
  const auto t0 = Clock::now();
  const std::vector<double> pts = read_sphere_points(a);
  const auto t1 = Clock::now();
  // Ctrl-C stops the run between chunks of cells, with nothing written.
  const SphericalVoronoi sv = run_cancellable("tessera: spherical cells", !a.quiet && stderr_is_terminal(),
                                              [&](auto progress) {
                                                SphericalVoronoiOptions o = options_of(a);
                                                o.progress = progress;
                                                return spherical_voronoi(pts, o);
                                              });
  const auto t2 = Clock::now();
  std::vector<std::string> written;
  {
    io::OutputGroup group;
    if (!a.output.empty()) io::write_spherical_cells(a.output, sv), written.push_back(a.output);
    if (!a.triangles.empty()) io::write_spherical_triangles(a.triangles, sv, pts), written.push_back(a.triangles);
    if (!a.cell_table.empty()) io::write_spherical_table(a.cell_table, sv), written.push_back(a.cell_table);
    if (!a.neighbors.empty()) io::write_spherical_neighbors(a.neighbors, sv), written.push_back(a.neighbors);
    group.commit();
  }
  const auto t3 = Clock::now();
  std::optional<SphereReport> report;
  if (a.validate) report = validate_spherical_voronoi(sv, pts);
  // The validation's line: after the summary, or alone under -q when it failed.
  auto print_validation = [&] {
    if (!report) return;
    const SphereReport& r = *report;
    std::printf("  %-14s %s: %zu asymmetric neighbours, %zu vertices not in their three cells, %zu rings out of "
                "order, %zu bad statuses, V - E + F = %lld, area error %.2g, %zu of %zu sampled facets with a "
                "point above\n",
                "validation", r.ok ? "passed" : "FAILED", r.asymmetric_neighbors, r.bad_vertex_cells, r.bad_rings,
                r.bad_status, r.euler, r.area_rel_error, r.nonempty_facets, r.vertices_checked);
    for (const auto& m : r.messages) std::printf("  %-14s %s\n", "", m.c_str());
  };
  const int rc = report && !report->ok ? kExitFailure : kExitOk;
  if (a.quiet) {
    if (rc != kExitOk) print_validation();
    return rc;
  }
  auto secs = [](Clock::time_point x, Clock::time_point y) { return std::chrono::duration<double>(y - x).count(); };
  const double full = 4 * std::numbers::pi * sv.radius * sv.radius;
  std::printf("tessera sphere: %zu points from %s%s\n", sv.n_points, shown_path(a.input).c_str(),
              a.lonlat ? " (longitude, latitude)" : "");
  std::printf("  %-14s centre (%.10g, %.10g, %.10g), radius %.10g%s; points off it by at most %.3g (relative)\n",
              "sphere", sv.center[0], sv.center[1], sv.center[2], sv.radius,
              a.radius > 0 || a.lonlat ? "" : " (their mean distance)", sv.max_deviation);
  std::string missing;
  if (sv.duplicates) missing += strf("%zu duplicates (their lowest id owns the cell)", sv.duplicates);
  if (sv.hidden) missing += strf("%s%zu inside the others' hull (no cell)", missing.empty() ? "" : ", ", sv.hidden);
  std::printf("  %-14s %zu%s\n", "cells", sv.n_cells(), missing.empty() ? "" : (" (" + missing + ")").c_str());
  std::printf("  %-14s %zu (the spherical Delaunay triangles)\n", "vertices", sv.n_vertices());
  std::printf("  %-14s %.17g (4 pi R^2 = %.17g, relative difference %.2g)\n", "area sum", sv.area_sum, full,
              (sv.area_sum - full) / full);
  std::printf("  %-14s %zu\n", "exact tests", sv.exact_tests);
  std::printf("  %-14s read %.3f s, cells %.3f s, write %.3f s (%d threads)\n", "time", secs(t0, t1), secs(t1, t2),
              secs(t2, t3), resolve_threads(a.threads));
  if (!written.empty()) std::printf("  %-14s %s\n", "wrote", written_list(written).c_str());
  print_validation();
  return rc;
}

int run_bench_sphere(const SphereArgs& a) {
  if (a.repeat < 1) throw InputError("--repeat must be at least 1");
  const std::vector<double> pts = read_sphere_points(a);
  const auto opt = options_of(a);
  for (int rep = 0; rep < a.repeat; ++rep) {
    const Usage u0 = usage_now();
    const auto t0 = Clock::now();
    const SphericalVoronoi sv = spherical_voronoi(pts, opt);
    const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
    const Usage u1 = usage_now();
    const double full = 4 * std::numbers::pi * sv.radius * sv.radius;
    std::printf(
        "{\"tool\":\"tessera\",\"op\":\"sphere\",\"n\":%zu,\"threads\":%d,\"seconds\":%.6f,\"simplices\":%zu,"
        "\"extra\":{\"cpu_user_s\":%.6f,\"cpu_sys_s\":%.6f,\"peak_rss_bytes\":%lld,\"cells\":%zu,\"hidden\":%zu,"
        "\"duplicates\":%zu,\"exact_tests\":%zu,\"area_error\":%.3g,\"repeat\":%d}}\n",
        sv.n_points, resolve_threads(a.threads), secs, sv.n_vertices(), u1.user_s - u0.user_s, u1.sys_s - u0.sys_s,
        u1.maxrss_bytes, sv.n_cells(), sv.hidden, sv.duplicates, sv.exact_tests, (sv.area_sum - full) / full, rep);
    std::fflush(stdout);
  }
  return kExitOk;
}

void add_sphere_commands(CLI::App& app, CLI::App& bench, SphereCommands& c) {
  auto common = [](CLI::App* s, SphereArgs& a) {
    s->add_option("INPUT", a.input,
                  "Points on a sphere: .npy, .csv/.xyz/.txt, .ply, ... as `voronoi` reads them, - standard input (x y "
                  "z; with --lonlat the first two columns are longitude and latitude in degrees)")
        ->required();
    s->add_flag("--lonlat", a.lonlat, "INPUT holds longitudes and latitudes in degrees (GeoJSON's order)");
    s->add_option("--center", a.center, "The sphere's centre X Y Z (default 0 0 0)")->expected(3);
    s->add_option("--radius", a.radius,
                  "The sphere's radius (default: the points' mean distance from the centre; with --lonlat, 1)");
    s->add_option("--tolerance", a.tolerance,
                  "Every point must lie within this fraction of the radius from the sphere (inf: no check)")
        ->capture_default_str();
    s->add_option("--threads", a.threads,
                  "Worker threads (default 0: $TESSERA_NUM_THREADS, else all cores); results are identical for any count")
        ->check(NonNegative);
  };
  c.run_app = app.add_subcommand(
      "sphere", "Voronoi cells on a sphere (and the dual spherical Delaunay triangles): scipy's SphericalVoronoi");
  common(c.run_app, c.run);
  c.run_app->add_option("-o,--output", c.run.output,
                        "Cells as polygons on the sphere (.vtp; cell data GeneratorId, Area, Neighbors)");
  c.run_app->add_option("--triangles", c.run.triangles,
                        "The spherical Delaunay triangles (the convex hull's facets, counter-clockwise seen from "
                        "outside) over the input points: .vtp or .npy (int64 (T, 3))");
  c.run_app->add_option("--cell-table", c.run.cell_table,
                        "Per cell: id,area,cx,cy,cz,edges,neighbors (.csv or .npy; the centroid on the sphere; - the "
                        "CSV on standard output)");
  c.run_app->add_option("--neighbors", c.run.neighbors,
                        "Neighbour lists of every point as CSR in one int64 .npy: [n, offsets[0..n], ids...] "
                        "(counter-clockwise, seen from outside)");
  c.run_app->add_flag("--validate", c.run.validate,
                      "Check the result independently (symmetric neighbours, rings, V - E + F = 2, areas adding to "
                      "4 pi R^2, 256 facets against every point); exit 1 if a check fails");
  c.run_app->add_flag("-q,--quiet", c.run.quiet, "No summary (a failed validation is still reported)");
  c.run_app->footer(
      "A cell is the set of directions closer to its point than to any other (for points a rounding off the\n"
      "sphere: the convex hull's normal cone at the point, so the topology is exact whatever the rounding).\n"
      "Cocircular points (a lon/lat grid, a cube's corners) are decided by a symbolic perturbation: every\n"
      "vertex has three generators. Exact duplicates: the lowest id owns the cell. A point inside the hull of\n"
      "the others (rounded inwards next to a near-duplicate) has no cell; the summary counts both.\n"
      "Examples:\n"
      "  tessera sphere stations.csv --lonlat -o cells.vtp --cell-table cells.csv\n"
      "  tessera sphere unit_vectors.npy --triangles mesh.vtp --neighbors nb.npy");
  c.bench_app = bench.add_subcommand(
      "sphere",
      "Time tessera::spherical_voronoi (cells, vertices, areas, centroids; no output files) K times. Each run prints "
      "{\"tool\":\"tessera\",\"op\":\"sphere\",\"n\",\"threads\",\"seconds\",\"simplices\" (= triangles),\"extra\":"
      "{cpu_user_s,cpu_sys_s,peak_rss_bytes,cells,hidden,duplicates,exact_tests,area_error,repeat}}");
  common(c.bench_app, c.bench);
  c.bench_app->add_option("--repeat", c.bench.repeat, "Number of timed runs")->check(Positive)->capture_default_str();
}

int run_sphere_command(const SphereCommands& c) {
  if (c.run_app != nullptr && c.run_app->parsed()) return run_sphere(c.run);
  if (c.bench_app != nullptr && c.bench_app->parsed()) return run_bench_sphere(c.bench);
  return -1;
}

}  // namespace tessera::cli
