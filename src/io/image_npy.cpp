// .npy images: a C-order array of shape (ny, nx) or (nz, ny, nx), read with
// the project's .npy reader (npy.cpp). C order with x last is exactly the
// image layout (x fastest). Geometry: spacing 1 and origin 0 unless the
// caller's ImageReadOptions say otherwise.
#include <string>

#include "image_detail.hpp"
#include "io_detail.hpp"
#include "tessera/io/npy.hpp"

namespace tessera::io::detail {

RawImage read_npy_image(const std::string& path, bool want_labels) {
  // Integer arrays keep their exact values (int64); float arrays are
  // rejected for labels by the caller, read as doubles for scalars.
  NpyArray a = want_labels ? NpyArray{} : read_npy_double(path);
  if (want_labels) {
    // read_npy_int rejects float arrays with its own message; say it as the
    // other image formats do instead.
    try {
      a = read_npy_int(path);
    } catch (const InputError& e) {
      const std::string msg = e.what();
      if (msg.find("expected an integer array") != std::string::npos)
        fail(path, "float data is not a label image (expected an integer array)");
      throw;
    }
  }
  const std::size_t nd = a.shape.size();
  if (nd != 2 && nd != 3)
    fail(path, "an image array must have shape (ny, nx) or (nz, ny, nx), got " + std::to_string(nd) + " dimensions");
  RawImage raw;
  raw.geometry.dim = static_cast<int>(nd);
  for (std::size_t d = 0; d < nd; ++d) {
    raw.geometry.size[d] = static_cast<std::int64_t>(a.shape[nd - 1 - d]);
    if (a.shape[nd - 1 - d] == 0) fail(path, "empty image (a zero in the shape)");
  }
  raw.converted = true;
  if (want_labels) {
    raw.type = ScalarType::i64;
    raw.ints = std::move(a.as_int);
  } else {
    raw.type = ScalarType::f64;
    raw.doubles = std::move(a.as_double);
  }
  return raw;
}

}  // namespace tessera::io::detail
