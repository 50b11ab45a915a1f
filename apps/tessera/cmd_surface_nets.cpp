// The `surface-nets` subcommand and `bench surface-nets` (see commands.hpp):
// labelled points, or a label image sampled first, -> tessera::surface_nets
// -> a .vtp of polygons or triangles with BoundaryLabels. Arguments and the
// output path are checked before anything is read; the file is written
// atomically.
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "frame_series.hpp"
#include "stdin_input.hpp"
#include "option_checks.hpp"
#include "progress.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/dual.hpp"
#include "tessera/surface_nets.hpp"

namespace tessera::cli {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

// ------------------------------------------------------------------ input

/// The points to tessellate: read from a point file, or sampled from an image.
struct NetInput {
  int dim = 3;
  std::vector<double> coords;
  std::vector<std::int32_t> labels;
  bool from_image = false;
  ImageGeometry geometry;  ///< the image's, when from_image
  LabelImage image;        ///< kept for the benchmark (re-sampled each run)
  double read_s = 0, sample_s = 0;
  std::size_t size() const { return coords.size() / static_cast<std::size_t>(dim); }
};

bool is_image_input(const SurfaceNetsArgs& a) {
  if (is_image_path(a.compute.input)) return true;
  if (!a.image) return false;
  // (.npy and .vtk hold points or an image: --image says which.)
  if (extension(a.compute.input) != ".npy" && extension(a.compute.input) != ".vtk")
    throw InputError("--image: INPUT must be a label image (.npy, .nrrd, .nhdr, .mha, .mhd, .vti, .vtk, .nii, .nii.gz or .hdr), got '" +
                     extension(a.compute.input) + "'");
  return true;
}

SamplerArgs sampler_of(const SurfaceNetsArgs& a) {
  SamplerArgs s = a.sampler;
  s.select = a.select;
  s.threads = a.compute.threads;
  return s;
}

/// Checks that need no file: options, output path (when `output`).
void check_args(const SurfaceNetsArgs& a, bool output) {
  if (output) {
    if (a.output.empty()) throw InputError("nothing to do: give -o OUT.vtp");
    if (extension(a.output) != ".vtp")
      throw InputError("output " + a.output + ": a surface net is written as .vtp (got '" + extension(a.output) + "')");
  }
  check_bounds_arg(a.compute.bounds);
  if (a.background_label >= 0)
    throw InputError("--background-label must be negative (labels >= 0 are regions), got " +
                     std::to_string(a.background_label));
  if (a.smooth < 0) throw InputError("--smooth must be >= 0 (0 = no smoothing), got " + std::to_string(a.smooth));
  if (!(a.relax > 0 && a.relax <= 1)) throw InputError("--relax must be in (0, 1], got " + num(a.relax));
  if (!(a.constraint >= 0) || !std::isfinite(a.constraint))
    throw InputError("--constraint must be a finite number >= 0, got " + num(a.constraint));
  if (is_image_input(a)) {
    if (!a.compute.labels.empty()) throw InputError("--labels applies to point input; an image carries its labels");
    if (a.compute.dim != 0) throw InputError("--dim applies to point input; an image has its own dimension");
  } else {
    const SamplerArgs defaults;
    const SamplerArgs& s = a.sampler;
    if (!s.read.spacing.empty() || !s.read.origin.empty() || !s.read.array.empty() || s.schedule != defaults.schedule ||
        s.step != defaults.step || s.no_randomize || !s.probability.empty() || s.seed != defaults.seed ||
        s.joggle != defaults.joggle)
      throw InputError("the sampler options (--spacing, --origin, --array, --schedule, --step, --no-randomize, "
                       "--probability, --seed, --joggle) apply to an image INPUT (.nrrd/.nhdr/.mha/.mhd/.vti/.nii/.nii.gz, or .npy "
                       "with --image)");
  }
}

NetInput read_net_input(const SurfaceNetsArgs& a) {
  NetInput in;
  auto t0 = Clock::now();
  if (is_image_input(a)) {
    in.from_image = true;
    const SamplerArgs s = sampler_of(a);
    in.image = read_label_image_file(a.compute.input, s);
    in.geometry = in.image.geometry;
    in.read_s = seconds_since(t0);
    t0 = Clock::now();
    LabelledPoints p = sample_label_image(a.compute.input, in.image, s);
    in.sample_s = seconds_since(t0);
    in.dim = p.dim;
    in.coords = std::move(p.coords);
    in.labels = std::move(p.labels);
    if (!a.compute.bounds.empty() && static_cast<int>(a.compute.bounds.size()) != 2 * in.dim)
      throw InputError("--bounds needs " + std::to_string(2 * in.dim) + " numbers for this " +
                       std::to_string(in.dim) + "D image");
    if (in.size() == 0) throw InputError(a.compute.input + ": the sampler kept no points");
  } else {
    io::PointCloud pc;
    try {
      pc = read_input(a.compute);
    } catch (const InputError& e) {
      if (extension(a.compute.input) != ".npy") throw;
      throw InputError(std::string(e.what()) + " (a label image? add --image)");
    }
    in.read_s = seconds_since(t0);
    in.dim = pc.dim;
    in.coords = std::move(pc.coords);
    in.labels = std::move(pc.labels);
    if (in.labels.empty())
      throw InputError("surface nets need region labels: give --labels FILE.npy or the name of a .ply/.csv/.vtp/.vtu/.vtk/.pcd/structured .npy label column");
  }
  return in;
}

SurfaceNetsOptions net_options(const SurfaceNetsArgs& a, const NetInput& in) {
  SurfaceNetsOptions o;
  ComputeArgs compute = a.compute;
  if (in.from_image && a.compute.bounds.empty()) {
    // The domain is the image's voxels: half a spacing beyond the outer
    // voxel centres, so surfaces reaching the image border lie on the box,
    // and with --periodic the image tiles space (a periodic microstructure).
    for (int d = 0; d < in.dim; ++d) {
      const double h = in.geometry.spacing[d], o0 = in.geometry.origin[d];
      compute.bounds.push_back(o0 - 0.5 * h);
      compute.bounds.push_back(o0 + (static_cast<double>(in.geometry.size[d]) - 0.5) * h);
    }
  }
  o.voronoi = make_options(compute, in.dim, in.coords);
  o.select = a.select;
  o.background_label = a.background_label;
  o.capping = a.capping;
  o.smoothing.iterations = a.smooth;
  o.smoothing.relaxation = a.relax;
  o.smoothing.constraint = a.constraint;
  o.smoothing.constraint_is_absolute = a.absolute_constraint;
  o.triangles = a.triangles;
  return o;
}

// ------------------------------------------------------------------ checks

/// Watertightness of every selected label's surface (its faces, reversed
/// where the label is on side 1). 3D: an edge used once is a boundary edge;
/// used twice in the same direction, or more than twice, non-manifold. 2D:
/// a vertex without exactly one arriving and one leaving segment. In a
/// periodic box an edge's ends are copies of vertices (vertex_copies): the
/// edge is the pair of copies' groups and the translation between them.
struct Watertight {
  std::size_t boundary_edges = 0, nonmanifold_edges = 0;
  std::vector<std::int32_t> open_labels;  ///< ascending
  bool closed() const { return open_labels.empty(); }
};

/// `one_region`: every point has one label in a box periodic along every
/// axis, so its region has no boundary and no face (closed, though empty).
Watertight check_watertight(const SurfaceNet& net, const VertexCopies& copies, bool one_region) {
  const FaceSet& m = net.mesh;
  const auto& sel = net.selected;
  auto selected = [&](std::int32_t l) { return std::binary_search(sel.begin(), sel.end(), l); };
  const auto du = static_cast<std::size_t>(m.dim);
  // (label, a, b, translation from a to b, direction), a <= b (by group, then
  // translation); 2D: (label, vertex, 0, 0, +1 leaving / -1 arriving).
  using Shift = std::array<std::int32_t, 3>;
  std::vector<std::tuple<std::int32_t, std::int32_t, std::int32_t, Shift, std::int8_t>> e;
  auto group = [&](std::int32_t v) { return copies.group[static_cast<std::size_t>(v)]; };
  auto shift_of = [&](std::int32_t v) {
    Shift s{0, 0, 0};
    if (copies.periodic())
      for (std::size_t a = 0; a < du; ++a) s[a] = copies.shift[static_cast<std::size_t>(v) * du + a];
    return s;
  };
  for (std::size_t f = 0; f < m.n_faces(); ++f) {
    const auto b = static_cast<std::size_t>(m.face_offsets[f]), n = static_cast<std::size_t>(m.face_offsets[f + 1]) - b;
    for (int side = 0; side < 2; ++side) {
      const std::int32_t l = m.boundary_labels[2 * f + side];
      if (side == 1 && !selected(l)) continue;
      const std::int8_t dir = side == 0 ? 1 : -1;
      if (m.dim == 2) {
        e.emplace_back(l, group(m.face_vertices[b]), 0, Shift{}, dir);
        e.emplace_back(l, group(m.face_vertices[b + 1]), 0, Shift{}, static_cast<std::int8_t>(-dir));
        continue;
      }
      for (std::size_t q = 0; q < n; ++q) {
        const std::int32_t u = m.face_vertices[b + q], w = m.face_vertices[b + (q + 1) % n];
        const Shift su = shift_of(u), sw = shift_of(w);
        Shift d{sw[0] - su[0], sw[1] - su[1], sw[2] - su[2]};
        const std::int32_t gu = group(u), gw = group(w);
        const Shift minus{-d[0], -d[1], -d[2]};
        if (std::tie(gu, d) <= std::tie(gw, minus))
          e.emplace_back(l, gu, gw, d, dir);
        else
          e.emplace_back(l, gw, gu, minus, static_cast<std::int8_t>(-dir));
      }
    }
  }
  tbb::parallel_sort(e.begin(), e.end());
  Watertight w;
  auto same_edge = [](const auto& x, const auto& y) {
    return std::get<0>(x) == std::get<0>(y) && std::get<1>(x) == std::get<1>(y) && std::get<2>(x) == std::get<2>(y) &&
           std::get<3>(x) == std::get<3>(y);
  };
  for (std::size_t i = 0; i < e.size();) {
    std::size_t j = i;
    int sum = 0;
    while (j < e.size() && same_edge(e[j], e[i])) sum += std::get<4>(e[j++]);
    const std::size_t count = j - i;
    if (count != 2 || sum != 0) {
      ++(count == 1 ? w.boundary_edges : w.nonmanifold_edges);
      const std::int32_t l = std::get<0>(e[i]);
      if (w.open_labels.empty() || w.open_labels.back() != l) w.open_labels.push_back(l);
    }
    i = j;
  }
  // A selected label on no face at all: its whole surface was left out (its
  // neighbours are all unselected, or the box, without --capping), which is
  // open, not closed (an empty net was reported watertight).
  if (!one_region) {
    std::vector<std::int32_t> faced;
    for (const auto& x : e) faced.push_back(std::get<0>(x));
    faced.erase(std::unique(faced.begin(), faced.end()), faced.end());  // (e is sorted by label first)
    for (const std::int32_t l : sel)
      if (!std::binary_search(faced.begin(), faced.end(), l)) w.open_labels.push_back(l);
    std::sort(w.open_labels.begin(), w.open_labels.end());
  }
  return w;
}

/// Whether the points are one region filling a box periodic on every axis.
bool one_region(const FaceSet& m, std::span<const std::int32_t> labels) {
  for (int a = 0; a < m.dim; ++a)
    if (!m.periodic[static_cast<std::size_t>(a)]) return false;
  return std::adjacent_find(labels.begin(), labels.end(), std::not_equal_to<>()) == labels.end();
}

// ------------------------------------------------------------------ output

std::string label_list(const std::vector<std::int32_t>& l, std::size_t max = 12) {
  std::string s;
  for (std::size_t i = 0; i < l.size() && i < max; ++i) s += (i ? "," : "") + std::to_string(l[i]);
  if (l.size() > max) s += ",... (" + std::to_string(l.size()) + ")";
  return s;
}

std::size_t triangle_count(const SurfaceNet& net) {
  const FaceSet& m = net.mesh;
  if (m.dim != 3) return 0;
  return static_cast<std::size_t>(m.face_offsets.empty() ? 0 : m.face_offsets.back()) - 2 * m.n_faces();
}

std::size_t polygon_count(const SurfaceNet& net) {
  if (net.polygon_of_face.empty()) return 0;
  return static_cast<std::size_t>(net.polygon_of_face.back()) + 1;  // polygons are listed in order
}

/// surface_nets with a progress bar (when wanted) and Ctrl-C cancellation.
SurfaceNet run_pipeline(const NetInput& in, SurfaceNetsOptions o, bool show_progress) {
  return run_cancellable("tessera: surface nets", show_progress, [&](auto progress) {
    o.voronoi.progress = progress;
    return surface_nets(in.coords, in.labels, o);
  });
}

}  // namespace

