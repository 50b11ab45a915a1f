// read_points: dispatch by extension, then the checks common to all formats
// (non-empty, finite coordinates, labels of the right length).
#include "tessera/io/points.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>

#include "io_detail.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/npy.hpp"

namespace tessera::io {

namespace detail {

void fail(const std::string& path, std::string_view what) {
  std::string msg = path;
  msg += ": ";
  msg += what;
  throw InputError(msg);  // one printable line, whatever got spliced in (one_printable_line)
}

void check_readable(const std::string& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) {
    const int err = ec ? ec.value() : ENOENT;
    throw InputError("cannot open " + path + ": " + std::strerror(err));
  }
  if (std::filesystem::is_directory(st))
    throw InputError("cannot open " + path + ": " + std::strerror(EISDIR));
  // A device never ends (/dev/zero, /dev/urandom) or is a disk: read whole,
  // it took all memory. Pipes and FIFOs end, and are read (<(command)).
  if (std::filesystem::is_character_file(st) || std::filesystem::is_block_file(st) ||
      std::filesystem::is_socket(st))
    throw InputError("cannot read " + path + ": a device or socket, not a file");
}

std::string read_file_bytes(const std::string& path) {
  check_readable(path);
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> f(std::fopen(path.c_str(), "rb"));
  if (!f) throw InputError("cannot open " + path + ": " + std::strerror(errno));
  std::string bytes;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec) bytes.reserve(size);
  // Read in blocks until EOF: file_size is only a hint (pipes, growing files).
  char buf[1 << 16];
  for (;;) {
    const std::size_t got = std::fread(buf, 1, sizeof buf, f.get());
    bytes.append(buf, got);
    if (got < sizeof buf) {
      if (std::ferror(f.get())) {
        const int err = errno;
        throw InputError("cannot read " + path + ": " + std::strerror(err));
      }
      break;
    }
  }
  return bytes;
}

std::string read_file_head(const std::string& path, std::size_t bytes, std::uint64_t offset) {
  check_readable(path);
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::unique_ptr<std::FILE, Closer> f(std::fopen(path.c_str(), "rb"));
  if (!f) throw InputError("cannot open " + path + ": " + std::strerror(errno));
  if (offset != 0 && fseeko(f.get(), static_cast<off_t>(offset), SEEK_SET) != 0)
    throw InputError("cannot read " + path + " from byte " + std::to_string(offset) + ": " + std::strerror(errno));
  std::string head(bytes, '\0');
  head.resize(std::fread(head.data(), 1, bytes, f.get()));
  if (std::ferror(f.get())) throw InputError("cannot read " + path + ": " + std::strerror(errno));
  return head;
}

std::string lower_extension(const std::string& path) {
  return lower(std::filesystem::path(path).extension().string());
}

}  // namespace detail

namespace {

/// Points from a structured .npy array: its fields named x, y and z (any
/// case), as a text file's header names them, and labels from the field
/// `label_name`.
PointCloud points_from_records(const std::string& path, NpyRecords& r, const ReadOptions& options,
                               const std::string& label_name) {
  std::vector<std::string> names;
  for (const auto& f : r.fields) names.push_back(f.name);
  const detail::NamedAxes axes = detail::named_axes(path, names, label_name, options.dim, "field");
  if (!axes.found)
    detail::fail(path, "a structured array needs fields x and y (and z in 3D) for the points (fields: " +
                           detail::quoted_list(names) + ")");
  PointCloud pc;
  pc.dim = axes.dim;
  pc.n = r.n;
  const auto dim = static_cast<std::size_t>(axes.dim);
  pc.coords.resize(r.n * dim);
  for (std::size_t d = 0; d < dim; ++d) {
    const std::vector<double>& v = r.fields[axes.col[d]].values;
    for (std::size_t i = 0; i < r.n; ++i) pc.coords[i * dim + d] = v[i];
  }
  if (label_name.empty()) return pc;
  for (const auto& f : r.fields)
    if (f.name == label_name) {
      if (f.kind == 'f')
        detail::fail(path, "labels field '" + label_name + "' holds floating-point values, not integers");
      pc.labels = detail::labels_from_values(path, label_name, f.values);
      return pc;
    }
  detail::fail(path, "no field '" + label_name + "' for labels (fields: " + detail::quoted_list(names) + ")");
}

/// Points from an .npy array of shape (N, 2) or (N, 3), or a structured one
/// (points_from_records).
PointCloud read_npy_points(const std::string& path, const ReadOptions& options, const std::string& label_name) {
  NpyRecords r = read_npy_records(path, [&](const std::string& name) {
    const std::string l = detail::lower(name);
    return name == label_name || l == "x" || l == "y" || l == "z";
  });
  if (r.structured) return points_from_records(path, r, options, label_name);
  if (!label_name.empty())
    detail::fail(path, "labels '" + label_name + "': with .npy points, labels must be a .npy file (or a field of a structured array)");
  NpyArray a = read_npy_double(path);
  // (As Python's points=: a bool array is a mask, not coordinates.)
  if (a.kind == 'b') detail::fail(path, "expected a float or integer point array, found dtype bool");
  const auto& s = a.shape;
  if (s.size() != 2 || s[1] < 2 || s[1] > 3) {
    std::ostringstream shape;
    shape << '(';
    for (std::size_t k = 0; k < s.size(); ++k) shape << (k ? ", " : "") << s[k];
    shape << (s.size() == 1 ? ",)" : ")");
    detail::fail(path, "expected a point array of shape (N, 2) or (N, 3), found shape " + shape.str());
  }
  const int cols = static_cast<int>(s[1]);
  const int dim = options.dim ? options.dim : cols;
  if (dim > cols)
    detail::fail(path,
                 "3D points asked but the array has 2 columns (shape (" + std::to_string(s[0]) + ", 2))");
  PointCloud pc;
  pc.dim = dim;
  pc.n = s[0];
  pc.coords = std::move(a.as_double);
  if (dim < cols) {
    // Keep x,y of each row, compacting in place (write index never passes read index).
    for (std::size_t i = 0; i < pc.n; ++i) {
      pc.coords[i * 2] = pc.coords[i * 3];
      pc.coords[i * 2 + 1] = pc.coords[i * 3 + 1];
    }
    pc.coords.resize(pc.n * 2);
    pc.coords.shrink_to_fit();
  }
  return pc;
}

}  // namespace

