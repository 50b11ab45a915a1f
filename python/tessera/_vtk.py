"""VTK objects from tessera results (needs ``vtk``, Debian python3-vtk9).

Imported lazily: ``import tessera`` never loads VTK. The float64 (V, 3)
vertices and the per-cell data go to VTK without copies (the VTK array keeps a
reference to the numpy array); what VTK wants in another layout (the
polyhedron face stream, vtkIdType connectivity, 2D points with z = 0) is built
with numpy, vectorised.
"""

from __future__ import annotations

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
        n_faces = len(fvo) - 1
        faces_per_cell = np.diff(cfo)
        verts_per_face = np.diff(fvo)
        # VTK's face stream, per cell: [n_faces, n_pts, ids..., n_pts, ids...];
        # face_locations[c] is where cell c's record starts.
        cell_len = 1 + faces_per_cell + np.diff(fvo[cfo])
        face_locations = np.zeros(n_cells, dtype=np.int64)
        np.cumsum(cell_len[:-1], out=face_locations[1:])
        stream = np.empty(int(cell_len.sum()), dtype=np.int64)
        stream[face_locations] = faces_per_cell
        face_cell = np.repeat(np.arange(n_cells), faces_per_cell)
        local_face = np.arange(n_faces) - cfo[face_cell]
        header = face_locations[face_cell] + 1 + local_face + (fvo[:-1] - fvo[cfo[face_cell]])
        stream[header] = verts_per_face
        entry_face = np.repeat(np.arange(n_faces), verts_per_face)
        stream[header[entry_face] + 1 + (np.arange(len(fv)) - fvo[entry_face])] = fv
        # Cell connectivity: the distinct vertices of each cell.
        n_v = max(vor.n_vertices, 1)
        keys = np.unique(np.repeat(np.arange(n_cells, dtype=np.int64), np.diff(fvo[cfo])) * n_v + fv)
        offsets = np.zeros(n_cells + 1, dtype=np.int64)
        np.cumsum(np.bincount(keys // n_v, minlength=n_cells), out=offsets[1:])
        types = numpy_to_vtk(np.full(n_cells, VTK_POLYHEDRON, dtype=np.uint8), deep=1,
                             array_type=VTK_UNSIGNED_CHAR)
        out.SetCells(types, _cell_array(offsets, keys % n_v), _ids(face_locations), _ids(stream))
        names = ("Volume", "NumberOfFaces")
    _add_cell_data(out, "GeneratorId", vor.generators)
    _add_cell_data(out, "Region", vor.regions)
    _add_cell_data(out, names[0], vor.volumes)
    _add_cell_data(out, names[1], vor.num_faces)
    _add_cell_data(out, "NumberOfNeighbors", np.diff(vor.neighbor_offsets).astype(np.int32))
    return out


def simplices_to_vtk(dt: "Delaunay") -> Any:
    """vtkUnstructuredGrid of VTK_TETRA (3D) / VTK_TRIANGLE (2D) over all input points."""
    out = vtkUnstructuredGrid()
    out.SetPoints(_points(dt.points))
    k = dt.ndim + 1
    offsets = np.arange(0, k * (dt.nsimplex + 1), k, dtype=np.int64)
    out.SetCells(VTK_TETRA if dt.ndim == 3 else VTK_TRIANGLE, _cell_array(offsets, dt.simplices.ravel()))
    return out
