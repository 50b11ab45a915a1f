// Helpers for the image tests: a self-cleaning temporary directory, error
// capture, and the reference voxel formulas of make_images.py.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <string_view>

#include "tessera/cells.hpp"

namespace image_test {

namespace fs = std::filesystem;

class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    std::random_device rd;
    path_ = fs::temp_directory_path() / ("tessera_image_test_" + std::to_string(::getpid()) + "_" +
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
  std::string write(const std::string& name, std::string_view bytes) const {
    const std::string p = file(name);
    std::ofstream f(p, std::ios::binary);
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p;
  }

 private:
  fs::path path_;
};

/// The message of the InputError `f` throws ("" and a test failure if none).
inline std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const tessera::InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return "";
}

/// Checks that `msg` is one line mentioning every one of `parts`.
inline void expect_error(const std::string& msg, std::initializer_list<std::string_view> parts) {
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  for (std::string_view p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
}

// make_images.py's formulas (voxel index i, j, k; x fastest).
inline std::int32_t label_at(std::int64_t i, std::int64_t j, std::int64_t k) {
  return static_cast<std::int32_t>((7 * i + 13 * j + 31 * k) % 97 - 20);
}
inline double field_at(std::int64_t i, std::int64_t j, std::int64_t k) {
  return 0.5 * static_cast<double>(i) - 0.25 * static_cast<double>(j) + 2.0 * static_cast<double>(k) + 0.125;
}
inline std::int32_t byte_at(std::int64_t i, std::int64_t j, std::int64_t k) {
  return static_cast<std::int32_t>((3 * i + 5 * j + 11 * k) % 256);
}

}  // namespace image_test
