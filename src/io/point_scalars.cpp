// io::read_point_scalars (include/tessera/io/points.hpp): a .npy array, or a
// named .ply vertex property / text column / structured .npy field of the
// points' own file.
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"

namespace tessera::io {

std::vector<double> read_point_scalars(const std::string& points_path, const std::string& source,
                                       const FramePlace& frame) {
  if (source.empty()) throw InputError("no scalars given (a .npy file or a property/column name)");
  if (detail::lower_extension(source) == ".npy") {
    NpyArray a = read_npy_double(source);
    if (a.kind == 'b') detail::fail(source, "scalars must be floats or integers, found dtype bool");
    if (!(a.shape.size() == 1 || (a.shape.size() == 2 && a.shape[1] == 1))) {
      std::string shape = "(";
      for (std::size_t k = 0; k < a.shape.size(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape[k]);
      detail::fail(source, "scalars must be a 1-D array, found shape " + shape + ")");
    }
    return std::move(a.as_double);
  }
  const std::string ext = detail::lower_extension(points_path);
  if (ext == ".ply") return detail::read_ply_property(points_path, source);
  if (ext == ".vtp" || ext == ".vtu") return detail::read_vtk_point_array(points_path, source);
  if (ext == ".vtk") return detail::read_vtk_legacy_point_array(points_path, source);
  if (ext == ".pcd") return detail::read_pcd_field(points_path, source);
  if (ext == ".las" || ext == ".laz") return detail::read_las_field(points_path, source);
  if (detail::is_dump_extension(ext)) return detail::read_dump_column(points_path, source, frame);
  if (ext == ".csv" || ext == ".xyz" || ext == ".txt") return detail::read_text_column(points_path, source, frame);
  if (ext == ".npy") {  // a field of a structured array
    NpyRecords r = read_npy_records(points_path, [&](const std::string& name) { return name == source; });
    for (auto& f : r.fields)
      if (f.taken) return std::move(f.values);
    if (r.structured) detail::fail(points_path, "no field '" + source + "' for scalars");
  }
  detail::fail(points_path, "scalars '" + source + "': name a .ply property, a .csv column, a .vtp/.vtu/.vtk point data "
                            "array, a LAMMPS dump's column or a field of a .pcd, a .las or a structured .npy, or give a .npy file");
}

}  // namespace tessera::io
