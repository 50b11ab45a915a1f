// Reading images — label volumes and scalar fields — by extension.
//
// Formats (readers of our own, zlib from Debian for gzip/deflate; see
// docs/design.md "Image readers"):
//   .npy          integer or float array, C order, shape (ny, nx) or (nz, ny, nx);
//                 spacing/origin from ImageReadOptions (default 1 / 0)
//   .nrrd / .nhdr NRRD 2D/3D, encodings raw, gzip and ascii, detached data
//                 files (line skip, byte skip), axis-aligned space directions
//                 (positive steps) or spacings
//   .mha / .mhd   MetaImage, ElementDataFile LOCAL or a file name, raw,
//                 compressed (zlib) or ascii, TransformMatrix identity only
//   .vti          VTK XML ImageData, ascii / binary (base64) / appended
//                 (raw or base64), optionally zlib-compressed, UInt32 or UInt64
//                 headers, several pieces; one point-data array (the named
//                 one, else the active scalars, else the first). The origin is
//                 that of the extent's first voxel (Origin + start * Spacing);
//                 one slice along z makes a 2D image.
// Multi-component data and rotated images (a non-diagonal direction) are
// rejected with InputError.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "tessera/image.hpp"

namespace tessera::io {

struct ImageReadOptions {
  /// Override (or, for .npy, supply) the spacing / origin; x, y, z order.
  std::optional<std::array<double, 3>> spacing;
  std::optional<std::array<double, 3>> origin;
  /// .vti: the point-data array to read ("" = active scalars, else the first).
  std::string array;
};

/// An integer image (int8..int64, uint8..uint32; values must fit int32).
/// Throws tessera::InputError (one line naming the file and the problem) on a
/// missing file, unknown extension, malformed header, data shorter than the
/// header says, non-integer data, or values out of int32 range.
LabelImage read_label_image(const std::string& path, const ImageReadOptions& options = {});

/// Throws tessera::InputError ("WHAT: ...", one line) unless `g` is a
/// geometry the image tools can use: 2D or 3D, 1 to 2^40 voxels, finite
/// spacing > 0, finite origin, and every voxel centre (with the half voxel
/// around it) within double's range. The readers check what they read;
/// callers that build a geometry or override one check it here.
void check_image_geometry(const std::string& what, const ImageGeometry& g);

/// Any numeric image, converted to double. Same errors as read_label_image
/// (float data is accepted; NaN is kept and probes as NaN).
ScalarImage read_scalar_image(const std::string& path, const ImageReadOptions& options = {});

}  // namespace tessera::io
