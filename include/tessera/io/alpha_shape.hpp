// Files of an alpha shape's boundary (tessera::alpha_shape): what the CLI's
// `delaunay --boundary` and Python's AlphaShape.save write.
#pragma once

#include <span>
#include <string>

#include "tessera/alpha_shape.hpp"

namespace tessera::io {

/// The boundary facets (AlphaShape::boundary), then with `singular` the
/// singular ones, to `path` by its extension, atomically:
/// * .vtp: triangles (2D segments) over the points they use, point data
///   PointId, cell data SimplexId (the simplex a boundary facet bounds, -1
///   for singular ones: with `kept_order` its index among the kept
///   simplices, as the CLI's --simplices lists them, else its row of `dt`)
///   and Singular (0/1);
/// * .npy: int64 (B, D) point ids in that order ("-": standard output);
/// * .geojson (2D): a FeatureCollection of one MultiPolygon, a polygon per
///   piece (boundary_polygons(): outer ring counter-clockwise, holes
///   clockwise, each closed by repeating its first point, as RFC 7946 asks)
///   with the shape's alpha, pieces, area and length as properties, and with
///   `singular` a MultiLineString of the singular segments.
/// Throws InputError on another extension, .geojson in 3D, a periodic
/// triangulation, or a path that cannot be written.
void write_alpha_boundary(const std::string& path, const Delaunay& dt, const AlphaShape& shape,
                          std::span<const double> points, bool singular, bool kept_order);

}  // namespace tessera::io
