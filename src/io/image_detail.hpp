// Private helpers of the image readers (src/io/image_*.cpp); not installed.
//
// Every format reader decodes its header into an ImageGeometry and its data
// into a RawImage: the voxel bytes of one scalar type, x fastest, in the
// file's byte order. image.cpp then converts to labels (int32, range-checked)
// or to doubles, and applies the ImageReadOptions overrides.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "tessera/image.hpp"
#include "tessera/io/image.hpp"

namespace tessera::io::detail {

/// Scalar types the readers accept.
enum class ScalarType : std::uint8_t { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64 };

std::size_t scalar_size(ScalarType t);
const char* scalar_name(ScalarType t);  ///< "int16", "float32", ...
inline bool is_float(ScalarType t) { return t == ScalarType::f32 || t == ScalarType::f64; }

/// One image as decoded from a file.
struct RawImage {
  ImageGeometry geometry;
  ScalarType type = ScalarType::u8;
  bool big_endian = false;  ///< byte order of `bytes`
  std::string bytes;        ///< n_voxels * scalar_size(type)
  /// Already converted values (used by .npy, read through the .npy reader):
  /// when `converted` is set, `ints` (integer types) or `doubles` (float types)
  /// hold the voxels and `bytes` is empty.
  bool converted = false;
  std::vector<std::int64_t> ints;
  std::vector<double> doubles;
  /// Axes the file stores with a negative step (a flipped direction): the
  /// reader has set `geometry` as the image will be (positive spacing, the
  /// origin at the lowest voxel), and read_raw reverses the voxels along them.
  std::array<bool, 3> flip{false, false, false};
};

RawImage read_npy_image(const std::string& path, bool want_labels);
RawImage read_nrrd_image(const std::string& path);
RawImage read_metaimage(const std::string& path);
RawImage read_vti_image(const std::string& path, const std::string& array);
/// (`want_labels`: scaled values, scl_slope/scl_inter, are refused.)
RawImage read_nifti_image(const std::string& path, bool want_labels);
/// A legacy VTK image (.vtk, DATASET STRUCTURED_POINTS; vtk_legacy.cpp): the
/// POINT_DATA attribute `array`, else the first of one component.
RawImage read_vtk_legacy_image(const std::string& path, const std::string& array);
/// Whether `path` names a NIfTI file: .nii, .nii.gz or .hdr (with its .img).
bool is_nifti_path(const std::string& path);

// ---- shared by the readers ----

/// Checks sizes (>= 1, product fits and is below 2^40 voxels), spacing (> 0,
/// finite) and origin (finite); throws InputError naming `path`.
void check_geometry(const std::string& path, const ImageGeometry& g);

/// Number of data bytes an image of geometry `g` and type `t` needs.
std::size_t data_bytes(const ImageGeometry& g, ScalarType t);

/// Inflate a zlib or gzip stream (auto-detected; concatenated gzip members
/// allowed) of exactly `expected` bytes. `what` names the data in messages
/// ("gzip data", "compressed block 3"). Throws InputError naming `path` when
/// the stream is corrupt, shorter or longer than `expected`.
std::string inflate_exact(const std::string& path, std::string_view what, std::string_view src,
                          std::size_t expected);

/// At most the first `limit` bytes a zlib or gzip stream inflates to (fewer
/// where it ends first); InputError naming `path` where it is corrupt. For
/// formats whose header lies inside the compressed stream (.nii.gz).
std::string inflate_prefix(const std::string& path, std::string_view what, std::string_view src,
                           std::size_t limit);

/// Every voxel's value as a double (converted or not).
std::vector<double> raw_as_doubles(const RawImage& raw);

/// Reverses the voxels along `axis` (0 x, 1 y, 2 z), for images stored with
/// a negative step along it; the caller moves the geometry's origin.
void flip_axis(RawImage& raw, int axis);

/// Parse whitespace-separated numbers into `count` values of type `t`
/// (native byte order), for ascii encodings. Throws InputError on a bad
/// token, a value out of the type's range, too few or too many values.
std::string parse_ascii_values(const std::string& path, std::string_view text, ScalarType t, std::size_t count);

/// The bytes of the detached data file `data_path` named by the header
/// `path`; a missing or unreadable one is InputError("PATH: cannot open data
/// file DATA_PATH: reason").
std::string read_detached(const std::string& path, const std::string& data_path);

/// Directory part of `path` ("" or ending in '/'), for detached data files.
std::string directory_of(const std::string& path);

/// At most `max` characters of `s` for an error message, with anything not
/// printable ASCII shown as '?'.
std::string printable(std::string_view s, std::size_t max = 60);

/// Trim ASCII whitespace at both ends.
std::string_view trim(std::string_view s);

/// Parse exactly `n` finite doubles separated by whitespace; false on failure.
bool parse_doubles(std::string_view text, std::size_t n, double* out);
/// Parse exactly `n` positive 64-bit integers separated by whitespace.
bool parse_sizes(std::string_view text, std::size_t n, std::int64_t* out);

}  // namespace tessera::io::detail
