// Front end: the Delaunay triangulation of a point set, the dual of the cells.
//
// Every Voronoi vertex of the (symbolically perturbed) diagram is one Delaunay
// simplex. The cells pass finds those whose circumcentre lies in the domain
// box; hull completion then adds the thin simplices near the convex hull whose
// circumcentres lie outside it, so the result covers the convex hull of the
// input exactly (docs/design.md, "Delaunay and hull completion"). Where a
// pilot finds the cells far costlier than what they find (points sampled on
// surfaces), points go to incremental insertion instead, which builds the same
// simplices. With labels, the result is the simplices of that whole
// triangulation whose vertices are all inside points (label >= 0).
//
// In a periodic box (every axis periodic, VoronoiOptions::periodic and
// tilt) the triangulation is that of the points among all their images,
// each simplex once, with the shifts of its vertices (Delaunay::simplex_shifts).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera {

/// How tessera::delaunay builds the triangulation (the result is the same).
enum class DelaunayMethod {
  /// With complete_hull and automatic skip_cells:
  /// insertion below 20,000 points. From there a pilot builds a few
  /// hundred cells; insertion is chosen where they cost far more than the
  /// simplices they find (surface samples, clustered volumes, points nearly
  /// on a sphere; in 2D points on a circle or along curves) and, on one or
  /// two threads, where they met no exact ties
  /// (uniform, jittered, rotated points: ties need coordinates on a grid).
  /// The rest (lattices, whose ties make insertion slower) goes to the
  /// cells pass, which in 3D hands
  /// over to insertion if hull completion runs past its budget
  /// (near-coplanar hull faces: a rotated lattice). Otherwise the cells
  /// pass. Every path gives the same rows.
  automatic,
  cells,      ///< the cells pass (and hull completion)
  /// Incremental insertion (parallel by phases); with complete_hull only.
  insertion,
};

struct DelaunayOptions : VoronoiOptions {
  /// Close the triangulation up to the convex hull (simplices whose
  /// circumcentre lies outside the domain box). With labels, the result is
  /// then the whole triangulation's simplices whose vertices are all inside
  /// points, whatever the box; without completion, those of the inside
  /// points' cells (circumcentre in the box, every vertex inside), as the
  /// cells pass finds them.
  bool complete_hull = true;
  /// With hull completion: the fraction of the points, in [0, 1), whose
  /// cells are not built (picked by a hash of their id; points with an exact
  /// duplicate are always built). Each simplex with a built vertex is still
  /// read off that vertex's cell; the cavities of skipped points only are
  /// closed by gift wrapping, as hull completion closes the hull. The result
  /// is the same, row for row. Negative: automatic (from 20,000 points, by
  /// what a cell costs per simplex it finds, measured on a sample of cells
  /// first: in 3D 0.35 to 0.9; in 2D 0 on uniform points, 0.3 to 0.6 on
  /// clustered ones; else 0). Ignored without hull completion.
  double skip_cells = -1;
  DelaunayMethod method = DelaunayMethod::automatic;
};

/// Simplices of the Delaunay triangulation (triangles in 2D, tetrahedra in 3D).
struct Delaunay {
  int dim = 3;
  std::size_t n_points = 0;
  Bounds bounds;                           ///< the domain box of the cells pass
  /// n_simplices * (dim+1) point ids. Row r's first id is its lowest; rows are
  /// in ascending order of their sorted id tuples. 3D tets are positively
  /// oriented (det[p1-p0, p2-p0, p3-p0] > 0), 2D triangles counter-clockwise,
  /// decided by exact predicates.
  Buffer<std::int32_t> simplices;
  std::size_t from_cells = 0;              ///< simplices found by the cells pass
  std::size_t from_hull_completion = 0;    ///< simplices added by hull completion (and skipped cells' cavities)
  std::size_t skipped_cells = 0;           ///< generators whose cells were not built (DelaunayOptions::skip_cells)
  std::size_t from_insertion = 0;          ///< simplices built by incremental insertion (DelaunayOptions::method)
  /// The simplices cover the convex hull of the points: hull completion ran
  /// and no labels left simplices out (locate() may walk).
  bool hull_completed = false;
  /// With labels and complete_hull, where some inside point's cell reaches
  /// the domain box (so the whole triangulation was built): its simplices
  /// left out for an outside vertex; the from_* counts are then of the whole
  /// triangulation, and sum to n_simplices() plus this. 0 where no inside
  /// cell reaches the box: the labelled cells pass found every inside
  /// simplex, building the inside cells only.
  std::size_t outside_simplices = 0;
  /// (duplicate, owner): not vertices. With labels, only inside duplicates.
  /// With radii, coincident points leave the largest radius (ties: the
  /// lowest id) as the owner.
  std::vector<std::pair<std::int32_t, std::int32_t>> duplicates;
  /// A regular triangulation (VoronoiOptions::radii, not all equal): the
  /// dual of the power cells.
  bool power = false;
  /// With radii and hull completion: the points in no simplex, neither
  /// duplicates nor set aside (ascending). Their power cells are empty:
  /// every point of the hull has a lower power to some other point. With
  /// labels, only inside points.
  std::vector<std::int32_t> hidden;
  std::vector<std::int32_t> ignored_outside_bounds;
  std::uint64_t exact_predicate_calls = 0;
  int threads_used = 1;
  /// Periodic boxes (DelaunayOptions::periodic, every axis periodic), else
  /// empty: per row entry, dim shifts of that point's image (n_simplices *
  /// (dim+1) * dim, in box lengths; lattice vectors with tilts). Each
  /// simplex of the periodic triangulation is listed once, translated so
  /// that its least (id, shift) entry, its first, is at shift 0; rows
  /// ascend by (id, shift) entries, but for the orientation's swap, and are
  /// positively oriented with the shifts applied (Cells::periodic_points +
  /// shift . lattice).
  Buffer<std::int8_t> simplex_shifts;
  std::array<bool, 3> periodic{false, false, false};
  std::array<double, 3> tilt{0, 0, 0};     ///< as used, rounded and reduced (Cells::tilt): the shifts' basis
  std::vector<double> periodic_points;     ///< the points as wrapped and rounded (Cells::periodic_points)

