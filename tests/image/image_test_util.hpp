// Helpers for the image tests: error checks and the reference voxel formulas
// of make_images.py (the temporary directory and error capture are the io
// tests', tests/io/io_test_util.hpp).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>

#include "io/io_test_util.hpp"
#include "tessera/cells.hpp"

namespace image_test {

namespace fs = std::filesystem;

// The io tests' self-cleaning temporary directory and InputError capture.
using tessera_test::input_error;
using tessera_test::TempDir;

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
