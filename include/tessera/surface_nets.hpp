// Front end: generalized surface nets — smooth, watertight, consistently
// oriented surfaces between the regions of labelled points (Schroeder,
// Thompson, Tsalikis, "A Parallel Meshless Voronoi Method for Generalized
// SurfaceNets", IEEE TVCG 2026).
//
// Pipeline: Voronoi cells of the selected regions' points (the others clip as
// outside points) -> the surface-net face set (faces between different
// selected regions; with capping also the faces against the domain box and
// against unselected/outside points) -> optional constrained smoothing ->
// optional triangulation.
//
// Conventions: those of FaceSet (include/tessera/faces.hpp). BoundaryLabels
// holds (side 0 label, side 1 label): side 0 is always a selected region;
// between two selected regions side 0 is the lower label, so pairs are
// (lo, hi); a capping face has side 1 = the outside point's own label, or
// background_label for the domain box. Faces are oriented from side 0 to
// side 1 (right-hand normal into side 1): every region's surface (its faces
// with the region on side 0, plus the reversed faces with it on side 1) is
// closed and outward-facing.
//
// Periodic boxes (voronoi.periodic, voronoi.tilt): regions wrap around the box.
// Faces lie where their side-0 cell is (FaceSet::side_shifts names side 1's
// image), a vertex is listed once per frame its cells see it from, and its
// copies (vertex_copies, faces.hpp) are smoothed as one: the stencil is the
// union of the copies' stencils, each brought into one frame, and the copies
// stay lattice translations of each other, so every region's surface closes
// up across the box's faces.
//
// Smoothing. Each merged vertex is classified from its topological
// coordinate by the number of distinct regions among its D+1 generators —
// counting the domain box planes each as its own region and every unselected
// or outside point as the region of its label:
//   2 regions: surface vertex — moves freely (Laplacian over its polygon-edge
//              neighbours);
//   3 regions: junction vertex — on a curve where three regions meet (or an
//              interface meets the box); it averages only its neighbours
//              across junction edges (edges whose D shared generators span
//              three regions: exactly its two neighbours along the curve), so
//              it moves along its curve;
//   4+ regions: corner — fixed.
// In 2D (faces are segments) a vertex has 3 generators: 2 regions = curve
// vertex (free), 3 = corner (fixed).
// Stencils come from the polygon edges (before triangulation: no diagonals).
// Iteration (Jacobi: every vertex from the previous positions, so any thread
// count gives the same bits): x <- x + relaxation * (mean(stencil) - x), then
// pulled back to within the constraint distance of the vertex's original
// position; coordinates on a box plane are kept (vertices stay on the box).
// The constraint is `constraint` times the vertex's local spacing (the
// distance from the vertex to its generators, i.e. its petal radius), or an
// absolute distance with `constraint_is_absolute`.
// Guard: after each step every polygon must still have a ladder
// triangulation (below) whose triangles all face the polygon's original
// normal (2D: every segment keeps its direction); the vertices of a polygon
// that has none keep their previous positions for that step (decided in
// rounds, deterministically). So no output face flips, whatever the options.
// Untangling (3D): where output triangles cross (share a point interior to
// one of them, exactly), the polygons around both are pinned where they
// started and the smoothing runs again from the start around them (the rest
// of the net held), until none do; so no face passes through another (voxel
// label maps of many touching labels had such crossings at junction curves).
//
// Defaults (iterations 20, relaxation 0.5, constraint 0.5), chosen on
// nested spheres, touching boxes and three sectors sampled as exact and
// jittered lattices and uniform random points (docs/design.md, "Generalized
// surface nets", has the numbers):
//   * relaxation 0.5: the largest step for which the Jacobi iteration damps
//     the highest-frequency (zig-zag) mode without overshooting it; 1.0
//     oscillates and ends at the constraint just the same.
//   * constraint 0.5 x petal radius: the smoothing is constraint-bound (more
//     iterations barely change the result). 0.5 keeps a voxel-lattice vertex
//     within 0.43 voxel of where it started (inside its dual cube, as classic
//     SurfaceNets does), brings the area of a sphere from +45..50% to within
//     ~5-8% and its volume within a few % (shrinkage falls with
//     resolution). No flipped triangle in any run (the guard). 0.6-1.0
//     smooth further (normals within ~10 degrees of a sphere's instead of
//     ~20) but make crossings more frequent (the untangling pins more), and
//     shrink small features more.
//   * 20 iterations: enough to reach the constraint-bound state (10 leave
//     visibly more roughness, 40 change the area by < 1% and only shrink).
// Triangulation (`triangles`): each polygon is split by a "ladder" (a strip
// zig-zagging between the two ends of the loop, not a fan); of its n
// rotations the one whose worst triangle (facing its original normal,
// relative to its squared edges) is best is used.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/faces.hpp"