// ------------------------------------------------------------------ options

void add_surface_nets_options(CLI::App* app, SurfaceNetsArgs& a, bool bench) {
  if (!bench) {
    app->add_option("-o,--output", a.output,
                    "Surface net as VTK PolyData (.vtp): polygons (or triangles; 2D: segments), cell data "
                    "BoundaryLabels (2 x int32: the two labels), Sides, SpokeClass, PolygonId; point data "
                    "VertexKind (0 surface, 1 junction, 2 corner)");
    app->add_flag("-q,--quiet", a.quiet, "No summary and no progress bar");
  } else {
    app->add_option("--repeat", a.repeat, "Number of timed runs")->check(Positive)->capture_default_str();
  }
  app->add_option("--select", a.select,
                  "Labels L1,L2,... to wrap (default: every label >= 0); points of other labels act as outside "
                  "points. A label no point (voxel) has is an error")
      ->delimiter(',');
  app->add_flag("--capping", a.capping,
                "Also the faces against the domain box and against unselected / outside points, so every "
                "selected region is closed");
  app->add_option("--smooth", a.smooth, "Smoothing iterations (0: none, the raw Voronoi faces)")->capture_default_str();
  app->add_option("--relax", a.relax, "Relaxation factor of each smoothing step, in (0, 1]")->capture_default_str();
  app->add_option("--constraint", a.constraint,
                  "No vertex moves farther than F x its local spacing (its distance to its generators) from "
                  "where it started; with --absolute-constraint, F in model units")
      ->capture_default_str();
  app->add_flag("--absolute-constraint", a.absolute_constraint, "--constraint is a distance, not a fraction");
  app->add_flag("--triangles", a.triangles, "3D: split each polygon into triangles (both labels copied)");
  app->add_flag("--image", a.image, "INPUT .npy is a label image (integer array (ny, nx) / (nz, ny, nx)), not points");
  // The sampler's options, for an image INPUT; its --background-label (the
  // label of unselected voxels) would clash with ours (the box's label).
  add_sampler_options(app, a.sampler);
  if (CLI::Option* clash = app->get_option_no_throw("--background-label")) app->remove_option(clash);
  app->add_option("--background-label", a.background_label,
                  "BoundaryLabels value for the domain-box side of capping faces (must be < 0)")
      ->capture_default_str();
  app->footer(
      "INPUT: labelled points (any point file of voronoi's, with --labels) or a label image (.nrrd/.nhdr/.mha/.mhd/\n"
      ".vti/.nii/.nii.gz/.hdr, or .npy or legacy .vtk with --image), which is sampled first (the sampler options: see tessera sample-image --help; the\n"
      "domain is then the image's voxels). BoundaryLabels = (side 0, side 1): side 0 is always a selected\n"
      "label; between two selected labels (lower, higher); a capping face carries the other point's own label\n"
      "or --background-label for the box. Faces point from side 0 into side 1, so each label's surface (its\n"
      "faces, reversed where it is side 1) is closed and outward. Smoothing: surface vertices move freely,\n"
      "junction vertices (three regions) along their curve, corners (four) stay.\n"
      "Examples:\n"
      "  tessera surface-nets seg.nrrd -o seg.vtp --select 1,2,3 --capping --triangles\n"
      "  tessera surface-nets labels.npy --image --spacing 0.5,0.5,1 -o out.vtp\n"
      "  tessera surface-nets cells.ply --labels region -o net.vtp --smooth 0");
}

