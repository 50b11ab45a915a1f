// tessera._core.SurfaceNet / surface_nets(): generalized surface nets
// (include/tessera/surface_nets.hpp), the mesh arrays viewing the result's
// FaceSet (face_arrays.hpp). Runs without the GIL; Ctrl-C stops the cells
// pass between batches and the pipeline between stages.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "face_arrays.hpp"
#include "interrupt.hpp"
#include "options.hpp"
#include "tessera/surface_nets.hpp"

namespace tessera::python {
namespace {

using Points = py::array_t<double, py::array::c_style>;

SurfaceNet run_surface_nets(const Points& points, const py::object& labels, const std::vector<std::int32_t>& select,
                            std::int32_t background_label, bool capping, int iterations, double relaxation,
                            double constraint, bool constraint_is_absolute, bool triangles,
                            const std::optional<std::vector<double>>& bounds, double padding, bool ignore_outside,
                            int threads, const std::array<bool, 3>& periodic, const std::array<double, 3>& tilt,
                            const py::object& walls) {
  const int dim = checked_dim(points);
  SurfaceNetsOptions opt;
  fill_common(opt.voronoi, dim, bounds, padding, ignore_outside, threads);
  opt.voronoi.walls = walls_from(walls, dim);
  opt.voronoi.periodic = periodic;
  opt.voronoi.tilt = tilt;
  opt.select = select;
  opt.background_label = background_label;
  opt.capping = capping;
  opt.smoothing.iterations = iterations;
  opt.smoothing.relaxation = relaxation;
  opt.smoothing.constraint = constraint;
  opt.smoothing.constraint_is_absolute = constraint_is_absolute;
  opt.triangles = triangles;
  const auto pts = as_span(points);
  const auto lab = as_labels(labels);
  return without_gil([&] { return surface_nets(pts, lab, opt); });
}

}  // namespace

void bind_surface_nets(py::module_& m) {
  py::class_<SurfaceNet> net(m, "SurfaceNet", "Result of surface_nets(): the mesh (a FaceSet) and vertex kinds.");
  def_face_arrays(net, [](const SurfaceNet& s) -> const FaceSet& { return s.mesh; });
  net.def_property_readonly("vertex_kind", [](py::object s) { return byte_view(s.cast<const SurfaceNet&>().vertex_kind, s); })
      .def_property_readonly("polygon_of_face",
                             [](py::object s) { return view_flat(s.cast<const SurfaceNet&>().polygon_of_face, s); })
      .def_readonly("n_cells", &SurfaceNet::n_cells)
      .def_readonly("max_displacement", &SurfaceNet::max_displacement)
      .def_readonly("selected", &SurfaceNet::selected)
      .def_property_readonly("seconds", [](const SurfaceNet& s) {
        py::dict d;
        d["cells"] = s.seconds.cells;
        d["faces"] = s.seconds.faces;
        d["smoothing"] = s.seconds.smoothing;
        d["triangulation"] = s.seconds.triangulation;
        return d;
      });

  m.attr("NET_SURFACE") = static_cast<int>(NetVertexKind::surface);
  m.attr("NET_JUNCTION") = static_cast<int>(NetVertexKind::junction);
  m.attr("NET_CORNER") = static_cast<int>(NetVertexKind::corner);

  m.def("surface_nets", &run_surface_nets, py::arg("points").noconvert(), py::arg("labels").none(true),
        py::arg("select"), py::arg("background_label"), py::arg("capping"), py::arg("iterations"),
        py::arg("relaxation"), py::arg("constraint"), py::arg("constraint_is_absolute"), py::arg("triangles"),
        py::arg("bounds"), py::arg("padding"), py::arg("ignore_outside"), py::arg("threads"), py::arg("periodic"),
        py::arg("tilt"), py::arg("walls").none(true) = py::none(),
        "Surface nets of float64 (N, D) points with int32 labels. Runs without the GIL.");
}

}  // namespace tessera::python
