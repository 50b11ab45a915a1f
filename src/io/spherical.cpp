// Spherical Voronoi files; see spherical.hpp.
#include "tessera/io/spherical.hpp"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <vector>

#include "io_detail.hpp"
#include "ordered_chunks.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/vtk_polydata.hpp"

namespace tessera::io {
namespace {

bool has_cell(const SphericalVoronoi& sv, std::size_t i) { return sv.status[i] == SphereCellStatus::cell; }

std::int64_t count(std::span<const std::int64_t> offsets, std::size_t i) { return offsets[i + 1] - offsets[i]; }

}  // namespace

void write_spherical_cells(const std::string& path, const SphericalVoronoi& sv) {
  if (detail::lower_extension(path) != ".vtp")
    detail::fail(path, "unknown extension '" + detail::lower_extension(path) + "' for spherical cells (expected .vtp)");
  std::vector<std::int64_t> offsets{0};
  std::vector<std::int32_t> connectivity, generator, neighbors;
  std::vector<double> area;
  for (std::size_t i = 0; i < sv.n_points; ++i) {
    if (count(sv.region_offsets, i) < 3) continue;
    connectivity.insert(connectivity.end(), sv.region_vertices.begin() + sv.region_offsets[i],
                        sv.region_vertices.begin() + sv.region_offsets[i + 1]);
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
    generator.push_back(static_cast<std::int32_t>(i));
    neighbors.push_back(static_cast<std::int32_t>(count(sv.neighbor_offsets, i)));
    area.push_back(sv.areas[i]);
  }
  PolyData pd;
  pd.points = sv.vertices;
  pd.polys = {offsets, connectivity};
  pd.cell_data = {{"GeneratorId", std::span<const std::int32_t>(generator)},
                  {"Area", std::span<const double>(area)},
                  {"Neighbors", std::span<const std::int32_t>(neighbors)}};
  write_polydata(path, pd);
}

void write_spherical_triangles(const std::string& path, const SphericalVoronoi& sv, std::span<const double> points) {
  const std::string ext = detail::lower_extension(path);
  const std::size_t t = sv.n_vertices();
  if (ext == ".npy") {
    std::vector<std::int64_t> a(sv.triangles.begin(), sv.triangles.end());
    write_file_atomic(path, npy_bytes(a.data(), {t, 3}));
    return;
  }
  if (ext != ".vtp") detail::fail(path, "unknown extension '" + ext + "' for triangles (expected .vtp or .npy)");
  std::vector<std::int64_t> offsets(t + 1);
  for (std::size_t k = 0; k <= t; ++k) offsets[k] = static_cast<std::int64_t>(3 * k);
  std::vector<std::int32_t> ids(sv.n_points);
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<std::int32_t>(i);
  PolyData pd;
  pd.points = points;
  pd.polys = {offsets, sv.triangles};
  pd.point_data = {{"PointId", std::span<const std::int32_t>(ids)}};
  write_polydata(path, pd);
}

void write_spherical_table(const std::string& path, const SphericalVoronoi& sv) {
  const std::string ext = path == "-" ? ".csv" : detail::lower_extension(path);
  if (ext != ".csv" && ext != ".npy") detail::fail(path, "unknown table extension '" + ext + "' (expected .csv or .npy)");
  constexpr std::size_t cols = 7;
  auto row = [&](std::size_t i, double* r) {
    r[0] = static_cast<double>(i);
    r[1] = sv.areas[i];
    for (int d = 0; d < 3; ++d) r[2 + d] = sv.centroids[3 * i + static_cast<std::size_t>(d)];
    r[5] = static_cast<double>(count(sv.region_offsets, i));
    r[6] = static_cast<double>(count(sv.neighbor_offsets, i));
  };
  if (ext == ".npy") {
    std::vector<double> t;
    t.reserve(sv.n_cells() * cols);
    for (std::size_t i = 0; i < sv.n_points; ++i)
      if (has_cell(sv, i)) {
        double r[cols];
        row(i, r);
        t.insert(t.end(), r, r + cols);
      }
    write_file_atomic(path, npy_bytes(t.data(), {t.size() / cols, cols}));
    return;
  }
  write_file_atomic(path, [&](std::ostream& os) {
    os << "id,area,cx,cy,cz,edges,neighbors\n";
    // Rows formatted by chunks on the worker threads, written in order (as
    // the cells' table, tables.cpp).
    constexpr std::size_t kRowsPerChunk = 8192, kRowBytes = cols * 26;
    detail::write_ordered_chunks(sv.n_points, kRowsPerChunk, [&](std::size_t i0, std::size_t i1, std::vector<char>& out) {
      out.resize((i1 - i0) * kRowBytes);
      char* p = out.data();
      char* const end = p + out.size();
      for (std::size_t i = i0; i < i1; ++i) {
        if (!has_cell(sv, i)) continue;
        double r[cols];
        row(i, r);
        for (std::size_t k = 0; k < cols; ++k) {
          // Integers (id, counts) as integers, the measures in their shortest round-trip form.
          p = (k == 0 || k >= 5) ? std::to_chars(p, end, static_cast<std::int64_t>(r[k])).ptr : std::to_chars(p, end, r[k]).ptr;
          *p++ = k + 1 < cols ? ',' : '\n';
        }
      }
      out.resize(static_cast<std::size_t>(p - out.data()));
    }, [&](const char* data, std::size_t size) { os.write(data, static_cast<std::streamsize>(size)); });
  });
}

void write_spherical_neighbors(const std::string& path, const SphericalVoronoi& sv) {
  std::vector<std::int64_t> a;
  a.reserve(2 + sv.n_points + sv.neighbors.size());
  a.push_back(static_cast<std::int64_t>(sv.n_points));
  a.insert(a.end(), sv.neighbor_offsets.begin(), sv.neighbor_offsets.end());
  a.insert(a.end(), sv.neighbors.begin(), sv.neighbors.end());
  write_file_atomic(path, npy_bytes(a.data(), {a.size()}));
}

}  // namespace tessera::io