// ------------------------------------------------------------------ run

namespace {

/// `surface-nets` on one frame (any --frame: run_frames).
int run_surface_nets_frame(const SurfaceNetsArgs& a) {
  check_args(a, true);
  io::check_writable(a.output);
  const NetInput in = read_net_input(a);
  const SurfaceNet net = run_pipeline(in, net_options(a, in), !a.quiet && stderr_is_terminal());
  if (a.quiet) {
    io::write_surface_net_vtp(a.output, net);
    return kExitOk;
  }
  // The summary's checks (watertightness: the vertex copies, every edge)
  // run before the file is written: a failure there (memory, on a net of
  // hundreds of MB) left a whole file behind an exit status of 1.
  const FaceSet& m = net.mesh;
  std::size_t kinds[3] = {0, 0, 0};
  for (NetVertexKind k : net.vertex_kind) ++kinds[static_cast<int>(k)];
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  for (std::size_t f = 0; f < m.n_faces(); ++f) pairs.emplace_back(m.boundary_labels[2 * f], m.boundary_labels[2 * f + 1]);
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  const VertexCopies copies = vertex_copies(m);
  const Watertight w = check_watertight(net, copies, one_region(m, in.labels));
  auto t0 = Clock::now();
  io::write_surface_net_vtp(a.output, net);
  const double write_s = seconds_since(t0);
  if (a.compute.brief) {
    const std::string closed =
        w.open_labels.empty() ? "watertight" : "open: label" + std::string(w.open_labels.size() == 1 ? " " : "s ") +
                                                   label_list(w.open_labels);
    print_frame_line("surface-nets", a.compute,
                     strf("%zu points, %zu %s, %s", in.size(), m.n_faces(), m.dim == 3 ? "polygons" : "segments",
                          closed.c_str()),
                     net.seconds.cells + net.seconds.faces + net.seconds.smoothing + net.seconds.triangulation,
                     {a.output});
    return kExitOk;
  }

  std::printf("tessera surface-nets: %zu points (%dD) from %s%s\n", in.size(), in.dim, shown_input(a.compute).c_str(),
              in.from_image ? " (sampled image)" : "");
  if (in.from_image)
    std::printf("  %-18s %lldx%lld%s voxels\n", "image", static_cast<long long>(in.geometry.size[0]),
                static_cast<long long>(in.geometry.size[1]),
                in.dim == 3 ? ("x" + std::to_string(in.geometry.size[2])).c_str() : "");
  std::printf("  %-18s %s\n", "selected labels", label_list(net.selected).c_str());
  std::printf("  %-18s %zu\n", "cells", net.n_cells);
  if (!a.compute.box_source.empty()) std::printf("  %-18s %s\n", "domain from", a.compute.box_source.c_str());
  if (m.is_periodic()) {
    std::string axes;
    for (int k = 0; k < m.dim; ++k)
      if (m.periodic[static_cast<std::size_t>(k)]) axes += "xyz"[k];
    std::printf("  %-18s %s; %zu of the %zu vertices repeat others across the box's faces\n", "periodic",
                axes.c_str(), m.n_vertices() - copies.n_groups(), m.n_vertices());
    // The tilts used are the lattice's (reduced where given past a length).
    const std::array<double, 3> used{m.lattice[1][0], m.lattice[2][0], m.lattice[2][1]};
    Bounds lengths;
    for (std::size_t d = 0; d < 3; ++d) lengths.hi[d] = m.lattice[d][d];
    if (const std::string t = tilt_text(a.compute, used, lengths, m.dim); !t.empty())
      std::printf("  %-18s %s\n", "tilt (triclinic)", t.c_str());
  }
  if (m.dim == 3 && a.triangles)
    std::printf("  %-18s %zu triangles from %zu polygons\n", "faces", m.n_faces(), polygon_count(net));
  else
    std::printf("  %-18s %zu %s\n", "faces", m.n_faces(), m.dim == 3 ? "polygons" : "segments");
  std::printf("  %-18s %zu (surface %zu, junction %zu, corner %zu)\n", "vertices", m.n_vertices(), kinds[0], kinds[1],
              kinds[2]);
  std::printf("  %-18s %zu\n", "label pairs", pairs.size());
  if (w.open_labels.empty())
    std::printf("  %-18s every selected label's surface is closed and manifold\n", "watertight");
  else
    std::printf("  %-18s open: label%s %s (%s)%s\n", "watertight", w.open_labels.size() == 1 ? "" : "s",
                label_list(w.open_labels).c_str(),
                w.boundary_edges + w.nonmanifold_edges == 0
                    ? "no faces"
                    : strf("%zu boundary, %zu non-manifold edges", w.boundary_edges, w.nonmanifold_edges).c_str(),
                a.capping ? "" : "; they reach the domain box or unselected points (--capping closes them)");
  if (a.smooth > 0)
    std::printf("  %-18s %d iterations, relaxation %g, constraint %g%s; largest move %.6g\n", "smoothing", a.smooth,
                a.relax, a.constraint, a.absolute_constraint ? "" : " x local spacing", net.max_displacement);
  else
    std::printf("  %-18s off\n", "smoothing");
  std::printf("  %-18s read %.3f, sample %.3f, cells %.3f, faces %.3f, smoothing %.3f, triangles %.3f, write %.3f s"
              " on %d thread%s\n",
              "time", in.read_s, in.sample_s, net.seconds.cells, net.seconds.faces, net.seconds.smoothing,
              net.seconds.triangulation, write_s, resolve_threads(a.compute.threads),
              resolve_threads(a.compute.threads) == 1 ? "" : "s");
  std::printf("  %-18s %s\n", "wrote", a.output.c_str());
  std::fflush(stdout);
  return kExitOk;
}

}  // namespace

