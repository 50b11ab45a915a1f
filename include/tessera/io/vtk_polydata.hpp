// A general VTK XML PolyData (.vtp) writer over borrowed arrays: points,
// vertex / line / polygon cells, and named point and cell data. The dual
// products (graph, face sets, flowers) are written through it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

namespace tessera::io {

/// A named array of `components` values per tuple (borrowed, not copied).
struct DataArray {
  std::string name;
  std::variant<std::span<const std::uint8_t>, std::span<const std::int32_t>, std::span<const std::int64_t>,
               std::span<const double>>
      values;
  int components = 1;
};

/// Cells of one kind as CSR: offsets (n + 1 values, the first 0) into
/// connectivity (point ids). A line cell with more than two points is a polyline.
struct CellArray {
  std::span<const std::int64_t> offsets;
  std::span<const std::int32_t> connectivity;
  std::size_t size() const { return offsets.empty() ? 0 : offsets.size() - 1; }
};

struct PolyData {
  int dim = 3;                      ///< coordinates per point in `points`; 2D is written with z = 0
  std::span<const double> points;   ///< n_points * dim
  CellArray verts, lines, polys;
  std::vector<DataArray> point_data;  ///< one tuple per point
  /// One tuple per cell, in VTK's cell order: the verts, then the lines, then the polys.
  std::vector<DataArray> cell_data;
};

/// Writes `pd` as VTK XML PolyData (binary appended, as write_cells_vtk)
/// atomically. Throws InputError when the path does not end in .vtp or cannot
/// be written, std::invalid_argument when the arrays are inconsistent (a
/// point id out of range, an array of the wrong length).
void write_polydata(const std::string& path, const PolyData& pd);

}  // namespace tessera::io
