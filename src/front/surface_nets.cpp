// tessera::surface_nets: selection -> cells -> surface-net faces ->
// constrained smoothing -> optional "ladder" triangulation (conventions in
// include/tessera/surface_nets.hpp).
#include "tessera/surface_nets.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "net_smoothing.hpp"
#include "tessera/engine/thread_arena.hpp"

namespace tessera {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// The selected labels, ascending: the given ones (each >= 0 and carried by
/// some point) or every label >= 0 present.
std::vector<std::int32_t> resolve_selection(std::span<const std::int32_t> labels,
                                            const std::vector<std::int32_t>& select) {
  std::vector<std::int32_t> present;
  for (std::int32_t l : labels)
    if (l >= 0) present.push_back(l);
  std::sort(present.begin(), present.end());
  present.erase(std::unique(present.begin(), present.end()), present.end());
  if (select.empty()) {
    if (present.empty())
      throw InputError("empty selection: no point has a label >= 0 (labels < 0 are outside points)");
    return present;
  }
  std::vector<std::int32_t> out(select.begin(), select.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  for (std::int32_t l : out) {
    if (l < 0)
      throw InputError("selected label " + std::to_string(l) +
                       " is negative: labels < 0 mark outside points and cannot be selected");
    if (!std::binary_search(present.begin(), present.end(), l))
      throw InputError("unknown label " + std::to_string(l) + ": no point carries it");
  }
  return out;
}

/// Splits every polygon into n-2 triangles by a ladder (front::ladder: a
/// strip zig-zagging between the two ends of the loop, not a fan), each
/// copying the polygon's sides, labels and class. Of the n rotations of the
/// ladder the one with the best front::ladder_score is taken: its triangles
/// all face the polygon's original (unsmoothed, `before`) normal — the
/// smoothing guard made sure one such rotation exists — and its worst
/// triangle is the best shaped. A fixed ladder would make slivers of three
/// corners along a straightened junction curve, which flip. A polygon
/// degenerate before smoothing (front::reference_orientation; the cells'
/// `points` give its local spacing) is measured against its smoothed normal.
void triangulate_ladder(FaceSet& m, std::vector<double> before, std::span<const double> points,
                        std::vector<std::int64_t>& polygon_of_face) {
  // Normals and areas in the net's frame (front::net_frame_shift): read from
  // scaled copies, as the positions themselves stay.
  const int k = front::net_frame_shift(m.vertices, points, 3);
  std::vector<double> scaled_points, scaled_vertices;
  const double* xyz = m.vertices.data();
  if (k != 0) {
    scaled_points.assign(points.begin(), points.end());
    front::scale_pow2(scaled_points, k);
    points = scaled_points;
    scaled_vertices = m.vertices;
    front::scale_pow2(scaled_vertices, k);
    xyz = scaled_vertices.data();
    front::scale_pow2(before, k);
  }
  const std::vector<double> petal = front::petal_radii(m, before, points, k);
  const std::size_t np = m.n_faces();
  const std::size_t dn = 3, shifted = m.side_shifts.empty() ? 0 : dn;  // periodic: side shifts per triangle
  // Polygon p starts at triangle offset[p] - 2p: n - 2 triangles per n corners.
  const std::size_t nt = np == 0 ? 0 : static_cast<std::size_t>(m.face_offsets[np]) - 2 * np;
  std::vector<std::int64_t> offsets(nt + 1);
  std::vector<std::int32_t> corners(3 * nt), sides(2 * nt), labels(2 * nt);
  std::vector<SpokeClass> cls(nt);
  std::vector<std::int8_t> side_shifts(shifted * nt);
  polygon_of_face.resize(nt);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, np, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t p = r.begin(); p != r.end(); ++p) {
      const auto b = static_cast<std::size_t>(m.face_offsets[p]);
      const auto n = static_cast<std::size_t>(m.face_offsets[p + 1]) - b;
      const std::int32_t* loop = &m.face_vertices[b];
      double ref[3];
      front::reference_orientation(3, before.data(), petal.data(), loop, n, ref);
      const std::size_t best = front::output_ladder_rotation(xyz, before.data(), loop, n, ref);
      std::size_t t = b - 2 * p;
      front::ladder(n, best, [&](std::size_t i, std::size_t j, std::size_t k) {
        corners[3 * t] = loop[i], corners[3 * t + 1] = loop[j], corners[3 * t + 2] = loop[k];
        offsets[t + 1] = static_cast<std::int64_t>(3 * (t + 1));
        sides[2 * t] = m.sides[2 * p], sides[2 * t + 1] = m.sides[2 * p + 1];
        labels[2 * t] = m.boundary_labels[2 * p], labels[2 * t + 1] = m.boundary_labels[2 * p + 1];
        cls[t] = m.face_class[p];
        std::copy_n(m.side_shifts.data() + shifted * p, shifted, side_shifts.data() + shifted * t);
        polygon_of_face[t] = static_cast<std::int64_t>(p);
        ++t;
      });
    }
  });
  offsets[0] = 0;
  m.face_offsets = std::move(offsets);
  m.face_vertices = std::move(corners);
  m.sides = std::move(sides);
  m.boundary_labels = std::move(labels);
  m.face_class = std::move(cls);
  m.side_shifts = std::move(side_shifts);
}

}  // namespace

