// NIfTI images (.nii, .nii.gz, and .hdr with its .img), the format the
// medical segmentation tools write their label maps in (nnU-Net,
// TotalSegmentator, MONAI, FSL, ITK-SNAP, 3D Slicer). NIfTI-1 (348-byte
// header) and NIfTI-2 (540), either byte order, gzip or not.
//
// Geometry: the sform where its code is set, else the qform (quaternion,
// qfac in pixdim[0]), else pixdim alone; voxel centres at the affine's images
// of the indices, in the file's world frame (RAS for NIfTI). An axis stored
// with a negative step (a flipped axis, common: the x of an RAS image from
// LPS data) is reversed on reading, so the image keeps positive spacings
// with the same voxels at the same places. An affine that rotates or
// permutes the axes is refused (resample first), as in the other readers.
// Values: the ten integer and float types; scl_slope/scl_inter are applied
// for scalar images, and refused for label images (scaled labels are no
// labels). 4D and vector images are refused.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include "../message_text.hpp"
#include "image_detail.hpp"
#include "io_detail.hpp"

namespace tessera::io::detail {
namespace {

using tessera::detail::axis_name;
using tessera::detail::number_text;

bool gzipped(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f && static_cast<unsigned char>(bytes[1]) == 0x8b;
}

/// Reads values from the header in its byte order.
struct HeaderBytes {
  std::string_view s;
  bool swap = false;
  template <class T>
  T at(std::size_t offset) const {
    unsigned char b[sizeof(T)];
    std::memcpy(b, s.data() + offset, sizeof(T));
    if (swap)
      for (std::size_t k = 0; k < sizeof(T) / 2; ++k) std::swap(b[k], b[sizeof(T) - 1 - k]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }
};

/// The header's fields we use, from either version.
struct NiftiHeader {
  int version = 1;
  bool big_endian = false;
  bool pair = false;  // ni1/ni2: the data in a .img file
  std::array<std::int64_t, 8> dim{};
  int datatype = 0, bitpix = 0;
  std::array<double, 8> pixdim{};
  double vox_offset = 0, slope = 0, inter = 0;
  int qform = 0, sform = 0;
  double qb = 0, qc = 0, qd = 0, qx = 0, qy = 0, qz = 0;
  double srow[3][4] = {};
};

NiftiHeader parse_header(const std::string& path, std::string_view h) {
  NiftiHeader n;
  if (h.size() < 348) fail(path, "not a NIfTI file (shorter than a NIfTI header)");
  HeaderBytes b{h, false};
  const std::int32_t size = b.at<std::int32_t>(0);
  std::int32_t swapped;
  {
    HeaderBytes s{h, true};
    swapped = s.at<std::int32_t>(0);
  }
  if (size == 348 || swapped == 348) {
    n.version = 1;
    b.swap = size != 348;
  } else if (size == 540 || swapped == 540) {
    n.version = 2;
    b.swap = size != 540;
    if (h.size() < 540) fail(path, "NIfTI-2 header cut short");
  } else {
    fail(path, "not a NIfTI file (its header size is neither 348 nor 540)");
  }
  n.big_endian = (std::endian::native == std::endian::little) == b.swap;
  const std::string_view magic = n.version == 1 ? h.substr(344, 3) : h.substr(4, 3);
  if (magic == "n+1" || magic == "n+2")
    n.pair = false;
  else if (magic == "ni1" || magic == "ni2")
    n.pair = true;
  else
    fail(path, n.version == 1 ? "an Analyze 7.5 header without NIfTI's magic (its orientation is undefined): "
                                "convert it to NIfTI first"
                              : "malformed NIfTI-2 magic");
  if (n.version == 1) {
    for (int k = 0; k < 8; ++k) n.dim[static_cast<std::size_t>(k)] = b.at<std::int16_t>(40 + 2 * k);
    n.datatype = b.at<std::int16_t>(70);
    n.bitpix = b.at<std::int16_t>(72);
    for (int k = 0; k < 8; ++k) n.pixdim[static_cast<std::size_t>(k)] = b.at<float>(76 + 4 * k);
    n.vox_offset = b.at<float>(108);
    n.slope = b.at<float>(112);
    n.inter = b.at<float>(116);
    n.qform = b.at<std::int16_t>(252);
    n.sform = b.at<std::int16_t>(254);
    n.qb = b.at<float>(256), n.qc = b.at<float>(260), n.qd = b.at<float>(264);
    n.qx = b.at<float>(268), n.qy = b.at<float>(272), n.qz = b.at<float>(276);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) n.srow[r][c] = b.at<float>(280 + 16 * static_cast<std::size_t>(r) + 4 * c);
  } else {
    n.datatype = b.at<std::int16_t>(12);
    n.bitpix = b.at<std::int16_t>(14);
    for (int k = 0; k < 8; ++k) n.dim[static_cast<std::size_t>(k)] = b.at<std::int64_t>(16 + 8 * k);
    for (int k = 0; k < 8; ++k) n.pixdim[static_cast<std::size_t>(k)] = b.at<double>(104 + 8 * k);
    n.vox_offset = static_cast<double>(b.at<std::int64_t>(168));
    n.slope = b.at<double>(176);
    n.inter = b.at<double>(184);
    n.qform = b.at<std::int32_t>(344);
    n.sform = b.at<std::int32_t>(348);
    n.qb = b.at<double>(352), n.qc = b.at<double>(360), n.qd = b.at<double>(368);
    n.qx = b.at<double>(376), n.qy = b.at<double>(384), n.qz = b.at<double>(392);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) n.srow[r][c] = b.at<double>(400 + 32 * static_cast<std::size_t>(r) + 8 * c);
  }
  return n;
}

bool nifti_type(int code, ScalarType& t) {
  switch (code) {
    case 2: t = ScalarType::u8; return true;
    case 4: t = ScalarType::i16; return true;
    case 8: t = ScalarType::i32; return true;
    case 16: t = ScalarType::f32; return true;
    case 64: t = ScalarType::f64; return true;
    case 256: t = ScalarType::i8; return true;
    case 512: t = ScalarType::u16; return true;
    case 768: t = ScalarType::u32; return true;
    case 1024: t = ScalarType::i64; return true;
    case 1280: t = ScalarType::u64; return true;
    default: return false;
  }
}

/// The data file of a header/image pair: NAME.img (or .img.gz) beside NAME.hdr.
std::string image_file_of(const std::string& path) {
  const std::string base = path.substr(0, path.size() - (ends_with_ci(path, ".hdr.gz") ? 7 : 4));
  for (const char* ext : {".img", ".img.gz", ".IMG"}) {
    std::error_code ec;
    if (std::filesystem::exists(base + ext, ec)) return base + ext;
  }
  return base + ".img";  // read_detached names it in its error
}

}  // namespace

