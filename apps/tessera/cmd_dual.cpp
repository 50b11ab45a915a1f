// The `graph`, `faces` and `flower` subcommands: products read off the merged
// cells (see commands.hpp). Each checks its arguments and output paths before
// reading or computing anything, computes the cells with the mesh, and writes
// its files atomically.
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "commands.hpp"
#include "frame_series.hpp"
#include "stdin_input.hpp"
#include "progress.hpp"
#include "tessera/faces.hpp"
#include "tessera/flower.hpp"
#include "tessera/graph.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/dual.hpp"

namespace tessera::cli {
namespace {

void require_extension(const std::string& path, const char* ext, const std::string& option, const char* what) {
  if (extension(path) != ext)
    throw InputError(option + " " + path + ": " + what + " is written as " + ext + " (got '" + extension(path) + "')");
}

/// Reads INPUT and computes the cells with the merged mesh; bad input and an
/// empty result are InputError, as for `voronoi`.
struct Computed {
  io::PointCloud pc;
  Cells cells;
  double seconds = 0;
  std::size_t n_cells = 0;  ///< the cells of all points (also where `cells` holds some only)
};

/// `asked` (flower): only the cells of those points are built, with their
/// neighbours' (VoronoiOptions::only), each as among all cells, not all N.
/// Ids that are no point are left to the caller to refuse, after the cells
/// as when all were built (input errors first); where none is one, point
/// 0's cell stands in. `with_faces` (faces): only the cells with a face of
/// these classes (VoronoiOptions::only_with_faces), which give the face set
/// of all cells. The summary's count is still all cells' (Cells::generators
/// less the empty power cells: with only_with_faces Cells::empty_cells are
/// all of them, and flower takes no radii, so none is empty).
Computed read_and_compute(const ComputeArgs& a, bool quiet, std::span<const std::int64_t> asked = {},
                          SpokeClassSet with_faces = 0) {
  Computed r;
  r.pc = read_input(a);
  VoronoiOptions opt = make_options(a, r.pc.dim, r.pc.coords);
  opt.build_mesh = true;
  std::vector<std::int32_t> only;
  for (const std::int64_t id : asked)
    if (id >= 0 && static_cast<std::uint64_t>(id) < r.pc.n) only.push_back(static_cast<std::int32_t>(id));
  if (!asked.empty() && only.empty()) only.push_back(0);
  opt.only = only;
  opt.only_with_faces = with_faces;
  r.cells = compute(r.pc, opt, !quiet && stderr_is_terminal(), r.seconds);
  r.n_cells = r.cells.partial ? r.cells.generators - r.cells.empty_cells.size() : r.cells.n_cells();
  if (r.n_cells == 0) throw InputError(no_cells_reason(r.pc, r.cells));
  return r;
}

void print_header(const char* command, const ComputeArgs& a, const Computed& r) {
  std::printf("tessera %s: %zu points (%dD) from %s\n", command, r.pc.n, r.cells.dim, shown_input(a).c_str());
  std::printf("  %-18s %zu\n", "cells", r.n_cells);
  std::printf("  %-18s %.3f s on %d thread%s\n", "compute", r.seconds, r.cells.threads_used,
              r.cells.threads_used == 1 ? "" : "s");
  if (r.cells.power) print_power_line(r.pc, r.cells);
  if (!a.box_source.empty()) std::printf("  %-18s %s\n", "domain from", a.box_source.c_str());
  if (r.cells.is_periodic()) {
    std::string axes;
    for (int k = 0; k < r.cells.dim; ++k)
      if (r.cells.periodic[static_cast<std::size_t>(k)]) axes += "xyz"[k];
    std::printf("  %-18s %s (%zu images of points)\n", "periodic", axes.c_str(), r.cells.periodic_images);
    if (const std::string t = tilt_text(a, r.cells.tilt, r.cells.bounds, r.cells.dim); !t.empty())
      std::printf("  %-18s %s\n", "tilt (triclinic)", t.c_str());
  }
}

void print_written(const std::vector<std::string>& written) {
  std::printf("  %-18s %s\n", "wrote", written_list(written).c_str());
  std::fflush(stdout);
}

}  // namespace

// ------------------------------------------------------------------ graph

namespace {

/// `graph` on one frame (any --frame: run_frames).
int run_graph_frame(const GraphArgs& a) {
  if (a.output.empty() && a.csr.empty() && a.spoke_classes.empty() && a.spoke_measures.empty() &&
      a.spoke_shifts.empty())
    throw InputError(
        "nothing to do: give -o GRAPH.vtp, --csr FILE.npy, --spoke-classes FILE.npy, --spoke-measures FILE.npy "
        "or --spoke-shifts FILE.npy");
  if (!a.spoke_shifts.empty()) {
    require_extension(a.spoke_shifts, ".npy", "--spoke-shifts", "the spoke shifts");
    if (a.compute.periodic.empty())
      throw InputError("--spoke-shifts: only with --periodic (without it every spoke leads to the point itself)");
  }
  if (!a.output.empty()) require_extension(a.output, ".vtp", "output", "the graph (lines)");
  if (!a.csr.empty()) require_extension(a.csr, ".npy", "--csr", "the wheels");
  if (!a.spoke_classes.empty()) require_extension(a.spoke_classes, ".npy", "--spoke-classes", "the spoke classes");
  if (!a.spoke_measures.empty())
    require_extension(a.spoke_measures, ".npy", "--spoke-measures", "the spoke measures");
  if (!(a.prune_tolerance >= 0) || !std::isfinite(a.prune_tolerance))
    throw InputError("--prune-tolerance must be a finite number >= 0");
  check_bounds_arg(a.compute.bounds);
  check_distinct_outputs({{"-o", &a.output},
                          {"--csr", &a.csr},
                          {"--spoke-classes", &a.spoke_classes},
                          {"--spoke-measures", &a.spoke_measures},
                          {"--spoke-shifts", &a.spoke_shifts}});
  for (const std::string* p : {&a.output, &a.csr, &a.spoke_classes, &a.spoke_measures, &a.spoke_shifts})
    if (!p->empty()) io::check_writable(*p);

  const Computed r = read_and_compute(a.compute, a.quiet);
  GraphOptions go;
  go.prune_tolerance = a.prune_tolerance;
  const AdjacencyGraph g = adjacency_graph(r.cells, go);
  std::vector<std::string> written;
  if (!a.output.empty()) {
    io::write_graph_vtp(a.output, g, r.cells.is_periodic() ? std::span<const double>(r.cells.periodic_points)
                                                           : std::span<const double>(r.pc.coords),
                        r.pc.labels);
    written.push_back(a.output);
  }
  if (!a.csr.empty()) {
    io::write_graph_csr_npy(a.csr, g);
    written.push_back(a.csr);
  }
  if (!a.spoke_classes.empty()) {
    io::write_spoke_classes_npy(a.spoke_classes, g);
    written.push_back(a.spoke_classes);
  }
  if (!a.spoke_measures.empty()) {
    io::write_spoke_measures_npy(a.spoke_measures, g);
    written.push_back(a.spoke_measures);
  }

  if (!a.spoke_shifts.empty()) {
    io::write_spoke_shifts_npy(a.spoke_shifts, g);
    written.push_back(a.spoke_shifts);
  }

  if (!a.quiet && a.compute.brief) {
    print_frame_line("graph", a.compute, strf("%zu points, %zu cells, %zu spokes", r.pc.n, r.n_cells,
                                              g.n_spokes()),
                     r.seconds, written);
  } else if (!a.quiet) {
    std::size_t by_class[4] = {0, 0, 0, 0};
    for (SpokeClass s : g.spoke_class) ++by_class[static_cast<int>(s)];
    print_header("graph", a.compute, r);
    std::printf("  %-18s %zu (same region %zu, region boundary %zu, domain boundary %zu, outside %zu)\n", "spokes",
                g.n_spokes(), by_class[0], by_class[1], by_class[2], by_class[3]);
    std::printf("  %-18s %zu\n", "edges", graph_edges(g).size());
    if (a.prune_tolerance > 0)
      std::printf("  %-18s %zu spokes with face %s < %.6g\n", "pruned", g.pruned_spokes,
                  g.dim == 3 ? "area" : "length", g.prune_threshold);
    print_written(written);
  }
  return kExitOk;
}

}  // namespace

int run_graph(const GraphArgs& a) {
  return run_frames(a,
                    {{"-o", &GraphArgs::output},
                     {"--csr", &GraphArgs::csr},
                     {"--spoke-classes", &GraphArgs::spoke_classes},
                     {"--spoke-measures", &GraphArgs::spoke_measures},
                     {"--spoke-shifts", &GraphArgs::spoke_shifts}},
                    run_graph_frame);
}

// ------------------------------------------------------------------ faces

namespace {

/// `faces` on one frame (any --frame: run_frames).
int run_faces_frame(const FacesArgs& a) {
  const auto kind = parse_face_set_kind(a.kind);
  if (!kind) throw InputError("--kind must be boundary, complex or surface-net, got '" + a.kind + "'");
  if (a.capping && *kind != FaceSetKind::surface_net)
    throw InputError("--capping applies to --kind surface-net only");
  if (a.output.empty()) throw InputError("nothing to do: give -o FACES.vtp");
  require_extension(a.output, ".vtp", "output", "a face set");
  check_bounds_arg(a.compute.bounds);
  io::check_writable(a.output);

  FaceSetOptions fo;
  fo.kind = *kind;
  fo.capping = a.capping;
  // The cells with a face of the set only (for the complex, all of them).
  const Computed r = read_and_compute(a.compute, a.quiet, {}, face_set_classes(fo));
  const FaceSet fs = extract_faces(r.cells, r.pc.labels, fo);
  io::write_faces_vtp(a.output, fs);

  if (!a.quiet && a.compute.brief) {
    print_frame_line("faces", a.compute, strf("%zu points, %zu cells, %zu faces", r.pc.n, r.n_cells,
                                              fs.n_faces()),
                     r.seconds, {a.output});
  } else if (!a.quiet) {
    print_header("faces", a.compute, r);
    std::printf("  %-18s %s%s\n", "kind", face_set_kind_name(fs.kind), a.capping ? " (capped)" : "");
    std::printf("  %-18s %zu %s\n", "faces", fs.n_faces(), fs.dim == 3 ? "polygons" : "segments");
    std::printf("  %-18s %zu\n", "vertices", fs.n_vertices());
    if (fs.kind == FaceSetKind::surface_net && r.pc.labels.empty())
      std::printf("  %-18s no --labels: every cell is in region 0, so there are no interfaces\n", "note");
    print_written({a.output});
  }
  return kExitOk;
}

}  // namespace

int run_faces(const FacesArgs& a) {
  return run_frames(a, {{"-o", &FacesArgs::output}}, run_faces_frame);
}

// ------------------------------------------------------------------ flower

namespace {

/// `flower` on one frame (any --frame: run_frames).
int run_flower_frame(const FlowerArgs& a) {
  if (a.points.empty()) throw InputError("give at least one --point ID");
  if (a.output.empty()) throw InputError("nothing to do: give -o FLOWER.vtp");
  require_extension(a.output, ".vtp", "output", "a flower");
  for (std::int64_t id : a.points)
    if (id < 0) throw InputError("--point " + std::to_string(id) + ": point ids are >= 0");
  check_bounds_arg(a.compute.bounds);
  io::check_writable(a.output);

  // The cells asked for (and their neighbours', which place the merged
  // vertices they share), not all N: the same flowers (read_and_compute).
  const Computed r = read_and_compute(a.compute, a.quiet, a.points);
  std::vector<std::int32_t> ids;
  for (std::int64_t id : a.points) {
    if (static_cast<std::uint64_t>(id) >= r.pc.n)
      throw InputError("--point " + std::to_string(id) + ": there are " + std::to_string(r.pc.n) +
                       " points (ids 0.." + std::to_string(r.pc.n - 1) + ")");
    ids.push_back(static_cast<std::int32_t>(id));
  }
  const std::vector<Flower> fl = flowers(r.cells, r.pc.coords, ids);
  io::write_flowers_vtp(a.output, fl, r.pc.coords, a.glyphs);

  if (!a.quiet && a.compute.brief) {
    print_frame_line("flower", a.compute, strf("%zu points, %zu cells, %zu flower%s", r.pc.n, r.n_cells,
                                               fl.size(), fl.size() == 1 ? "" : "s"),
                     r.seconds, {a.output});
  } else if (!a.quiet) {
    print_header("flower", a.compute, r);
    for (const Flower& f : fl)
      std::printf("  point %-12" PRId32 " %zu petals, circumflower radius %.6g, %zu clipping neighbours\n",
                  f.generator, f.n_petals(), f.circumflower_radius, f.neighbors.size());
    print_written({a.output});
  }
  return kExitOk;
}

}  // namespace

int run_flower(const FlowerArgs& a) {
  return run_frames(a, {{"-o", &FlowerArgs::output}}, run_flower_frame);
}

}  // namespace tessera::cli
