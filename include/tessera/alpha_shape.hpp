// Alpha shapes: the part of a Delaunay triangulation made of its small
// simplices, and the boundary of that part (a concave hull; a surface
// reconstructed from samples; with radii, the dual of a union of balls).
//
// A simplex is kept when its circumsphere's radius is at most alpha (with
// radii, a regular triangulation's: when its orthosphere's squared radius
// |c - p|^2 - r_p^2 is at most alpha^2, which the balls grown by alpha
// make: H. Edelsbrunner, "The union of balls and its dual shape", Discrete
// Comput. Geom. 13 (1995)). The shape is the union of the kept simplices,
// CGAL's REGULARIZED alpha shape at CGAL's alpha = alpha^2 (H. Edelsbrunner
// and E. P. Mücke, "Three-dimensional alpha shapes", ACM Trans. Graph. 13(1),
// 1994); the lower-dimensional faces the full alpha complex adds (edges and
// triangles no kept simplex holds, VTK's leftovers) are not part of it.
//
// The comparison with alpha is exact: a float filter with an error bound,
// then rationals where it cannot decide, so simplices whose radii are equal
// in exact arithmetic (a lattice's) are all kept or all left out, on any
// thread count.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tessera/delaunay.hpp"

namespace tessera {

struct AlphaShape {
  int dim = 3;
  double alpha = 0;
  /// The triangulation's rows kept, ascending.
  std::vector<std::int32_t> simplex_rows;
  /// The boundary of the union of the kept simplices: the facets of kept
  /// simplices whose other side is not kept (or is outside the
  /// triangulation), dim point ids each, in the order of their simplex's
  /// row and then of the vertex they face. 3D: triangles counter-clockwise
  /// seen from outside (the normal (b - a) x (c - a) points out of the
  /// shape); 2D: segments with the shape on their left (outer boundaries
  /// counter-clockwise, holes clockwise, as GeoJSON's rings).
  std::vector<std::int32_t> boundary;
  /// Per boundary facet, the kept simplex (a row of the triangulation) it bounds.
  std::vector<std::int32_t> boundary_simplex;
  /// The singular faces of the alpha complex: facets (dim ids each) that no
  /// kept simplex holds, whose smallest circumsphere (orthosphere) has a
  /// radius at most alpha and holds neither of the facet's opposite
  /// vertices strictly inside (CGAL's SINGULAR facets). Surface samples have
  /// no volume to keep: their reconstructed surface is these triangles (in
  /// 2D, a curve's samples give these segments). Facets of the triangulation
  /// in row order; their orientation means nothing.
  std::vector<std::int32_t> singular;
  /// A periodic triangulation's (else empty): per entry of `boundary` and
  /// of `singular`, dim shifts of that point's image in lattice vectors, in
  /// the frame of the facet's simplex (Delaunay::simplex_shifts).
  std::vector<std::int8_t> boundary_shifts, singular_shifts;
  /// Pieces of the shape: kept simplices joined through shared facets (two
  /// pieces may touch at an edge or a vertex).
  std::size_t components = 0;
  /// Per kept simplex (as simplex_rows), its piece: 0 .. components - 1,
  /// numbered in the order of the pieces' lowest rows.
  std::vector<std::int32_t> piece;
  /// Where the boundary is not a manifold: in 3D boundary edges in more than
  /// two boundary triangles (pieces touching along an edge); in 2D boundary
  /// vertices in more than two boundary segments (pieces touching at a point).
  std::size_t nonmanifold_ridges = 0;
  double volume = 0;            ///< of the kept simplices (area in 2D), a compensated float sum
  double boundary_measure = 0;  ///< area of the boundary triangles (2D: length of the segments)
  std::size_t exact_tests = 0;  ///< keep tests the float filter left to exact arithmetic

  std::size_t n_simplices() const { return simplex_rows.size(); }
  std::size_t n_boundary() const { return boundary.size() / static_cast<std::size_t>(dim); }
  std::size_t n_singular() const { return singular.size() / static_cast<std::size_t>(dim); }
};

/// A 2D shape's boundary as polygons (boundary_polygons()): polygon k's
/// rings are rings [polygon_rings[k], polygon_rings[k+1]), ring r's points
/// are points[ring_points[r] .. ring_points[r+1]) (ids, once around: the
/// first is not repeated at the end).
struct BoundaryPolygons {
  std::vector<std::int64_t> polygon_rings{0};
  std::vector<std::int64_t> ring_points{0};
  std::vector<std::int32_t> points;

  std::size_t n_polygons() const { return polygon_rings.size() - 1; }
  std::size_t n_rings() const { return ring_points.size() - 1; }
};

/// The boundary of a 2D alpha shape (AlphaShape::boundary, of `dt` and
/// `points`) chained into polygons, one per piece (in the order of the
/// pieces' lowest rows): its outer ring, counter-clockwise, then its holes,
/// clockwise, so the shape lies on each ring's left (GeoJSON's RFC 7946
/// order; shapely.Polygon(points[outer], [points[h] for h in holes])). At a
/// vertex where the shape touches itself the ring keeps to the sector it
/// came through (walking the kept triangles around the vertex), so rings
/// never cross; a hole may touch its outer ring, or another hole, at a
/// vertex, as the OGC's simple features allow. A ring's orientation is
/// decided exactly (at its lowest vertex). Throws InputError for a 3D shape,
/// a periodic triangulation's, or one not computed from `dt`.
BoundaryPolygons boundary_polygons(const Delaunay& dt, std::span<const double> points, const AlphaShape& shape);

/// Per row of `dt` (periodic too), the squared radius of its circumsphere (with `radii`, a
/// regular triangulation's: of its orthosphere, |c - p|^2 - r_p^2, which may
/// be negative), in floating point; +inf where the simplex is flat in
/// floating point. For inspection (ParaView, histograms to choose alpha);
/// alpha_shape() decides by exact comparisons.
std::vector<double> simplex_squared_radii(const Delaunay& dt, std::span<const double> points,
                                          std::span<const double> radii = {});

/// The alpha shape of `dt` (the triangulation of `points`; a regular one,
/// dt.power, needs the radii it was computed with, and an ordinary one
/// takes none). alpha >= 0; +inf keeps every simplex, so the boundary is the
/// triangulation's own: the convex hull, or with labels the inside region's
/// boundary. A periodic triangulation's (dt.is_periodic()) is computed on
/// its own wrapped points and images (`points` is not read): its facets
/// match up to translation, and carry their shifts. Runs on dt.threads_used
/// threads; the result does not depend on them. Throws InputError on a NaN
/// or negative alpha, or radii that do not match dt.
AlphaShape alpha_shape(const Delaunay& dt, std::span<const double> points, double alpha,
                       std::span<const double> radii = {});

}  // namespace tessera
