// VTK output of a Delaunay triangulation: the input points and the simplices.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "tessera/delaunay.hpp"

namespace tessera::io {

/// .vtu: VTK_TETRA (3D) or VTK_TRIANGLE (2D) cells over all input points (2D
/// written with z = 0); .vtp (2D only): triangles as polygons. Cell data:
/// SimplexId (Int64). Point data: PointId (Int32). Written atomically. Throws
/// InputError on another extension, .vtp in 3D, an unwritable path, or
/// `points` not of the triangulation's n_points * dim coordinates.
/// A periodic triangulation (Delaunay::is_periodic) is written over its own
/// points as wrapped (`points` is not read), followed by one point at each
/// image a simplex uses; PointId names the point an image is of. `radii`
/// (a regular triangulation's, one per point, or empty) add point data Radius
/// (Float64; an image has its point's), for glyphs in ParaView.
void write_simplices_vtk(const std::string& path, const Delaunay& dt, std::span<const double> points,
                         std::span<const double> radii = {});

/// .vtp of facets (an alpha shape's boundary and singular facets: `facets`,
/// dim point ids each): 3D triangles as polygons, 2D segments as lines
/// (z = 0), over the points they use only (point data PointId: the input
/// point). Cell data, one per facet: SimplexId (Int64, the row of the
/// simplices written that it bounds, or -1) and Singular (UInt8). Written
/// atomically; throws as write_polydata.
void write_boundary_vtp(const std::string& path, int dim, std::span<const std::int32_t> facets,
                        std::span<const std::int64_t> simplex_id, std::span<const std::uint8_t> singular,
                        std::span<const double> points);

}  // namespace tessera::io
