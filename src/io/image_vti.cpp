// VTK XML ImageData (.vti), read through VtkXmlFile (vtk_xml_read.hpp):
//
//     <ImageData WholeExtent="x0 x1 y0 y1 z0 z1" Origin="..." Spacing="..." Direction="1 0 0 0 1 0 0 0 1">
//       <Piece Extent="...">
//         <PointData Scalars="name">
//           <DataArray type="Int32" Name="name" ...>...</DataArray>
//
// Voxel (i, j, k) of extent [x0..x1]x[y0..y1]x[z0..z1] sits at Origin +
// (i, j, k) * Spacing, so the geometry's origin (voxel of index 0) is
// Origin + (x0, y0, z0) * Spacing: cropped extents keep their true positions.
// An image with one slice along z is 2D. Several pieces are assembled into
// the whole extent (they may share their boundary layer, as VTK's do).
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "image_detail.hpp"
#include "io_detail.hpp"
#include "vtk_xml_read.hpp"

namespace tessera::io::detail {
namespace {

bool parse_extent(std::string_view s, std::array<std::int64_t, 6>& e) {
  double d[6];
  if (!parse_doubles(s, 6, d)) return false;
  for (int k = 0; k < 6; ++k) {
    if (d[k] != std::floor(d[k]) || std::abs(d[k]) > 1e15) return false;
    e[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(d[k]);
  }
  for (int a = 0; a < 3; ++a)
    if (e[static_cast<std::size_t>(2 * a + 1)] < e[static_cast<std::size_t>(2 * a)]) return false;
  return true;
}

}  // namespace

RawImage read_vti_image(const std::string& path, const std::string& array) {
  const VtkXmlFile file(path, {"ImageData"});
  auto child = [&](std::size_t parent, const char* name) { return file.child(parent, name); };
  auto attr = [&](std::size_t e, const char* name) { return file.attr(e, name); };
  const std::size_t root = file.root();

  const std::size_t id = child(root, "ImageData");
  if (!id) fail(path, "no <ImageData> element");
  std::array<std::int64_t, 6> whole{};
  const std::string* we = attr(id, "WholeExtent");
  if (!we || !parse_extent(*we, whole)) fail(path, "missing or malformed WholeExtent");
  RawImage raw;
  ImageGeometry& g = raw.geometry;
  std::array<double, 3> origin{0, 0, 0};
  if (const std::string* o = attr(id, "Origin"); o && !parse_doubles(*o, 3, origin.data()))
    fail(path, "malformed Origin '" + *o + "'");
  if (const std::string* s = attr(id, "Spacing"); s && !parse_doubles(*s, 3, g.spacing.data()))
    fail(path, "malformed Spacing '" + *s + "'");
  if (const std::string* d = attr(id, "Direction")) {
    double m[9];
    if (!parse_doubles(*d, 9, m)) fail(path, "malformed Direction '" + *d + "'");
    // The identity, up to axes stored flipped (-1 on the diagonal: read reversed).
    for (int k = 0; k < 9; ++k)
      if (std::abs(std::abs(m[k]) - (k % 4 == 0 ? 1.0 : 0.0)) > 1e-9)
        fail(path, "Direction is not axis-aligned (rotated or permuted images are not supported; resample first)");
    for (std::size_t a = 0; a < 3; ++a) raw.flip[a] = m[4 * a] < 0;
  }
  // A negative Spacing flips its axis as a Direction of -1 does (VTK places
  // voxel i at Origin + Direction i Spacing): both together cancel.
  for (std::size_t a = 0; a < 3; ++a)
    if (g.spacing[a] < 0) {
      g.spacing[a] = -g.spacing[a];
      raw.flip[a] = !raw.flip[a];
    }
  for (std::size_t a = 0; a < 3; ++a) {
    g.size[a] = whole[2 * a + 1] - whole[2 * a] + 1;
    // Voxel i along an axis lies at Origin + i * spacing, or at Origin - i *
    // spacing where the Direction flips it (its last voxel is then the lowest).
    g.origin[a] = raw.flip[a] ? origin[a] - static_cast<double>(whole[2 * a + 1]) * g.spacing[a]
                              : origin[a] + static_cast<double>(whole[2 * a]) * g.spacing[a];
  }
  g.dim = g.size[2] == 1 ? 2 : 3;
  check_geometry(path, g);

  const std::vector<std::size_t> pieces = file.children(id, "Piece");
  if (pieces.empty()) fail(path, "no <Piece> in <ImageData>");

  // What the image is sized by is checked before it is allocated: a file
  // of 500 bytes claiming 10^10 voxels took 20 GB before it was refused.
  // Any encoding takes at least 1/1032 of a byte per voxel (zlib's most),
  // and the pieces must hold as many voxels as the whole (they may share
  // their borders).
  const std::size_t n = g.n_voxels();
  if (n / 1100 > file.size())
    fail(path, "WholeExtent '" + *we + "' has " + std::to_string(n) + " voxels, more than the file's " +
                   std::to_string(file.size()) + " bytes can hold");
  auto piece_extent = [&](std::size_t piece) {
    std::array<std::int64_t, 6> ext{};
    const std::string* pe = attr(piece, "Extent");
    if (!pe || !parse_extent(*pe, ext)) fail(path, "missing or malformed Piece Extent");
    for (std::size_t a = 0; a < 3; ++a)
      if (ext[2 * a] < whole[2 * a] || ext[2 * a + 1] > whole[2 * a + 1])
        fail(path, "Piece Extent '" + *pe + "' lies outside WholeExtent '" + *we + "'");
    return ext;
  };
  std::size_t in_pieces = 0;
  for (std::size_t piece : pieces) {
    const auto ext = piece_extent(piece);
    in_pieces += static_cast<std::size_t>((ext[1] - ext[0] + 1) * (ext[3] - ext[2] + 1) * (ext[5] - ext[4] + 1));
    if (in_pieces >= n) break;  // (and the sum stays below the whole's, far from overflow)
  }
  if (in_pieces < n) fail(path, "the Pieces do not cover WholeExtent");

  std::string chosen;  // the array name, fixed by the first piece
  std::vector<std::uint8_t> covered;  // sized with the image, once the first piece's data is read
  bool type_set = false;

  for (std::size_t piece : pieces) {
    const std::array<std::int64_t, 6> ext = piece_extent(piece);
    const std::size_t pd = child(piece, "PointData");
    std::vector<std::size_t> arrays;
    if (pd) arrays = file.children(pd, "DataArray");
    if (arrays.empty()) {
      const bool cells = child(piece, "CellData") && !file.children(child(piece, "CellData"), "DataArray").empty();
      fail(path, std::string("no point data array") + (cells ? " (cell data is not supported)" : ""));
    }
    if (chosen.empty()) {
      if (!array.empty())
        chosen = array;
      else if (const std::string* sc = attr(pd, "Scalars"); sc && !sc->empty())
        chosen = *sc;
      else
        chosen = attr(arrays[0], "Name") ? *attr(arrays[0], "Name") : std::string();
    }
    std::size_t da = 0;
    for (std::size_t c : arrays) {
      const std::string* nm = attr(c, "Name");
      if ((nm ? *nm : std::string()) == chosen) {
        da = c;
        break;
      }
    }
    if (!da) {
      std::string names;
      for (std::size_t c : arrays) names += (names.empty() ? "" : ", ") + (attr(c, "Name") ? *attr(c, "Name") : "?");
      fail(path, "no point data array named '" + chosen + "' (arrays: " + names + ")");
    }
    const ScalarType t = file.array_type(da, chosen);
    if (type_set && t != raw.type) fail(path, "array '" + chosen + "' changes type between pieces");
    raw.type = t;
    type_set = true;
    if (const std::string* nc = attr(da, "NumberOfComponents"); nc && trim(*nc) != "1")
      fail(path, "array '" + chosen + "' has " + *nc + " components: multi-component data is not supported");

    std::array<std::int64_t, 3> psize{};
    for (std::size_t a = 0; a < 3; ++a) psize[a] = ext[2 * a + 1] - ext[2 * a] + 1;
    const std::size_t pn = static_cast<std::size_t>(psize[0] * psize[1] * psize[2]);
    const std::size_t item = scalar_size(t);
    bool big = false;
    std::string bytes = file.array_bytes(da, pn, chosen, big);

    // Place the piece into the whole image.
    if (pieces.size() == 1) {
      if (psize[0] != g.size[0] || psize[1] != g.size[1] || psize[2] != g.size[2])
        fail(path, "the only Piece's Extent does not cover WholeExtent");
      raw.bytes = std::move(bytes);
      raw.big_endian = big;
      break;
    }
    if (raw.bytes.empty()) {
      raw.bytes.assign(n * item, '\0');
      covered.assign(n, 0);
      raw.big_endian = big;
    }
    if (big != raw.big_endian)  // ascii piece among binary ones: swap to the common order
      for (std::size_t k = 0; k < pn; ++k) std::reverse(bytes.begin() + k * item, bytes.begin() + (k + 1) * item);
    const std::size_t row = static_cast<std::size_t>(psize[0]) * item;
    for (std::int64_t z = 0; z < psize[2]; ++z)
      for (std::int64_t y = 0; y < psize[1]; ++y) {
        const std::size_t dst = g.index(ext[0] - whole[0], ext[2] - whole[2] + y, ext[4] - whole[4] + z);
        std::memcpy(raw.bytes.data() + dst * item,
                    bytes.data() + static_cast<std::size_t>(y + psize[1] * z) * row, row);
        std::fill_n(covered.begin() + static_cast<std::ptrdiff_t>(dst), psize[0], std::uint8_t{1});
      }
  }
  if (pieces.size() > 1 && std::find(covered.begin(), covered.end(), std::uint8_t{0}) != covered.end())
    fail(path, "the Pieces do not cover WholeExtent");
  return raw;
}

}  // namespace tessera::io::detail
