// VTK XML PolyData writer over borrowed arrays (include/tessera/io/vtk_polydata.hpp).
//
// Same file layout as the cells writer (src/io/vtk_xml.cpp): one <Piece>, every
// DataArray format="appended" in one raw <AppendedData> block, each payload a
// UInt64 byte count followed by the values in native byte order. Here every
// payload already lies in memory as a contiguous span, so arrays are written
// straight from the caller's storage; only 2D points (padded with z = 0) and
// the cell offsets (VTK stores the ends, without the leading 0) are rewritten.
#include "tessera/io/vtk_polydata.hpp"

#include <bit>
#include <ostream>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "io_detail.hpp"
#include "tessera/io/atomic_file.hpp"

namespace tessera::io {
namespace {

template <class T>
const char* vtk_type_name();
template <> const char* vtk_type_name<std::uint8_t>() { return "UInt8"; }
template <> const char* vtk_type_name<std::int32_t>() { return "Int32"; }
template <> const char* vtk_type_name<std::int64_t>() { return "Int64"; }
template <> const char* vtk_type_name<double>() { return "Float64"; }

/// One appended block: its XML attributes, its size, and how to write its payload.
struct Block {
  std::string type, name;
  int components = 1;
  std::uint64_t bytes = 0;
  const void* data = nullptr;  ///< contiguous payload, or null for a computed one
};

std::string data_array_xml(const Block& b, std::uint64_t offset, const char* indent) {
  std::string xml = indent;
  xml += "<DataArray type=\"" + b.type + "\" Name=\"" + b.name + "\"";
  if (b.components != 1) xml += " NumberOfComponents=\"" + std::to_string(b.components) + "\"";
  xml += " format=\"appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
  return xml;
}

Block block_of(const DataArray& a, std::size_t tuples, const char* where) {
  return std::visit(
      [&](auto span) {
        using T = typename decltype(span)::value_type;
        if (a.components < 1 || span.size() != tuples * static_cast<std::size_t>(a.components))
          throw std::invalid_argument("write_polydata: " + std::string(where) + " array " + a.name + " has " +
                                      std::to_string(span.size()) + " values for " + std::to_string(tuples) +
                                      " tuples of " + std::to_string(a.components));
        return Block{vtk_type_name<std::remove_const_t<T>>(), a.name, a.components, span.size_bytes(), span.data()};
      },
      a.values);
}

void check_cells(const CellArray& cells, std::size_t n_points, const char* kind) {
  auto fail = [kind](const char* what) {
    throw std::invalid_argument(std::string("write_polydata: ") + kind + ": " + what);
  };
  if (cells.offsets.empty()) {
    if (!cells.connectivity.empty()) fail("connectivity without offsets");
    return;
  }
  if (cells.offsets.front() != 0 || static_cast<std::size_t>(cells.offsets.back()) != cells.connectivity.size())
    fail("offsets do not span the connectivity");
  for (std::size_t i = 1; i < cells.offsets.size(); ++i)
    if (cells.offsets[i] < cells.offsets[i - 1]) fail("offsets decrease");
  for (std::int32_t p : cells.connectivity)
    if (p < 0 || static_cast<std::size_t>(p) >= n_points) fail("point id out of range");
}

}  // namespace

void write_polydata(const std::string& path, const PolyData& pd) {
  if (detail::lower_extension(path) != ".vtp")
    throw InputError("cannot write " + path + ": this output is VTK PolyData (.vtp)");
  if (pd.dim != 2 && pd.dim != 3) throw std::invalid_argument("write_polydata: dim must be 2 or 3");
  if (pd.points.size() % static_cast<std::size_t>(pd.dim) != 0)
    throw std::invalid_argument("write_polydata: point array length is not a multiple of dim");
  const std::size_t np = pd.points.size() / static_cast<std::size_t>(pd.dim);
  const CellArray* kinds[3] = {&pd.verts, &pd.lines, &pd.polys};
  const char* section[3] = {"Verts", "Lines", "Polys"};
  std::size_t n_cells = 0;
  for (int k = 0; k < 3; ++k) {
    check_cells(*kinds[k], np, section[k]);
    n_cells += kinds[k]->size();
  }

  // Blocks in file order: point data, cell data, points, then per cell kind
  // connectivity and offsets.
  std::vector<Block> blocks;
  for (const DataArray& a : pd.point_data) blocks.push_back(block_of(a, np, "point data"));
  for (const DataArray& a : pd.cell_data) blocks.push_back(block_of(a, n_cells, "cell data"));
  const std::size_t points_block = blocks.size();
  blocks.push_back({"Float64", "Points", 3, np * 3 * sizeof(double), pd.dim == 3 ? pd.points.data() : nullptr});
  for (const CellArray* c : kinds) {
    blocks.push_back({"Int32", "connectivity", 1, c->connectivity.size_bytes(), c->connectivity.data()});
    blocks.push_back({"Int64", "offsets", 1, c->size() * sizeof(std::int64_t),
                      c->size() ? c->offsets.data() + 1 : nullptr});
  }
  std::vector<std::uint64_t> offset(blocks.size());
  std::uint64_t at = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    offset[b] = at;
    at += sizeof(std::uint64_t) + blocks[b].bytes;
  }

  std::string xml = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"";
  xml += std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
  xml += "\" header_type=\"UInt64\">\n  <PolyData>\n";
  xml += "    <Piece NumberOfPoints=\"" + std::to_string(np) + "\" NumberOfVerts=\"" +
         std::to_string(pd.verts.size()) + "\" NumberOfLines=\"" + std::to_string(pd.lines.size()) +
         "\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(pd.polys.size()) + "\">\n";
  std::size_t b = 0;
  xml += "      <PointData>\n";
  for (std::size_t i = 0; i < pd.point_data.size(); ++i, ++b) xml += data_array_xml(blocks[b], offset[b], "        ");
  xml += "      </PointData>\n      <CellData>\n";
  for (std::size_t i = 0; i < pd.cell_data.size(); ++i, ++b) xml += data_array_xml(blocks[b], offset[b], "        ");
  xml += "      </CellData>\n      <Points>\n";
  xml += data_array_xml(blocks[b], offset[b], "        ");
  ++b;
  xml += "      </Points>\n";
  for (const char* s : section) {
    xml += std::string("      <") + s + ">\n";
    xml += data_array_xml(blocks[b], offset[b], "        ");
    xml += data_array_xml(blocks[b + 1], offset[b + 1], "        ");
    xml += std::string("      </") + s + ">\n";
    b += 2;
  }
  xml += "    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";

  write_file_atomic(path, [&](std::ostream& os) {
    os.write(xml.data(), static_cast<std::streamsize>(xml.size()));
    for (std::size_t i = 0; i < blocks.size() && os; ++i) {
      const std::uint64_t bytes = blocks[i].bytes;
      os.write(reinterpret_cast<const char*>(&bytes), sizeof bytes);
      if (blocks[i].data != nullptr) {
        os.write(static_cast<const char*>(blocks[i].data), static_cast<std::streamsize>(bytes));
      } else if (i == points_block) {  // 2D: (x, y) -> (x, y, 0)
        for (std::size_t p = 0; p < np; ++p) {
          const double xyz[3] = {pd.points[2 * p], pd.points[2 * p + 1], 0.0};
          os.write(reinterpret_cast<const char*>(xyz), sizeof xyz);
        }
      }
    }
    os << "\n  </AppendedData>\n</VTKFile>\n";
  });
}

}  // namespace tessera::io
