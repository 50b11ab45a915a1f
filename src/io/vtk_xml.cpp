// VTK XML writer for Voronoi cells (see include/tessera/io/vtk_xml.hpp).
//
// Layout: one <Piece>; every DataArray is format="appended" and lives in a single
// <AppendedData encoding="raw"> block at the end of the file, each as a UInt64
// byte count followed by the raw values in native (little-endian on x86/ARM)
// byte order. The XML header needs every array's byte offset, so all sizes are
// computed first (cheap: they follow from the CSR offsets) and the arrays are then
// streamed through a 4 MiB buffer. The two largest 3D arrays (connectivity and
// faces) are formatted by chunks of cells in parallel and written in order
// (ordered_chunks.hpp); besides their chunk buffers, 3D allocates one uint32 per
// vertex per thread (the stamps of cell_vertex_lists.hpp, which lists each
// cell's distinct vertices) and one int64 per cell (offsets).
//
// 3D (.vtu, UnstructuredGrid, file version 1.0 as written by VTK 9.0-9.3):
//   connectivity  Int32  unique vertex ids of each cell (first-appearance order)
//   offsets       Int64  end of each cell in connectivity
//   types         UInt8  42 (VTK_POLYHEDRON)
//   faces         Int32  per cell: nFaces, then per face nPts, ids... (outward ccw)
//   faceoffsets   Int64  end of each cell's record in faces
// 2D (.vtp, PolyData): Polys connectivity (Int32) / offsets (Int64), one polygon
//   per cell made of the first vertex of each of its edges (already ccw).
// Int32 ids halve the largest arrays (faces is ~100 values per 3D cell); vertex ids
// are int32 in Cells anyway, and VTK converts any integer type to vtkIdType on read.
// Offsets are Int64 because `faces` passes 2^31 entries at ~20M cells.
#include "tessera/io/vtk_xml.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io_detail.hpp"  // ends_with_ci
#include "ordered_chunks.hpp"
#include "tessera/cell_vertex_lists.hpp"
#include "tessera/io/atomic_file.hpp"

namespace tessera::io {
namespace {

constexpr std::uint8_t kVtkPolyhedron = 42;
/// Cells per chunk of the parallel formatting (ordered_chunks.hpp): ~1.5 MB
/// of 3D faces, small enough that writing starts early.
constexpr std::size_t kCellsPerChunk = 4096;

const char* byte_order() {
  return std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
}


/// Buffered raw writer: values are appended to a fixed buffer that is flushed
/// with one ostream::write per block. Once the stream has failed (disk full...)
/// nothing more is written; the stream stays bad, so write_file_atomic discards
/// the temporary and reports the underlying error (errno), which an exception
/// thrown from here would hide.
class BlockWriter {
 public:
  explicit BlockWriter(std::ostream& os) : os_(os), buf_(kSize) {}

  template <class T>
  void put(T v) {
    if (used_ + sizeof(T) > kSize) flush();
    std::memcpy(buf_.data() + used_, &v, sizeof(T));
    used_ += sizeof(T);
  }
  /// Contiguous data goes straight to the stream (after what is buffered).
  void put_bytes(const void* p, std::size_t n) {
    if (n == 0) return;
    flush();
    if (os_) os_.write(static_cast<const char*>(p), static_cast<std::streamsize>(n));
  }
  void flush() {
    if (used_ == 0) return;
    if (os_) os_.write(buf_.data(), static_cast<std::streamsize>(used_));
    used_ = 0;
  }

