// tessera._core.Cells / voronoi() / validate_cells(): the cells front end
// (include/tessera/cells.hpp) as a Python class whose arrays view its buffers.
#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "interrupt.hpp"
#include "options.hpp"
#include "tessera/cell_vertex_lists.hpp"
#include "tessera/cells.hpp"
#include "tessera/engine/thread_arena.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace tessera::python {
namespace {

using Points = py::array_t<double, py::array::c_style>;

Cells run_voronoi(const Points& points, const py::object& labels, const std::optional<std::vector<double>>& bounds,
                  double padding, bool ignore_outside, int threads, bool merge, const std::string& method,
                  const std::array<bool, 3>& periodic, const std::array<double, 3>& tilt,
                  const py::object& radii, const py::object& only, int only_with_faces, const py::object& walls) {
  const int dim = checked_dim(points);
  VoronoiOptions opt;
  fill_common(opt, dim, bounds, padding, ignore_outside, threads);
  opt.walls = walls_from(walls, dim);
  opt.periodic = periodic;
  opt.tilt = tilt;
  opt.radii = as_radii(radii);  // views the caller's array, alive through the call
  opt.build_mesh = merge;
  // Some cells only (flower of points): None, or int32 ids, viewed as labels are.
  if (!only.is_none()) {
    if (!py::isinstance<py::array_t<std::int32_t, py::array::c_style>>(only))
      throw py::type_error("only must be None or a C-contiguous int32 array");
    opt.only = as_labels(only);
  }
  // Some cells only (faces of points): a set of spoke classes (face_set_classes).
  if (only_with_faces < 0 || only_with_faces > 15)
    throw py::value_error("only_with_faces must be a set of spoke classes (0..15), got " +
                          std::to_string(only_with_faces));
  opt.only_with_faces = static_cast<SpokeClassSet>(only_with_faces);
  if (method == "auto") opt.cell_method = CellMethod::automatic;
  else if (method == "search") opt.cell_method = CellMethod::search;
  else if (method == "insertion") opt.cell_method = CellMethod::insertion;
  else throw py::value_error("voronoi: method must be 'auto', 'search' or 'insertion', got '" + method + "'");
  const auto pts = as_span(points);
  const auto lab = as_labels(labels);
  return without_gil([&] { return voronoi(pts, dim, lab, opt); });
}

/// The first dim values of a per-axis array, as a tuple.
template <class T>
py::tuple per_axis(const std::array<T, 3>& values, int dim) {
  py::tuple t(static_cast<std::size_t>(dim));
  for (std::size_t a = 0; a < static_cast<std::size_t>(dim); ++a) t[a] = values[a];
  return t;
}

/// Per-face CSR and vertex arrays exist only when the cells were built with
/// the merged mesh (build_mesh); without it cell_face_offsets stays empty
/// (a result always has at least one cell).
bool has_mesh(const Cells& c) { return !c.cell_face_offsets.empty(); }

const Cells& mesh_of(const py::object& self) {
  const Cells& c = self.cast<const Cells&>();
  if (!has_mesh(c)) throw py::value_error("no mesh: these cells were computed with merge=False");
  return c;
}

/// VTK's arrays of 3D cells as VTK_POLYHEDRON (Python's to_vtk): the face
/// stream (per cell its number of faces, then per face its size and vertex
/// ids), where each cell's record starts, and each cell's distinct vertices
/// as CSR (offsets, ids; CellVertexLists' order, as the .vtu writer lists
/// them), all int64 (vtkIdType). Built here in parallel, on the cells'
/// thread count: numpy's version needed ~3.5 KB of int64 temporaries per
/// cell (9.3 GB at 2M cells) and took longer than the cells.
py::tuple polyhedron_arrays(const Cells& c) {
  const std::size_t nc = c.n_cells();
  const auto& cfo = c.cell_face_offsets;
  const auto& fvo = c.face_vertex_offsets;
  const auto& fv = c.face_vertices;
  std::vector<std::int64_t> stream, locations(nc), offsets, ids;
  without_gil([&] {
    engine::ThreadArena arena(c.threads_used);
    arena.execute([&] {
      using Range = tbb::blocked_range<std::size_t>;
      const CellVertexLists corners(c);
      offsets = corners.offsets();
      // Cell ci's record (1 + its faces + their vertex ids) starts after
      // those of the ci cells before it.
      auto record_start = [&](std::size_t ci) {
        return static_cast<std::int64_t>(ci) + cfo[ci] + fvo[cfo[ci]];
      };
      stream.resize(static_cast<std::size_t>(record_start(nc)));
      ids.resize(static_cast<std::size_t>(offsets[nc]));
      tbb::parallel_for(Range(0, nc), [&](const Range& r) {
        for (std::size_t ci = r.begin(); ci != r.end(); ++ci) {
          locations[ci] = record_start(ci);
          auto s = stream.begin() + locations[ci];
          *s++ = cfo[ci + 1] - cfo[ci];
          for (std::int64_t f = cfo[ci]; f < cfo[ci + 1]; ++f) {
            *s++ = fvo[f + 1] - fvo[f];
            s = std::copy(fv.begin() + fvo[f], fv.begin() + fvo[f + 1], s);
          }
          auto d = ids.begin() + offsets[ci];
          corners.for_each(ci, [&](std::int32_t v) { *d++ = v; });
        }
      });
    });
  });
  return py::make_tuple(adopt_flat(std::move(stream)), adopt_flat(std::move(locations)),
                        adopt_flat(std::move(offsets)), adopt_flat(std::move(ids)));
}

}  // namespace

