// An alpha shape's boundary files (include/tessera/io/alpha_shape.hpp).
#include "tessera/io/alpha_shape.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/vtk_simplices.hpp"

namespace tessera::io {
namespace {

void append_number(std::string& s, double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  s += buf;
}

void write_geojson(const std::string& path, const Delaunay& dt, const AlphaShape& shape, std::span<const double> xy,
                   bool singular) {
  const BoundaryPolygons poly = boundary_polygons(dt, xy, shape);
  std::string s;
  auto point = [&](std::int32_t id) {
    s += "[";
    append_number(s, xy[2 * static_cast<std::size_t>(id)]);
    s += ",";
    append_number(s, xy[2 * static_cast<std::size_t>(id) + 1]);
    s += "]";
  };
  s += R"({"type":"FeatureCollection","features":[{"type":"Feature","properties":{"alpha":)";
  append_number(s, shape.alpha);
  s += R"(,"pieces":)" + std::to_string(shape.components) + R"(,"area":)";
  append_number(s, shape.volume);
  s += R"(,"length":)";
  append_number(s, shape.boundary_measure);
  s += R"(},"geometry":{"type":"MultiPolygon","coordinates":[)";
  for (std::size_t k = 0; k < poly.n_polygons(); ++k) {
    s += k ? ",[" : "[";
    for (auto r = poly.polygon_rings[k]; r != poly.polygon_rings[k + 1]; ++r) {
      s += r != poly.polygon_rings[k] ? ",[" : "[";
      const auto b = poly.ring_points[static_cast<std::size_t>(r)], e = poly.ring_points[static_cast<std::size_t>(r) + 1];
      for (auto i = b; i != e; ++i) {
        point(poly.points[static_cast<std::size_t>(i)]);
        s += ",";
      }
      point(poly.points[static_cast<std::size_t>(b)]);
      s += "]";
    }
    s += "]";
  }
  s += "]}}";
  if (singular && !shape.singular.empty()) {
    s += R"(,{"type":"Feature","properties":{"singular":true},"geometry":{"type":"MultiLineString","coordinates":[)";
    for (std::size_t f = 0; f < shape.n_singular(); ++f) {
      s += f ? ",[" : "[";
      point(shape.singular[2 * f]);
      s += ",";
      point(shape.singular[2 * f + 1]);
      s += "]";
    }
    s += "]}}";
  }
  s += "]}\n";
  write_file_atomic(path, s);
}

}  // namespace

void write_alpha_boundary(const std::string& path, const Delaunay& dt, const AlphaShape& shape,
                          std::span<const double> points, bool singular, bool kept_order) {
  if (dt.is_periodic())
    throw InputError(path + ": a periodic triangulation's boundary is not written (its facets meet images; "
                     "AlphaShape::boundary_shifts has them)");
  const bool npy = path == "-" || detail::ends_with_ci(path, ".npy");
  if (detail::ends_with_ci(path, ".geojson")) {
    if (shape.dim != 2) throw InputError(path + ": GeoJSON polygons are for a 2D shape (use .vtp or .npy in 3D)");
    write_geojson(path, dt, shape, points, singular);
    return;
  }
  std::vector<std::int32_t> facets(shape.boundary);
  if (singular) facets.insert(facets.end(), shape.singular.begin(), shape.singular.end());
  const std::size_t nf = facets.size() / static_cast<std::size_t>(shape.dim);
  if (detail::ends_with_ci(path, ".vtp")) {
    std::vector<std::int64_t> simplex(nf, -1);
    std::vector<std::uint8_t> is_singular(nf, 1);
    for (std::size_t f = 0; f < shape.n_boundary(); ++f) {
      const std::int32_t r = shape.boundary_simplex[f];
      simplex[f] = kept_order ? std::lower_bound(shape.simplex_rows.begin(), shape.simplex_rows.end(), r) -
                                    shape.simplex_rows.begin()
                              : r;
      is_singular[f] = 0;
    }
    write_boundary_vtp(path, shape.dim, facets, simplex, is_singular, points);
    return;
  }
  if (!npy) throw InputError(path + ": unknown extension for a boundary (use .vtp, .npy or, in 2D, .geojson)");
  std::vector<std::int64_t> ids(facets.begin(), facets.end());
  write_file_atomic(path, npy_bytes(ids.data(), {nf, static_cast<std::size_t>(shape.dim)}));
}

}  // namespace tessera::io
