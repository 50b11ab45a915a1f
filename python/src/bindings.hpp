// One registration function per product; module.cpp calls them in order.
#pragma once

#include <pybind11/pybind11.h>

namespace tessera::python {

void bind_voronoi(pybind11::module_& m);   // bind_voronoi.cpp: Cells, voronoi, validate_cells
void bind_delaunay(pybind11::module_& m);  // bind_delaunay.cpp: Delaunay, delaunay, validate_delaunay
void bind_dual(pybind11::module_& m);      // bind_dual.cpp: Graph, FaceSet, Flowers and their functions
void bind_surface_nets(pybind11::module_& m);  // bind_surface_nets.cpp: SurfaceNet, surface_nets
void bind_prep(pybind11::module_& m);      // bind_prep.cpp: images, sample_image, joggle, fill, threshold, probe
void bind_io(pybind11::module_& m);        // bind_io.cpp: the VTK XML writers
void bind_sphere(pybind11::module_& m);    // bind_sphere.cpp: SphericalVoronoi, spherical_voronoi, lonlat_to_points

}  // namespace tessera::python
