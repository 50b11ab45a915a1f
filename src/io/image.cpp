// read_label_image / read_scalar_image: dispatch by extension to the format
// readers (image_npy.cpp, image_nrrd.cpp, image_metaimage.cpp, image_vti.cpp),
// then conversion of the decoded voxels to int32 labels or doubles. Also the
// helpers the readers share (zlib inflation, ascii values, geometry checks).
#include "tessera/io/image.hpp"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <type_traits>

#include "image_detail.hpp"
#include "io_detail.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/atomic_file.hpp"

namespace tessera::io {
namespace detail {

std::size_t scalar_size(ScalarType t) {
  switch (t) {
    case ScalarType::i8:
    case ScalarType::u8:
      return 1;
    case ScalarType::i16:
    case ScalarType::u16:
      return 2;
    case ScalarType::i32:
    case ScalarType::u32:
    case ScalarType::f32:
      return 4;
    default:
      return 8;
  }
}

const char* scalar_name(ScalarType t) {
  static constexpr const char* names[] = {"int8",   "uint8", "int16", "uint16",  "int32",
                                          "uint32", "int64", "uint64", "float32", "float64"};
  return names[static_cast<int>(t)];
}

void check_geometry(const std::string& path, const ImageGeometry& g) {
  if (g.dim != 2 && g.dim != 3) fail(path, "images must be 2D or 3D, got " + std::to_string(g.dim) + "D");
  if (g.dim == 2 && g.size[2] != 1) fail(path, "a 2D image has one voxel along z");
  // 2^40 voxels: far beyond memory, and the product cannot overflow below it.
  constexpr std::int64_t kMax = std::int64_t(1) << 40;
  std::int64_t n = 1;
  for (int a = 0; a < 3; ++a) {
    const std::int64_t s = g.size[static_cast<std::size_t>(a)];
    if (s < 1) fail(path, "empty image (size " + std::to_string(s) + " along axis " + std::to_string(a) + ")");
    if (s > kMax || n > kMax / s) fail(path, "image too large (more than 2^40 voxels)");
    n *= s;
  }
  for (int a = 0; a < g.dim; ++a) {
    const double s = g.spacing[static_cast<std::size_t>(a)], o = g.origin[static_cast<std::size_t>(a)];
    if (!(s > 0) || !std::isfinite(s))
      fail(path, "spacing along axis " + std::to_string(a) + " must be a finite number > 0");
    if (!std::isfinite(o)) fail(path, "origin along axis " + std::to_string(a) + " must be finite");
    // The last voxel centre (and the half voxel beyond it that bounds the
    // image's domain) must be representable: samples there were infinite.
    const double last = static_cast<double>(g.size[static_cast<std::size_t>(a)] - 1);
    if (!std::isfinite(o + (last + 0.5) * s) || !std::isfinite(o - 0.5 * s))
      fail(path, "voxel centres along axis " + std::to_string(a) + " (origin + index x spacing) pass double's range");
  }
}

std::size_t data_bytes(const ImageGeometry& g, ScalarType t) { return g.n_voxels() * scalar_size(t); }

std::string inflate_exact(const std::string& path, std::string_view what, std::string_view src,
                          std::size_t expected) {
  // Inflation expands at most ~1032:1; a header claiming more than that is
  // lying about the sizes (and would make us allocate for nothing).
  if (expected / 1100 > src.size() + 64)
    fail(path, std::string(what) + " is " + std::to_string(src.size()) + " bytes, far too short for the " +
                   std::to_string(expected) + " bytes the header gives");
  std::string out(expected, '\0');
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) fail(path, "zlib initialisation failed");
  std::size_t in_pos = 0, out_pos = 0;
  int rc = Z_OK;
  unsigned char overflow[256];
  bool too_long = false;
  for (;;) {
    const std::size_t in_chunk = std::min<std::size_t>(src.size() - in_pos, 1u << 30);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(src.data() + in_pos));
    z.avail_in = static_cast<uInt>(in_chunk);
    if (out_pos < expected) {
      const std::size_t out_chunk = std::min<std::size_t>(expected - out_pos, 1u << 30);
      z.next_out = reinterpret_cast<Bytef*>(out.data() + out_pos);
      z.avail_out = static_cast<uInt>(out_chunk);
    } else {
      z.next_out = overflow;  // anything produced here is too much
      z.avail_out = sizeof(overflow);
    }
    const uInt avail_out_before = z.avail_out;
    rc = inflate(&z, Z_NO_FLUSH);
    const std::size_t produced = avail_out_before - z.avail_out;
    in_pos += in_chunk - z.avail_in;
    if (out_pos < expected)
      out_pos += produced;
    else if (produced > 0)
      too_long = true;
    if (too_long) break;
    if (rc == Z_STREAM_END) {
      // Concatenated gzip members: go on with the next one, if any (only
      // when there is more than trailing padding).
      std::size_t rest = in_pos;
      while (rest < src.size() && src[rest] == '\0') ++rest;
      if (rest >= src.size()) break;
      if (inflateReset(&z) != Z_OK) break;
      continue;
    }
    if (rc == Z_BUF_ERROR && z.avail_in == 0 && in_pos >= src.size()) break;  // input ended early
    if (rc != Z_OK) break;
  }
  inflateEnd(&z);
  if (too_long)
    fail(path, std::string(what) + " inflates to more than the " + std::to_string(expected) +
                   " bytes the header gives (mismatched sizes)");
  if (rc != Z_STREAM_END && rc != Z_OK && rc != Z_BUF_ERROR)
    fail(path, std::string(what) + " is corrupt (zlib: " + (z.msg ? z.msg : "error " + std::to_string(rc)) + ")");
  if (out_pos < expected)
    fail(path, std::string(what) + " inflates to " + std::to_string(out_pos) + " bytes, shorter than the " +
                   std::to_string(expected) + " the header gives");
  if (rc != Z_STREAM_END)
    fail(path, std::string(what) + " is truncated (the compressed stream does not end)");
  return out;
}

