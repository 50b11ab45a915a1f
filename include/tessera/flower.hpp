// Front end: the flower of a cell, for debugging and teaching.
//
// Each vertex v of the cell of generator p is the centre of a petal: the ball
// (disk in 2D) through p centred at v, of radius |v - p|. A candidate point
// clips the cell iff it lies inside some petal; the union of the petals is
// the flower. The circumflower — the ball around p of twice the largest petal
// radius, the security radius — contains the flower, so the neighbour search
// stops once it has visited every point within it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tessera/cells.hpp"

namespace tessera {

struct Flower {
  int dim = 3;
  std::int32_t generator = -1;
  std::array<double, 3> site{0, 0, 0};      ///< the generator's position (z = 0 in 2D; in a periodic box as wrapped)
  /// Petals: one per cell vertex. The centres are the cell's merged vertices
  /// (their ids in Cells in `vertex_ids`), in ascending vertex id.
  std::vector<std::int32_t> vertex_ids;
  std::vector<double> petal_centres;        ///< n_petals * dim
  std::vector<double> petal_radii;          ///< distance from each centre to the generator
  double circumflower_radius = 0;           ///< 2 * max petal radius: the security radius
  /// The cell: its faces (3D polygons, 2D edges) as CSR over petal indices,
  /// oriented as in Cells, with the spoke across each face (neighbour id, or
  /// negative box-plane id).
  std::vector<std::int64_t> face_offsets;   ///< n_faces + 1
  std::vector<std::int32_t> face_vertices;  ///< indices into the petals
  std::vector<std::int32_t> face_neighbor;
  /// The neighbours that clipped the cell (generators across its faces), ascending.
  std::vector<std::int32_t> neighbors;
  /// Where each neighbour is (n_neighbors * dim): its point, or in a periodic
  /// box the image across the face (its point as wrapped, moved by its shift).
  std::vector<double> neighbor_positions;
  /// Periodic boxes only, else empty: the shift of each neighbour's image
  /// (n_neighbors * dim, Cells::neighbor_shifts) and of each face's
  /// (n_faces * dim, Cells::face_shift; 0 for a wall).
  std::vector<std::int8_t> neighbor_shifts;
  std::vector<std::int8_t> face_shifts;

  std::size_t n_petals() const { return petal_radii.size(); }
};

/// Flowers of the cells of points `ids`, from cells computed with
/// VoronoiOptions::build_mesh (std::invalid_argument otherwise) on `points`
/// (n * dim, the same array). Throws InputError when an id is out of range or
/// its point owns no cell (outside label, duplicate, outside the bounds).
/// The cells may be some only, VoronoiOptions::only = `ids` (the CLI's and
/// Python's flower of points): the same flowers as from all cells at the
/// cost of a few (2M uniform 3D points: 0.24 s of CPU against 26 s,
/// docs/design.md, "Flowers"), but for `vertex_ids`, which number the
/// merged vertices of the cells built (in the same order), and in a
/// periodic box whose cells all need a wider layer of images than these
/// (VoronoiOptions::only): the petals may then come in another order.
std::vector<Flower> flowers(const Cells& cells, std::span<const double> points, std::span<const std::int32_t> ids);

}  // namespace tessera
