// Front-end options from the keyword arguments the Python layer passes on.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "interrupt.hpp"
#include "tessera/cells.hpp"

namespace tessera::python {

namespace py = pybind11;

/// Domain box in the CLI's order (x0, x1, y0, y1[, z0, z1]) -> Bounds. The
/// length must be 2 * dim; the ranges themselves are checked by the front end.
inline Bounds bounds_from(const std::vector<double>& b, int dim) {
  if (b.size() != static_cast<std::size_t>(2 * dim))
    throw py::value_error("bounds must have " + std::to_string(2 * dim) + " values (x0, x1, y0, y1" +
                          (dim == 3 ? ", z0, z1" : "") + ") for " + std::to_string(dim) + "D points, got " +
                          std::to_string(b.size()));
  Bounds out;
  for (int d = 0; d < dim; ++d) {
    out.lo[static_cast<std::size_t>(d)] = b[static_cast<std::size_t>(2 * d)];
    out.hi[static_cast<std::size_t>(d)] = b[static_cast<std::size_t>(2 * d + 1)];
  }
  return out;
}

/// Bounds -> the CLI's order, as a Python tuple.
inline py::tuple bounds_tuple(const Bounds& b, int dim) {
  py::tuple t(static_cast<std::size_t>(2 * dim));
  for (int d = 0; d < dim; ++d) {
    t[static_cast<std::size_t>(2 * d)] = b.lo[static_cast<std::size_t>(d)];
    t[static_cast<std::size_t>(2 * d + 1)] = b.hi[static_cast<std::size_t>(d)];
  }
  return t;
}

/// Options every product shares (threads: 0 = TESSERA_NUM_THREADS, else all
/// cores, resolved by the front end). Must be called with the GIL held (it sets
/// up the Ctrl-C check).
inline void fill_common(VoronoiOptions& opt, int dim, const std::optional<std::vector<double>>& bounds,
                        double padding, bool ignore_outside, int threads) {
  if (threads < 0) throw py::value_error("threads must be >= 1, or 0/None for the default");
  opt.dim = dim;
  if (bounds) opt.bounds = bounds_from(*bounds, dim);
  opt.padding = padding;
  opt.ignore_outside_points = ignore_outside;
  opt.threads = threads;
  opt.progress = interrupt_check();
}

/// Walls (VoronoiOptions::walls) from None or a float64 (k, dim + 1) array of
/// rows (normal..., offset), as the Python layer passes them (_inputs.as_walls).
inline std::vector<Wall> walls_from(const py::object& walls, int dim) {
  std::vector<Wall> out;
  if (walls.is_none()) return out;
  const auto w = walls.cast<py::array_t<double, py::array::c_style>>();
  if (w.ndim() != 2 || w.shape(1) != dim + 1)
    throw py::value_error("walls must be a float64 array of shape (k, " + std::to_string(dim + 1) + ")");
  for (py::ssize_t k = 0; k < w.shape(0); ++k) {
    Wall wall;
    for (int a = 0; a < dim; ++a) wall.normal[static_cast<std::size_t>(a)] = w.at(k, a);
    wall.offset = w.at(k, dim);
    out.push_back(wall);
  }
  return out;
}

}  // namespace tessera::python
