// Helpers for the IO tests: a self-cleaning temporary directory, raw .npy
// construction (to test headers/dtypes NumPy would write), and error capture.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "tessera/cells.hpp"
#include "tessera/io/points.hpp"

namespace tessera_test {

namespace fs = std::filesystem;

/// A fresh directory under the system temp dir, removed with its contents.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("tessera_io_test_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(counter++) + "_" + std::to_string(rd()));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  /// Write `bytes` to `name` in the directory; returns the full path.
  std::string write(const std::string& name, std::string_view bytes) const {
    std::string p = file(name);
    std::ofstream f(p, std::ios::binary);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p;
  }
  /// Names of the entries in the directory, sorted.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

 private:
  fs::path path_;
};

inline std::string read_all(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

/// Raw bytes of `v`, little-endian or (big_endian) byte-swapped per item.
template <class T>
std::string raw_bytes(const std::vector<T>& v, bool big_endian = false) {
  std::string s(v.size() * sizeof(T), '\0');
  if (!v.empty()) std::memcpy(s.data(), v.data(), s.size());
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  if (swap)
    for (std::size_t k = 0; k < v.size(); ++k)
      std::reverse(s.begin() + static_cast<std::ptrdiff_t>(k * sizeof(T)),
                   s.begin() + static_cast<std::ptrdiff_t>((k + 1) * sizeof(T)));
  return s;
}

/// An .npy file image with the given descr/shape text (e.g. "<f8", "(3, 2)";
/// a structured descr as its list literal, "[('x', '<f8'), ...]"),
/// header version `major`.0 and raw data.
inline std::string make_npy(const std::string& descr, const std::string& shape, std::string_view data,
                            bool fortran = false, int major = 1) {
  // A structured dtype's descr is a list literal, written as given.
  const std::string d = !descr.empty() && descr[0] == '[' ? descr : "'" + descr + "'";
  std::string dict = "{'descr': " + d + ", 'fortran_order': " + (fortran ? "True" : "False") +
                     ", 'shape': " + shape + ", }";
  const std::size_t prefix = major == 1 ? 10 : 12;
  dict.append((64 - (prefix + dict.size() + 1) % 64) % 64, ' ');
  dict += '\n';
  std::string out = "\x93NUMPY";
  out += static_cast<char>(major);
  out += '\0';
  const std::size_t len = dict.size();
  out += static_cast<char>(len & 0xff);
  out += static_cast<char>((len >> 8) & 0xff);
  if (major != 1) {
    out += static_cast<char>((len >> 16) & 0xff);
    out += static_cast<char>((len >> 24) & 0xff);
  }
  out += dict;
  out.append(data);
  return out;
}

/// Run `f`, expecting tessera::InputError; returns its message ("" and a test
/// failure if nothing or something else was thrown).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const tessera::InputError& e) {
    std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "error message is not one line: " << msg;
    return msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing thrown";
  return "";
}

/// Read options asking for labels from the column, property or field `name`.
inline tessera::io::ReadOptions labels(const std::string& name) {
  tessera::io::ReadOptions o;
  o.labels = name;
  return o;
}

/// A read cloud's dimension, coordinates and (where given) labels.
inline void expect_cloud(const tessera::io::PointCloud& pc, int dim, const std::vector<double>& coords,
                         const std::vector<std::int32_t>& labels = {}) {
  EXPECT_EQ(pc.dim, dim);
  EXPECT_EQ(pc.n, coords.size() / static_cast<std::size_t>(dim));
  EXPECT_EQ(pc.coords, coords);
  if (!labels.empty()) EXPECT_EQ(pc.labels, labels);
}

}  // namespace tessera_test
