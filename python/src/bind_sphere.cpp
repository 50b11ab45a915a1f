// tessera._core.SphericalVoronoi / spherical_voronoi() / lonlat_to_points():
// Voronoi cells on a sphere (include/tessera/spherical_voronoi.hpp), the
// arrays viewing the result. Runs without the GIL.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "interrupt.hpp"
#include "tessera/io/spherical.hpp"
#include "tessera/spherical_voronoi.hpp"

namespace tessera::python {
namespace {

using Points = py::array_t<double, py::array::c_style>;

SphericalVoronoi run(const Points& points, const std::array<double, 3>& center, double radius, double tolerance,
                     int threads) {
  if (points.ndim() != 2 || points.shape(1) != 3) throw py::value_error("points must have shape (N, 3)");
  SphericalVoronoiOptions o;
  o.center = center;
  o.radius = radius;
  o.tolerance = tolerance;
  o.threads = threads;
  o.progress = interrupt_check();  // Ctrl-C: KeyboardInterrupt between chunks of cells
  const auto pts = as_span(points);
  return without_gil([&] { return spherical_voronoi(pts, o); });
}

}  // namespace

void bind_sphere(py::module_& m) {
  using SV = SphericalVoronoi;
  py::class_<SV> c(m, "SphericalVoronoi", "Result of spherical_voronoi(): cells on a sphere and their dual triangles.");
  auto get = [](py::object s) -> const SV& { return s.cast<const SV&>(); };
  c.def_property_readonly("center", [](const SV& s) { return s.center; })
      .def_readonly("radius", &SV::radius)
      .def_readonly("n_points", &SV::n_points)
      .def_readonly("duplicates", &SV::duplicates)
      .def_readonly("hidden", &SV::hidden)
      .def_readonly("max_deviation", &SV::max_deviation)
      .def_readonly("area_sum", &SV::area_sum)
      .def_readonly("exact_tests", &SV::exact_tests)
      .def_property_readonly("region_offsets", [get](py::object s) { return view_flat(get(s).region_offsets, s); })
      .def_property_readonly("region_vertices", [get](py::object s) { return view_flat(get(s).region_vertices, s); })
      .def_property_readonly("neighbor_offsets", [get](py::object s) { return view_flat(get(s).neighbor_offsets, s); })
      .def_property_readonly("neighbors", [get](py::object s) { return view_flat(get(s).neighbors, s); })
      .def_property_readonly("vertices", [get](py::object s) { return view_rows(get(s).vertices, 3, s); })
      .def_property_readonly("triangles", [get](py::object s) { return view_rows(get(s).triangles, 3, s); })
      .def_property_readonly("areas", [get](py::object s) { return view_flat(get(s).areas, s); })
      .def_property_readonly("centroids", [get](py::object s) { return view_rows(get(s).centroids, 3, s); })
      .def_property_readonly("status",
                             [get](py::object s) {
                               const auto& st = get(s).status;
                               return view(std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(st.data()), st.size()),
                                           {static_cast<py::ssize_t>(st.size())}, s);
                             })
      .def_property_readonly("duplicate_of", [get](py::object s) { return view_flat(get(s).duplicate_of, s); })
      .def(
          "save_cells", [](const SV& s, const std::string& path) { without_gil([&] { io::write_spherical_cells(path, s); }); },
          py::arg("path"))
      .def(
          "save_triangles",
          [](const SV& s, const std::string& path, const Points& points) {
            const auto pts = as_span(points);
            without_gil([&] { io::write_spherical_triangles(path, s, pts); });
          },
          py::arg("path"), py::arg("points"))
      .def(
          "save_table", [](const SV& s, const std::string& path) { without_gil([&] { io::write_spherical_table(path, s); }); },
          py::arg("path"))
      .def(
          "save_neighbors",
          [](const SV& s, const std::string& path) { without_gil([&] { io::write_spherical_neighbors(path, s); }); },
          py::arg("path"));
  py::class_<SphereReport>(m, "SphereReport", "What SphericalVoronoi.validate() found (validate_spherical_voronoi).")
      .def_readonly("ok", &SphereReport::ok)
      .def_readonly("asymmetric_neighbors", &SphereReport::asymmetric_neighbors)
      .def_readonly("bad_vertex_cells", &SphereReport::bad_vertex_cells)
      .def_readonly("bad_rings", &SphereReport::bad_rings)
      .def_readonly("bad_status", &SphereReport::bad_status)
      .def_readonly("nonempty_facets", &SphereReport::nonempty_facets)
      .def_readonly("vertices_checked", &SphereReport::vertices_checked)
      .def_readonly("euler", &SphereReport::euler)
      .def_readonly("area_rel_error", &SphereReport::area_rel_error)
      .def_readonly("messages", &SphereReport::messages)
      .def("__bool__", [](const SphereReport& r) { return r.ok; })
      .def("__repr__", [](const SphereReport& r) {
        return std::string("<tessera.SphereReport ") + (r.ok ? "ok" : "FAILED: " + (r.messages.empty() ? std::string() : r.messages[0])) + ">";
      });
  c.def(
      "validate",
      [](const SV& s, const Points& points, std::size_t sample) {
        const auto pts = as_span(points);
        return without_gil([&] { return validate_spherical_voronoi(s, pts, sample); });
      },
      py::arg("points"), py::arg("sample"));
  m.def("spherical_voronoi", &run, py::arg("points").noconvert(), py::arg("center"), py::arg("radius"),
        py::arg("tolerance"), py::arg("threads"));
  m.def(
      "lonlat_to_points",
      [](const Points& lonlat, double radius, const std::array<double, 3>& center) {
        if (lonlat.ndim() != 2 || lonlat.shape(1) != 2) throw py::value_error("lonlat must have shape (N, 2)");
        auto out = lonlat_to_points(as_span(lonlat), radius, center);
        const auto n = static_cast<py::ssize_t>(out.size() / 3);
        return adopt(std::move(out), {n, 3});
      },
      py::arg("lonlat").noconvert(), py::arg("radius"), py::arg("center"));
}

}  // namespace tessera::python
