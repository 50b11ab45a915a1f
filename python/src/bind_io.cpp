// tessera._core.write_cells_vtk: the C++ VTK XML writer (include/tessera/io/vtk_xml.hpp).
//
// The Delaunay result is saved from Python (through vtk) until a C++ writer
// for it exists in vtk_xml.hpp; bind it here when it lands.
#include <string>

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "interrupt.hpp"
#include "tessera/cells.hpp"
#include "tessera/io/vtk_xml.hpp"

namespace tessera::python {

void bind_io(py::module_& m) {
  m.def(
      "write_cells_vtk",
      [](const std::string& path, const Cells& cells) {
        if (cells.cell_face_offsets.empty())
          throw py::value_error("cannot save cells computed with merge=False: they have no mesh");
        try {
          without_gil([&] { io::write_cells_vtk(path, cells); });
        } catch (const InputError& e) {
          // The Python layer checks the extension first, so what is left is a
          // file that could not be written ("cannot write PATH: reason").
          PyErr_SetString(PyExc_OSError, e.what());
          throw py::error_already_set();
        }
      },
      py::arg("path"), py::arg("cells"),
      "Write cells as .vtu (3D polyhedra) or .vtp (2D polygons), atomically, without the GIL. "
      "OSError if the file cannot be written.");
}

}  // namespace tessera::python
