// Per-cell tables and neighbour lists.
#pragma once

#include <string>

#include "tessera/cells.hpp"

namespace tessera::io {

/// Per-cell table, one row per cell in generator-id order.
/// .csv: header `id,region,volume,cx,cy,cz,faces,neighbors` (2D:
/// `id,region,area,cx,cy,edges,neighbors`), doubles with 17 significant digits.
/// .npy: float64 array (n_cells, 8) (2D: (n_cells, 7)) with the same columns.
/// `-`: the CSV on standard output (write_file_atomic).
void write_cell_table(const std::string& path, const Cells& cells);

/// Neighbour lists as one int64 .npy array in CSR layout:
///   [n_cells, offsets[0..n_cells] (n_cells+1 values), generator ids of cell 0..., ...]
/// i.e. a = np.load(f); n = a[0]; off = a[1:n+2]; ids = a[n+2:];
/// neighbours of cell c (generator cells.generator[c]) = ids[off[c]:off[c+1]].
void write_neighbors_npy(const std::string& path, const Cells& cells);

}  // namespace tessera::io
