"""VTK objects from tessera results (needs ``vtk``, Debian python3-vtk9).

Imported lazily: ``import tessera`` never loads VTK. The float64 (V, 3)
vertices and the per-cell data go to VTK without copies (the VTK array keeps a
reference to the numpy array); what VTK wants in another layout (the
polyhedron face stream, vtkIdType connectivity, 2D points with z = 0) is built
with numpy, vectorised.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

try:
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import VTK_UNSIGNED_CHAR, vtkPoints
    from vtkmodules.vtkCommonDataModel import (
        VTK_POLYHEDRON,
        VTK_TETRA,
        VTK_TRIANGLE,
        vtkCellArray,
        vtkPolyData,
        vtkUnstructuredGrid,
    )
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError(f"tessera: to_vtk() needs the vtk package (Debian python3-vtk9): {e}") from e

if TYPE_CHECKING:  # pragma: no cover
    from ._delaunay import Delaunay
    from ._voronoi import Voronoi


def _points(xyz: np.ndarray) -> vtkPoints:
    """vtkPoints over (n, 3) float64 coordinates; 2D input gets z = 0 (a copy)."""
    if xyz.shape[1] == 2:
        xyz = np.column_stack([xyz, np.zeros(xyz.shape[0])])
    p = vtkPoints()
    p.SetData(numpy_to_vtk(np.ascontiguousarray(xyz, dtype=np.float64)))
    return p


def _ids(a: np.ndarray) -> Any:
    """vtkIdTypeArray holding a copy of `a`. Always a copy: vtkCellArray.SetData
    shallow-copies an IdType array into a new VTK object, which would not keep a
    shared numpy buffer alive (the original wrapper does, through its reference)."""
    return numpy_to_vtkIdTypeArray(np.ascontiguousarray(a, dtype=np.int64), deep=1)


def _cell_array(offsets: np.ndarray, connectivity: np.ndarray) -> vtkCellArray:
    cells = vtkCellArray()
    cells.SetData(_ids(offsets), _ids(connectivity))
    return cells


def _add_cell_data(target: Any, name: str, values: np.ndarray) -> None:
    arr = numpy_to_vtk(values)
    arr.SetName(name)
    target.GetCellData().AddArray(arr)


def cells_to_vtk(vor: "Voronoi") -> Any:
    """vtkUnstructuredGrid of VTK_POLYHEDRON cells (3D) or vtkPolyData of
    polygons (2D), with the cell data of the C++ writer (same names)."""
    cfo = vor.cell_face_offsets  # raises for merge=False
    fvo, fv = vor.face_vertex_offsets, vor.face_vertices
    n_cells = vor.n_cells
    if vor.ndim == 2:
        out = vtkPolyData()
        out.SetPoints(_points(vor.vertices))
        # Polygon of a cell: the first vertex of each of its edges, in order.
        out.SetPolys(_cell_array(cfo, fv[fvo[:-1]]))
        names = ("Area", "NumberOfEdges")
    else:
        out = vtkUnstructuredGrid()
        out.SetPoints(_points(vor.vertices))
        # VTK's face stream (per cell: [n_faces, n_pts, ids..., n_pts, ids...]),
        # where each cell's record starts, and each cell's distinct vertices:
        # built in C++, without numpy's temporaries.
        # Each is copied into VTK (_ids) and let go at once, so the peak holds
        # one copy of the largest, the stream, beside VTK's.
        arrays = list(vor._cells._polyhedron_arrays())
        vtk_arrays = []
        while arrays:
            vtk_arrays.append(_ids(arrays.pop(0)))
        stream, face_locations, offsets, ids = vtk_arrays
        connectivity = vtkCellArray()
        connectivity.SetData(offsets, ids)
        types = numpy_to_vtk(np.full(n_cells, VTK_POLYHEDRON, dtype=np.uint8), deep=1,
                             array_type=VTK_UNSIGNED_CHAR)
        out.SetCells(types, connectivity, face_locations, stream)
        names = ("Volume", "NumberOfFaces")
    _add_cell_data(out, "GeneratorId", vor.generators)
    _add_cell_data(out, "Region", vor.regions)
    _add_cell_data(out, names[0], vor.volumes)
    _add_cell_data(out, names[1], vor.num_faces)
    _add_cell_data(out, "NumberOfNeighbors", np.diff(vor.neighbor_offsets).astype(np.int32))
    return out


def simplices_to_vtk(dt: "Delaunay") -> Any:
    """vtkUnstructuredGrid of VTK_TETRA (3D) / VTK_TRIANGLE (2D) over all input
    points. A periodic triangulation's is the file its save() writes, read back
    (the wrapped points, then one point per image a simplex uses)."""
    if dt.is_periodic:
        import tempfile

        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

        with tempfile.TemporaryDirectory(prefix="tessera-") as tmp:
            path = os.path.join(tmp, "simplices.vtu")
            dt.save(path)
            reader = vtkXMLUnstructuredGridReader()
            reader.SetFileName(path)
            reader.Update()
            return reader.GetOutput()
    out = vtkUnstructuredGrid()
    out.SetPoints(_points(dt.points))
    k = dt.ndim + 1
    offsets = np.arange(0, k * (dt.nsimplex + 1), k, dtype=np.int64)
    out.SetCells(VTK_TETRA if dt.ndim == 3 else VTK_TRIANGLE, _cell_array(offsets, dt.simplices.ravel()))
    return out


def _add_data(attributes: Any, name: str, values: np.ndarray) -> None:
    """Point or cell data from a (n,) or (n, k) array (k components), shared without a copy."""
    arr = numpy_to_vtk(np.ascontiguousarray(values))
    arr.SetName(name)
    attributes.AddArray(arr)


def _line_offsets(n: int, k: int = 2) -> np.ndarray:
    return np.arange(0, k * (n + 1), k, dtype=np.int64)


def faces_to_vtk(fs: Any) -> Any:
    """vtkPolyData of a face set (polygons in 3D, lines in 2D) or surface net,
    with the cell data of the C++ writer (BoundaryLabels, Sides, SpokeClass,
    and SideShift for periodic cells)."""
    out = vtkPolyData()
    out.SetPoints(_points(fs.vertices))
    cells = _cell_array(fs.face_offsets, fs.face_vertices)
    if fs.ndim == 3:
        out.SetPolys(cells)
    else:
        out.SetLines(cells)
    cd = out.GetCellData()
    _add_data(cd, "BoundaryLabels", fs.boundary_labels)
    _add_data(cd, "Sides", fs.sides)
    _add_data(cd, "SpokeClass", fs.face_class)
    if fs.side_shifts.size:  # periodic cells: which image of side 1 (int32, as the C++ writer)
        _add_data(cd, "SideShift", fs.side_shifts.astype(np.int32))
    return out


def graph_to_vtk(g: Any) -> Any:
    """vtkPolyData of the graph: the input points, a line per edge; point data
    Region, cell data SpokeClass and FaceArea / FaceLength. A periodic graph's
    is the file its save() writes, read back (images as extra points)."""
    if any(g.voronoi.periodic):
        import tempfile

        with tempfile.TemporaryDirectory(prefix="tessera-") as tmp:
            path = os.path.join(tmp, "graph.vtp")
            g.save(path)
            return read_vtp(path)
    out = vtkPolyData()
    out.SetPoints(_points(g.points))
    ends = g.edges()
    out.SetLines(_cell_array(_line_offsets(len(ends)), ends.ravel()))
    labels = g.labels
    _add_data(out.GetPointData(), "Region",
              labels if labels is not None else np.zeros(g.n_points, dtype=np.int32))
    spoke = g.edge_spokes
    _add_data(out.GetCellData(), "SpokeClass", g.spoke_class[spoke])
    _add_data(out.GetCellData(), "FaceArea" if g.ndim == 3 else "FaceLength", g.spoke_measure[spoke])
    return out


def read_vtp(path: str) -> Any:
    """A .vtp file as a vtkPolyData (VTK's XML reader)."""
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

    reader = vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def flowers_to_vtk(flowers: Any, glyphs: bool) -> Any:
    """The flowers file written by the library, read back (the layout of glyphs,
    roles and spokes is the writer's; one source of truth)."""
    import tempfile

    with tempfile.TemporaryDirectory(prefix="tessera-") as tmp:
        path = os.path.join(tmp, "flowers.vtp")
        flowers.save(path, glyphs=glyphs)
        return read_vtp(path)


def surface_net_to_vtk(net: Any) -> Any:
    """vtkPolyData of a surface net: the face set's, plus VertexKind (point
    data) and PolygonId (cell data), as the C++ writer."""
    out = faces_to_vtk(net)
    _add_data(out.GetPointData(), "VertexKind", net.vertex_kind)
    _add_data(out.GetCellData(), "PolygonId", net.polygon_of_face)
    return out
