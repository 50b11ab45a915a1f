// tessera._core.write_*: the library's VTK XML writers (include/tessera/io/).
//
// Each writer runs without the GIL and writes atomically. The Python layer
// checks the file extension before calling, so an InputError from a writer
// here is a file that could not be written ("cannot write PATH: reason"), and
// it is raised as OSError.
#include <string>
#include <utility>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "delaunay_result.hpp"
#include "dual_result.hpp"
#include "interrupt.hpp"
#include "signal_cleanup.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/dual.hpp"
#include "tessera/io/vtk_polydata.hpp"
#include "tessera/surface_nets.hpp"
#include "tessera/io/alpha_shape.hpp"
#include "tessera/io/vtk_simplices.hpp"
#include "tessera/io/vtk_xml.hpp"

namespace tessera::python {
namespace {

/// Run a writer without the GIL; its InputError becomes OSError (see above).
template <class Write>
void write_or_oserror(Write&& write) {
  const SignalCleanupDuringWrite cleanup;  // taken with the GIL held
  try {
    without_gil(std::forward<Write>(write));
  } catch (const InputError& e) {
    PyErr_SetString(PyExc_OSError, e.what());
    throw py::error_already_set();
  }
}

}  // namespace

void bind_io(py::module_& m) {
  m.def(
      "write_cells_vtk",
      [](const std::string& path, const Cells& cells) {
        if (cells.cell_face_offsets.empty())
          throw py::value_error("cannot save cells computed with merge=False: they have no mesh");
        write_or_oserror([&] { io::write_cells_vtk(path, cells); });
      },
      py::arg("path"), py::arg("cells"),
      "Write cells as .vtu (3D polyhedra) or .vtp (2D polygons). OSError if the file cannot be written.");

  m.def(
      "write_simplices_vtk",
      [](const std::string& path, const DelaunayResult& r, const py::array_t<double, py::array::c_style>& points,
         const py::object& radii) {
        if (checked_dim(points) != r.dt.dim || static_cast<std::size_t>(points.shape(0)) != r.dt.n_points)
          throw py::value_error("write_simplices_vtk: points are not the ones triangulated");
        const auto pts = as_span(points);
        const auto rad = as_radii(radii);  // the caller's array: alive through the call
        write_or_oserror([&] { io::write_simplices_vtk(path, r.dt, pts, rad); });
      },
      py::arg("path"), py::arg("delaunay"), py::arg("points").noconvert(), py::arg("radii").none(true) = py::none(),
      "Write simplices as .vtu (VTK_TETRA / VTK_TRIANGLE over all points; 2D also .vtp polygons); radii "
      "(a regular triangulation's) add point data Radius. OSError if the file cannot be written.");

  m.def(
      "write_alpha_boundary",
      [](const std::string& path, const DelaunayResult& r, const py::array_t<double, py::array::c_style>& points,
         const AlphaShape& shape, bool singular) {
        if (checked_dim(points) != r.dt.dim || static_cast<std::size_t>(points.shape(0)) != r.dt.n_points)
          throw py::value_error("write_alpha_boundary: points are not the ones triangulated");
        const auto pts = as_span(points);
        write_or_oserror([&] { io::write_alpha_boundary(path, r.dt, shape, pts, singular, false); });
      },
      py::arg("path"), py::arg("delaunay"), py::arg("points").noconvert(), py::arg("shape"), py::arg("singular"),
      "Write an alpha shape's boundary (and singular facets) as .vtp, .npy or (2D) .geojson. OSError if the file "
      "cannot be written.");

  m.def(
      "write_graph_vtp",
      [](const std::string& path, const GraphResult& r, const py::array_t<double, py::array::c_style>& points,
         const py::object& labels) {
        if (checked_dim(points) != r.graph.dim || static_cast<std::size_t>(points.shape(0)) != r.graph.n_points)
          throw py::value_error("write_graph_vtp: points are not the ones of the graph");
        const auto pts = as_span(points);
        const auto lab = as_labels(labels);
        if (!lab.empty() && lab.size() != r.graph.n_points)
          throw py::value_error("write_graph_vtp: labels do not match the points");
        write_or_oserror([&] { io::write_graph_vtp(path, r.graph, pts, lab); });
      },
      py::arg("path"), py::arg("graph"), py::arg("points").noconvert(), py::arg("labels").none(true),
      "Write the graph as .vtp lines over the input points (one per edge). OSError if the file cannot be written.");

  m.def(
      "write_faces_vtp",
      [](const std::string& path, const FaceSet& faces) {
        write_or_oserror([&] { io::write_faces_vtp(path, faces); });
      },
      py::arg("path"), py::arg("faces"),
      "Write a face set as .vtp (3D polygons, 2D lines) with BoundaryLabels, Sides and SpokeClass cell data.");

  m.def(
      "write_flowers_vtp",
      [](const std::string& path, const FlowerSet& fs, const py::array_t<double, py::array::c_style>& points,
         bool glyphs) {
        if (fs.flowers.empty()) throw py::value_error("write_flowers_vtp: no flowers");
        if (checked_dim(points) != fs.flowers.front().dim)
          throw py::value_error("write_flowers_vtp: points are not the ones of the flowers");
        const auto pts = as_span(points);
        write_or_oserror([&] { io::write_flowers_vtp(path, fs.flowers, pts, glyphs); });
      },
      py::arg("path"), py::arg("flowers"), py::arg("points").noconvert(), py::arg("glyphs"),
      "Write flowers as one .vtp (sites, petal centres, neighbours, spokes, cell faces; optional glyphs).");

  m.def(
      "write_surface_net_vtp",
      [](const std::string& path, const SurfaceNet& net) {
        write_or_oserror([&] { io::write_surface_net_vtp(path, net); });
      },
      py::arg("path"), py::arg("net"),
      "Write a surface net as .vtp: the face set's cell data plus VertexKind (point data) and PolygonId.");
}

}  // namespace tessera::python
