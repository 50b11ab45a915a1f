// Voronoi cells on a sphere (scipy's SphericalVoronoi, d3-geo-voronoi), by
// the meshless method: each point clips its own spherical polygon from the
// whole sphere by its neighbours' bisector planes, in parallel
// (kernels/sphere_tile.hpp), with the topology decided exactly
// (kernels/sphere_predicates.hpp). The dual of the cells is the spherical
// Delaunay triangulation: the points' convex hull.
//
// A cell is the set of directions u with u.p >= u.q for every other point q
// (the hull's normal cone at p): for points on the sphere exactly the
// directions closer to p than to any other point, and for points a rounding
// off it (unit vectors from lon/lat) the same up to that rounding, with a
// topology that is exact and consistent whatever the rounding did. A point
// that lies inside the hull of the others (one rounded inwards next to a
// near-duplicate, far closer than any real spacing) has an empty cell.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "tessera/buffer.hpp"

namespace tessera {

struct SphericalVoronoiOptions {
  std::array<double, 3> center{0, 0, 0};
  /// The sphere's radius; 0: the mean distance of the points from `center`.
  double radius = 0;
  /// Every point must lie within tolerance * radius of the sphere (InputError
  /// naming the farthest otherwise); infinite: no check.
  double tolerance = 1e-6;
  int threads = 0;          ///< 0: TESSERA_NUM_THREADS, else all cores
  double bin_points = 0;    ///< the locator's mean points per bin; 0: automatic (for a surface)
  /// Called from the calling thread between chunks of cells with the
  /// fraction done; it may throw tessera::Cancelled to stop the run (Ctrl-C).
  std::function<void(double)> progress;
};

/// What became of a point.
enum class SphereCellStatus : std::uint8_t {
  cell = 0,       ///< it has a cell (possibly of zero area, from an exact tie)
  duplicate = 1,  ///< at exactly the coordinates of a lower id, which owns the cell
  hidden = 2,     ///< inside the hull of the others: no cell
};

/// Large arrays are tessera::Buffer (a std::vector that leaves resized
/// elements uninitialized, on huge pages): the cells fill them in parallel.
struct SphericalVoronoi {
  std::array<double, 3> center{0, 0, 0};
  double radius = 0;
  std::size_t n_points = 0;
  /// Cells, per point in id order, as CSR: cell i's vertices are
  /// region_vertices[region_offsets[i] .. region_offsets[i+1]),
  /// counter-clockwise seen from outside the sphere. Empty for duplicates
  /// and hidden points.
  Buffer<std::int64_t> region_offsets;
  Buffer<std::int32_t> region_vertices;
  /// Per point, its neighbours neighbors[neighbor_offsets[i] ..
  /// neighbor_offsets[i+1]): the point across edge k, the edge from vertex k
  /// to vertex k+1. The same offsets as the regions' except where a cell has
  /// no vertex: one point's cell is the whole sphere (no neighbour), two
  /// points' cells are hemispheres (one neighbour each).
  Buffer<std::int64_t> neighbor_offsets;
  Buffer<std::int32_t> neighbors;
  /// Cell vertices on the sphere, 3 doubles each, numbered by the lowest
  /// generator's cell (in id order) and that cell's order.
  Buffer<double> vertices;
  /// Per vertex its three generators, counter-clockwise seen from outside:
  /// the spherical Delaunay triangles (the convex hull's facets, outward).
  Buffer<std::int32_t> triangles;
  Buffer<double> areas;      ///< per point: its cell's area (R^2 x solid angle); 0 without a cell
  Buffer<double> centroids;  ///< per point: the cell's centroid projected to the sphere (3 each); the point itself without a cell
  std::vector<SphereCellStatus> status;  ///< per point
  std::vector<std::int32_t> duplicate_of;  ///< per point: the lowest id at its coordinates, or -1
  std::size_t duplicates = 0, hidden = 0;
  double max_deviation = 0;       ///< max | |p - center| - radius | / radius over the points
  double area_sum = 0;            ///< the cells' areas summed (compensated): 4 pi R^2 up to rounding
  std::size_t exact_tests = 0;    ///< clip tests the float filter left to exact arithmetic

  std::size_t n_vertices() const { return vertices.size() / 3; }
  std::size_t n_cells() const { return n_points - duplicates - hidden; }
};

/// The spherical Voronoi cells of `points` (n x 3, row-major). Throws
/// InputError on no points, a NaN or infinite coordinate, a point at the
/// centre, a non-positive or non-finite radius, or a point off the sphere
/// by more than the tolerance. The result does not depend on the thread
/// count.
SphericalVoronoi spherical_voronoi(std::span<const double> points, const SphericalVoronoiOptions& options = {});

/// What validate_spherical_voronoi found: counts of each kind of fault (all
/// zero when ok) and the measures compared.
struct SphereReport {
  bool ok = true;
  std::size_t asymmetric_neighbors = 0;  ///< i lists j but j does not list i (or lists it twice)
  std::size_t bad_vertex_cells = 0;      ///< vertices not in exactly the cells of their three generators
  std::size_t bad_rings = 0;             ///< cells whose vertex k is not the facet (i, neighbour k-1, neighbour k)
  std::size_t bad_status = 0;            ///< duplicates not at their owner's coordinates, cells of points without one
  std::size_t nonempty_facets = 0;       ///< sampled vertices with a point above their facet (brute force)
  std::size_t vertices_checked = 0;      ///< vertices whose facet was tested against every point
  long long euler = 2;                   ///< V - E + F (2 for a sphere tiled by three or more cells)
  double area_rel_error = 0;             ///< |sum of areas - 4 pi R^2| / (4 pi R^2)
  std::vector<std::string> messages;     ///< one line each
};

/// Checks a result independently of the pass that made it: the adjacency
/// is symmetric, every vertex is in the cells of its three generators and
/// where their rings say, V - E + F = 2, the areas add to 4 pi R^2 (to
/// 1e-9), duplicates sit on their owners, and `sample` vertices spread over
/// the numbering have no point above their facet (every point tested, by
/// the exact perturbed predicate: the empty-circle property).
SphereReport validate_spherical_voronoi(const SphericalVoronoi& sv, std::span<const double> points,
                                        std::size_t sample = 256);

/// Unit vectors (times `radius`, about `center`) from longitudes and
/// latitudes in degrees (n x 2, lon then lat). InputError on a non-finite
/// value or a latitude beyond [-90, 90].
std::vector<double> lonlat_to_points(std::span<const double> lonlat, double radius = 1,
                                     const std::array<double, 3>& center = {0, 0, 0});

}  // namespace tessera
