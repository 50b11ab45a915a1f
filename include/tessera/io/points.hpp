// Reading point clouds (and their labels) from files, by extension.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tessera/labelled_points.hpp"

namespace tessera::io {

/// A point cloud as read from a file: n rows of `dim` doubles, row-major.
struct PointCloud {
  int dim = 3;                        ///< columns kept (2 or 3)
  std::size_t n = 0;
  std::vector<double> coords;         ///< n * dim
  std::vector<std::int32_t> labels;   ///< empty, or n labels
  /// Empty, or n sphere radii for power cells (VoronoiOptions::radii): not
  /// read by read_points; the CLI's --radii fills it (read_point_scalars).
  std::vector<double> radii;
};

/// Where a frame of a trajectory (a LAMMPS dump, an XYZ file) starts: its
/// byte and its line in the file, and its place among the frames (0 the
/// first). The default is the first frame (find_frame gives the others).
struct FramePlace {
  std::uint64_t offset = 0;
  std::size_t line = 1;
  std::size_t index = 0;
  /// The frame's number of atoms, where the walk that found it went past
  /// it (find_frames: every frame but one cut short); -1 where it did not.
  std::int64_t atoms = -1;
};

struct ReadOptions {
  /// 2 or 3 to force the dimension (3-column input with dim 2 keeps x,y);
  /// 0: take it from the file (2 or 3 columns, or a text header's named x, y
  /// and z; .ply is always 3D unless forced).
  int dim = 0;
  /// Labels: empty = none; a path ending in .npy = an integer array of length n;
  /// otherwise the name of an integer .ply vertex property (or, for a .csv with
  /// a header, a column name).
  std::string labels;
  /// Keep points with a NaN or infinite coordinate (organized clouds' missing
  /// returns) for the computation to set aside, as VoronoiOptions::
  /// ignore_outside_points does; otherwise such a point is an input error.
  bool keep_non_finite = false;
  /// How the error on such a point says to keep them: the caller's own
  /// option ("--ignore-outside sets such points aside"); empty: this
  /// struct's keep_non_finite.
  std::string non_finite_hint;
  /// The frame of a trajectory to read (find_frame); the first by default.
  /// A file of another format has only the first.
  FramePlace frame;
};

/// ReadOptions::non_finite_hint, or its default when empty.
std::string non_finite_hint(const ReadOptions& options);

/// The simulation box a point file declares (a LAMMPS dump's BOX BOUNDS, an
/// extended XYZ's Lattice, Origin and pbc), in
/// the terms of --bounds, --periodic and --tilt (VoronoiOptions): the box is
/// the parallelepiped spanned from `lo` by a = (Lx, 0, 0), b = (xy, Ly, 0),
/// c = (xz, yz, Lz), L = hi - lo.
struct FileBox {
  std::array<double, 3> lo{0, 0, 0};
  std::array<double, 3> hi{0, 0, 0};
  std::array<double, 3> tilt{0, 0, 0};       ///< xy, xz, yz as lengths (0 unless triclinic)
  std::array<bool, 3> periodic{false, false, false};
  bool triclinic = false;                    ///< the file declared tilts (possibly all 0)
  std::int64_t timestep = 0;                 ///< a dump frame's TIMESTEP; 0 for XYZ
  std::string declared_by;                   ///< "LAMMPS dump, timestep 100", "extended XYZ Lattice"
};

/// The box `path` declares in a frame (the first by default), read from its
/// header alone: LAMMPS dumps (.dump, .lammpstrj) and extended XYZ files
/// with a Lattice have one, other formats none (nullopt). Throws InputError
/// on a malformed header.
std::optional<FileBox> read_file_box(const std::string& path, const FramePlace& frame = {});

/// Whether `path` is a trajectory whose frames read_frame and find_frame
/// read: a LAMMPS dump (.dump, .lammpstrj), or an .xyz/.txt file in XYZ's
/// format.
bool is_trajectory(const std::string& path);

/// Where frame `index` of a trajectory starts: 0 the first, 1 the next, and
/// negative indices count from the end (-1 the last). The frames before it
/// (all of them for a negative index) are walked by their headers and line
/// counts, their numbers not parsed. Throws InputError where the file has no
/// such frame (saying how many it has), is no trajectory, or a frame on the
/// way is malformed (naming its line).
FramePlace find_frame(const std::string& path, std::int64_t index);

/// Where every frame of a trajectory starts, in file order (find_frame's
/// walk to the end).
std::vector<FramePlace> find_frames(const std::string& path);

/// One frame of a trajectory file (a LAMMPS dump, an XYZ file).
struct TrajectoryFrame {
  PointCloud points;              ///< its atoms, in file order (labels where asked)
  std::optional<FileBox> box;     ///< its box: every dump frame's, an extended XYZ's Lattice
  std::uint64_t next_offset = 0;  ///< the byte where the next frame starts
  std::size_t next_line = 1;      ///< the number of its first line (for error messages)
  bool last = true;               ///< no frame follows (only blank lines, or nothing)
};

/// The frame of a LAMMPS dump (.dump, .lammpstrj) or an XYZ file that starts
/// at byte `offset`, line `line`: 0 and 1 for the first, then the previous
/// frame's next_offset and next_line. Only that frame's bytes are read.
/// `options.labels` names an integer column (a .npy file of labels is one
/// array for every frame: the caller's). Throws InputError on a malformed
/// frame (its line numbers count from the file's start) and on a file with
/// no frames (other formats).
TrajectoryFrame read_frame(const std::string& path, std::uint64_t offset = 0, std::size_t line = 1,
                           const ReadOptions& options = {});

/// Read .npy (C or Fortran order), .csv/.xyz/.txt (the columns a header names
/// x, y and z in any case, else the first ones; Qhull's format; XYZ's first
/// frame), .ply, .vtp/.vtu, .pcd, or a LAMMPS dump's first frame (.dump,
/// .lammpstrj: its x y z, xu yu zu, or scaled xs ys zs columns, atoms in
/// file order). Throws tessera::InputError (one line naming the
/// file and the problem) on a missing/unreadable file, unknown extension, wrong
/// dtype/shape, empty input, NaN/Inf, or labels of the wrong length.
PointCloud read_points(const std::string& path, const ReadOptions& options = {});

/// Labels from a .npy integer array (int8..int64, uint8..uint32), as int32.
std::vector<std::int32_t> read_labels_npy(const std::string& path);

/// Per-point scalars for the points of `points_path`: `source` ending in .npy
/// is a 1-D float or integer array; otherwise it names a numeric .ply vertex
/// property or a header column of a .csv/.xyz/.txt file (the points' own
/// file). NaN values are allowed. The length is the caller's to check.
/// Throws InputError (one line naming the file) on a missing array/column.
/// A trajectory's column is read from `frame`.
std::vector<double> read_point_scalars(const std::string& points_path, const std::string& source,
                                       const FramePlace& frame = {});

struct WritePointsOptions {
  /// .npy output only: where the labels go ("" = OUT with "_labels.npy" in
  /// place of ".npy"); nothing is written when the points have no labels.
  std::string labels_path;
  /// Write the labels (the .npy sidecar, the "label" property or array) even
  /// when there are none because there are no points: an empty `labels`
  /// otherwise means "unlabelled", and a labelled output of zero points lost
  /// its labels file.
  bool labelled = false;
  /// Extra per-point double arrays (name, n values): properties of .ply,
  /// point data of .vtp; for .npy each goes to OUT with "_<name>.npy".
  std::vector<std::pair<std::string, std::span<const double>>> scalars;
};

/// Write points with their labels by extension: .npy (float64 (n, dim)),
/// .ply (binary little-endian, float64 x y z, int32 property "label"),
/// .vtp (VTK XML PolyData, one vertex per point, int32 point data "label").
/// `-` is the .ply on standard output (one stream holds the points, labels
/// and arrays; write_file_atomic). Every file is written atomically (all or
/// nothing). Returns the paths
/// written. Throws InputError on an unknown extension or arrays of the wrong
/// length.
std::vector<std::string> write_points(const std::string& path, const LabelledPoints& points,
                                      const WritePointsOptions& options = {});

}  // namespace tessera::io
