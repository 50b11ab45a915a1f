// NumPy .npy format (version 1.0-3.0) reader and writer.
// Format: https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tessera::io {

/// A whole .npy array converted to double or int64 as asked.
struct NpyArray {
  std::vector<std::size_t> shape;
  char kind = 'f';          ///< 'f' float, 'i' signed, 'u' unsigned, 'b' bool (source dtype)
  int item_size = 8;        ///< bytes per element in the file
  std::vector<double> as_double;       ///< filled by read_npy_double
  std::vector<std::int64_t> as_int;    ///< filled by read_npy_int
};

/// Read a float32/float64 array (also accepts integer arrays, converted),
/// returned in C order. Big-endian data is byte-swapped; a Fortran-order
/// array is reordered.
NpyArray read_npy_double(const std::string& path);
/// Read an integer array (any int/uint width, or bool), returned in C order.
NpyArray read_npy_int(const std::string& path);

/// Serialise arrays (C order, little-endian) to an .npy byte string; write the
/// result with write_file_atomic. shape = {n} or {n, m}.
std::string npy_bytes(const double* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::uint8_t* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::int32_t* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::int64_t* data, const std::vector<std::size_t>& shape);

}  // namespace tessera::io
