// tessera._core.Graph / FaceSet / Flowers and adjacency_graph() /
// extract_faces() / flowers(): the products read off the merged mesh of a
// Cells (include/tessera/graph.hpp, faces.hpp, flower.hpp). Each takes the
// Cells object of a voronoi() call, so the Python layer can reuse a Voronoi
// result or compute one; the work runs without the GIL, on the thread count
// the cells were computed with.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "dual_result.hpp"
#include "face_arrays.hpp"
#include "interrupt.hpp"
#include "tessera/cells.hpp"
#include "tessera/faces.hpp"
#include "tessera/flower.hpp"
#include "tessera/graph.hpp"

namespace tessera::python {
namespace {

using Points = py::array_t<double, py::array::c_style>;
using Ids = py::array_t<std::int32_t, py::array::c_style>;

/// The products need the merged mesh; say so in the Python user's words.
const Cells& with_mesh(const Cells& c, const char* what) {
  if (c.cell_face_offsets.empty())
    throw py::value_error(std::string(what) + ": the Voronoi result was computed with merge=False (no mesh); "
                                              "compute it with merge=True");
  return c;
}

const GraphEdges& edges_of(GraphResult& r) {
  if (!r.edges) {
    auto e = without_gil([&] { return graph_edges(r.graph); });
    if (!r.edges) r.edges = std::move(e);  // GIL held again: no race on the member
  }
  return *r.edges;
}

}  // namespace

void bind_dual(py::module_& m) {
  // ---- adjacency graph ----------------------------------------------------
  py::class_<GraphResult>(m, "Graph", "Result of adjacency_graph(): wheels and spokes (CSR over all points).")
      .def_property_readonly("dim", [](const GraphResult& r) { return r.graph.dim; })
      .def_property_readonly("n_points", [](const GraphResult& r) { return r.graph.n_points; })
      .def_property_readonly("n_spokes", [](const GraphResult& r) { return r.graph.n_spokes(); })
      .def_property_readonly("prune_threshold", [](const GraphResult& r) { return r.graph.prune_threshold; })
      .def_property_readonly("pruned_spokes", [](const GraphResult& r) { return r.graph.pruned_spokes; })
      .def_property_readonly("wheel_offsets",
                             [](py::object s) { return view_flat(s.cast<const GraphResult&>().graph.wheel_offsets, s); })
      .def_property_readonly("spokes",
                             [](py::object s) { return view_flat(s.cast<const GraphResult&>().graph.spokes, s); })
      .def_property_readonly("spoke_class",
                             [](py::object s) { return byte_view(s.cast<const GraphResult&>().graph.spoke_class, s); })
      .def_property_readonly(
          "spoke_measure", [](py::object s) { return view_flat(s.cast<const GraphResult&>().graph.spoke_measure, s); })
      .def_property_readonly("spoke_shifts",
                             [](py::object s) {
                               const AdjacencyGraph& g = s.cast<const GraphResult&>().graph;
                               return view_rows(g.spoke_shift, static_cast<std::size_t>(g.dim), s);
                             })
      // Edges: computed on first use, then shared by every view.
      .def_property_readonly("edge_ends",
                             [](py::object s) { return view_rows(edges_of(s.cast<GraphResult&>()).ends, 2, s); })
      .def_property_readonly("edge_spokes",
                             [](py::object s) { return view_flat(edges_of(s.cast<GraphResult&>()).spoke, s); })
      .def_property_readonly("edge_shifts", [](py::object s) {
        GraphResult& r = s.cast<GraphResult&>();
        return view_rows(edges_of(r).shift, static_cast<std::size_t>(r.graph.dim), s);
      });

  m.def(
      "adjacency_graph",
      [](const Cells& cells, double prune_tolerance) {
        const Cells& c = with_mesh(cells, "adjacency");
        GraphOptions opt;
        opt.prune_tolerance = prune_tolerance;
        opt.progress = interrupt_check();
        return GraphResult{without_gil([&] { return adjacency_graph(c, opt); }), std::nullopt};
      },
      py::arg("cells"), py::arg("prune_tolerance"), "The adjacency graph of cells computed with merge=True.");

  // ---- face sets ----------------------------------------------------------
  py::class_<FaceSet> faces(m, "FaceSet", "Result of extract_faces(): faces over merged vertices, with their sides.");
  def_face_arrays(faces, [](const FaceSet& f) -> const FaceSet& { return f; });

  m.def(
      "extract_faces",
      [](const Cells& cells, const py::object& labels, const std::string& kind, bool capping,
         std::int32_t background_label) {
        const Cells& c = with_mesh(cells, "faces");
        const auto k = parse_face_set_kind(kind);
        if (!k) throw py::value_error("kind: expected 'boundary', 'complex' or 'surface-net', got '" + kind + "'");
        FaceSetOptions opt;
        opt.kind = *k;
        opt.capping = capping;
        opt.background_label = background_label;
        opt.progress = interrupt_check();
        const auto lab = as_labels(labels);
        return without_gil([&] { return extract_faces(c, lab, opt); });
      },
      py::arg("cells"), py::arg("labels").none(true), py::arg("kind"), py::arg("capping"),
      py::arg("background_label"), "A face set of cells computed with merge=True; labels as given to voronoi().");

  m.def(
      "face_set_classes",
      [](const std::string& kind, bool capping) {
        const auto k = parse_face_set_kind(kind);
        if (!k) throw py::value_error("kind: expected 'boundary', 'complex' or 'surface-net', got '" + kind + "'");
        FaceSetOptions opt;
        opt.kind = *k;
        opt.capping = capping;
        return static_cast<int>(face_set_classes(opt));
      },
      py::arg("kind"), py::arg("capping"),
      "The spoke classes of a face set's faces, as voronoi()'s only_with_faces takes them.");

  // ---- flowers ------------------------------------------------------------
  // A Flower is an element of its FlowerSet (returned by reference, keeping
  // the set alive); its arrays view the set's buffers through it.
  py::class_<Flower>(m, "Flower", "One cell's flower: petals, circumflower, faces and clipping neighbours.")
      .def_readonly("dim", &Flower::dim)
      .def_readonly("generator", &Flower::generator)
      .def_property_readonly("site",
                             [](const Flower& f) {
                               py::tuple t(static_cast<std::size_t>(f.dim));
                               for (int a = 0; a < f.dim; ++a)
                                 t[static_cast<std::size_t>(a)] = f.site[static_cast<std::size_t>(a)];
                               return t;
                             })
      .def_readonly("circumflower_radius", &Flower::circumflower_radius)
      .def_property_readonly("n_petals", &Flower::n_petals)
      .def_property_readonly("vertex_ids", [](py::object s) { return view_flat(s.cast<const Flower&>().vertex_ids, s); })
      .def_property_readonly("petal_centres",
                             [](py::object s) {
                               const Flower& f = s.cast<const Flower&>();
                               return view_rows(f.petal_centres, static_cast<std::size_t>(f.dim), s);
                             })
      .def_property_readonly("petal_radii",
                             [](py::object s) { return view_flat(s.cast<const Flower&>().petal_radii, s); })
      .def_property_readonly("face_offsets",
                             [](py::object s) { return view_flat(s.cast<const Flower&>().face_offsets, s); })
      .def_property_readonly("face_vertices",
                             [](py::object s) { return view_flat(s.cast<const Flower&>().face_vertices, s); })
      .def_property_readonly("face_neighbor",
                             [](py::object s) { return view_flat(s.cast<const Flower&>().face_neighbor, s); })
      .def_property_readonly("neighbors", [](py::object s) { return view_flat(s.cast<const Flower&>().neighbors, s); })
      .def_property_readonly("neighbor_positions",
                             [](py::object s) {
                               const Flower& f = s.cast<const Flower&>();
                               return view_rows(f.neighbor_positions, static_cast<std::size_t>(f.dim), s);
                             })
      .def_property_readonly("neighbor_shifts",
                             [](py::object s) {
                               const Flower& f = s.cast<const Flower&>();
                               return view_rows(f.neighbor_shifts, static_cast<std::size_t>(f.dim), s);
                             })
      .def_property_readonly("face_shifts", [](py::object s) {
        const Flower& f = s.cast<const Flower&>();
        return view_rows(f.face_shifts, static_cast<std::size_t>(f.dim), s);
      });

  py::class_<FlowerSet>(m, "Flowers", "Result of flowers(): one Flower per requested point.")
      .def("__len__", [](const FlowerSet& s) { return s.flowers.size(); })
      .def(
          "__getitem__",
          [](const FlowerSet& s, py::ssize_t k) -> const Flower& {
            const auto n = static_cast<py::ssize_t>(s.flowers.size());
            if (k < 0) k += n;
            if (k < 0 || k >= n) throw py::index_error("flower index out of range");
            return s.flowers[static_cast<std::size_t>(k)];
          },
          py::return_value_policy::reference_internal);

  m.def(
      "flowers",
      [](const Cells& cells, const Points& points, const Ids& ids) {
        const Cells& c = with_mesh(cells, "flower");
        if (checked_dim(points) != c.dim || static_cast<std::size_t>(points.shape(0)) != c.n_points)
          throw py::value_error("flowers: points are not the ones the cells were computed from");
        if (ids.ndim() != 1) throw py::value_error("flowers: ids must be one-dimensional");
        const auto pts = as_span(points);
        const std::span<const std::int32_t> id_span(ids.data(), static_cast<std::size_t>(ids.size()));
        return FlowerSet{without_gil([&] { return flowers(c, pts, id_span); })};
      },
      py::arg("cells"), py::arg("points").noconvert(), py::arg("ids").noconvert(),
      "Flowers of the cells of points `ids` (int32), from cells computed with merge=True on `points`.");
}

}  // namespace tessera::python
