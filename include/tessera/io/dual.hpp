// Writers for the dual products: the adjacency graph, face sets and flowers.
// VTK files are PolyData (.vtp, through write_polydata); arrays are .npy.
// Every file is written atomically; a bad path throws InputError.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include "tessera/faces.hpp"
#include "tessera/flower.hpp"
#include "tessera/graph.hpp"
#include "tessera/surface_nets.hpp"

namespace tessera::io {

/// The graph as lines: points are the n input points (`points`, n * dim), one
/// line per undirected edge (graph_edges). Point data: Region (Int32, the
/// label, 0 without labels). Cell data: SpokeClass (UInt8, tessera::SpokeClass)
/// and FaceArea (3D) / FaceLength (2D) (Float64, the face behind the edge).
/// A periodic box's graph (AdjacencyGraph::periodic): `points` are the
/// points as the cells took them (Cells::periodic_points), and an edge to an
/// image ends at an extra point there, after the n (point data PointId: the
/// point it is an image of; the n points' own ids for them).
void write_graph_vtp(const std::string& path, const AdjacencyGraph& graph, std::span<const double> points,
                     std::span<const std::int32_t> labels);

/// The wheels as one int64 .npy array in the layout of --neighbors, over all
/// points: a = [n_points, offsets (n_points+1), spokes...]; the spokes of point
/// p are a[n+2:][off[p]:off[p+1]], ascending, negative ids for box planes.
void write_graph_csr_npy(const std::string& path, const AdjacencyGraph& graph);

/// A periodic graph's spoke shifts (AdjacencyGraph::spoke_shift), int8 .npy
/// of shape (spokes, dim) aligned with the spokes of the CSR file.
void write_spoke_shifts_npy(const std::string& path, const AdjacencyGraph& graph);

/// The class of every spoke, uint8 .npy aligned with the spokes of the CSR file.
void write_spoke_classes_npy(const std::string& path, const AdjacencyGraph& graph);
/// AdjacencyGraph::spoke_measure, float64 (n_spokes,) in the order of the
/// wheels (write_graph_csr_npy): each spoke's face area (3D) or length (2D).
void write_spoke_measures_npy(const std::string& path, const AdjacencyGraph& graph);

/// A face set: points are its vertices; 3D faces are polygons, 2D faces lines.
/// Cell data: BoundaryLabels (Int32, 2 components: side 0, side 1), Sides
/// (Int32, 2 components: side 0's generator, side 1's generator or negative
/// box-plane id) and SpokeClass (UInt8). Conventions: include/tessera/faces.hpp.
void write_faces_vtp(const std::string& path, const FaceSet& faces);

/// A surface net: the face set's file (above) plus point data VertexKind
/// (UInt8: 0 surface, 1 junction, 2 corner) and cell data PolygonId (Int64:
/// the Voronoi face each output face came from).
void write_surface_net_vtp(const std::string& path, const SurfaceNet& net);

/// Roles of the points and cells in a flower file (point and cell data "Role").
enum class FlowerRole : std::uint8_t {
  generator = 0,        ///< the site (a vertex cell)
  petal_centre = 1,     ///< a cell vertex (a vertex cell)
  neighbor = 2,         ///< a point that clipped the cell (a vertex cell)
  spoke = 3,            ///< line from the site to a neighbour
  cell = 4,             ///< a face of the cell (3D) / the tile (2D)
  petal_glyph = 5,      ///< circle / sphere of a petal (and its points)
  circumflower_glyph = 6,  ///< circle / sphere of the circumflower (and its points)
};

/// Value of the "Spoke" cell data for cells that are not spokes or faces.
inline constexpr std::int32_t kNoSpoke = std::numeric_limits<std::int32_t>::min();

/// Flowers as one PolyData. Points: per flower its site, petal centres,
/// neighbour points (and glyph points). Point data: Radius (Float64: the
/// circumflower radius at the site, the petal radius at a petal centre and on
/// its glyph, 0 at neighbours), Role (UInt8, FlowerRole), GeneratorId (Int32,
/// the flower's generator), PointId (Int32, input id of sites and neighbours,
/// -1 otherwise). Cells: a vertex per site, petal centre and neighbour; a line
/// per spoke; the cell's faces (the tile in 2D); with `glyphs`, a circle
/// (closed polyline, 2D) or sphere (polygons, 3D) per petal and for the
/// circumflower. Cell data: Role, GeneratorId, and Spoke (Int32: the
/// neighbour of a spoke line or face, negative for a box plane, kNoSpoke
/// otherwise).
void write_flowers_vtp(const std::string& path, std::span<const Flower> flowers, std::span<const double> points,
                       bool glyphs);

}  // namespace tessera::io
