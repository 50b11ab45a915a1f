// Helpers shared by the readers whose points come from named columns or
// fields (text headers, structured .npy records, PCD fields; .vtp/.vtu and
// .ply labels): the coordinates by name and labels from numeric values.
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "../message_text.hpp"
#include "io_detail.hpp"

namespace tessera::io::detail {

std::string quoted_list(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t k = 0; k < names.size(); ++k) s += (k ? ", '" : "'") + names[k] + "'";
  return s;
}

NamedAxes named_axes(const std::string& path, const std::vector<std::string>& names, const std::string& labels,
                     int dim, const std::string& what) {
  const std::size_t none = names.size();
  std::size_t col[3] = {none, none, none};
  for (std::size_t c = 0; c < names.size(); ++c) {
    const std::string& n = names[c];
    if (n.size() != 1) continue;
    const char l = static_cast<char>(n[0] | 0x20);  // ASCII lower case
    if (l < 'x' || l > 'z') continue;
    std::size_t& at = col[l - 'x'];
    if (at != none)
      fail(path, "the " + what + "s name coordinate '" + std::string(1, l) + "' twice (" + what + "s: " +
                     quoted_list(names) + ")");
    at = c;
  }
  NamedAxes a;
  if (col[0] == none || col[1] == none) return a;
  a.found = true;
  a.dim = dim ? dim : col[2] != none ? 3 : 2;
  if (a.dim == 3 && col[2] == none)
    fail(path, "3D points asked but no " + what + " is named 'z' (" + what + "s: " + quoted_list(names) + ")");
  for (int k = 0; k < a.dim; ++k) {
    a.col[k] = col[k];
    if (!labels.empty() && names[col[k]] == labels)
      fail(path, what + " '" + labels + "' cannot be both a coordinate and the labels");
  }
  return a;
}

std::vector<std::int32_t> labels_from_values(const std::string& path, const std::string& name,
                                             const std::vector<double>& v) {
  std::vector<std::int32_t> labels(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!(v[i] >= std::numeric_limits<std::int32_t>::min() && v[i] <= std::numeric_limits<std::int32_t>::max()))
      fail(path, "label in '" + name + "' at point " + std::to_string(i) + " does not fit in int32");
    // An integer column holding 2.7 (a text file's, a legacy VTK file's) was
    // truncated to label 2, silently.
    if (v[i] != std::floor(v[i]))
      fail(path, "label in '" + name + "' at point " + std::to_string(i) + " is " + tessera::detail::number_text(v[i]) +
                     ", not a whole number");
    labels[i] = static_cast<std::int32_t>(v[i]);
  }
  return labels;
}

std::vector<std::int32_t> atom_labels(const std::string& path, const std::string& column,
                                      const std::vector<double>& values, std::size_t stride, std::size_t at) {
  std::vector<std::int32_t> labels(stride == 0 ? 0 : values.size() / stride);
  for (std::size_t k = 0; k < labels.size(); ++k) {
    const double value = values[k * stride + at];
    if (!(value == std::floor(value) && value >= std::numeric_limits<std::int32_t>::min() &&
          value <= std::numeric_limits<std::int32_t>::max())) {
      char buf[40];
      std::snprintf(buf, sizeof buf, "%.17g", value);
      fail(path, "labels '" + column + "' of atom " + std::to_string(k) + " (0-based, in file order): " + buf +
                     " is not an int32");
    }
    labels[k] = static_cast<std::int32_t>(value);
  }
  return labels;
}

}  // namespace tessera::io::detail
