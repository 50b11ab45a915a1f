// numpy arrays over buffers that a C++ result owns, and checked inputs.
//
// Ownership contract (docs/design.md, "Python module"): a result struct
// (tessera::Cells, tessera::Delaunay) is moved once into the heap object of
// its bound Python class and never resized afterwards. Every array handed to
// Python views one of its std::vectors, with numpy's `base` set to that Python
// object, so the buffer lives as long as any view of it and nothing is copied.
// Views are read-only: the same buffers feed save(), to_vtk() and the derived
// scipy-style arrays, and writing into them could break those (e.g. a vertex id
// out of range in face_vertices); users copy what they want to modify.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

namespace tessera::python {

namespace py = pybind11;

/// Read-only array of `shape` over `data` (C order), kept alive by `owner`.
/// `data.size()` must equal the product of `shape`.
template <class T>
py::array view(std::span<const T> data, std::initializer_list<py::ssize_t> shape, py::handle owner) {
  // An empty std::vector may have a null data(); pybind11 would then allocate
  // (and own) a fresh buffer. Any valid address does for a zero-size view.
  static const T empty_marker{};
  const T* ptr = data.empty() ? &empty_marker : data.data();
  py::array_t<T> a(std::vector<py::ssize_t>(shape), ptr, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

/// Over any std::vector, whatever its allocator: the results' large arrays
/// are tessera::Buffer.
template <class T, class A>
py::array view(const std::vector<T, A>& data, std::initializer_list<py::ssize_t> shape, py::handle owner) {
  return view(std::span<const T>(data), shape, owner);
}

/// Rows of `width` values: shape (size / width, width).
template <class T, class A>
py::array view_rows(const std::vector<T, A>& data, std::size_t width, py::handle owner) {
  return view(std::span<const T>(data),
              {static_cast<py::ssize_t>(data.size() / width), static_cast<py::ssize_t>(width)}, owner);
}

/// One-dimensional view.
template <class T, class A>
py::array view_flat(const std::vector<T, A>& data, py::handle owner) {
  return view(std::span<const T>(data), {static_cast<py::ssize_t>(data.size())}, owner);
}

/// A writable array of `shape` that takes over `data` (moved, not copied):
/// for results that are nothing but arrays (joggled points, sampled labels),
/// where no C++ object outlives the call. A capsule owns the vector and is the
/// array's base; the array is the buffer's only user, so it may be written.
template <class T>
py::array adopt(std::vector<T>&& data, std::vector<py::ssize_t> shape) {
  auto heap = std::make_unique<std::vector<T>>(std::move(data));
  static const T empty_marker{};
  const T* ptr = heap->empty() ? &empty_marker : heap->data();
  py::capsule owner(heap.get(), [](void* p) { delete static_cast<std::vector<T>*>(p); });
  heap.release();  // the capsule owns it now
  py::array_t<T> a(shape, ptr, owner);
  // An empty vector points at the shared marker: never let it be written.
  if (ptr == &empty_marker) a.attr("setflags")(py::arg("write") = false);
  return a;
}

template <class T>
py::array adopt_flat(std::vector<T>&& data) {
  const auto n = static_cast<py::ssize_t>(data.size());
  return adopt(std::move(data), {n});
}

/// (k, 2) int32 array of id pairs (duplicates: (duplicate, owner)). A vector
/// of std::pair is not a numeric buffer, so this one is a copy; it is short.
inline py::array pairs_copy(const std::vector<std::pair<std::int32_t, std::int32_t>>& pairs) {
  py::array_t<std::int32_t> a({static_cast<py::ssize_t>(pairs.size()), py::ssize_t{2}});
  auto w = a.mutable_unchecked<2>();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    w(static_cast<py::ssize_t>(k), 0) = pairs[k].first;
    w(static_cast<py::ssize_t>(k), 1) = pairs[k].second;
  }
  return a;
}

/// Input points as given by the Python layer: float64, C-contiguous, shape
/// (N, 2) or (N, 3). The Python layer converts user input and writes the
/// user-facing messages; this re-checks the contract so the compiled functions
/// are safe to call directly. Returns the dimension.
inline int checked_dim(const py::array_t<double, py::array::c_style>& points) {
  if (points.ndim() != 2 || (points.shape(1) != 2 && points.shape(1) != 3))
    throw py::value_error("points must have shape (N, 2) or (N, 3)");
  return static_cast<int>(points.shape(1));
}

inline std::span<const double> as_span(const py::array_t<double, py::array::c_style>& a) {
  return {a.data(), static_cast<std::size_t>(a.size())};
}

/// Labels: None (no labels) or an int32 C-contiguous 1-D array.
inline std::span<const std::int32_t> as_labels(const py::object& labels) {
  if (labels.is_none()) return {};
  if (!py::isinstance<py::array_t<std::int32_t, py::array::c_style>>(labels))
    throw py::type_error("labels must be None or a C-contiguous int32 array");
  auto a = labels.cast<py::array_t<std::int32_t, py::array::c_style>>();
  if (a.ndim() != 1) throw py::value_error("labels must be one-dimensional");
  return {a.data(), static_cast<std::size_t>(a.size())};
}

/// Radii of power cells: None (ordinary cells) or a float64 C-contiguous
/// 1-D array. The span views the caller's array, which must stay alive (and
/// unchanged) for as long as the span is used.
inline std::span<const double> as_radii(const py::object& radii) {
  if (radii.is_none()) return {};
  if (!py::isinstance<py::array_t<double, py::array::c_style>>(radii))
    throw py::type_error("radii must be None or a C-contiguous float64 array");
  auto a = radii.cast<py::array_t<double, py::array::c_style>>();
  if (a.ndim() != 1) throw py::value_error("radii must be one-dimensional");
  return {a.data(), static_cast<std::size_t>(a.size())};
}

}  // namespace tessera::python
