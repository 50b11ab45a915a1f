// Per-cell tables (.csv / .npy) and CSR neighbour lists (.npy). All writes
// go through write_file_atomic, so a failed write leaves no partial file.
#include "tessera/io/tables.hpp"

#include <charconv>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "io_detail.hpp"
#include "ordered_chunks.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"

namespace tessera::io {
namespace {

/// Cells come from our own engine, so inconsistent sizes are a programming
/// error (std::invalid_argument), not an input error.
void check_cells(const Cells& c) {
  const std::size_t n = c.n_cells();
  const std::size_t d = c.dim == 2 ? 2 : 3;
  const bool ok = (c.dim == 2 || c.dim == 3) && c.region.size() == n && c.volume.size() == n &&
                  c.centroid.size() == n * d && c.num_faces.size() == n &&
                  (c.neighbor_offsets.size() == n + 1 || (n == 0 && c.neighbor_offsets.empty())) &&
                  (c.neighbor_offsets.empty() ||
                   (c.neighbor_offsets.front() == 0 &&
                    static_cast<std::size_t>(c.neighbor_offsets.back()) == c.neighbors.size()));
  if (!ok) throw std::invalid_argument("tessera::io: inconsistent Cells (per-cell array sizes differ)");
}

std::int64_t neighbor_count(const Cells& c, std::size_t i) {
  return c.neighbor_offsets[i + 1] - c.neighbor_offsets[i];
}

/// Columns of the table, in order: id, region, volume/area, centroid (dim), faces/edges, neighbors.
std::size_t table_columns(const Cells& c) { return c.dim == 2 ? 7 : 8; }

void write_csv(const std::string& path, const Cells& c) {
  write_file_atomic(path, [&c](std::ostream& os) {
    const std::size_t d = static_cast<std::size_t>(c.dim);
    const char* header =
        c.dim == 2 ? "id,region,area,cx,cy,edges,neighbors\n" : "id,region,volume,cx,cy,cz,faces,neighbors\n";
    os.write(header, static_cast<std::streamsize>(std::strlen(header)));
    // Rows are formatted by chunks on the worker threads (doubles in their
    // shortest form that round-trips, which dominates) and written in order.
    constexpr std::size_t kRowsPerChunk = 8192;
    constexpr std::size_t kRowBytes = 8 * 24 + 8;  // every field at its longest, and the separators
    detail::write_ordered_chunks(c.n_cells(), kRowsPerChunk, [&](std::size_t i0, std::size_t i1, std::vector<char>& out) {
      out.resize((i1 - i0) * kRowBytes);
      char* p = out.data();
      char* const end = p + out.size();
      auto field = [&](auto v, char sep) {
        p = std::to_chars(p, end, v).ptr;
        *p++ = sep;
      };
      for (std::size_t i = i0; i < i1; ++i) {
        field(c.generator[i], ',');
        field(c.region[i], ',');
        field(c.volume[i], ',');
        for (std::size_t k = 0; k < d; ++k) field(c.centroid[i * d + k], ',');
        field(c.num_faces[i], ',');
        field(neighbor_count(c, i), '\n');
      }
      out.resize(static_cast<std::size_t>(p - out.data()));
    }, [&](const char* data, std::size_t size) { os.write(data, static_cast<std::streamsize>(size)); });
  });
}

void write_table_npy(const std::string& path, const Cells& c) {
  const std::size_t n = c.n_cells();
  const std::size_t d = static_cast<std::size_t>(c.dim);
  const std::size_t cols = table_columns(c);
  std::vector<double> t(n * cols);
  for (std::size_t i = 0; i < n; ++i) {
    double* row = &t[i * cols];
    std::size_t k = 0;
    row[k++] = c.generator[i];
    row[k++] = c.region[i];
    row[k++] = c.volume[i];
    for (std::size_t a = 0; a < d; ++a) row[k++] = c.centroid[i * d + a];
    row[k++] = c.num_faces[i];
    row[k++] = static_cast<double>(neighbor_count(c, i));
  }
  write_file_atomic(path, npy_bytes(t.data(), {n, cols}));
}

}  // namespace

void write_cell_table(const std::string& path, const Cells& cells) {
  const std::string ext = path == "-" ? ".csv" : detail::lower_extension(path);
  if (ext != ".csv" && ext != ".npy")
    detail::fail(path, "unknown table extension '" + ext + "' (expected .csv or .npy)");
  check_cells(cells);
  if (ext == ".csv")
    write_csv(path, cells);
  else
    write_table_npy(path, cells);
}

void write_neighbors_npy(const std::string& path, const Cells& cells) {
  check_cells(cells);
  const std::size_t n = cells.n_cells();
  std::vector<std::int64_t> a;
  a.reserve(1 + (n + 1) + cells.neighbors.size());
  a.push_back(static_cast<std::int64_t>(n));
  if (cells.neighbor_offsets.empty())
    a.push_back(0);  // n == 0 without offsets
  else
    a.insert(a.end(), cells.neighbor_offsets.begin(), cells.neighbor_offsets.end());
  a.insert(a.end(), cells.neighbors.begin(), cells.neighbors.end());
  write_file_atomic(path, npy_bytes(a.data(), {a.size()}));
}

}  // namespace tessera::io
