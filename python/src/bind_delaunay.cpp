// tessera._core.Delaunay / delaunay() / validate_delaunay(): the Delaunay
// front end (include/tessera/delaunay.hpp), its arrays viewing its buffers.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "delaunay_result.hpp"
#include "interrupt.hpp"
#include "options.hpp"
#include "tessera/alpha_shape.hpp"
#include "tessera/delaunay.hpp"

namespace tessera::python {
namespace {

using Points = py::array_t<double, py::array::c_style>;

DelaunayResult run_delaunay(const Points& points, const py::object& labels,
                            const std::optional<std::vector<double>>& bounds, double padding, bool ignore_outside,
                            int threads, bool complete_hull, const std::string& method,
                            const std::array<bool, 3>& periodic, const std::array<double, 3>& tilt,
                            const py::object& radii) {
  const int dim = checked_dim(points);
  DelaunayOptions opt;
  fill_common(opt, dim, bounds, padding, ignore_outside, threads);
  opt.periodic = periodic;
  opt.tilt = tilt;
  opt.radii = as_radii(radii);  // views the caller's array, alive through the call
  opt.complete_hull = complete_hull;
  if (method == "auto") opt.method = DelaunayMethod::automatic;
  else if (method == "cells") opt.method = DelaunayMethod::cells;
  else if (method == "insertion") opt.method = DelaunayMethod::insertion;
  else throw py::value_error("delaunay: method must be 'auto', 'cells' or 'insertion', got '" + method + "'");
  const auto pts = as_span(points);
  const auto lab = as_labels(labels);
  return DelaunayResult{without_gil([&] { return delaunay(pts, dim, lab, opt); }), {}, {}, {}};
}

py::array neighbors_view(py::object self) {
  auto& r = self.cast<DelaunayResult&>();
  if (!r.neighbors && r.locator) r.neighbors = r.locator->neighbors();  // a walk's (null for a grid)
  if (!r.neighbors) {
    // Computed without the GIL into a local; stored once the GIL is back, so
    // two threads asking at once cannot race on the member.
    auto nb = without_gil([&] { return std::make_shared<const std::vector<std::int32_t>>(simplex_neighbors(r.dt)); });
    if (!r.neighbors) r.neighbors = std::move(nb);
  }
  return view_rows(*r.neighbors, static_cast<std::size_t>(r.dt.dim + 1), self);
}

py::tuple vertex_neighbors_view(py::object self) {
  auto& r = self.cast<DelaunayResult&>();
  if (!r.vertex_neighbors) {
    auto vn = without_gil([&] { return vertex_neighbors(r.dt); });
    if (!r.vertex_neighbors) r.vertex_neighbors = std::move(vn);
  }
  return py::make_tuple(view_flat(r.vertex_neighbors->offsets, self), view_flat(r.vertex_neighbors->ids, self));
}

// The simplex holding each query point (-1: none). The locator is built on
// the first call (without the GIL) and kept for the next ones. threads: the
// triangulation's own count (0 or less: the default).
py::array locate_points(DelaunayResult& r, const Points& points, const Points& queries, int threads) {
  if (checked_dim(points) != r.dt.dim || static_cast<std::size_t>(points.shape(0)) != r.dt.n_points)
    throw py::value_error("locate: points are not the ones triangulated");
  if (queries.ndim() != 2 || queries.shape(1) != r.dt.dim)
    throw py::value_error("locate: queries must have shape (M, " + std::to_string(r.dt.dim) + ")");
  const auto pts = as_span(points);
  const auto q = as_span(queries);
  std::shared_ptr<const SimplexLocator> loc = r.locator;
  if (!loc) {
    SimplexLocator::Adjacency nb = r.neighbors;  // shared with .neighbors, whichever comes first
    loc = without_gil([&] { return std::make_shared<const SimplexLocator>(r.dt, pts, threads, LocateMethod::automatic, nb); });
    if (!r.locator) r.locator = loc;
    if (!r.neighbors) r.neighbors = loc->neighbors();
  }
  auto check = interrupt_check();
  return adopt_flat(without_gil([&] { return loc->locate(r.dt, pts, q, threads, check); }));
}

}  // namespace

void bind_delaunay(py::module_& m) {
  py::class_<DelaunayReport>(m, "DelaunayReport", "Checks of a triangulation (Delaunay.validate).")
      .def_readonly("ok", &DelaunayReport::ok)
      .def_readonly("simplices", &DelaunayReport::simplices)
      .def_readonly("flat_or_inverted", &DelaunayReport::flat_or_inverted)
      .def_readonly("nonmanifold_facets", &DelaunayReport::nonmanifold_facets)
      .def_readonly("boundary_facets", &DelaunayReport::boundary_facets)
      .def_readonly("open_boundary_ridges", &DelaunayReport::open_boundary_ridges)
      .def_readonly("nonconvex_boundary", &DelaunayReport::nonconvex_boundary)
      .def_readonly("missing_points", &DelaunayReport::missing_points)
      .def_readonly("local_delaunay_violations", &DelaunayReport::local_delaunay_violations)
      .def_readonly("hidden_not_hidden", &DelaunayReport::hidden_not_hidden,
                    "(radii) points listed as hidden that are vertices, duplicates or set aside")
      .def_readonly("hidden_in_conflict", &DelaunayReport::hidden_in_conflict,
                    "(radii, no labels) hidden points in conflict with the simplex holding them")
      .def_readonly("volume_sum", &DelaunayReport::volume_sum)
      .def_readonly("enclosed_volume", &DelaunayReport::enclosed_volume)
      .def_readonly("volume_tolerance", &DelaunayReport::volume_tolerance)
      .def_readonly("messages", &DelaunayReport::messages)
      .def("__bool__", [](const DelaunayReport& r) { return r.ok; })
      .def("__repr__", [](const DelaunayReport& r) {
        return py::str("DelaunayReport(ok={}, simplices={}, flat_or_inverted={}, nonmanifold_facets={}, "
                       "local_delaunay_violations={}, missing_points={}, hidden_not_hidden={}, "
                       "hidden_in_conflict={})")
            .format(r.ok, r.simplices, r.flat_or_inverted, r.nonmanifold_facets, r.local_delaunay_violations,
                    r.missing_points, r.hidden_not_hidden, r.hidden_in_conflict);
      });

  py::class_<DelaunayResult>(m, "Delaunay", "Result of delaunay(): owns the buffers its array properties view.")
      .def_property_readonly("dim", [](const DelaunayResult& r) { return r.dt.dim; })
      .def_property_readonly("n_points", [](const DelaunayResult& r) { return r.dt.n_points; })
      .def_property_readonly("n_simplices", [](const DelaunayResult& r) { return r.dt.n_simplices(); })
      .def_property_readonly("bounds", [](const DelaunayResult& r) { return bounds_tuple(r.dt.bounds, r.dt.dim); })
      .def_property_readonly("simplices",
                             [](py::object s) {
                               const Delaunay& dt = s.cast<const DelaunayResult&>().dt;
                               return view_rows(dt.simplices, static_cast<std::size_t>(dt.dim + 1), s);
                             })
      .def_property_readonly("neighbors", &neighbors_view)
      .def_property_readonly("vertex_neighbors", &vertex_neighbors_view)
      .def("vertex_to_simplex", [](const DelaunayResult& r) { return adopt_flat(vertex_to_simplex(r.dt)); })
      .def_property_readonly("from_cells", [](const DelaunayResult& r) { return r.dt.from_cells; })
      .def_property_readonly("from_hull_completion", [](const DelaunayResult& r) { return r.dt.from_hull_completion; })
      .def_property_readonly("from_insertion", [](const DelaunayResult& r) { return r.dt.from_insertion; })
      .def_property_readonly("hull_completed", [](const DelaunayResult& r) { return r.dt.hull_completed; })
      .def_property_readonly("outside_simplices", [](const DelaunayResult& r) { return r.dt.outside_simplices; })
      .def_property_readonly("duplicates", [](const DelaunayResult& r) { return pairs_copy(r.dt.duplicates); })
      .def_property_readonly("power", [](const DelaunayResult& r) { return r.dt.power; })
      .def_property_readonly("hidden",
                             [](py::object s) { return view_flat(s.cast<const DelaunayResult&>().dt.hidden, s); })
      .def_property_readonly("ignored_outside_bounds",
                             [](py::object s) {
                               return view_flat(s.cast<const DelaunayResult&>().dt.ignored_outside_bounds, s);
                             })
      .def_property_readonly("exact_predicate_calls",
                             [](const DelaunayResult& r) { return r.dt.exact_predicate_calls; })
      .def_property_readonly("threads_used", [](const DelaunayResult& r) { return r.dt.threads_used; })
      .def_property_readonly("periodic", [](const DelaunayResult& r) { return r.dt.periodic; })
      .def_property_readonly("tilt", [](const DelaunayResult& r) { return r.dt.tilt; })
      .def_property_readonly("simplex_shifts",
                             [](py::object s) {
                               const Delaunay& dt = s.cast<const DelaunayResult&>().dt;
                               const auto d = static_cast<py::ssize_t>(dt.dim);
                               return view(std::span<const std::int8_t>(dt.simplex_shifts.data(), dt.simplex_shifts.size()),
                                           {dt.is_periodic() ? static_cast<py::ssize_t>(dt.n_simplices()) : 0, d + 1, d},
                                           s);
                             })
      .def_property_readonly("periodic_points", [](py::object s) {
        const Delaunay& dt = s.cast<const DelaunayResult&>().dt;
        return view_rows(dt.periodic_points, static_cast<std::size_t>(dt.dim), s);
      });

  m.def("delaunay", &run_delaunay, py::arg("points").noconvert(), py::arg("labels").none(true), py::arg("bounds"),
        py::arg("padding"), py::arg("ignore_outside"), py::arg("threads"), py::arg("complete_hull"),
        py::arg("method"), py::arg("periodic"), py::arg("tilt"), py::arg("radii").none(true) = py::none(),
        "Delaunay simplices of float64 C-ordered (N, D) points; labels None or int32 (N,); radii None or float64 "
        "(N,) (the regular triangulation, dual of the power cells). Runs without the GIL.");

  py::class_<AlphaShape>(m, "AlphaShape", "Result of alpha_shape(): owns the arrays its properties view.")
      .def_property_readonly("dim", [](const AlphaShape& a) { return a.dim; })
      .def_property_readonly("alpha", [](const AlphaShape& a) { return a.alpha; })
      .def_property_readonly("simplex_rows", [](py::object s) { return view_flat(s.cast<const AlphaShape&>().simplex_rows, s); })
      .def_property_readonly("boundary",
                             [](py::object s) {
                               const auto& a = s.cast<const AlphaShape&>();
                               return view_rows(a.boundary, static_cast<std::size_t>(a.dim), s);
                             })
      .def_property_readonly("boundary_simplex",
                             [](py::object s) { return view_flat(s.cast<const AlphaShape&>().boundary_simplex, s); })
      .def_property_readonly("singular",
                             [](py::object s) {
                               const auto& a = s.cast<const AlphaShape&>();
                               return view_rows(a.singular, static_cast<std::size_t>(a.dim), s);
                             })
      .def_property_readonly("piece", [](py::object s) { return view_flat(s.cast<const AlphaShape&>().piece, s); })
      .def_property_readonly("boundary_shifts",
                             [](py::object s) {
                               const auto& a = s.cast<const AlphaShape&>();
                               const auto d = static_cast<py::ssize_t>(a.dim);
                               return view(std::span<const std::int8_t>(a.boundary_shifts),
                                           {static_cast<py::ssize_t>(a.boundary_shifts.size()) / (d * d), d, d}, s);
                             })
      .def_property_readonly("singular_shifts",
                             [](py::object s) {
                               const auto& a = s.cast<const AlphaShape&>();
                               const auto d = static_cast<py::ssize_t>(a.dim);
                               return view(std::span<const std::int8_t>(a.singular_shifts),
                                           {static_cast<py::ssize_t>(a.singular_shifts.size()) / (d * d), d, d}, s);
                             })
      .def_readonly("components", &AlphaShape::components)
      .def_readonly("nonmanifold_ridges", &AlphaShape::nonmanifold_ridges)
      .def_readonly("volume", &AlphaShape::volume)
      .def_readonly("boundary_measure", &AlphaShape::boundary_measure)
      .def_readonly("exact_tests", &AlphaShape::exact_tests);

  m.def(
      "alpha_shape",
      [](const DelaunayResult& r, const Points& points, double alpha, const py::object& radii) {
        if (checked_dim(points) != r.dt.dim || static_cast<std::size_t>(points.shape(0)) != r.dt.n_points)
          throw py::value_error("alpha_shape: points are not the ones triangulated");
        const auto pts = as_span(points);
        const auto rad = as_radii(radii);
        return without_gil([&] { return alpha_shape(r.dt, pts, alpha, rad); });
      },
      py::arg("delaunay"), py::arg("points").noconvert(), py::arg("alpha"), py::arg("radii").none(true) = py::none(),
      "The alpha shape of a triangulation (include/tessera/alpha_shape.hpp); a regular one needs its radii. "
      "Runs without the GIL.");

  m.def(
      "boundary_polygons",
      [](const DelaunayResult& r, const Points& points, const AlphaShape& a) {
        const auto pts = as_span(points);
        BoundaryPolygons p = without_gil([&] { return boundary_polygons(r.dt, pts, a); });
        return py::make_tuple(adopt_flat(std::move(p.polygon_rings)), adopt_flat(std::move(p.ring_points)),
                              adopt_flat(std::move(p.points)));
      },
      py::arg("delaunay"), py::arg("points").noconvert(), py::arg("shape"),
      "A 2D alpha shape's boundary as polygons: (polygon_rings, ring_points, points) offsets and ids.");

  m.def(
      "simplex_squared_radii",
      [](const DelaunayResult& r, const Points& points, const py::object& radii) {
        if (checked_dim(points) != r.dt.dim || static_cast<std::size_t>(points.shape(0)) != r.dt.n_points)
          throw py::value_error("simplex_squared_radii: points are not the ones triangulated");
        const auto pts = as_span(points);
        const auto rad = as_radii(radii);
        return adopt_flat(without_gil([&] { return simplex_squared_radii(r.dt, pts, rad); }));
      },
      py::arg("delaunay"), py::arg("points").noconvert(), py::arg("radii").none(true) = py::none(),
      "Per simplex, the squared radius of its circumsphere (orthosphere with radii), in floats; inf where flat.");

  m.def("locate", &locate_points, py::arg("delaunay"), py::arg("points").noconvert(), py::arg("queries").noconvert(),
        py::arg("threads"),
        "Per float64 C-ordered (M, D) query: the lowest simplex holding it, or -1. Runs without the GIL.");

  m.def(
      "validate_delaunay",
      [](const DelaunayResult& r, const Points& points, const py::object& labels, const py::object& radii) {
        if (checked_dim(points) != r.dt.dim || static_cast<std::size_t>(points.shape(0)) != r.dt.n_points)
          throw py::value_error("validate_delaunay: points are not the ones triangulated");
        const auto pts = as_span(points);
        const auto lab = as_labels(labels);
        const auto rad = as_radii(radii);  // the caller's array: alive through the call
        // Radii missing (or too few) for a regular triangulation, or given for
        // an ordinary one: the library's InputError.
        return without_gil([&] { return validate(r.dt, pts, lab, rad); });
      },
      py::arg("delaunay"), py::arg("points").noconvert(), py::arg("labels").none(true),
      py::arg("radii").none(true) = py::none(),
      "Checks of a triangulation (the CLI's `delaunay --validate`); a regular triangulation (power) needs "
      "the radii it was computed with.");
}

}  // namespace tessera::python