void bind_voronoi(py::module_& m) {
  py::class_<ValidationReport>(m, "ValidationReport", "Invariant checks of a Voronoi result (Cells.validate).")
      .def_readonly("ok", &ValidationReport::ok)
      .def_readonly("volume_sum", &ValidationReport::volume_sum)
      .def_readonly("domain_volume", &ValidationReport::domain_volume)
      .def_readonly("volume_rel_error", &ValidationReport::volume_rel_error)
      .def_readonly("volumes_checked", &ValidationReport::volumes_checked)
      .def_readonly("asymmetric_spokes", &ValidationReport::asymmetric_spokes)
      .def_readonly("bad_vertex_degree", &ValidationReport::bad_vertex_degree)
      .def_readonly("bad_euler", &ValidationReport::bad_euler)
      .def_readonly("underflowed_volumes", &ValidationReport::underflowed_volumes,
                    "cells whose exact volume is below the smallest double (reported as 0; not a failure)")
      .def_readonly("measures_checked", &ValidationReport::measures_checked,
                    "sampled cells whose volume and centroid were compared with exact arithmetic")
      .def_readonly("measure_rel_error", &ValidationReport::measure_rel_error,
                    "the largest relative volume (area) error among them")
      .def_readonly("measure_worst", &ValidationReport::measure_worst, "that cell's generator (-1: none checked)")
      .def_readonly("vertex_rel_error", &ValidationReport::vertex_rel_error,
                    "the largest distance of those cells' merged vertices from their exact positions, relative to "
                    "the cell's radius")
      .def_readonly("vertex_worst", &ValidationReport::vertex_worst, "that merged vertex (-1: none checked)")
      .def_readonly("messages", &ValidationReport::messages)
      .def("__bool__", [](const ValidationReport& r) { return r.ok; })
      .def("__repr__", [](const ValidationReport& r) {
        return py::str("ValidationReport(ok={}, volume_rel_error={:.3g}, asymmetric_spokes={}, "
                       "bad_vertex_degree={}, bad_euler={})")
            .format(r.ok, r.volume_rel_error, r.asymmetric_spokes, r.bad_vertex_degree, r.bad_euler);
      });

  // Every array property returns a fresh read-only view whose base is the
  // Cells object itself (arrays.hpp); the Python layer documents each one.
  py::class_<Cells> cells(m, "Cells", "Result of voronoi(): owns the buffers that its array properties view.");
  cells.def_readonly("dim", &Cells::dim)
      .def_readonly("n_points", &Cells::n_points)
      .def_property_readonly("n_cells", &Cells::n_cells)
      .def_property_readonly("n_vertices", [](const Cells& c) { return has_mesh(c) ? c.n_vertices() : 0; })
      .def_property_readonly("has_mesh", &has_mesh)
      .def_property_readonly("bounds", [](const Cells& c) { return bounds_tuple(c.bounds, c.dim); })
      .def_readonly("exact_predicate_calls", &Cells::exact_predicate_calls)
      .def_readonly("far_points", &Cells::far_points)
      .def_readonly("threads_used", &Cells::threads_used)
      .def_readonly("from_insertion", &Cells::from_insertion)
      .def_readonly("assembled_from_stars", &Cells::assembled_from_stars)
      .def_readonly("cells_from_pilot", &Cells::cells_from_pilot)
      .def_readonly("generators", &Cells::generators)
      .def_readonly("partial", &Cells::partial)
      .def_readonly("with_faces_of", &Cells::with_faces_of)
      // per cell
      .def_property_readonly("generator", [](py::object s) { return view_flat(s.cast<const Cells&>().generator, s); })
      .def_property_readonly("region", [](py::object s) { return view_flat(s.cast<const Cells&>().region, s); })
      .def_property_readonly("volume", [](py::object s) { return view_flat(s.cast<const Cells&>().volume, s); })
      .def_property_readonly("centroid",
                             [](py::object s) {
                               const Cells& c = s.cast<const Cells&>();
                               return view_rows(c.centroid, static_cast<std::size_t>(c.dim), s);
                             })
      .def_property_readonly("num_faces", [](py::object s) { return view_flat(s.cast<const Cells&>().num_faces, s); })
      .def_property_readonly("neighbor_offsets",
                             [](py::object s) { return view_flat(s.cast<const Cells&>().neighbor_offsets, s); })
      .def_property_readonly("neighbors", [](py::object s) { return view_flat(s.cast<const Cells&>().neighbors, s); })
      .def_property_readonly("neighbor_shifts",
                             [](py::object s) {
                               const Cells& c = s.cast<const Cells&>();
                               return view_rows(c.neighbor_shifts, static_cast<std::size_t>(c.dim), s);
                             })
      .def_property_readonly("periodic", [](const Cells& c) { return per_axis(c.periodic, c.dim); })
      .def_property_readonly("walls",
                             [](const Cells& c) {
                               py::array_t<double> a({static_cast<py::ssize_t>(c.walls.size()),
                                                      static_cast<py::ssize_t>(c.dim + 1)});
                               auto m = a.mutable_unchecked<2>();
                               for (std::size_t k = 0; k < c.walls.size(); ++k) {
                                 for (int d = 0; d < c.dim; ++d)
                                   m(static_cast<py::ssize_t>(k), d) = c.walls[k].normal[static_cast<std::size_t>(d)];
                                 m(static_cast<py::ssize_t>(k), c.dim) = c.walls[k].offset;
                               }
                               return a;
                             })
      .def_readonly("periodic_images", &Cells::periodic_images)
      .def_property_readonly("tilt", [](const Cells& c) { return c.tilt; })
      .def_property_readonly("periodic_points",
                             [](py::object s) {
                               const Cells& c = s.cast<const Cells&>();
                               return view_rows(c.periodic_points, static_cast<std::size_t>(c.dim), s);
                             })
      .def_property_readonly("image_reach", [](const Cells& c) { return per_axis(c.image_reach, c.dim); })
      // per generator
      .def_property_readonly("cell_of", [](py::object s) { return view_flat(s.cast<const Cells&>().cell_of, s); })
      // merged mesh
      .def_property_readonly("vertices",
                             [](py::object s) {
                               const Cells& c = mesh_of(s);
                               return view_rows(c.vertices, static_cast<std::size_t>(c.dim), s);
                             })
      .def_property_readonly("vertex_keys",
                             [](py::object s) {
                               const Cells& c = mesh_of(s);
                               return view_rows(c.vertex_keys, static_cast<std::size_t>(c.dim + 1), s);
                             })
      .def_property_readonly("cell_face_offsets",
                             [](py::object s) { return view_flat(mesh_of(s).cell_face_offsets, s); })
      .def_property_readonly("face_vertex_offsets",
                             [](py::object s) { return view_flat(mesh_of(s).face_vertex_offsets, s); })
      .def_property_readonly("face_vertices", [](py::object s) { return view_flat(mesh_of(s).face_vertices, s); })
      .def_property_readonly("face_neighbor", [](py::object s) { return view_flat(mesh_of(s).face_neighbor, s); })
      .def("_polyhedron_arrays", [](py::object s) { return polyhedron_arrays(mesh_of(s)); },
           "(stream, cell record starts, connectivity offsets, connectivity ids) of the 3D cells as "
           "VTK_POLYHEDRON, int64; runs without the GIL.")
      .def_property_readonly("face_class",
                             [](py::object s) {
                               const auto& fc = mesh_of(s).face_class;
                               static_assert(sizeof(SpokeClass) == sizeof(std::uint8_t));
                               return view(std::span<const std::uint8_t>(
                                               reinterpret_cast<const std::uint8_t*>(fc.data()), fc.size()),
                                           {static_cast<py::ssize_t>(fc.size())}, s);
                             })
      // diagnostics
      .def_property_readonly("duplicates", [](const Cells& c) { return pairs_copy(c.duplicates); })
      .def_readonly("power", &Cells::power)
      .def_property_readonly("empty_cells",
                             [](py::object s) { return view_flat(s.cast<const Cells&>().empty_cells, s); })
      .def_property_readonly("ignored_outside_bounds",
                             [](py::object s) { return view_flat(s.cast<const Cells&>().ignored_outside_bounds, s); });

  m.attr("SAME_REGION") = static_cast<int>(SpokeClass::same_region);
  m.attr("REGION_BOUNDARY") = static_cast<int>(SpokeClass::region_boundary);
  m.attr("DOMAIN_BOUNDARY") = static_cast<int>(SpokeClass::domain_boundary);
  m.attr("OUTSIDE") = static_cast<int>(SpokeClass::outside);

  m.def("voronoi", &run_voronoi, py::arg("points").noconvert(), py::arg("labels").none(true), py::arg("bounds"),
        py::arg("padding"), py::arg("ignore_outside"), py::arg("threads"), py::arg("merge"),
        py::arg("method"), py::arg("periodic"), py::arg("tilt"), py::arg("radii").none(true) = py::none(),
        py::arg("only").none(true) = py::none(), py::arg("only_with_faces") = 0,
        py::arg("walls").none(true) = py::none(),
        "Cells of float64 C-ordered (N, D) points; labels None or int32 (N,); radii None or float64 (N,) "
        "(power cells); only None or int32 ids: those cells and their neighbours' (VoronoiOptions::only); "
        "only_with_faces: a set of spoke classes (face_set_classes), the cells with a face of one of them "
        "(VoronoiOptions::only_with_faces); walls None or float64 (k, D + 1) rows (normal, offset): "
        "half-spaces normal . x <= offset cutting the box (VoronoiOptions::walls). Runs without the GIL.");

  m.def(
      "hull_walls",
      [](const Points& points, double dilation, int threads) {
        const int dim = checked_dim(points);
        const auto pts = as_span(points);
        const std::vector<Wall> walls = without_gil([&] { return hull_walls(pts, dim, dilation, threads); });
        py::array_t<double> out({static_cast<py::ssize_t>(walls.size()), static_cast<py::ssize_t>(dim + 1)});
        auto o = out.mutable_unchecked<2>();
        for (std::size_t k = 0; k < walls.size(); ++k) {
          for (int a = 0; a < dim; ++a) o(static_cast<py::ssize_t>(k), a) = walls[k].normal[static_cast<std::size_t>(a)];
          o(static_cast<py::ssize_t>(k), dim) = walls[k].offset;
        }
        return out;
      },
      py::arg("points").noconvert(), py::arg("dilation"), py::arg("threads"),
      "The convex hull of float64 C-ordered (N, D) points as walls, float64 (k, D + 1) rows (normal, offset) "
      "(tessera::hull_walls). Runs without the GIL.");

  m.def(
      "validate_cells",
      [](const Cells& c, const py::object& labels, const py::object& points, const py::object& radii) {
        const auto lab = as_labels(labels);
        const auto rad = as_radii(radii);  // the caller's array: alive through the call
        std::span<const double> pts;
        std::optional<Points> held;  // keeps the array alive while the GIL is released
        if (!points.is_none()) {
          held = points.cast<Points>();
          if (checked_dim(*held) != c.dim || static_cast<std::size_t>(held->shape(0)) != c.n_points)
            throw py::value_error("validate_cells: points are not the ones the cells were computed from");
          pts = as_span(*held);
        }
        if (!rad.empty() && rad.size() != c.n_points)
          throw py::value_error("validate_cells: radii are not the ones the cells were computed with");
        if (!pts.empty() && c.power && rad.empty())
          throw py::value_error("validate_cells: power cells need their radii with the points");
        return without_gil([&] { return validate(c, lab, pts, rad); });
      },
      py::arg("cells"), py::arg("labels").none(true), py::arg("points").none(true) = py::none(),
      py::arg("radii").none(true) = py::none(),
      "Invariant checks (the CLI's --validate); with the points (and a power diagram's radii), also a "
      "sample of cells' measures against exact arithmetic.");
}

}  // namespace tessera::python
