// One registration function per product; module.cpp calls them in order.
#pragma once

#include <pybind11/pybind11.h>

namespace tessera::python {

void bind_voronoi(pybind11::module_& m);   // bind_voronoi.cpp: Cells, voronoi, validate_cells
void bind_delaunay(pybind11::module_& m);  // bind_delaunay.cpp: Delaunay, delaunay, validate_delaunay
void bind_io(pybind11::module_& m);        // bind_io.cpp: the VTK XML writers

}  // namespace tessera::python