std::string inflate_prefix(const std::string& path, std::string_view what, std::string_view src, std::size_t limit) {
  // Grown as the stream gives bytes, never sized by the caller's limit alone.
  std::string out;
  z_stream z{};
  if (inflateInit2(&z, 15 + 32) != Z_OK) fail(path, "zlib initialisation failed");
  std::size_t in_pos = 0;
  int rc = Z_OK;
  char buf[1 << 16];
  while (out.size() < limit) {
    const std::size_t in_chunk = std::min<std::size_t>(src.size() - in_pos, 1u << 30);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(src.data() + in_pos));
    z.avail_in = static_cast<uInt>(in_chunk);
    z.next_out = reinterpret_cast<Bytef*>(buf);
    z.avail_out = static_cast<uInt>(std::min<std::size_t>(sizeof buf, limit - out.size()));
    const uInt before = z.avail_out;
    rc = inflate(&z, Z_NO_FLUSH);
    out.append(buf, before - z.avail_out);
    in_pos += in_chunk - z.avail_in;
    if (rc == Z_STREAM_END) {
      if (in_pos >= src.size() || inflateReset(&z) != Z_OK) break;  // (concatenated members go on)
      continue;
    }
    if (rc == Z_BUF_ERROR && z.avail_in == 0 && in_pos >= src.size()) break;  // input ended early
    if (rc != Z_OK) break;
  }
  inflateEnd(&z);
  if (rc != Z_STREAM_END && rc != Z_OK && rc != Z_BUF_ERROR)
    fail(path, std::string(what) + " is corrupt (zlib: " + (z.msg ? z.msg : "error " + std::to_string(rc)) + ")");
  return out;
}

