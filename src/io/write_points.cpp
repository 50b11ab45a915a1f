// io::write_points (include/tessera/io/points.hpp): labelled points to .npy
// (+ sidecar arrays), .ply (binary little-endian) or .vtp (VTK PolyData
// vertices). Each file is written atomically; the paths are all checked
// writable before the first one is written.
//
// 2D points: .npy keeps shape (n, 2); .ply and .vtp have no 2D form, so they
// get z = 0 (read them back with dim 2 to drop it).
#include <bit>
#include <cstring>
#include <limits>
#include <ostream>
#include <string>

#include "io_detail.hpp"
#include "tessera/io/atomic_file.hpp"
#include "tessera/io/npy.hpp"
#include "tessera/io/points.hpp"
#include "tessera/io/vtk_polydata.hpp"

namespace tessera::io {
namespace {

/// A scalar array's name must be usable as a .ply property, an XML attribute
/// and part of a file name.
void check_name(const std::string& path, const std::string& name) {
  bool ok = !name.empty() && name.size() <= 64;
  for (char c : name)
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                c == '-' || c == '.');
  if (!ok)
    throw InputError("cannot write " + path + ": array name '" + name +
                     "' (use 1 to 64 letters, digits, '_', '-' or '.')");
  if (name == "x" || name == "y" || name == "z" || name == "label")
    throw InputError("cannot write " + path + ": array name '" + name + "' is taken (x, y, z, label)");
}

/// `path` with its 4-character extension (".npy") replaced by `suffix`.
std::string sidecar(const std::string& path, const std::string& suffix) {
  return path.substr(0, path.size() - 4) + suffix;
}

template <class T>
void put_le(char*& p, T v) {
  if constexpr (std::endian::native == std::endian::big) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    for (std::size_t k = 0; k < sizeof(T); ++k) *p++ = static_cast<char>(b[sizeof(T) - 1 - k]);
  } else {
    std::memcpy(p, &v, sizeof(T));
    p += sizeof(T);
  }
}

void write_ply(const std::string& path, const LabelledPoints& pts, const WritePointsOptions& opt) {
  const std::size_t n = pts.size();
  const auto dim = static_cast<std::size_t>(pts.dim);
  const bool labelled = !pts.labels.empty() || opt.labelled;
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by tessera";
  if (pts.dim == 2) header += " (2D points, z = 0)";
  header += "\nelement vertex " + std::to_string(n) + "\nproperty double x\nproperty double y\nproperty double z\n";
  if (labelled) header += "property int label\n";
  for (const auto& [name, values] : opt.scalars) header += "property double " + name + "\n";
  header += "end_header\n";
  const std::size_t row = 3 * sizeof(double) + (labelled ? sizeof(std::int32_t) : 0) +
                          opt.scalars.size() * sizeof(double);
  write_file_atomic(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    constexpr std::size_t kRows = 4096;
    std::string buf(kRows * row, '\0');
    for (std::size_t first = 0; first < n && os; first += kRows) {
      const std::size_t last = std::min(n, first + kRows);
      char* p = buf.data();
      for (std::size_t i = first; i < last; ++i) {
        for (std::size_t d = 0; d < 3; ++d) put_le<double>(p, d < dim ? pts.coords[i * dim + d] : 0.0);
        if (labelled) put_le<std::int32_t>(p, pts.labels[i]);
        for (const auto& s : opt.scalars) put_le<double>(p, s.second[i]);
      }
      os.write(buf.data(), static_cast<std::streamsize>((last - first) * row));
    }
  });
}

void write_vtp(const std::string& path, const LabelledPoints& pts, const WritePointsOptions& opt) {
  const std::size_t n = pts.size();
  if (n > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError("cannot write " + path + ": more than 2^31 - 1 points in one .vtp");
  std::vector<std::int64_t> offsets(n + 1);
  std::vector<std::int32_t> connectivity(n);
  for (std::size_t i = 0; i <= n; ++i) offsets[i] = static_cast<std::int64_t>(i);
  for (std::size_t i = 0; i < n; ++i) connectivity[i] = static_cast<std::int32_t>(i);
  PolyData pd;
  pd.dim = pts.dim;
  pd.points = pts.coords;
  pd.verts = CellArray{offsets, connectivity};
  if (!pts.labels.empty() || opt.labelled)
    pd.point_data.push_back({"label", std::span<const std::int32_t>(pts.labels), 1});
  for (const auto& [name, values] : opt.scalars) pd.point_data.push_back({name, values, 1});
  write_polydata(path, pd);
}

}  // namespace

std::vector<std::string> write_points(const std::string& path, const LabelledPoints& points,
                                      const WritePointsOptions& options) {
  if (points.dim != 2 && points.dim != 3)
    throw InputError("cannot write " + path + ": points must be 2D or 3D, not " + std::to_string(points.dim) + "D");
  if (points.coords.size() % static_cast<std::size_t>(points.dim) != 0)
    throw InputError("cannot write " + path + ": " + std::to_string(points.coords.size()) +
                     " coordinates are not a whole number of " + std::to_string(points.dim) + "D points");
  const std::size_t n = points.size();
  if ((!points.labels.empty() || options.labelled) && points.labels.size() != n)
    throw InputError("cannot write " + path + ": " + std::to_string(points.labels.size()) + " labels for " +
                     std::to_string(n) + " points");
  for (std::size_t k = 0; k < options.scalars.size(); ++k) {
    const auto& [name, values] = options.scalars[k];
    check_name(path, name);
    if (values.size() != n)
      throw InputError("cannot write " + path + ": array '" + name + "' has " + std::to_string(values.size()) +
                       " values for " + std::to_string(n) + " points");
    for (std::size_t j = 0; j < k; ++j)
      if (options.scalars[j].first == name)
        throw InputError("cannot write " + path + ": two arrays named '" + name + "'");
  }

  const std::string ext = path == "-" ? ".ply" : detail::lower_extension(path);  // standard output: one stream
  std::vector<std::string> written;
  if (ext == ".npy") {
    // All paths first, so that a bad sidecar path stops the run before any write.
    std::vector<std::string> paths{path};
    const bool labelled = !points.labels.empty() || options.labelled;
    if (labelled) paths.push_back(options.labels_path.empty() ? sidecar(path, "_labels.npy") : options.labels_path);
    for (const auto& s : options.scalars) paths.push_back(sidecar(path, "_" + s.first + ".npy"));
    for (std::size_t a = 0; a < paths.size(); ++a) {
      for (std::size_t b = 0; b < a; ++b)
        if (paths[a] == paths[b]) throw InputError("cannot write " + paths[a] + ": the same file twice");
      check_writable(paths[a]);
    }
    // All or none: a new points file beside the old labels would pair wrongly.
    OutputGroup group;
    std::size_t k = 0;
    write_file_atomic(paths[k++], npy_bytes(points.coords.data(), {n, static_cast<std::size_t>(points.dim)}));
    if (labelled) write_file_atomic(paths[k++], npy_bytes(points.labels.data(), {n}));
    for (const auto& s : options.scalars) write_file_atomic(paths[k++], npy_bytes(s.second.data(), {n}));
    group.commit();
    return paths;
  }
  if (ext == ".ply") {
    check_writable(path);
    write_ply(path, points, options);
  } else if (ext == ".vtp") {
    check_writable(path);
    write_vtp(path, points, options);
  } else {
    throw InputError("cannot write " + path + ": unknown extension '" + ext + "' for points (expected .npy, .ply, .vtp)");
  }
  written.push_back(path);
  return written;
}

}  // namespace tessera::io
