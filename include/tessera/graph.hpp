// Front end: the adjacency graph of a tessellation — wheels and spokes.
//
// The graph connects every generator with its face neighbours: a spoke is a
// cell face seen as the link from the generator to the point (or domain-box
// plane) across it, and a generator's wheel is all of its spokes. It is read
// off the merged mesh of Cells, so it is exactly as symmetric as the cells
// (every spoke i -> j between two cells has its twin j -> i).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera {

struct GraphOptions {
  /// Drop spokes whose face is tiny, for parity with VTK's PruneTolerance
  /// (off by default: with exact topology no face needs pruning). A spoke is
  /// dropped when its face measure (area in 3D, length in 2D) is below
  ///   prune_tolerance * (mean cell volume)^((D-1)/D),
  /// i.e. relative to the face size of an average cell. Both directions of a
  /// face use one measure (computed in the lower generator's cell), so the
  /// decision is the same from either side and the graph stays symmetric.
  double prune_tolerance = 0;
  /// As VoronoiOptions::progress: called between chunks of cells (once per
  /// pass over them), it may throw Cancelled to stop.
  std::function<void(double)> progress;
};

/// Wheels and spokes as CSR over all n input points: the wheel of generator
/// g is spokes[wheel_offsets[g] .. wheel_offsets[g+1]). Points without a cell
/// (outside points, duplicates, points dropped outside the bounds) have empty
/// wheels. Within a wheel spokes are in ascending neighbour order, the
/// domain-box planes first: they are the negative ids of Cells::vertex_keys
/// (x0=-1, x1=-2, y0=-3, y1=-4, z0=-5, z1=-6).
struct AdjacencyGraph {
  int dim = 3;
  std::size_t n_points = 0;
  std::vector<std::int64_t> wheel_offsets;  ///< n_points + 1
  std::vector<std::int32_t> spokes;         ///< neighbour id, or a negative box-plane id
  std::vector<SpokeClass> spoke_class;      ///< per spoke, as in Cells::face_class
  /// Area (3D) or length (2D) of the face behind each spoke; equal for both
  /// directions of a face.
  std::vector<double> spoke_measure;
  /// Periodic boxes only, else empty: per spoke, dim shifts of the
  /// neighbour's image (Cells::neighbor_shifts). Within a wheel spokes are
  /// then ascending by neighbour, then shift, and the twin of spoke
  /// i -> (j, s) is j -> (i, -s).
  std::vector<std::int8_t> spoke_shift;
  std::array<bool, 3> periodic{false, false, false};
  /// Periodic boxes: Cells::lattice(), what a shift of one moves by.
  std::array<std::array<double, 3>, 3> lattice{};
  double prune_threshold = 0;               ///< absolute measure threshold used (0: no pruning)
  std::size_t pruned_spokes = 0;            ///< spokes dropped by pruning (each direction counted)

  std::size_t n_spokes() const { return spokes.size(); }
};

/// The graph of a tessellation computed with VoronoiOptions::build_mesh
/// (std::invalid_argument otherwise, and for cells that are some only,
/// Cells::partial), periodic boxes included. Throws InputError for a negative or
/// non-finite prune tolerance.
AdjacencyGraph adjacency_graph(const Cells& cells, const GraphOptions& options = {});

/// The undirected edges between generators: one per face between two cells
/// (from the lower id to the higher; in a periodic box from the lower of
/// (i, j, s) and (j, i, -s), so an edge between a point and its own image is
/// listed once) and one per face between a cell and an outside point (from
/// the cell's generator); box spokes are not edges. Edges are listed in the
/// order of their spokes in the graph.
struct GraphEdges {
  std::vector<std::int32_t> ends;     ///< 2 point ids per edge
  std::vector<std::int64_t> spoke;    ///< index of the representing spoke in AdjacencyGraph::spokes
  /// Periodic boxes only: dim shifts per edge, of its second end's image.
  std::vector<std::int8_t> shift;
  std::size_t size() const { return spoke.size(); }
};
GraphEdges graph_edges(const AdjacencyGraph& graph);

}  // namespace tessera