namespace tessera {

struct SmoothingOptions {
  int iterations = 20;              ///< 0 = no smoothing
  double relaxation = 0.5;          ///< in (0, 1]
  double constraint = 0.5;          ///< fraction of the local spacing (or absolute)
  bool constraint_is_absolute = false;
};

struct SurfaceNetsOptions {
  /// dim 2 or 3; build_mesh is forced on, and only_with_faces set to the
  /// net's classes (face_set_classes).
  VoronoiOptions voronoi;
  /// Selected (inside) labels; empty = every label >= 0 present. Points with
  /// other labels are outside points: they clip, and own no cell.
  std::vector<std::int32_t> select;
  std::int32_t background_label = -1;  ///< BoundaryLabels value for the domain box (< 0)
  bool capping = false;
  SmoothingOptions smoothing;
  bool triangles = false;           ///< 3D: split each polygon into triangles (both labels copied)
};

enum class NetVertexKind : std::uint8_t { surface = 0, junction = 1, corner = 2 };

struct SurfaceNet {
  /// The faces (polygons, or triangles), merged vertices (smoothed) and their
  /// topological coordinates, sides, BoundaryLabels and classes.
  FaceSet mesh;
  std::vector<NetVertexKind> vertex_kind;  ///< per mesh vertex
  /// Per output face: the index of the Voronoi face (polygon) it came from
  /// (identity without triangulation).
  std::vector<std::int64_t> polygon_of_face;
  /// The cells of the selected points.
  std::size_t n_cells = 0;
  /// Of those, the cells built with the mesh: those with a face of the net
  /// (VoronoiOptions::only_with_faces), or all n_cells.
  std::size_t cells_built = 0;
  double max_displacement = 0;             ///< largest distance a vertex moved
  std::vector<std::int32_t> selected;      ///< the selected labels, ascending
  /// Wall time of each stage, seconds.
  struct Timings {
    double cells = 0, faces = 0, smoothing = 0, triangulation = 0;
  } seconds;
};

/// Throws InputError on bad points / labels (as voronoi()), labels missing or
/// of the wrong length, a selected label that no point carries
/// ("unknown label"), an empty selection, background_label >= 0, or bad
/// smoothing options. May throw Cancelled from the progress callback.
SurfaceNet surface_nets(std::span<const double> points, std::span<const std::int32_t> labels,
                        const SurfaceNetsOptions& options = {});

/// The smoothing step alone, on a surface-net FaceSet whose vertex_keys are
/// intact (exposed for tests): classifies the vertices as above (`labels` =
/// the labels of the points the face set was computed from; box planes are
/// their own regions), smooths `mesh.vertices` in place and returns the kinds.
/// `points` gives the local spacing (for a periodic face set, the points as
/// the cells took them: Cells::periodic_points). Returns max displacement
/// via `moved`.
std::vector<NetVertexKind> smooth_surface_net(FaceSet& mesh, std::span<const double> points,
                                              std::span<const std::int32_t> labels,
                                              const SmoothingOptions& options, double& moved);

}  // namespace tessera