  bool is_periodic() const { return periodic[0] || periodic[1] || periodic[2]; }
  std::size_t n_simplices() const { return simplices.size() / static_cast<std::size_t>(dim + 1); }
};

/// Compute the Delaunay triangulation. Same input rules as voronoi() (points
/// n*dim row-major; labels empty or n ints, < 0 = outside). Throws InputError.
/// With options.radii (n finite radii >= 0, not all equal) it is the regular
/// (weighted Delaunay) triangulation, the dual of the power cells: a simplex
/// is regular when no point's power to its orthocentre is below the
/// vertices' (symbolically perturbed as the cells are). Built by the cells
/// pass and hull completion (not insertion); in a periodic box every image
/// has its point's radius.
Delaunay delaunay(std::span<const double> points, int dim, std::span<const std::int32_t> labels,
                  const DelaunayOptions& options);

/// Adjacent simplices, as scipy.spatial.Delaunay.neighbors: entry r*(dim+1)+k is
/// the simplex sharing the facet opposite vertex k of simplex r, or -1.
/// InputError for a periodic triangulation (its facets match by ids and
/// shifts, not by ids alone).
std::vector<std::int32_t> simplex_neighbors(const Delaunay& dt);

/// For each point the lowest index of a simplex having it as a vertex, or -1
/// (a duplicate, an outside point), as scipy.spatial.Delaunay.vertex_to_simplex.
std::vector<std::int32_t> vertex_to_simplex(const Delaunay& dt);

/// The Delaunay edges as CSR, as scipy.spatial.Delaunay.vertex_neighbor_vertices:
/// the points sharing a simplex with point v are ids[offsets[v] .. offsets[v+1]),
/// ascending (none for a point in no simplex: a duplicate, an outside point).
struct VertexNeighbors {
  std::vector<std::int64_t> offsets;  ///< n_points + 1
  std::vector<std::int32_t> ids;
};
VertexNeighbors vertex_neighbors(const Delaunay& dt);

/// Checks of a triangulation (the CLI's `delaunay --validate`).
struct DelaunayReport {
  bool ok = true;
  std::size_t simplices = 0;
  std::size_t flat_or_inverted = 0;        ///< simplices not strictly positively oriented
  std::size_t nonmanifold_facets = 0;      ///< facets in more than two simplices, or twice with one orientation
  std::size_t boundary_facets = 0;         ///< facets in exactly one simplex
  // The three below need a hull-complete result without labels (hull_completed).
  std::size_t open_boundary_ridges = 0;    ///< boundary ridges not shared by exactly two boundary facets
  std::size_t nonconvex_boundary = 0;      ///< boundary ridges where the hull is not convex
  std::size_t missing_points = 0;          ///< non-duplicate points in no simplex
  std::size_t local_delaunay_violations = 0;  ///< interior facets whose opposite vertex is in the circumsphere (radii: power sphere)
  std::size_t hidden_not_hidden = 0;       ///< (radii) points in Delaunay::hidden that are vertices, duplicates or set aside
  std::size_t hidden_in_conflict = 0;      ///< (radii, no labels) hidden points in conflict with the simplex holding them
  double volume_sum = 0;                   ///< sum of simplex volumes (areas in 2D)
  double enclosed_volume = 0;              ///< volume enclosed by the boundary facets
  /// How far the two volumes may differ and still agree: their float
  /// rounding (bounded from each determinant) plus 1e-9 relative. On nearly
  /// flat input both are at this noise level, and either may be negative.
  double volume_tolerance = 0;
  std::vector<std::string> messages;       ///< one line each
};
/// A regular triangulation (dt.power) needs the radii it was computed with;
/// local Delaunay is then local regularity, and each hidden point must lie in
/// a simplex whose orthosphere it is not in conflict with.
DelaunayReport validate(const Delaunay& dt, std::span<const double> points, std::span<const std::int32_t> labels,
                        std::span<const double> radii = {});

}  // namespace tessera
