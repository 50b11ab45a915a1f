// Point sets from VTK XML files, as ParaView and VTK's writers save them:
// .vtp (PolyData) and .vtu (UnstructuredGrid). The points are every piece's
// <Points> (three components, any numeric type), in piece order; labels and
// per-point scalars come from a named one-component point data array. Cells
// (verts, polys, connectivity) are not read: the points are the input.
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "tessera/io/points.hpp"
#include "vtk_xml_read.hpp"

namespace tessera::io::detail {
namespace {

/// The dataset's pieces with their point counts.
struct Pieces {
  std::vector<std::size_t> piece;
  std::vector<std::size_t> points;
  std::size_t total = 0;
};

Pieces pieces_of(const VtkXmlFile& file) {
  const std::size_t ds = file.child(file.root(), file.type());
  if (!ds) fail(file.path(), "no <" + file.type() + "> element");
  Pieces p;
  p.piece = file.children(ds, "Piece");
  if (p.piece.empty()) fail(file.path(), "no <Piece> in <" + file.type() + ">");
  for (std::size_t e : p.piece) {
    const std::string* np = file.attr(e, "NumberOfPoints");
    double n = 0;
    if (!np || !parse_doubles(*np, 1, &n) || n < 0 || n != std::floor(n) || n > 1e15)
      fail(file.path(), "missing or malformed NumberOfPoints in a <Piece>");
    p.points.push_back(static_cast<std::size_t>(n));
    p.total += static_cast<std::size_t>(n);
  }
  return p;
}

/// Number of components of DataArray `da` (VTK's default: 1).
std::size_t components(const VtkXmlFile& file, std::size_t da, const std::string& array) {
  const std::string* nc = file.attr(da, "NumberOfComponents");
  double c = 1;
  if (nc && (!parse_doubles(*nc, 1, &c) || c < 1 || c != std::floor(c) || c > 1e6))
    fail(file.path(), "array '" + array + "' has a malformed NumberOfComponents '" + *nc + "'");
  return static_cast<std::size_t>(c);
}

/// The one-component point data array `name` over all pieces, and whether
/// it holds floating-point values.
std::vector<double> point_array(const VtkXmlFile& file, const Pieces& p, const std::string& name, bool& is_float) {
  std::vector<double> out;  // (grown with the data read, not sized by the header)
  for (std::size_t k = 0; k < p.piece.size(); ++k) {
    const std::size_t pd = file.child(p.piece[k], "PointData");
    std::size_t da = 0;
    std::string names;
    if (pd)
      for (std::size_t c : file.children(pd, "DataArray")) {
        const std::string* nm = file.attr(c, "Name");
        const std::string n = nm ? *nm : std::string();
        if (n == name) {
          da = c;
          break;
        }
        names += (names.empty() ? "'" : ", '") + n + "'";
      }
    if (!da)
      fail(file.path(), "no point data array '" + name + "'" + (names.empty() ? std::string(" (the file has none)")
                                                                               : " (arrays: " + names + ")"));
    if (const std::size_t c = components(file, da, name); c != 1)
      fail(file.path(), "array '" + name + "' has " + std::to_string(c) + " components, expected 1");
    const ScalarType t = file.array_type(da, name);
    is_float = is_float || detail::is_float(t);
    bool big = false;
    const std::string bytes = file.array_bytes(da, p.points[k], name, big);
    const std::vector<double> v = values_as_double(bytes, t, big);
    out.insert(out.end(), v.begin(), v.end());
  }
  return out;
}

}  // namespace

PointCloud read_vtk_points(const std::string& path, const ReadOptions& options, const std::string& label_array) {
  const VtkXmlFile file(path, {"PolyData", "UnstructuredGrid"});
  const Pieces p = pieces_of(file);
  const int dim = options.dim ? options.dim : 3;
  PointCloud pc;
  pc.dim = dim;
  pc.n = p.total;
  for (std::size_t k = 0; k < p.piece.size(); ++k) {
    if (p.points[k] == 0) continue;
    const std::size_t pts = file.child(p.piece[k], "Points");
    const std::size_t da = pts ? file.child(pts, "DataArray") : 0;
    if (!da) fail(path, "a <Piece> of " + std::to_string(p.points[k]) + " points has no <Points> array");
    if (const std::size_t c = components(file, da, "Points"); c != 3)
      fail(path, "the points array has " + std::to_string(c) + " components, expected 3");
    bool big = false;
    const std::string bytes = file.array_bytes(da, 3 * p.points[k], "Points", big);
    const std::vector<double> xyz = values_as_double(bytes, file.array_type(da, "Points"), big);
    for (std::size_t i = 0; i < p.points[k]; ++i)
      for (int d = 0; d < dim; ++d) pc.coords.push_back(xyz[3 * i + static_cast<std::size_t>(d)]);
  }
  if (!label_array.empty()) {
    bool is_float = false;
    const std::vector<double> v = point_array(file, p, label_array, is_float);
    if (is_float) fail(path, "labels array '" + label_array + "' holds floating-point values, not integers");
    pc.labels = labels_from_values(path, label_array, v);
  }
  return pc;
}

std::vector<double> read_vtk_point_array(const std::string& path, const std::string& name) {
  const VtkXmlFile file(path, {"PolyData", "UnstructuredGrid"});
  bool is_float = false;
  return point_array(file, pieces_of(file), name, is_float);
}

}  // namespace tessera::io::detail