void flip_axis(RawImage& raw, int axis) {
  const ImageGeometry& g = raw.geometry;
  const std::size_t nx = static_cast<std::size_t>(g.size[0]), ny = static_cast<std::size_t>(g.size[1]),
                    nz = static_cast<std::size_t>(g.size[2]);
  // Voxel (x, y, z) takes the item of its mirror along `axis`, in place:
  // the first half of each line swaps with the second.
  auto swap_all = [&](auto&& swap_items) {
    const std::size_t n[3] = {nx, ny, nz};
    const std::size_t stride[3] = {1, nx, nx * ny};
    const std::size_t a = static_cast<std::size_t>(axis);
    const std::size_t len = n[a], step = stride[a];
    for (std::size_t z = 0; z < (a == 2 ? 1 : nz); ++z)
      for (std::size_t y = 0; y < (a == 1 ? 1 : ny); ++y)
        for (std::size_t x = 0; x < (a == 0 ? 1 : nx); ++x) {
          const std::size_t base = x + nx * (y + ny * z);
          for (std::size_t i = 0; i < len / 2; ++i) swap_items(base + i * step, base + (len - 1 - i) * step);
        }
  };
  if (raw.converted) {
    if (is_float(raw.type))
      swap_all([&](std::size_t p, std::size_t q) { std::swap(raw.doubles[p], raw.doubles[q]); });
    else
      swap_all([&](std::size_t p, std::size_t q) { std::swap(raw.ints[p], raw.ints[q]); });
    return;
  }
  const std::size_t item = scalar_size(raw.type);
  swap_all([&](std::size_t p, std::size_t q) {
    std::swap_ranges(raw.bytes.begin() + static_cast<std::ptrdiff_t>(p * item),
                     raw.bytes.begin() + static_cast<std::ptrdiff_t>((p + 1) * item),
                     raw.bytes.begin() + static_cast<std::ptrdiff_t>(q * item));
  });
}

std::string printable(std::string_view s, std::size_t max) {
  std::string r(s.substr(0, max));
  for (char& c : r)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  if (s.size() > max) r += "...";
  return r;
}

std::string_view trim(std::string_view s) {
  auto ws = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; };
  while (!s.empty() && ws(s.front())) s.remove_prefix(1);
  while (!s.empty() && ws(s.back())) s.remove_suffix(1);
  return s;
}