bool is_nifti_path(const std::string& path) {
  return ends_with_ci(path, ".nii") || ends_with_ci(path, ".nii.gz") || ends_with_ci(path, ".hdr") ||
         ends_with_ci(path, ".hdr.gz");
}

RawImage read_nifti_image(const std::string& path, bool want_labels) {
  const std::string file = read_file_bytes(path);
  const bool gz = gzipped(file);
  const NiftiHeader h = parse_header(path, gz ? inflate_prefix(path, "gzip data", file, 540) : file);

  RawImage raw;
  if (!nifti_type(h.datatype, raw.type))
    fail(path, "NIfTI datatype " + std::to_string(h.datatype) +
                   " is not supported (integers of 8 to 64 bits, float32 or float64; no complex or RGB data)");
  if (h.bitpix != static_cast<int>(8 * scalar_size(raw.type)))
    fail(path, "NIfTI bitpix " + std::to_string(h.bitpix) + " does not match its datatype (" +
                   scalar_name(raw.type) + ")");
  const std::int64_t nd = h.dim[0];
  if (nd < 1 || nd > 7) fail(path, "NIfTI dim[0] must be 1 to 7, got " + std::to_string(nd));
  for (std::int64_t k = 4; k <= nd; ++k)
    if (h.dim[static_cast<std::size_t>(k)] != 1)
      fail(path, "a " + std::to_string(nd) + "D NIfTI image (dim[" + std::to_string(k) + "] = " +
                     std::to_string(h.dim[static_cast<std::size_t>(k)]) +
                     ": a time series or vector data) is not supported: extract one 3D volume");
  if (nd < 2) fail(path, "a 1D NIfTI image is not supported (images must be 2D or 3D)");
  ImageGeometry& g = raw.geometry;
  g.dim = nd == 2 ? 2 : 3;
  for (int a = 0; a < 3; ++a) g.size[static_cast<std::size_t>(a)] = a < g.dim ? h.dim[static_cast<std::size_t>(a) + 1] : 1;
  for (int a = 0; a < g.dim; ++a)
    if (g.size[static_cast<std::size_t>(a)] < 1)
      fail(path, "NIfTI dim[" + std::to_string(a + 1) + "] must be >= 1, got " +
                     std::to_string(g.size[static_cast<std::size_t>(a)]));

  // The affine from voxel indices to the world: its columns are the axes' steps.
  double m[3][3] = {}, t[3] = {0, 0, 0};
  if (h.sform > 0) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[r][c] = h.srow[r][c];
      t[r] = h.srow[r][3];
    }
  } else if (h.qform > 0) {
    const double b = h.qb, c = h.qc, d = h.qd;
    const double a = std::sqrt(std::max(0.0, 1.0 - (b * b + c * c + d * d)));
    const double rot[3][3] = {{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                              {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                              {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
    const double step[3] = {h.pixdim[1], h.pixdim[2], (h.pixdim[0] < 0 ? -1.0 : 1.0) * h.pixdim[3]};
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) m[r][col] = rot[r][col] * step[col];
    t[0] = h.qx, t[1] = h.qy, t[2] = h.qz;
  } else {
    for (int a = 0; a < 3; ++a) m[a][a] = h.pixdim[static_cast<std::size_t>(a) + 1];
  }
  // Axis-aligned up to the float rounding a stored rotation carries (the
  // quaternion of the identity gives off-diagonal terms near 1e-8).
  std::array<bool, 3>& flip = raw.flip;
  for (int a = 0; a < g.dim; ++a) {
    const double step = m[a][a];
    // One slice: its column places no second voxel (pixdim 0 is common there).
    if (g.size[static_cast<std::size_t>(a)] == 1 && !(std::fabs(step) > 0)) {
      g.spacing[static_cast<std::size_t>(a)] = 1;
      g.origin[static_cast<std::size_t>(a)] = t[a];
      continue;
    }
    for (int r = 0; r < 3; ++r)
      if (r != a && !(std::fabs(m[r][a]) <= 1e-6 * std::fabs(step)))
        fail(path, "NIfTI orientation (" + std::string(h.sform > 0 ? "sform" : "qform") +
                       ") rotates or permutes the axes: only axis-aligned images (flips allowed) are supported; "
                       "resample it first");
    if (!(std::fabs(step) > 0) || !std::isfinite(step))
      fail(path, std::string("NIfTI voxel size along ") + axis_name(a) + " is " + number_text(step) +
                     " (it must be a finite nonzero length)");
    const std::size_t au = static_cast<std::size_t>(a);
    flip[au] = step < 0;
    g.spacing[au] = std::fabs(step);
    g.origin[au] = t[a] + (flip[au] ? static_cast<double>(g.size[au] - 1) * step : 0.0);
  }
  check_geometry(path, g);

  // The data: after vox_offset in the same file, or in the pair's .img.
  const std::size_t need = data_bytes(g, raw.type);
  if (!(h.vox_offset >= 0) || h.vox_offset > 1e12)
    fail(path, "NIfTI vox_offset " + number_text(h.vox_offset) + " is not a valid offset");
  const std::size_t offset = static_cast<std::size_t>(h.vox_offset);
  const std::string data_path = h.pair ? image_file_of(path) : path;
  if (!h.pair && offset < (h.version == 1 ? 348u : 540u))
    fail(path, "NIfTI vox_offset " + std::to_string(offset) + " lies inside the header");
  const std::string detached = h.pair ? read_detached(path, data_path) : std::string();
  const std::string& source = h.pair ? detached : file;
  // (The voxels are copied once: out of the file, or inflated in place.)
  const bool data_gz = gzipped(source);
  if (data_gz && (offset + need) / 1100 > source.size() + 64)
    fail(data_path, "gzip data is " + std::to_string(source.size()) + " bytes, far too short for the " +
                        std::to_string(need) + " bytes of the image the header gives");
  std::string inflated = data_gz ? inflate_prefix(data_path, "gzip data", source, offset + need) : std::string();
  const std::string& whole = data_gz ? inflated : source;
  if (whole.size() < offset + need)
    fail(data_path, "the data ends " + std::to_string(offset + need - whole.size()) +
                        " bytes short of the image the header gives (" + std::to_string(g.n_voxels()) + " voxels of " +
                        scalar_name(raw.type) + ")");
  if (data_gz) {
    inflated.erase(0, offset);
    raw.bytes = std::move(inflated);
  } else {
    raw.bytes.assign(source, offset, need);
  }
  raw.big_endian = h.big_endian;

  // Scaled values: the scalar image's own; labels cannot be scaled.
  const bool scaled = h.slope != 0 && std::isfinite(h.slope) && (h.slope != 1 || h.inter != 0);
  if (scaled && !std::isfinite(h.inter))  // (nibabel refuses it too: every voxel would be NaN)
    fail(path, "NIfTI scl_slope " + number_text(h.slope) + " with an intercept scl_inter that is not finite");
  if (scaled) {
    if (want_labels)
      fail(path, "NIfTI scl_slope/scl_inter scale the values (" + number_text(h.slope) + ", " +
                     number_text(h.inter) + "): a label image holds its labels unscaled");
    raw.doubles = raw_as_doubles(raw);
    for (double& v : raw.doubles) v = h.slope * v + h.inter;
    raw.bytes.clear();
    raw.type = ScalarType::f64;
    raw.converted = true;
  }
  return raw;
}

}  // namespace tessera::io::detail
