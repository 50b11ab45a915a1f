// NumPy .npy format (version 1.0-3.0) reader and writer.
// Format: https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
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
/// array is reordered; a structured one is an InputError (read_npy_records).
NpyArray read_npy_double(const std::string& path);
/// Read an integer array (any int/uint width, or bool), returned in C order.
NpyArray read_npy_int(const std::string& path);

/// A structured .npy array: a 1-D array of records with named fields (PDAL's
/// point views, np.recarray, pandas' DataFrame.to_records()).
struct NpyRecords {
  bool structured = false;  ///< false: a plain array (nothing else filled)
  std::size_t n = 0;        ///< records
  struct Field {
    std::string name;
    char kind = 'V';             ///< 'f', 'i', 'u', 'b'; 'V' void (padding, raw bytes)
    bool taken = false;
    std::vector<double> values;  ///< n values when taken
  };
  std::vector<Field> fields;     ///< in record order
};
/// Read the fields `take(name)` asks for, converted to double (each must be
/// a numeric scalar field, or InputError). A plain array returns
/// structured = false without reading its data.
NpyRecords read_npy_records(const std::string& path, const std::function<bool(const std::string&)>& take);

/// Serialise arrays (C order, little-endian) to an .npy byte string; write the
/// result with write_file_atomic. shape = {n} or {n, m}.
std::string npy_bytes(const double* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::uint8_t* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::int8_t* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::int32_t* data, const std::vector<std::size_t>& shape);
std::string npy_bytes(const std::int64_t* data, const std::vector<std::size_t>& shape);

}  // namespace tessera::io
