// VTK output of a Delaunay triangulation: the input points and the simplices.
#pragma once

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

}  // namespace tessera::io
