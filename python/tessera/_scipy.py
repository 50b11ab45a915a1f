"""A ``scipy.spatial.Voronoi``-compatible view of :class:`tessera.Voronoi`.

For code written against scipy: the attributes have scipy's names, types and
meanings, with one difference that follows from tessera's bounded domain:
every region is a closed cell inside the box, so no vertex index is -1, and the
faces that lie on the box (they have no point across) are not ridges. Regions
are indexed by cell (``point_region`` maps points to them), not by qhull's order.
"""

from __future__ import annotations

import gc
from contextlib import contextmanager
from functools import cached_property
from typing import TYPE_CHECKING, Dict, Iterator, List, Optional, Tuple

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from ._voronoi import Voronoi


@contextmanager
def _collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off for a while, as it was after.
    Building millions of lists (a 3D ridge per face) set it off again and
    again, each time scanning every list made so far: two thirds of the time
    at 200k points, and the share grew with the count."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def _lists(flat: np.ndarray, offsets: np.ndarray, select: Optional[np.ndarray] = None) -> List[List[int]]:
    """``flat[offsets[i]:offsets[i + 1]]`` as a list, for every i (or every i
    in ``select``): one ``tolist`` and slices of it, not a numpy slice and
    ``tolist`` per list."""
    values = flat.tolist()
    starts = offsets[:-1] if select is None else offsets[select]
    ends = offsets[1:] if select is None else offsets[select + 1]
    with _collector_paused():
        return [values[a:b] for a, b in zip(starts.tolist(), ends.tolist())]


class ScipyVoronoi:
    """Attributes of ``scipy.spatial.Voronoi`` over tessera cells (see :attr:`tessera.Voronoi.scipy`)."""

    furthest_site = False

    def __init__(self, vor: "Voronoi"):
        if not vor.has_mesh:
            raise ValueError("the scipy view needs the mesh: compute with merge=True")
        if any(vor.periodic):
            # scipy has no periodic boxes: its ridges would pair points with
            # images without saying which.
            raise ValueError("the scipy view has no periodic boxes: use neighbors and neighbor_shifts")
        self._vor = vor

    @property
    def points(self) -> np.ndarray:
        """float64 (N, D): the input points."""
        return self._vor.points

    @property
    def vertices(self) -> np.ndarray:
        """float64 (V, D): Voronoi vertices, box corners and edge crossings included."""
        return self._vor.vertices

    @property
    def ndim(self) -> int:
        return self._vor.ndim

    @property
    def npoints(self) -> int:
        return self._vor.points.shape[0]

    @property
    def min_bound(self) -> np.ndarray:
        return self._vor.points.min(axis=0)

    @property
    def max_bound(self) -> np.ndarray:
        return self._vor.points.max(axis=0)

    @cached_property
    def _face_generator(self) -> np.ndarray:
        """The generator whose cell each face belongs to."""
        v = self._vor
        return np.repeat(v.generators, np.diff(v.cell_face_offsets))

    @cached_property
    def _ridge_faces(self) -> np.ndarray:
        """Indices of the faces that are ridges: one per pair of adjacent cells
        (seen from the lower id), plus the faces towards outside points
        (label < 0), which own no cell and so are seen from one side only."""
        v = self._vor
        nb = v.face_neighbor
        across = nb >= 0
        nb_has_cell = np.zeros(nb.shape, dtype=bool)
        nb_has_cell[across] = v.cell_of[nb[across]] >= 0
        keep = across & ((nb > self._face_generator) | ~nb_has_cell)
        return np.flatnonzero(keep)

    @cached_property
    def ridge_points(self) -> np.ndarray:
        """int32 (R, 2): the two points each ridge lies between."""
        faces = self._ridge_faces
        return np.column_stack([self._face_generator[faces], self._vor.face_neighbor[faces]]).astype(np.intc)

    @cached_property
    def ridge_vertices(self) -> List[List[int]]:
        """Vertex indices of each ridge (in 3D counter-clockwise seen from
        outside the cell of ``ridge_points[r, 0]``)."""
        v = self._vor
        faces = self._ridge_faces
        fvo, fv = v.face_vertex_offsets, v.face_vertices
        if v.ndim == 2:  # every face is an edge of two vertices
            with _collector_paused():
                return fv.reshape(-1, 2)[faces].tolist()
        return _lists(fv, fvo, faces)

    @cached_property
    def regions(self) -> List[List[int]]:
        """Vertex indices of each cell (region ``c`` is cell ``c``): in 2D the
        polygon counter-clockwise, in 3D the cell's vertices, ascending."""
        v = self._vor
        cfo, fvo, fv = v.cell_face_offsets, v.face_vertex_offsets, v.face_vertices
        if v.ndim == 2:
            first = fv[fvo[:-1]]  # first vertex of each edge, in polygon order
            return _lists(first, cfo)
        # 3D: the distinct vertices of each cell's faces, via one sort of (cell, vertex) keys.
        per_cell = np.diff(fvo[cfo])
        cell = np.repeat(np.arange(v.n_cells, dtype=np.int64), per_cell)
        keys = np.unique(cell * max(v.n_vertices, 1) + fv)
        counts = np.bincount(keys // max(v.n_vertices, 1), minlength=v.n_cells)
        verts = keys % max(v.n_vertices, 1)
        return _lists(verts, np.concatenate([[0], np.cumsum(counts)]))

    @cached_property
    def point_region(self) -> np.ndarray:
        """intp (N,), as scipy's: the region (cell) of each point, -1 for a
        point without one (outside label, dropped outside the bounds, a
        duplicate, or an empty power cell). A copy of :attr:`Voronoi.cell_of`
        (int32), read-only."""
        region = self._vor.cell_of.astype(np.intp)
        region.setflags(write=False)
        return region

    @cached_property
    def ridge_dict(self) -> Dict[Tuple[int, int], List[int]]:
        """{(p, q): ridge vertices}, as scipy's."""
        vertices = self.ridge_vertices
        first, second = self.ridge_points[:, 0].tolist(), self.ridge_points[:, 1].tolist()
        with _collector_paused():
            return {(p, q): rv for p, q, rv in zip(first, second, vertices)}

    def __repr__(self) -> str:
        return f"<tessera scipy view of {self._vor!r}>"
