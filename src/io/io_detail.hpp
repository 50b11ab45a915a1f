// Private helpers shared by the IO readers and writers (not installed).
#pragma once

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/io/points.hpp"

namespace tessera::io::detail {

/// Throw tessera::InputError("PATH: what"). Every reader error goes through
/// here so that messages are one line and start with the file path.
[[noreturn]] void fail(const std::string& path, std::string_view what);

/// The whole file as bytes. Throws InputError("cannot open PATH: reason")
/// (reason from strerror, e.g. "No such file or directory").
std::string read_file_bytes(const std::string& path);

/// Throws InputError("cannot open PATH: reason") unless `path` names an
/// existing file that is not a directory. Used before opening a file.
void check_readable(const std::string& path);

/// `s` in lower case (ASCII).
inline std::string lower(std::string_view s) {
  std::string r(s);
  for (char& c : r) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return r;
}

/// Whether `s` ends with `suffix` (lower case), in any case: ".nii.gz" names.
inline bool ends_with_ci(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && lower(s.substr(s.size() - suffix.size())) == suffix;
}

/// The item of type T stored at `p` (any alignment), byte-swapped when the
/// file's byte order is not ours.
template <class T>
T load_item(const void* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

/// The extension of `path`, lowercased, with its dot ("" when there is none).
std::string lower_extension(const std::string& path);

/// 'a', 'b', 'c' for error messages.
std::string quoted_list(const std::vector<std::string>& names);

/// The coordinates a file's column or field `names` give (named_points.cpp):
/// those named x, y and z in any case and order. found: x and y are named;
/// dim: `dim` (the option) or 3 where z is named, else 2; col: the columns
/// of the dim coordinates. `what` ("column", "field") names them in the
/// errors: a coordinate named twice, 3D asked without z, the `labels`
/// column being a coordinate.
struct NamedAxes {
  bool found = false;
  int dim = 0;
  std::size_t col[3] = {0, 0, 0};
};
NamedAxes named_axes(const std::string& path, const std::vector<std::string>& names, const std::string& labels,
                     int dim, const std::string& what);

/// Labels from numeric values (a column's, a field's, a point data
/// array's): integers that fit in int32, else InputError naming `name` and
/// the point.
std::vector<std::int32_t> labels_from_values(const std::string& path, const std::string& name,
                                             const std::vector<double>& v);

/// Text point files (.csv/.xyz/.txt). `label_column` is empty, or the header
/// name of the column holding integer labels. Coordinates are checked finite
/// (errors name the line). Returns the cloud with labels filled when asked.
PointCloud read_text_points(const std::string& path, const ReadOptions& options,
                            const std::string& label_column);

/// .ply files (ascii or binary, either byte order). `label_property` is empty, or
/// the name of an integer vertex property holding labels.
PointCloud read_ply_points(const std::string& path, const ReadOptions& options,
                           const std::string& label_property);

/// The values of the numeric scalar vertex property `name` of a .ply file, in
/// vertex order (used for per-point scalars, e.g. `tessera threshold`).
std::vector<double> read_ply_property(const std::string& path, const std::string& name);

/// The values of the header column `name` of a text point file, one per data
/// line (NaN and Inf allowed; the caller decides).
/// An XYZ file's property is read from `frame`.
std::vector<double> read_text_column(const std::string& path, const std::string& name, const FramePlace& frame);

/// Where a trajectory's frame ended: the bytes of the parsed text it took
/// (up to the next frame's first line), that line's number, and whether no
/// frame follows; and the frame's atoms (its header's count).
struct FrameEnd {
  std::size_t bytes = 0, next_line = 1;
  bool last = true;
  std::size_t atoms = 0;
};

/// LAMMPS dumps (.dump, .lammpstrj; lammps_dump.cpp): a frame's atoms
/// (`label_column`: empty, or the integer column holding labels), the atoms
/// of options.frame, one numeric column of a frame, its box (the header
/// alone), and a frame skipped (its lines split, not parsed: find_frame).
TrajectoryFrame read_dump_frame(const std::string& path, std::uint64_t offset, std::size_t line,
                                const ReadOptions& options, const std::string& label_column);
PointCloud read_dump_points(const std::string& path, const ReadOptions& options, const std::string& label_column);
std::vector<double> read_dump_column(const std::string& path, const std::string& name, const FramePlace& frame);
FileBox read_dump_box(const std::string& path, const FramePlace& frame);
FrameEnd skip_dump_frame(const std::string& path, std::uint64_t offset, std::size_t line);

/// XYZ and extended XYZ files (xyz_points.cpp), read by the text reader
/// where `text` (the file's first bytes) starts as XYZ does: the atoms of
/// options.frame, one property's values, the Lattice's box (none without a
/// Lattice) and a frame skipped, as the dump's.
bool looks_like_xyz(std::string_view text);
bool is_xyz_file(const std::string& path);  ///< looks_like_xyz on as much of the file as its first lines take
/// (`with_box`: a Lattice that is no box of ours is an error, as the
/// frame's box; read_xyz_points reads the atoms alone.)
TrajectoryFrame read_xyz_frame(const std::string& path, std::uint64_t offset, std::size_t line,
                               const ReadOptions& options, const std::string& label_column, bool with_box);
PointCloud read_xyz_points(const std::string& path, const ReadOptions& options, const std::string& label_column);
std::vector<double> read_xyz_column(const std::string& path, const std::string& name, const FramePlace& frame);
std::optional<FileBox> read_xyz_box(const std::string& path, const FramePlace& frame);
FrameEnd skip_xyz_frame(const std::string& path, std::uint64_t offset, std::size_t line);

/// The labels read from `column` of a trajectory file (LAMMPS dump, XYZ)
/// as numbers, values[k * stride + at] for atom k: integers in int32's
/// range, else InputError naming the atom in file order.
std::vector<std::int32_t> atom_labels(const std::string& path, const std::string& column,
                                      const std::vector<double>& values, std::size_t stride, std::size_t at);

/// `bytes` bytes of a file from byte `offset` (to its end where it is
/// shorter), for the readers of a header alone and of a trajectory's frames.
std::string read_file_head(const std::string& path, std::size_t bytes, std::uint64_t offset = 0);

/// Thrown by a frame parser whose frame runs past the end of a prefix of the
/// file that is not the whole file: frame_at reads more. (A logic_error:
/// should one escape frame_at, a bug, it is an internal error, not input's.)
struct FrameCut : std::logic_error {
  FrameCut() : std::logic_error("a frame parser asked for more of a whole file") {}
};

/// `parse(text, tail)` on the bytes of `path` from `offset`, cut after their
/// last line break, on more of them each time it throws FrameCut: a frame of
/// a trajectory without reading the frames after it (a trajectory may be
/// gigabytes). `tail`: the bytes after the cut, the start of a line not yet
/// whole; nullopt where `text` is the whole file, so that running out of
/// lines is the file's error, not the prefix's.
template <class Parse>
auto frame_at(const std::string& path, std::uint64_t offset, Parse&& parse) {
  for (std::size_t want = std::size_t{1} << 20;; want *= 4) {
    const std::string head = read_file_head(path, want, offset);
    const bool whole = head.size() < want;
    const std::size_t cut = whole ? head.size() : head.rfind('\n') + 1;  // (npos + 1 == 0: no line yet)
    const std::string_view text(head.data(), cut);
    try {
      return parse(text, whole ? std::nullopt : std::optional<std::string_view>(std::string_view(head).substr(cut)));
    } catch (const FrameCut&) {
      if (whole) throw;  // a parser's bug: it may only ask for more of a prefix
    }
  }
}

/// A frame that the end of the file cuts short (the last of a trajectory
/// still being written): an input error, which a walk over the frames
/// (find_frames) takes as the end of the frames, listing the cut frame so
/// that the frames before it stay readable and reading it names the problem.
struct FrameTruncated : InputError {
  using InputError::InputError;
};

/// A frame parser's text ran out: the file's error where `whole`
/// (FrameTruncated, naming the file), else more of the file is needed
/// (frame_at).
[[noreturn]] inline void frame_ended(const std::string& path, const std::string& what, bool whole) {
  if (!whole) throw FrameCut{};
  throw FrameTruncated(path + ": " + what);
}

/// A frame's atom lines ran out after `read` of its `atoms`, the text's
/// last line being `last_line` (frame_ended, in both readers' words).
[[noreturn]] inline void atoms_ended(const std::string& path, std::size_t last_line, std::size_t read,
                                     std::size_t atoms, bool whole) {
  frame_ended(path,
              "the file ends at line " + std::to_string(last_line) + ", after " + std::to_string(read) +
                  " of the frame's " + std::to_string(atoms) + " atoms",
              whole);
}

/// frame_at the file's start.
template <class Parse>
auto first_frame(const std::string& path, Parse&& parse) {
  return frame_at(path, 0, std::forward<Parse>(parse));
}

/// After a frame's last atom line, where `lines` ran out of a prefix: what
/// follows is a next frame's first line if `tail` starts with `start` (the
/// check asks for more of the file while `tail` is shorter than `start`).
/// True: a next frame (or the end of the file); false: something else.
inline bool frame_follows(std::optional<std::string_view> tail, std::string_view start) {
  if (!tail) return true;  // the end of the file
  // (Blanks first: a blank line cut by the prefix, which the frame's reader
  // skips as it skips whole ones.)
  std::string_view t = *tail;
  while (!t.empty() && (t.front() == ' ' || t.front() == '\t' || t.front() == '\r')) t.remove_prefix(1);
  if (t.size() < start.size()) throw FrameCut{};
  return t.substr(0, start.size()) == start;
}

/// Whether `ext` (lowercased, with its dot) is a LAMMPS dump's.
inline bool is_dump_extension(const std::string& ext) { return ext == ".dump" || ext == ".lammpstrj"; }

/// VTK XML point sets: .vtp (PolyData) and .vtu (UnstructuredGrid), the
/// points of every piece (vtk_points.cpp). `label_array` is empty, or the
/// name of an integer point data array holding labels.
PointCloud read_vtk_points(const std::string& path, const ReadOptions& options, const std::string& label_array);

/// Legacy VTK files (.vtk; vtk_legacy.cpp): the POINTS of a
/// POLYDATA, UNSTRUCTURED_GRID or STRUCTURED_GRID, ASCII or BINARY;
/// `label_array` is empty, or the name of an integer one-component
/// POINT_DATA attribute (SCALARS, or a FIELD's array).
PointCloud read_vtk_legacy_points(const std::string& path, const ReadOptions& options, const std::string& label_array);
/// The values of the one-component POINT_DATA attribute `name`, in point order.
std::vector<double> read_vtk_legacy_point_array(const std::string& path, const std::string& name);
/// Whether a file's first bytes are a legacy VTK header.
bool looks_like_legacy_vtk(std::string_view head);

/// LAS lidar files (.las 1.0-1.4, point formats 0-10; las.cpp): x, y, z
/// from the records' scaled integers; `label_field` is empty, or an integer
/// field (classification, intensity, return_number, ...).
PointCloud read_las_points(const std::string& path, const ReadOptions& options, const std::string& label_field);
/// The values of LAS field `name` (classification, intensity, gps_time, ...).
std::vector<double> read_las_field(const std::string& path, const std::string& name);

/// PCD files (the Point Cloud Library's; ascii, binary, binary_compressed):
/// the fields x, y (and z). `label_field` is empty, or an integer field.
PointCloud read_pcd_points(const std::string& path, const ReadOptions& options, const std::string& label_field);

/// The values of the one-value field `name` of a .pcd file, in point order.
std::vector<double> read_pcd_field(const std::string& path, const std::string& name);

/// The values of the one-component point data array `name` of a .vtp/.vtu
/// file, in point order (NaN and Inf allowed; the caller decides).
std::vector<double> read_vtk_point_array(const std::string& path, const std::string& name);

}  // namespace tessera::io::detail
