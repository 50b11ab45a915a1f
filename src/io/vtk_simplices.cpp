// VTK output of a Delaunay triangulation (include/tessera/io/vtk_simplices.hpp).
//
// The .vtu layout follows the cells writer (src/io/vtk_xml.cpp): one <Piece>,
// every DataArray appended raw in one <AppendedData> block, each payload a
// UInt64 byte count and then the values in native (little-endian) order.
// Simplices are all of one type, so offsets and types are generated on the fly.
#include "tessera/io/vtk_simplices.hpp"

#include <array>
#include <cstdint>
#include <map>
#include <numeric>
#include <ostream>
#include <vector>

#include "io_detail.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/vtk_polydata.hpp"

namespace tessera::io {
namespace {

constexpr std::uint8_t kVtkTriangle = 5, kVtkTetra = 10;

template <class T>
void put(std::ostream& os, const T& v) {
  os.write(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// point_id: per point of `points`, the point it is (an image's), or empty:
/// its own index. radii: per point id, or empty (no Radius array).
void write_vtu(const std::string& path, const Delaunay& dt, std::span<const double> points,
               std::span<const std::int32_t> point_id, std::span<const double> radii) {
  const int D = dt.dim;
  const std::size_t n = dt.n_points, m = dt.n_simplices(), w = static_cast<std::size_t>(D + 1);
  struct Array { const char* type; const char* name; int comps; std::uint64_t bytes; };
  const Array arrays[] = {
      {"Int32", "PointId", 1, n * 4},
      {"Int64", "SimplexId", 1, m * 8},
      {"Float64", "Points", 3, n * 3 * 8},
      {"Int32", "connectivity", 1, m * w * 4},
      {"Int64", "offsets", 1, m * 8},
      {"UInt8", "types", 1, m},
      {"Float64", "Radius", 1, n * 8},  // written only with radii, last in the appended block
  };
  const int n_arrays = radii.empty() ? 6 : 7;
  std::uint64_t offsets[7], at = 0;
  for (int k = 0; k < n_arrays; ++k) {
    offsets[k] = at;
    at += 8 + arrays[k].bytes;
  }
  auto id_of = [&](std::size_t i) { return point_id.empty() ? static_cast<std::int32_t>(i) : point_id[i]; };
  auto tag = [&](int k, const char* indent) {
    std::string s = std::string(indent) + "<DataArray type=\"" + arrays[k].type + "\" Name=\"" + arrays[k].name + "\"";
    if (arrays[k].comps != 1) s += " NumberOfComponents=\"" + std::to_string(arrays[k].comps) + "\"";
    return s + " format=\"appended\" offset=\"" + std::to_string(offsets[k]) + "\"/>\n";
  };
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" +
      std::to_string(n) + "\" NumberOfCells=\"" + std::to_string(m) + "\">\n";
  xml += "      <PointData>\n" + tag(0, "        ") + (radii.empty() ? "" : tag(6, "        ")) + "      </PointData>\n";
  xml += "      <CellData>\n" + tag(1, "        ") + "      </CellData>\n";
  xml += "      <Points>\n" + tag(2, "        ") + "      </Points>\n";
  xml += "      <Cells>\n" + tag(3, "        ") + tag(4, "        ") + tag(5, "        ") + "      </Cells>\n";
  xml += "    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";

  write_file_atomic(path, [&](std::ostream& os) {
    os << xml;
    std::vector<char> buf;
    auto flush = [&] { os.write(buf.data(), static_cast<std::streamsize>(buf.size())); buf.clear(); };
    auto emit = [&](const auto& v) {
      const char* p = reinterpret_cast<const char*>(&v);
      buf.insert(buf.end(), p, p + sizeof(v));
      if (buf.size() > (1u << 20)) flush();
    };
    emit(arrays[0].bytes);
    for (std::size_t i = 0; i < n; ++i) emit(id_of(i));
    emit(arrays[1].bytes);
    for (std::size_t s = 0; s < m; ++s) emit(static_cast<std::int64_t>(s));
    emit(arrays[2].bytes);
    for (std::size_t i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) emit(d < D ? points[i * static_cast<std::size_t>(D) + static_cast<std::size_t>(d)] : 0.0);
    flush();
    put(os, arrays[3].bytes);
    os.write(reinterpret_cast<const char*>(dt.simplices.data()), static_cast<std::streamsize>(arrays[3].bytes));
    emit(arrays[4].bytes);
    for (std::size_t s = 1; s <= m; ++s) emit(static_cast<std::int64_t>(s * w));
    emit(arrays[5].bytes);
    for (std::size_t s = 0; s < m; ++s) emit(D == 3 ? kVtkTetra : kVtkTriangle);
    if (!radii.empty()) {
      emit(arrays[6].bytes);
      for (std::size_t i = 0; i < n; ++i) emit(radii[static_cast<std::size_t>(id_of(i))]);
    }
    flush();
    os << "\n  </AppendedData>\n</VTKFile>\n";
  });
}

void write_vtp(const std::string& path, const Delaunay& dt, std::span<const double> points,
               std::span<const std::int32_t> point_id, std::span<const double> radii) {
  const std::size_t m = dt.n_simplices();
  std::vector<std::int64_t> offsets(m + 1);
  for (std::size_t s = 0; s <= m; ++s) offsets[s] = static_cast<std::int64_t>(3 * s);
  std::vector<std::int64_t> ids(m);
  std::iota(ids.begin(), ids.end(), 0);
  std::vector<std::int32_t> pids(point_id.begin(), point_id.end());
  if (pids.empty()) {
    pids.resize(dt.n_points);
    std::iota(pids.begin(), pids.end(), 0);
  }
  PolyData pd;
  pd.dim = 2;
  pd.points = points;
  pd.polys = {offsets, dt.simplices};
  pd.point_data.push_back({"PointId", std::span<const std::int32_t>(pids), 1});
  std::vector<double> radius;
  if (!radii.empty()) {
    for (const std::int32_t id : pids) radius.push_back(radii[static_cast<std::size_t>(id)]);
    pd.point_data.push_back({"Radius", std::span<const double>(radius), 1});
  }
  pd.cell_data.push_back({"SimplexId", std::span<const std::int64_t>(ids), 1});
  write_polydata(path, pd);
}

}  // namespace

/// A periodic triangulation as a plain one: the points as wrapped, then one
/// point per image a simplex uses (in order of first use), the rows over them.
struct Unrolled {
  Delaunay dt;
  std::vector<double> points;
  std::vector<std::int32_t> point_id;
};

Unrolled unroll(const Delaunay& dt) {
  const auto du = static_cast<std::size_t>(dt.dim);
  const auto lattice = periodic_lattice(dt.bounds, dt.tilt);
  Unrolled u;
  u.dt.dim = dt.dim;
  u.points = dt.periodic_points;
  u.point_id.resize(dt.n_points);
  std::iota(u.point_id.begin(), u.point_id.end(), 0);
  u.dt.simplices.resize(dt.simplices.size());
  std::map<std::pair<std::int32_t, std::array<std::int8_t, 3>>, std::int32_t> images;
  for (std::size_t e = 0; e < dt.simplices.size(); ++e) {
    const std::int32_t id = dt.simplices[e];
    std::array<std::int8_t, 3> s{0, 0, 0};
    for (std::size_t a = 0; a < du; ++a) s[a] = dt.simplex_shifts[e * du + a];
    if (s == std::array<std::int8_t, 3>{0, 0, 0}) {
      u.dt.simplices[e] = id;
      continue;
    }
    const auto [it, fresh] = images.try_emplace({id, s}, static_cast<std::int32_t>(u.point_id.size()));
    if (fresh) {
      double x[3];
      periodic_image(lattice, dt.dim, &dt.periodic_points[static_cast<std::size_t>(id) * du], s, x);
      u.points.insert(u.points.end(), x, x + du);
      u.point_id.push_back(id);
    }
    u.dt.simplices[e] = it->second;
  }
  u.dt.n_points = u.point_id.size();
  return u;
}

void write_simplices_vtk(const std::string& path, const Delaunay& dt, std::span<const double> points,
                         std::span<const double> radii) {
  const std::string ext = detail::lower_extension(path);
  if (!radii.empty() && radii.size() != dt.n_points)
    throw InputError("cannot write " + path + ": " + std::to_string(radii.size()) + " radii for " +
                     std::to_string(dt.n_points) + " points");
  // The rows index the points: a span of another input would be read past
  // its end (a periodic triangulation carries its wrapped points itself).
  if (!dt.is_periodic() && points.size() != dt.n_points * static_cast<std::size_t>(dt.dim))
    throw InputError("cannot write " + path + ": " + std::to_string(points.size()) + " coordinates for the " +
                     std::to_string(dt.n_points) + " points of a " + std::to_string(dt.dim) + "D triangulation");
  if (dt.is_periodic() && (ext == ".vtu" || (ext == ".vtp" && dt.dim == 2))) {
    const Unrolled u = unroll(dt);
    return ext == ".vtu" ? write_vtu(path, u.dt, u.points, u.point_id, radii)
                         : write_vtp(path, u.dt, u.points, u.point_id, radii);
  }
  if (ext == ".vtu") return write_vtu(path, dt, points, {}, radii);
  if (ext == ".vtp" && dt.dim == 2) return write_vtp(path, dt, points, {}, radii);
  if (ext == ".vtp")
    throw InputError("cannot write " + path + ": 3D Delaunay output is an unstructured grid (.vtu)");
  throw InputError("cannot write " + path + ": unknown extension '" + ext + "' (use .vtu, or .vtp in 2D)");
}

void write_boundary_vtp(const std::string& path, int dim, std::span<const std::int32_t> facets,
                        std::span<const std::int64_t> simplex_id, std::span<const std::uint8_t> singular,
                        std::span<const double> points) {
  const auto d = static_cast<std::size_t>(dim);
  const std::size_t nf = facets.size() / d;
  // The points the facets use, in ascending id order, renumbered.
  std::vector<std::int32_t> slot(points.size() / d, -1), point_id;
  for (const std::int32_t v : facets) slot[static_cast<std::size_t>(v)] = 0;
  for (std::size_t v = 0; v < slot.size(); ++v)
    if (slot[v] == 0) {
      slot[v] = static_cast<std::int32_t>(point_id.size());
      point_id.push_back(static_cast<std::int32_t>(v));
    }
  std::vector<double> xyz;
  xyz.reserve(point_id.size() * d);
  for (const std::int32_t v : point_id)
    xyz.insert(xyz.end(), points.begin() + static_cast<std::ptrdiff_t>(v * d),
               points.begin() + static_cast<std::ptrdiff_t>((v + 1) * d));
  std::vector<std::int32_t> conn(facets.size());
  for (std::size_t e = 0; e < facets.size(); ++e) conn[e] = slot[static_cast<std::size_t>(facets[e])];
  std::vector<std::int64_t> offsets(nf + 1);
  for (std::size_t f = 0; f <= nf; ++f) offsets[f] = static_cast<std::int64_t>(f * d);
  PolyData pd;
  pd.dim = dim;
  pd.points = xyz;
  if (dim == 3) pd.polys = {offsets, conn};
  else pd.lines = {offsets, conn};
  pd.point_data.push_back({"PointId", std::span<const std::int32_t>(point_id)});
  pd.cell_data.push_back({"SimplexId", simplex_id});
  pd.cell_data.push_back({"Singular", singular});
  write_polydata(path, pd);
}

}  // namespace tessera::io
