// Array properties shared by the face-set-like results: FaceSet
// (bind_dual.cpp) and SurfaceNet (bind_surface_nets.cpp, whose mesh is a
// FaceSet). Every property is a read-only view whose base is the result
// object (arrays.hpp).
#pragma once

#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "arrays.hpp"
#include "tessera/faces.hpp"

namespace tessera::python {

/// uint8 view of a vector of a one-byte enum (SpokeClass, NetVertexKind).
template <class E>
py::array byte_view(const std::vector<E>& v, py::handle owner) {
  static_assert(std::is_enum_v<E> && sizeof(E) == sizeof(std::uint8_t));
  return view(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(v.data()), v.size()),
              {static_cast<py::ssize_t>(v.size())}, owner);
}

/// Defines the FaceSet arrays on `cls`; `mesh(const Class&)` returns the FaceSet.
template <class Class, class Mesh>
void def_face_arrays(py::class_<Class>& cls, Mesh mesh) {
  auto of = [mesh](const py::object& s) -> const FaceSet& { return mesh(s.cast<const Class&>()); };
  cls.def_property_readonly("dim", [mesh](const Class& c) { return mesh(c).dim; })
      .def_property_readonly("kind", [mesh](const Class& c) { return std::string(face_set_kind_name(mesh(c).kind)); })
      .def_property_readonly("n_faces", [mesh](const Class& c) { return mesh(c).n_faces(); })
      .def_property_readonly("n_vertices", [mesh](const Class& c) { return mesh(c).n_vertices(); })
      .def_property_readonly("vertices",
                             [of](py::object s) {
                               const FaceSet& f = of(s);
                               return view_rows(f.vertices, static_cast<std::size_t>(f.dim), s);
                             })
      .def_property_readonly("vertex_keys",
                             [of](py::object s) {
                               const FaceSet& f = of(s);
                               return view_rows(f.vertex_keys, static_cast<std::size_t>(f.dim + 1), s);
                             })
      .def_property_readonly("face_offsets", [of](py::object s) { return view_flat(of(s).face_offsets, s); })
      .def_property_readonly("face_vertices", [of](py::object s) { return view_flat(of(s).face_vertices, s); })
      .def_property_readonly("sides", [of](py::object s) { return view_rows(of(s).sides, 2, s); })
      .def_property_readonly("boundary_labels", [of](py::object s) { return view_rows(of(s).boundary_labels, 2, s); })
      .def_property_readonly("face_class", [of](py::object s) { return byte_view(of(s).face_class, s); })
      // Periodic cells only (empty otherwise): int8 (n_faces, D) and (n_vertices, D + 1, D).
      .def_property_readonly("side_shifts",
                             [of](py::object s) {
                               const FaceSet& f = of(s);
                               return view_rows(f.side_shifts, static_cast<std::size_t>(f.dim), s);
                             })
      .def_property_readonly("vertex_key_shifts",
                             [of](py::object s) {
                               const FaceSet& f = of(s);
                               const auto du = static_cast<std::size_t>(f.dim);
                               const auto nv = static_cast<py::ssize_t>(f.vertex_key_shifts.size() / (du * (du + 1)));
                               return view(std::span<const std::int8_t>(f.vertex_key_shifts),
                                           {nv, static_cast<py::ssize_t>(du + 1), static_cast<py::ssize_t>(du)}, s);
                             })
      .def_property_readonly("periodic", [mesh](const Class& c) {
        const FaceSet& f = mesh(c);
        py::tuple t(static_cast<std::size_t>(f.dim));
        for (int a = 0; a < f.dim; ++a) t[static_cast<std::size_t>(a)] = f.periodic[static_cast<std::size_t>(a)];
        return t;
      });
}

}  // namespace tessera::python