std::vector<std::int32_t> read_labels_npy(const std::string& path) {
  NpyArray a = read_npy_int(path);
  if (!(a.shape.size() == 1 || (a.shape.size() == 2 && a.shape[1] == 1))) {
    std::string shape = "(";
    for (std::size_t k = 0; k < a.shape.size(); ++k) shape += (k ? ", " : "") + std::to_string(a.shape[k]);
    detail::fail(path, "labels must be a 1-D integer array, found shape " + shape + ")");
  }
  std::vector<std::int32_t> labels(a.as_int.size());
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const std::int64_t v = a.as_int[i];
    if (v < std::numeric_limits<std::int32_t>::min() || v > std::numeric_limits<std::int32_t>::max())
      detail::fail(
          path, "label " + std::to_string(v) + " at index " + std::to_string(i) + " does not fit in int32");
    labels[i] = static_cast<std::int32_t>(v);
  }
  return labels;
}

std::string non_finite_hint(const ReadOptions& options) {
  return options.non_finite_hint.empty() ? "keep_non_finite keeps such points" : options.non_finite_hint;
}

bool is_trajectory(const std::string& path) {
  const std::string ext = detail::lower_extension(path);
  return detail::is_dump_extension(ext) || ((ext == ".xyz" || ext == ".txt") && detail::is_xyz_file(path));
}

std::optional<FileBox> read_file_box(const std::string& path, const FramePlace& frame) {
  const std::string ext = detail::lower_extension(path);
  if (detail::is_dump_extension(ext)) return detail::read_dump_box(path, frame);
  // An extended XYZ's Lattice.
  if ((ext == ".xyz" || ext == ".txt") && detail::is_xyz_file(path)) return detail::read_xyz_box(path, frame);
  return std::nullopt;
}

namespace {

/// The starts of a trajectory's frames, walked from the first until
/// `stop(place)` is true (that frame's start is the last listed) or the
/// frames end.
template <class Stop>
std::vector<FramePlace> walk_frames(const std::string& path, Stop&& stop) {
  if (!is_trajectory(path))
    detail::fail(path, "not a trajectory: frames are read from LAMMPS dumps (.dump, .lammpstrj) and XYZ files");
  const bool dump = detail::is_dump_extension(detail::lower_extension(path));
  std::vector<FramePlace> starts;  // 32 bytes a frame
  FramePlace at;
  for (;;) {
    starts.push_back(at);
    if (stop(at)) break;
    detail::FrameEnd end;
    try {
      end = dump ? detail::skip_dump_frame(path, at.offset, at.line) : detail::skip_xyz_frame(path, at.offset, at.line);
    } catch (const detail::FrameTruncated&) {
      break;  // the last frame, cut short (still being written): listed, and reading it says so
    }
    starts.back().atoms = static_cast<std::int64_t>(end.atoms);
    if (end.last) break;
    at.offset += end.bytes;
    at.line = end.next_line;
    ++at.index;
  }
  return starts;
}

}  // namespace