int run_surface_nets(const SurfaceNetsArgs& a) {
  return run_frames(a, {{"-o", &SurfaceNetsArgs::output}}, run_surface_nets_frame);
}

int run_bench_surface_nets(const SurfaceNetsArgs& a) {
  check_args(a, false);
  if (a.repeat < 1) throw InputError("--repeat must be at least 1");
  NetInput in = read_net_input(a);  // an image is read (untimed) and sampled once here to get going
  const SamplerArgs s = sampler_of(a);
  const int threads = resolve_threads(a.compute.threads);
  for (int rep = 0; rep < a.repeat; ++rep) {
    // Timed: sampling (images) + cells + faces + smoothing (+ triangles).
    const Usage u0 = usage_now();
    const auto t0 = Clock::now();
    double sample_s = 0;
    if (in.from_image) {
      const auto ts = Clock::now();
      LabelledPoints p = sample_label_image(a.compute.input, in.image, s);
      sample_s = seconds_since(ts);
      in.coords = std::move(p.coords);
      in.labels = std::move(p.labels);
    }
    const SurfaceNet net = surface_nets(in.coords, in.labels, net_options(a, in));
    const double secs = seconds_since(t0);
    const Usage u1 = usage_now();
    const Watertight w = check_watertight(net, vertex_copies(net.mesh), one_region(net.mesh, in.labels));
    const std::size_t tris = net.mesh.dim == 3 && a.triangles ? net.mesh.n_faces() : triangle_count(net);
    std::printf(
        "{\"tool\":\"tessera\",\"op\":\"surface-nets\",\"n\":%zu,\"threads\":%d,\"seconds\":%.6f,\"simplices\":%zu,"
        "\"extra\":{\"cpu_user_s\":%.6f,\"cpu_sys_s\":%.6f,\"minflt\":%lld,\"peak_rss_bytes\":%lld,\"voxels\":%zu,"
        "\"points\":%zu,\"cells\":%zu,\"cells_built\":%zu,\"polygons\":%zu,\"triangles\":%zu,\"vertices\":%zu,"
        "\"labels\":%zu,\"watertight\":%s,\"open_labels\":%zu,\"boundary_edges\":%zu,\"nonmanifold_edges\":%zu,"
        "\"sample_s\":%.6f,\"cells_s\":%.6f,\"faces_s\":%.6f,\"smoothing_s\":%.6f,\"triangulation_s\":%.6f,"
        "\"smooth\":%d,\"capping\":%s,\"repeat\":%d}}\n",
        in.size(), threads, secs, net.mesh.n_faces(), u1.user_s - u0.user_s, u1.sys_s - u0.sys_s,
        u1.minflt - u0.minflt, u1.maxrss_bytes, in.from_image ? in.geometry.n_voxels() : std::size_t{0}, in.size(),
        net.n_cells, net.cells_built, polygon_count(net), tris, net.mesh.n_vertices(), net.selected.size(),
        w.closed() ? "true" : "false", w.open_labels.size(), w.boundary_edges, w.nonmanifold_edges, sample_s,
        net.seconds.cells, net.seconds.faces, net.seconds.smoothing, net.seconds.triangulation, a.smooth,
        a.capping ? "true" : "false", rep);
    std::fflush(stdout);
  }
  return kExitOk;
}

}  // namespace tessera::cli
