// tessera._core: the compiled half of the Python module.
//
// Thin bindings over the compiled front end (include/tessera/cells.hpp,
// delaunay.hpp, graph.hpp, faces.hpp, flower.hpp, surface_nets.hpp, prep/,
// io/); no templates of the kernels or the engine are instantiated here. The
// pure-Python package (python/tessera/) converts and checks user input,
// documents everything and builds the derived views; this layer takes
// float64/int32 C-ordered arrays only, releases the GIL for every computation
// and hands results back as read-only numpy views of the C++ buffers
// (arrays.hpp; the preparation tools' plain output arrays take over the
// library's vectors instead).
#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "tessera/cells.hpp"

#ifndef TESSERA_VERSION
#error "TESSERA_VERSION must be defined by the build (the CMake project version)"
#endif

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  m.doc() = "Compiled bindings of tessera (use the `tessera` package, not this module).";
  m.attr("__version__") = TESSERA_VERSION;

  // Bad input is a ValueError; tessera.InputError lets callers tell the
  // library's own input checks apart from other ValueErrors.
  py::register_exception<tessera::InputError>(m, "InputError", PyExc_ValueError);
  // A cancelled run normally comes back as the Python exception the signal
  // handler set (interrupt.hpp); this covers a Cancelled with none pending.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const tessera::Cancelled& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });

  tessera::python::bind_voronoi(m);
  tessera::python::bind_delaunay(m);
  tessera::python::bind_dual(m);
  tessera::python::bind_surface_nets(m);
  tessera::python::bind_prep(m);
  tessera::python::bind_io(m);
  tessera::python::bind_sphere(m);
}