SurfaceNet surface_nets(std::span<const double> points, std::span<const std::int32_t> labels,
                        const SurfaceNetsOptions& options) {
  const int D = options.voronoi.dim;
  if (D != 2 && D != 3) throw InputError("dim must be 2 or 3, got " + std::to_string(D));
  if (!options.voronoi.radii.empty()) throw InputError("surface nets of power cells (radii) are not supported");
  if (points.size() % static_cast<std::size_t>(D) != 0)
    throw InputError("points: " + std::to_string(points.size()) + " coordinates is not a multiple of dim " +
                     std::to_string(D));
  const std::size_t n = points.size() / static_cast<std::size_t>(D);
  if (labels.empty())
    throw InputError("surface nets need labels: one region label per point (--labels)");
  if (labels.size() != n)
    throw InputError("labels: " + std::to_string(labels.size()) + " values for " + std::to_string(n) + " points");
  if (options.background_label >= 0)
    throw InputError("background label must be negative (labels >= 0 are regions), got " +
                     std::to_string(options.background_label));
  front::check_smoothing_options(options.smoothing);

  SurfaceNet out;
  out.selected = resolve_selection(labels, options.select);
  const auto& sel = out.selected;
  engine::ThreadArena arena(resolve_threads(options.voronoi.threads));

  // Unselected labels >= 0 become outside points for the cells (any negative
  // value will do); the faces get the original labels, so a capping face
  // against such a point carries that point's own label.
  std::vector<std::int32_t> cell_labels(n);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const std::int32_t l = labels[i];
        cell_labels[i] = l < 0 || std::binary_search(sel.begin(), sel.end(), l) ? l : -1;
      }
    });
  });

  FaceSetOptions fo;
  fo.kind = FaceSetKind::surface_net;
  fo.capping = options.capping;
  fo.background_label = options.background_label;
  auto t0 = Clock::now();
  VoronoiOptions vo = options.voronoi;
  vo.build_mesh = true;
  // The cells with a face of the net only (VoronoiOptions::only_with_faces):
  // the same net.
  vo.only_with_faces = face_set_classes(fo);
  // In a periodic box the faces lie where the cells took the points (wrapped
  // into the box): smoothing and triangulation measure against those.
  std::vector<double> wrapped;
  {
    const Cells cells = voronoi(points, D, cell_labels, vo);
    if (cells.is_periodic()) {
      wrapped.assign(cells.periodic_points.begin(), cells.periodic_points.end());
      points = wrapped;
    }
    out.n_cells = cells.partial ? cells.generators : cells.n_cells();  // (no radii: no empty cells)
    out.cells_built = cells.n_cells();
    out.seconds.cells = since(t0);
    std::vector<std::int32_t>().swap(cell_labels);
    t0 = Clock::now();
    out.mesh = extract_faces(cells, labels, fo);
    out.seconds.faces = since(t0);
  }  // the cells are freed here
  if (vo.progress) vo.progress(1.0);  // lets the caller cancel between stages

  t0 = Clock::now();
  const bool triangulate = options.triangles && D == 3;
  std::vector<double> before;
  if (triangulate) before = out.mesh.vertices;
  arena.execute([&] {
    out.vertex_kind = smooth_surface_net(out.mesh, points, labels, options.smoothing, out.max_displacement);
  });
  out.seconds.smoothing = since(t0);
  if (vo.progress) vo.progress(1.0);

  t0 = Clock::now();
  if (triangulate) {
    arena.execute([&] { triangulate_ladder(out.mesh, std::move(before), points, out.polygon_of_face); });
  } else {
    out.polygon_of_face.resize(out.mesh.n_faces());
    for (std::size_t f = 0; f < out.polygon_of_face.size(); ++f)
      out.polygon_of_face[f] = static_cast<std::int64_t>(f);
  }
  out.seconds.triangulation = since(t0);
  return out;
}

}  // namespace tessera