namespace {

bool is_ws(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }

/// Next whitespace-separated token of `s` from `pos` ("" at the end).
std::string_view next_token(std::string_view s, std::size_t& pos) {
  while (pos < s.size() && is_ws(s[pos])) ++pos;
  const std::size_t start = pos;
  while (pos < s.size() && !is_ws(s[pos])) ++pos;
  return s.substr(start, pos - start);
}

template <class T>
bool parse_one(std::string_view tok, T& v) {
  if (tok.empty()) return false;
  if constexpr (std::is_floating_point_v<T>) {
    // from_chars for double does not take "+1" or "inf"/"nan" spelled as
    // some writers do; strtod does (the token is short, copy it).
    std::string t(tok);
    char* end = nullptr;
    const double d = std::strtod(t.c_str(), &end);
    if (end != t.c_str() + t.size()) return false;
    v = static_cast<T>(d);
    return true;
  } else {
    if (tok.front() == '+') tok.remove_prefix(1);
    auto [p, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    return ec == std::errc() && p == tok.data() + tok.size();
  }
}

template <class T>
void parse_ascii_as(const std::string& path, std::string_view text, std::size_t count, std::string& out) {
  // n values take at least 2n - 1 characters: a count the text cannot hold
  // is refused before anything is sized by it.
  if (count > text.size() / 2 + 1)
    fail(path, "ascii data is shorter than the " + std::to_string(count) + " values the header gives");
  out.assign(count * sizeof(T), '\0');
  std::size_t pos = 0;
  for (std::size_t k = 0; k < count; ++k) {
    std::string_view tok = next_token(text, pos);
    if (tok.empty())
      fail(path, "ascii data has " + std::to_string(k) + " values, shorter than the " + std::to_string(count) +
                     " the header gives");
    T v{};
    if (!parse_one(tok, v))
      fail(path, "ascii data: '" + printable(tok, 40) + "' is not a valid " +
                     (std::is_floating_point_v<T> ? "number" : "integer of the declared type"));
    std::memcpy(out.data() + k * sizeof(T), &v, sizeof(T));
  }
  if (!next_token(text, pos).empty())
    fail(path, "ascii data has more values than the " + std::to_string(count) + " the header gives (mismatched sizes)");
}

}  // namespace

std::string parse_ascii_values(const std::string& path, std::string_view text, ScalarType t, std::size_t count) {
  std::string out;
  switch (t) {
    case ScalarType::i8: parse_ascii_as<std::int8_t>(path, text, count, out); break;
    case ScalarType::u8: parse_ascii_as<std::uint8_t>(path, text, count, out); break;
    case ScalarType::i16: parse_ascii_as<std::int16_t>(path, text, count, out); break;
    case ScalarType::u16: parse_ascii_as<std::uint16_t>(path, text, count, out); break;
    case ScalarType::i32: parse_ascii_as<std::int32_t>(path, text, count, out); break;
    case ScalarType::u32: parse_ascii_as<std::uint32_t>(path, text, count, out); break;
    case ScalarType::i64: parse_ascii_as<std::int64_t>(path, text, count, out); break;
    case ScalarType::u64: parse_ascii_as<std::uint64_t>(path, text, count, out); break;
    case ScalarType::f32: parse_ascii_as<float>(path, text, count, out); break;
    case ScalarType::f64: parse_ascii_as<double>(path, text, count, out); break;
  }
  return out;
}

std::string read_detached(const std::string& path, const std::string& data_path) {
  note_file_read(data_path, "the data file of " + path);
  // A FIFO named by a header (not by the user, who may pass <(command) as an
  // input) blocks until something writes to it: refused.
  std::error_code ec;
  if (std::filesystem::is_fifo(data_path, ec))
    fail(path, "cannot open data file " + data_path + ": a FIFO, not a file");
  try {
    return read_file_bytes(data_path);
  } catch (const InputError& e) {
    std::string why = e.what();
    const std::size_t colon = why.rfind(": ");
    why = colon == std::string::npos ? why : why.substr(colon + 2);
    fail(path, "cannot open data file " + data_path + ": " + why);
  }
}

std::string directory_of(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

bool parse_doubles(std::string_view text, std::size_t n, double* out) {
  std::size_t pos = 0;
  for (std::size_t k = 0; k < n; ++k) {
    std::string_view tok = next_token(text, pos);
    if (!parse_one(tok, out[k]) || !std::isfinite(out[k])) return false;
  }
  return next_token(text, pos).empty();
}

bool parse_sizes(std::string_view text, std::size_t n, std::int64_t* out) {
  std::size_t pos = 0;
  for (std::size_t k = 0; k < n; ++k) {
    std::string_view tok = next_token(text, pos);
    if (!parse_one(tok, out[k]) || out[k] < 1) return false;
  }
  return next_token(text, pos).empty();
}

}  // namespace detail

namespace {

using detail::RawImage;
using detail::ScalarType;


/// Calls f(value) for every voxel of `raw` (decoded bytes), as type T.
template <class T, class F>
void each_value(const RawImage& raw, F&& f) {
  const bool swap = sizeof(T) > 1 && raw.big_endian != (std::endian::native == std::endian::big);
  const char* p = raw.bytes.data();
  const std::size_t n = raw.bytes.size() / sizeof(T);
  for (std::size_t k = 0; k < n; ++k) f(k, detail::load_item<T>(p + k * sizeof(T), swap));
}

template <class F>
void dispatch(const RawImage& raw, F&& f) {
  switch (raw.type) {
    case ScalarType::i8: each_value<std::int8_t>(raw, f); break;
    case ScalarType::u8: each_value<std::uint8_t>(raw, f); break;
    case ScalarType::i16: each_value<std::int16_t>(raw, f); break;
    case ScalarType::u16: each_value<std::uint16_t>(raw, f); break;
    case ScalarType::i32: each_value<std::int32_t>(raw, f); break;
    case ScalarType::u32: each_value<std::uint32_t>(raw, f); break;
    case ScalarType::i64: each_value<std::int64_t>(raw, f); break;
    case ScalarType::u64: each_value<std::uint64_t>(raw, f); break;
    case ScalarType::f32: each_value<float>(raw, f); break;
    case ScalarType::f64: each_value<double>(raw, f); break;
  }
}

RawImage read_raw(const std::string& path, const ImageReadOptions& options, bool want_labels) {
  const std::string ext = detail::lower_extension(path);
  RawImage raw;
  if (detail::is_nifti_path(path)) {
    raw = detail::read_nifti_image(path, want_labels);
  } else if (ext == ".npy") {
    raw = detail::read_npy_image(path, want_labels);
  } else if (ext == ".nrrd" || ext == ".nhdr") {
    raw = detail::read_nrrd_image(path);
  } else if (ext == ".mha" || ext == ".mhd") {
    raw = detail::read_metaimage(path);
  } else if (ext == ".vti") {
    raw = detail::read_vti_image(path, options.array);
  } else if (ext == ".vtk") {
    raw = detail::read_vtk_legacy_image(path, options.array);
  } else {
    detail::fail(path, "unknown image extension '" + ext +
                           "' (expected .npy, .nrrd, .nhdr, .mha, .mhd, .vti, .vtk, .nii, .nii.gz or .hdr)");
  }
  for (int a = 0; a < 3; ++a)
    if (raw.flip[static_cast<std::size_t>(a)]) detail::flip_axis(raw, a);
  if (!options.array.empty() && ext != ".vti" && ext != ".vtk")
    detail::fail(path, "an array name ('" + options.array + "') can only be chosen in .vti and .vtk files");
  ImageGeometry& g = raw.geometry;
  if (options.spacing) g.spacing = *options.spacing;
  if (options.origin) g.origin = *options.origin;
  if (g.dim == 2) {
    g.spacing[2] = 1;
    g.origin[2] = 0;
  }
  detail::check_geometry(path, g);
  const std::size_t n = g.n_voxels();
  const std::size_t have = raw.converted ? (detail::is_float(raw.type) ? raw.doubles.size() : raw.ints.size())
                                         : raw.bytes.size() / detail::scalar_size(raw.type);
  if (have != n)  // a reader bug, not bad input: readers check the data length
    detail::fail(path, "internal error: decoded " + std::to_string(have) + " voxels, expected " + std::to_string(n));
  return raw;
}

}  // namespace

void check_image_geometry(const std::string& what, const ImageGeometry& g) { detail::check_geometry(what, g); }

LabelImage read_label_image(const std::string& path, const ImageReadOptions& options) {
  RawImage raw = read_raw(path, options, true);
  if (detail::is_float(raw.type))
    detail::fail(path, std::string(detail::scalar_name(raw.type)) +
                           " data is not a label image (expected an integer type)");
  LabelImage img;
  img.geometry = raw.geometry;
  img.labels.resize(raw.geometry.n_voxels());
  constexpr std::int64_t lo = std::numeric_limits<std::int32_t>::min();
  constexpr std::int64_t hi = std::numeric_limits<std::int32_t>::max();
  auto out_of_range = [&](std::size_t k, const std::string& v) {
    detail::fail(path, "label " + v + " at voxel " + std::to_string(k) + " does not fit in int32");
  };
  if (raw.converted) {
    for (std::size_t k = 0; k < raw.ints.size(); ++k) {
      const std::int64_t v = raw.ints[k];
      if (v < lo || v > hi) out_of_range(k, std::to_string(v));
      img.labels[k] = static_cast<std::int32_t>(v);
    }
    return img;
  }
  dispatch(raw, [&](std::size_t k, auto v) {
    using T = decltype(v);
    if constexpr (std::is_floating_point_v<T>) {
      // unreachable: float types rejected above
    } else if constexpr (std::is_signed_v<T>) {
      if (static_cast<std::int64_t>(v) < lo || static_cast<std::int64_t>(v) > hi) out_of_range(k, std::to_string(v));
    } else {
      if (static_cast<std::uint64_t>(v) > static_cast<std::uint64_t>(hi)) out_of_range(k, std::to_string(v));
    }
    if constexpr (!std::is_floating_point_v<T>) img.labels[k] = static_cast<std::int32_t>(v);
  });
  return img;
}

namespace detail {

std::vector<double> raw_as_doubles(const RawImage& raw) {
  if (raw.converted && is_float(raw.type)) return raw.doubles;
  std::vector<double> out(raw.geometry.n_voxels());
  if (raw.converted)
    for (std::size_t k = 0; k < raw.ints.size(); ++k) out[k] = static_cast<double>(raw.ints[k]);
  else
    dispatch(raw, [&](std::size_t k, auto v) { out[k] = static_cast<double>(v); });
  return out;
}

}  // namespace detail

ScalarImage read_scalar_image(const std::string& path, const ImageReadOptions& options) {
  RawImage raw = read_raw(path, options, false);
  ScalarImage img;
  img.geometry = raw.geometry;
  img.values = raw.converted && detail::is_float(raw.type) ? std::move(raw.doubles) : detail::raw_as_doubles(raw);
  return img;
}

}  // namespace tessera::io
