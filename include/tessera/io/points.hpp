// Reading point clouds (and their labels) from files, by extension.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tessera::io {

/// A point cloud as read from a file: n rows of `dim` doubles, row-major.
struct PointCloud {
  int dim = 3;                        ///< columns kept (2 or 3)
  std::size_t n = 0;
  std::vector<double> coords;         ///< n * dim
  std::vector<std::int32_t> labels;   ///< empty, or n labels
};

struct ReadOptions {
  /// 2 or 3 to force the dimension (3-column input with dim 2 keeps x,y);
  /// 0: take it from the file (2 or 3 columns; .ply is always 3D unless forced).
  int dim = 0;
  /// Labels: empty = none; a path ending in .npy = an integer array of length n;
  /// otherwise the name of an integer .ply vertex property (or, for a .csv with
  /// a header, a column name).
  std::string labels;
};

/// Read .npy, .csv/.xyz/.txt or .ply. Throws tessera::InputError (one line naming the
/// file and the problem) on a missing/unreadable file, unknown extension, wrong
/// dtype/shape, empty input, NaN/Inf, or labels of the wrong length.
PointCloud read_points(const std::string& path, const ReadOptions& options = {});

/// Labels from a .npy integer array (int8..int64, uint8..uint32), as int32.
std::vector<std::int32_t> read_labels_npy(const std::string& path);

}  // namespace tessera::io
