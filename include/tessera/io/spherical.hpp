// Files of spherical Voronoi cells (tessera::spherical_voronoi). Every write
// is atomic (write_file_atomic): a failure leaves no partial file.
#pragma once

#include <span>
#include <string>

#include "tessera/spherical_voronoi.hpp"

namespace tessera::io {

/// The cells as VTK polygons on the sphere (.vtp): points are the cell
/// vertices, one polygon per cell of three or more vertices (in id order,
/// counter-clockwise seen from outside), cell data GeneratorId (int32), Area
/// (float64), Neighbors (int32).
void write_spherical_cells(const std::string& path, const SphericalVoronoi& sv);

/// The dual triangles (the spherical Delaunay triangulation, the hull's
/// facets, counter-clockwise seen from outside) over the input points:
/// .vtp (points = `points`, n x 3, point data PointId) or .npy (int64 (T, 3)).
void write_spherical_triangles(const std::string& path, const SphericalVoronoi& sv, std::span<const double> points);

/// One row per point that has a cell, in id order: .csv with the header
/// `id,area,cx,cy,cz,edges,neighbors` (the centroid on the sphere) or .npy
/// float64 (rows, 7) with those columns.
void write_spherical_table(const std::string& path, const SphericalVoronoi& sv);

/// Neighbour lists of every point (empty for duplicates and hidden points)
/// as one int64 .npy in the layout of write_neighbors_npy:
/// [n, offsets[0..n], ids...].
void write_spherical_neighbors(const std::string& path, const SphericalVoronoi& sv);

}  // namespace tessera::io
