// Pieces of the library's error messages: how they name an axis and write a
// number (the shortest text that reads back as the same double, so that a
// point an ulp outside a box shows it, and 0.1 stays 0.1).
#pragma once

#include <charconv>
#include <string>

namespace tessera::detail {

inline const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

/// Shortest text that reads back as `v`.
inline std::string number_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace tessera::detail