 private:
  static constexpr std::size_t kSize = std::size_t(1) << 22;  // 4 MiB
  std::ostream& os_;
  std::vector<char> buf_;
  std::size_t used_ = 0;
};

/// Stores `v` at `p` (any alignment) and returns the next position.
template <class T>
char* store(char* p, T v) {
  std::memcpy(p, &v, sizeof(T));
  return p + sizeof(T);
}

/// One appended DataArray: its XML attributes and its payload size in bytes.
struct ArraySpec {
  std::string type;   // VTK type name: Int32, Int64, UInt8, Float64
  std::string name;
  int components = 1;
  std::uint64_t bytes = 0;
  std::uint64_t offset = 0;  // into the appended block, filled by layout()
};

void layout(std::vector<ArraySpec*> arrays) {
  std::uint64_t off = 0;
  for (ArraySpec* a : arrays) {
    a->offset = off;
    off += sizeof(std::uint64_t) + a->bytes;  // UInt64 header + payload
  }
}

void append_data_array(std::string& xml, const ArraySpec& a, const char* indent) {
  xml += indent;
  xml += "<DataArray type=\"" + a.type + "\" Name=\"" + a.name + "\"";
  if (a.components != 1) xml += " NumberOfComponents=\"" + std::to_string(a.components) + "\"";
  xml += " format=\"appended\" offset=\"" + std::to_string(a.offset) + "\"/>\n";
}

void begin_block(BlockWriter& w, const ArraySpec& a) { w.put<std::uint64_t>(a.bytes); }

/// Validates the CSR arrays the writer indexes, so a malformed Cells cannot make
/// it read out of bounds. These are programming errors, not input errors.
void check_mesh(const Cells& c) {
  const std::size_t nc = c.n_cells();
  auto fail = [](const char* what) {
    throw std::invalid_argument(std::string("write_cells_vtk: ") + what);
  };
  if (c.dim != 2 && c.dim != 3) fail("dim must be 2 or 3");
  if (c.cell_face_offsets.size() != nc + 1)
    fail("cells have no mesh (compute them with VoronoiOptions::build_mesh = true)");
  if (c.region.size() != nc || c.volume.size() != nc || c.num_faces.size() != nc ||
      c.neighbor_offsets.size() != nc + 1)
    fail("per-cell arrays have inconsistent sizes");
  auto monotone = [](std::span<const std::int64_t> o) {
    if (o.empty() || o.front() != 0) return false;
    for (std::size_t i = 1; i < o.size(); ++i)
      if (o[i] < o[i - 1]) return false;
    return true;
  };
  if (!monotone(c.cell_face_offsets) || !monotone(c.face_vertex_offsets) || !monotone(c.neighbor_offsets))
    fail("CSR offsets must start at 0 and never decrease");
  const std::size_t nf = static_cast<std::size_t>(c.cell_face_offsets.back());
  if (c.face_vertex_offsets.size() != nf + 1 ||
      static_cast<std::size_t>(c.face_vertex_offsets.back()) != c.face_vertices.size())
    fail("face arrays have inconsistent sizes");
  if (c.vertices.size() % static_cast<std::size_t>(c.dim) != 0) fail("bad vertex array");
  const std::int64_t nv = static_cast<std::int64_t>(c.vertices.size() / c.dim);
  for (std::int32_t v : c.face_vertices)
    if (v < 0 || v >= nv) fail("face vertex id out of range");
  if (c.dim == 2)
    for (std::size_t f = 0; f < nf; ++f)
      if (c.face_vertex_offsets[f + 1] - c.face_vertex_offsets[f] < 1) fail("2D edge without vertices");
}

void write_cell_data(BlockWriter& w, const Cells& c, const ArraySpec& gid, const ArraySpec& reg,
                     const ArraySpec& vol, const ArraySpec& nfaces, const ArraySpec& nnb) {
  const std::size_t nc = c.n_cells();
  begin_block(w, gid);
  w.put_bytes(c.generator.data(), nc * sizeof(std::int32_t));
  begin_block(w, reg);
  w.put_bytes(c.region.data(), nc * sizeof(std::int32_t));
  begin_block(w, vol);
  w.put_bytes(c.volume.data(), nc * sizeof(double));
  begin_block(w, nfaces);
  w.put_bytes(c.num_faces.data(), nc * sizeof(std::int32_t));
  begin_block(w, nnb);
  for (std::size_t i = 0; i < nc; ++i)
    w.put<std::int32_t>(static_cast<std::int32_t>(c.neighbor_offsets[i + 1] - c.neighbor_offsets[i]));
}

std::string xml_prolog(const char* type) {
  std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"";
  xml += type;
  xml += "\" version=\"1.0\" byte_order=\"";
  xml += byte_order();
  xml += "\" header_type=\"UInt64\">\n";
  return xml;
}

constexpr const char* kEpilog = "\n  </AppendedData>\n</VTKFile>\n";

void write_vtu(const std::string& path, const Cells& c) {
  const std::size_t nc = c.n_cells();
  const std::size_t nv = c.vertices.size() / 3;
  const auto& cfo = c.cell_face_offsets;
  const auto& fvo = c.face_vertex_offsets;
  const auto& fv = c.face_vertices;

  // Connectivity: each cell's distinct vertices in first-appearance order
  // (cell_vertex_lists.hpp), counted first for the offsets, then streamed.
  const CellVertexLists corners(c);
  const std::vector<std::int64_t> conn_offsets = corners.offsets();
  const std::int64_t total_conn = conn_offsets[nc];
  const std::uint64_t n_faces = static_cast<std::uint64_t>(cfo.back());
  const std::uint64_t faces_len = nc + n_faces + fv.size();

  ArraySpec gid{"Int32", "GeneratorId", 1, nc * 4}, reg{"Int32", "Region", 1, nc * 4},
      vol{"Float64", "Volume", 1, nc * 8}, nfaces{"Int32", "NumberOfFaces", 1, nc * 4},
      nnb{"Int32", "NumberOfNeighbors", 1, nc * 4};
  ArraySpec pts{"Float64", "Points", 3, nv * 3 * 8};
  ArraySpec conn{"Int32", "connectivity", 1, static_cast<std::uint64_t>(total_conn) * 4},
      offs{"Int64", "offsets", 1, nc * 8}, types{"UInt8", "types", 1, nc},
      faces{"Int32", "faces", 1, faces_len * 4}, faceoffs{"Int64", "faceoffsets", 1, nc * 8};
  layout({&gid, &reg, &vol, &nfaces, &nnb, &pts, &conn, &offs, &types, &faces, &faceoffs});

  std::string xml = xml_prolog("UnstructuredGrid");
  xml += "  <UnstructuredGrid>\n";
  xml += "    <Piece NumberOfPoints=\"" + std::to_string(nv) + "\" NumberOfCells=\"" +
         std::to_string(nc) + "\">\n";
  xml += "      <PointData>\n      </PointData>\n";
  xml += "      <CellData Scalars=\"Region\">\n";
  for (const ArraySpec* a : {&gid, &reg, &vol, &nfaces, &nnb}) append_data_array(xml, *a, "        ");
  xml += "      </CellData>\n      <Points>\n";
  append_data_array(xml, pts, "        ");
  xml += "      </Points>\n      <Cells>\n";
  for (const ArraySpec* a : {&conn, &offs, &types, &faces, &faceoffs})
    append_data_array(xml, *a, "        ");
  xml += "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n";
  xml += "  <AppendedData encoding=\"raw\">\n   _";

  write_file_atomic(path, [&](std::ostream& os) {
    BlockWriter w(os);
    w.put_bytes(xml.data(), xml.size());
    write_cell_data(w, c, gid, reg, vol, nfaces, nnb);

    begin_block(w, pts);
    w.put_bytes(c.vertices.data(), nv * 3 * sizeof(double));

    begin_block(w, conn);
    detail::write_ordered_chunks(nc, kCellsPerChunk, [&](std::size_t c0, std::size_t c1, std::vector<char>& out) {
      out.resize(static_cast<std::size_t>(conn_offsets[c1] - conn_offsets[c0]) * 4);
      char* p = out.data();
      for (std::size_t ci = c0; ci < c1; ++ci)
        corners.for_each(ci, [&](std::int32_t v) { p = store<std::int32_t>(p, v); });
    }, [&](const char* data, std::size_t size) { w.put_bytes(data, size); });
    begin_block(w, offs);
    w.put_bytes(conn_offsets.data() + 1, nc * sizeof(std::int64_t));  // each cell's end
    begin_block(w, types);
    const std::vector<std::uint8_t> type_chunk(std::min<std::size_t>(nc, 1 << 16), kVtkPolyhedron);
    for (std::size_t done = 0; done < nc; done += type_chunk.size())
      w.put_bytes(type_chunk.data(), std::min(type_chunk.size(), nc - done));

    begin_block(w, faces);
    detail::write_ordered_chunks(nc, kCellsPerChunk, [&](std::size_t c0, std::size_t c1, std::vector<char>& out) {
      // Per cell: its number of faces, then per face its size and vertex ids.
      const std::int64_t f0 = cfo[c0], f1 = cfo[c1];
      out.resize(4 * static_cast<std::size_t>((c1 - c0) + (f1 - f0) + (fvo[f1] - fvo[f0])));
      char* p = out.data();
      for (std::size_t ci = c0; ci < c1; ++ci) {
        p = store<std::int32_t>(p, static_cast<std::int32_t>(cfo[ci + 1] - cfo[ci]));
        for (std::int64_t f = cfo[ci]; f < cfo[ci + 1]; ++f) {
          const std::int64_t n = fvo[f + 1] - fvo[f];
          p = store<std::int32_t>(p, static_cast<std::int32_t>(n));
          std::memcpy(p, fv.data() + fvo[f], static_cast<std::size_t>(n) * 4);  // ids are Int32 already
          p += n * 4;
        }
      }
    }, [&](const char* data, std::size_t size) { w.put_bytes(data, size); });
    begin_block(w, faceoffs);
    std::int64_t end = 0;
    for (std::size_t ci = 0; ci < nc; ++ci) {
      end += 1 + (cfo[ci + 1] - cfo[ci]) + (fvo[cfo[ci + 1]] - fvo[cfo[ci]]);
      w.put<std::int64_t>(end);
    }
    w.put_bytes(kEpilog, std::strlen(kEpilog));
    w.flush();
  });
}

void write_vtp(const std::string& path, const Cells& c) {
  const std::size_t nc = c.n_cells();
  const std::size_t nv = c.vertices.size() / 2;
  const auto& cfo = c.cell_face_offsets;
  const auto& fvo = c.face_vertex_offsets;
  const std::uint64_t n_edges = static_cast<std::uint64_t>(cfo.back());

  ArraySpec gid{"Int32", "GeneratorId", 1, nc * 4}, reg{"Int32", "Region", 1, nc * 4},
      vol{"Float64", "Area", 1, nc * 8}, nfaces{"Int32", "NumberOfEdges", 1, nc * 4},
      nnb{"Int32", "NumberOfNeighbors", 1, nc * 4};
  ArraySpec pts{"Float64", "Points", 3, nv * 3 * 8};
  ArraySpec conn{"Int32", "connectivity", 1, n_edges * 4}, offs{"Int64", "offsets", 1, nc * 8};
  layout({&gid, &reg, &vol, &nfaces, &nnb, &pts, &conn, &offs});

  std::string xml = xml_prolog("PolyData");
  xml += "  <PolyData>\n";
  xml += "    <Piece NumberOfPoints=\"" + std::to_string(nv) +
         "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
         std::to_string(nc) + "\">\n";
  xml += "      <PointData>\n      </PointData>\n";
  xml += "      <CellData Scalars=\"Region\">\n";
  for (const ArraySpec* a : {&gid, &reg, &vol, &nfaces, &nnb}) append_data_array(xml, *a, "        ");
  xml += "      </CellData>\n      <Points>\n";
  append_data_array(xml, pts, "        ");
  xml += "      </Points>\n      <Polys>\n";
  append_data_array(xml, conn, "        ");
  append_data_array(xml, offs, "        ");
  xml += "      </Polys>\n    </Piece>\n  </PolyData>\n";
  xml += "  <AppendedData encoding=\"raw\">\n   _";

  write_file_atomic(path, [&](std::ostream& os) {
    BlockWriter w(os);
    w.put_bytes(xml.data(), xml.size());
    write_cell_data(w, c, gid, reg, vol, nfaces, nnb);

    begin_block(w, pts);  // VTK points are always 3D: z = 0
    for (std::size_t i = 0; i < nv; ++i) {
      w.put<double>(c.vertices[2 * i]);
      w.put<double>(c.vertices[2 * i + 1]);
      w.put<double>(0.0);
    }
    begin_block(w, conn);  // polygon = first vertex of each edge, in order
    for (std::uint64_t f = 0; f < n_edges; ++f) w.put<std::int32_t>(c.face_vertices[fvo[f]]);
    begin_block(w, offs);
    for (std::size_t ci = 0; ci < nc; ++ci) w.put<std::int64_t>(cfo[ci + 1]);
    w.put_bytes(kEpilog, std::strlen(kEpilog));
    w.flush();
  });
}

}  // namespace

void write_cells_vtk(const std::string& path, const Cells& cells) {
  // Extension first: it is the caller's input, and the cheapest check.
  const bool vtu = detail::ends_with_ci(path, ".vtu"), vtp = detail::ends_with_ci(path, ".vtp");
  if (cells.dim == 3 && !vtu)
    throw InputError("cannot write " + path + ": 3D cells are written as VTK UnstructuredGrid (.vtu)" +
                     (vtp ? "; .vtp is for 2D" : ""));
  if (cells.dim == 2 && !vtp)
    throw InputError("cannot write " + path + ": 2D cells are written as VTK PolyData (.vtp)" +
                     (vtu ? "; .vtu is for 3D" : ""));
  check_mesh(cells);
  if (cells.dim == 3)
    write_vtu(path, cells);
  else
    write_vtp(path, cells);
}

}  // namespace tessera::io