FramePlace find_frame(const std::string& path, std::int64_t index) {
  const std::vector<FramePlace> starts = walk_frames(
      path, [&](const FramePlace& at) { return index >= 0 && at.index == static_cast<std::uint64_t>(index); });
  const std::size_t frames = starts.size();
  if (index >= 0 && starts.back().index == static_cast<std::uint64_t>(index)) return starts.back();
  if (index < 0 && static_cast<std::uint64_t>(-(index + 1)) < frames)
    return starts[frames - 1 - static_cast<std::size_t>(-(index + 1))];
  detail::fail(path, "no frame " + std::to_string(index) + ": it has " + std::to_string(frames) +
                         (frames == 1 ? " frame (0, or -1 from the end)"
                                      : " frames (0 to " + std::to_string(frames - 1) + ", or -" +
                                            std::to_string(frames) + " to -1 from the end)"));
}

std::vector<FramePlace> find_frames(const std::string& path) {
  return walk_frames(path, [](const FramePlace&) { return false; });
}

TrajectoryFrame read_frame(const std::string& path, std::uint64_t offset, std::size_t line,
                           const ReadOptions& options) {
  if (options.dim != 0 && options.dim != 2 && options.dim != 3)
    detail::fail(path, "dimension must be 2 or 3, not " + std::to_string(options.dim));
  if (!options.labels.empty() && detail::lower_extension(options.labels) == ".npy")
    detail::fail(path, "labels of a trajectory's frames: name a column of the file, not a .npy file");
  const std::string ext = detail::lower_extension(path);
  TrajectoryFrame f;
  if (detail::is_dump_extension(ext))
    f = detail::read_dump_frame(path, offset, line, options, options.labels);
  else if ((ext == ".xyz" || ext == ".txt") && detail::is_xyz_file(path))
    f = detail::read_xyz_frame(path, offset, line, options, options.labels, true);
  else
    detail::fail(path, "not a trajectory: frames are read from LAMMPS dumps (.dump, .lammpstrj) and XYZ files");
  for (std::size_t k = 0; k < f.points.coords.size() && !options.keep_non_finite; ++k)
    if (!std::isfinite(f.points.coords[k]))
      detail::fail(path, "non-finite coordinate in the frame from line " + std::to_string(line) + ", atom " +
                             std::to_string(k / static_cast<std::size_t>(f.points.dim)) + " (0-based; " +
                             non_finite_hint(options) + ")");
  return f;
}

PointCloud read_points(const std::string& path, const ReadOptions& options) {
  if (options.dim != 0 && options.dim != 2 && options.dim != 3)
    detail::fail(path, "dimension must be 2 or 3, not " + std::to_string(options.dim));

  if ((options.frame.offset != 0 || options.frame.index != 0) && !is_trajectory(path))
    detail::fail(path, "frame " + std::to_string(options.frame.index) +
                           ": not a trajectory (frames are read from LAMMPS dumps and XYZ files)");

  // A labels option ending in .npy is a file; anything else names a column/property.
  const bool labels_file = !options.labels.empty() && detail::lower_extension(options.labels) == ".npy";
  const std::string label_name = labels_file ? std::string() : options.labels;

  const std::string ext = detail::lower_extension(path);
  PointCloud pc;
  if (ext == ".npy") {
    pc = read_npy_points(path, options, label_name);
  } else if (ext == ".csv" || ext == ".xyz" || ext == ".txt") {
    pc = detail::read_text_points(path, options, label_name);
  } else if (ext == ".ply") {
    pc = detail::read_ply_points(path, options, label_name);
  } else if (ext == ".vtp" || ext == ".vtu") {
    pc = detail::read_vtk_points(path, options, label_name);
  } else if (ext == ".las" || ext == ".laz") {
    pc = detail::read_las_points(path, options, label_name);
  } else if (ext == ".vtk") {
    pc = detail::read_vtk_legacy_points(path, options, label_name);
  } else if (ext == ".pcd") {
    pc = detail::read_pcd_points(path, options, label_name);
  } else if (detail::is_dump_extension(ext)) {
    pc = detail::read_dump_points(path, options, label_name);
  } else {
    detail::fail(path, "unknown input extension '" + ext +
                           "' (expected .npy, .csv, .xyz, .txt, .ply, .vtp, .vtu, .vtk, .pcd, .las, .dump, .lammpstrj)");
  }

  if (pc.n == 0) detail::fail(path, "no points");
  for (std::size_t k = 0; k < pc.coords.size() && !options.keep_non_finite; ++k) {
    if (!std::isfinite(pc.coords[k])) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%g", pc.coords[k]);
      detail::fail(path, "non-finite coordinate " + std::string(buf) + " in row " + std::to_string(k / pc.dim) +
                             " (0-based; " + non_finite_hint(options) + ")");
    }
  }

  if (labels_file) {
    pc.labels = read_labels_npy(options.labels);
    if (pc.labels.size() != pc.n)
      detail::fail(options.labels, "labels: " + std::to_string(pc.labels.size()) + " values for " +
                                       std::to_string(pc.n) + " points");
  }
  return pc;
}

}  // namespace tessera::io
