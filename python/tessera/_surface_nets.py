"""tessera.surface_nets() and its result, :class:`SurfaceNet`."""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _core, _inputs
from ._dual import FaceSet
from ._voronoi import periodic_box

PathLike = Union[str, "os.PathLike[str]"]

#: Values of :attr:`SurfaceNet.vertex_kind`.
NET_SURFACE: int = _core.NET_SURFACE
NET_JUNCTION: int = _core.NET_JUNCTION
NET_CORNER: int = _core.NET_CORNER


class SurfaceNet(FaceSet):
    """Smooth, watertight surfaces between the regions of labelled points.

    Made by :func:`tessera.surface_nets`. The mesh has the arrays and
    conventions of :class:`FaceSet` (``kind`` is ``'surface-net'``): faces
    between two selected regions have :attr:`boundary_labels` ``(lo, hi)`` and
    are oriented from the lower label to the higher; capping faces have side 1
    = the outside point's own label, or ``background_label`` on the domain box.
    Every region's surface (its faces with the region on side 0, plus the
    reversed faces with it on side 1) is closed and outward-facing.

    :attr:`vertices` are the smoothed positions; :attr:`vertex_keys` keep each
    vertex's topological coordinate. :attr:`vertex_kind` says how a vertex was
    allowed to move: NET_SURFACE (2 regions meet: free), NET_JUNCTION (3
    regions, on a junction curve: along the curve), NET_CORNER (4+: fixed);
    in 2D a vertex is a curve point (NET_SURFACE) or a corner. Box planes count
    as regions. With ``triangles=True`` (3D) each polygon is split into
    triangles that copy its sides and labels; :attr:`polygon_of_face` maps them
    back. Arrays are read-only views of the compiled result.

    In a periodic box (``surface_nets(..., periodic=...)``) each face lies
    where its side-0 cell is, and a vertex seen from several frames is listed
    once per frame, the copies lattice translations apart (they move as one);
    every region's surface is closed once copies are identified
    (:attr:`vertex_key_shifts`, :attr:`side_shifts`).
    """

    def __init__(self, net: Any, points: np.ndarray, labels: np.ndarray, options: Dict[str, Any]):
        super().__init__(net, None, options["capping"], options["background_label"])
        self._points = points
        self._labels = labels
        self._options = options

    @property
    def points(self) -> np.ndarray:
        """float64 (N, D): the input points."""
        return self._points

    @property
    def labels(self) -> np.ndarray:
        """int32 (N,): the input labels."""
        return self._labels

    @property
    def options(self) -> Dict[str, Any]:
        """The options the net was computed with (select, smooth, relax, ...)."""
        return dict(self._options)

    @property
    def selected(self) -> List[int]:
        """The selected (inside) labels, ascending."""
        return list(self._fs.selected)

    @property
    def triangles(self) -> bool:
        return self._options["triangles"] and self.ndim == 3

    @property
    def vertex_kind(self) -> np.ndarray:
        """uint8 (n_vertices,): NET_SURFACE (0), NET_JUNCTION (1) or NET_CORNER (2)."""
        return self._fs.vertex_kind

    @property
    def polygon_of_face(self) -> np.ndarray:
        """int64 (n_faces,): the Voronoi polygon each face came from (identity without triangles)."""
        return self._fs.polygon_of_face

    @property
    def n_cells(self) -> int:
        """Voronoi cells computed (the selected regions' points)."""
        return self._fs.n_cells

    @property
    def max_displacement(self) -> float:
        """The largest distance a vertex moved in smoothing."""
        return self._fs.max_displacement

    @property
    def seconds(self) -> Dict[str, float]:
        """Wall time of each stage: cells, faces, smoothing, triangulation."""
        return self._fs.seconds

    def region_faces(self, label: int) -> tuple:
        """The faces bounding region ``label``: (face ids, flip), where ``flip``
        is True for faces with the region on side 1 (reverse them to face out
        of the region)."""
        bl = self.boundary_labels
        ids = np.flatnonzero((bl[:, 0] == label) | (bl[:, 1] == label))
        return ids, bl[ids, 1] == label

    def save(self, path: PathLike) -> None:
        """Write the net for ParaView as ``.vtp`` (3D polygons or triangles, 2D
        lines with z = 0). Cell data BoundaryLabels, Sides, SpokeClass (as
        :meth:`FaceSet.save`) and PolygonId; point data VertexKind.
        ValueError for another extension, OSError when the file cannot be written."""
        path = _inputs.as_path(path)
        if not path.lower().endswith(".vtp"):
            raise ValueError(f"save: a surface net is written as VTK PolyData (.vtp), got {path!r}")
        _core.write_surface_net_vtp(path, self._fs)

    def to_vtk(self) -> Any:
        """The net as a ``vtkPolyData`` with the data of :meth:`save` (needs ``vtk``)."""
        from ._vtk import surface_net_to_vtk

        return surface_net_to_vtk(self)

    def __repr__(self) -> str:
        what = ("triangles" if self.triangles else "polygons") if self.ndim == 3 else "segments"
        return (f"<tessera.SurfaceNet {self.ndim}D: labels {self.selected}, {self.n_faces} {what}, "
                f"{self.n_vertices} vertices>")


def surface_nets(
    points: Any,
    labels: Any,
    select: Optional[Union[int, Sequence[int]]] = None,
    background_label: int = -1,
    capping: bool = False,
    smooth: int = 20,
    relax: float = 0.5,
    constraint: float = 0.5,
    constraint_is_absolute: bool = False,
    triangles: bool = False,
    bounds: Optional[Sequence[float]] = None,
    padding: float = 0.01,
    threads: Optional[int] = None,
    *,
    ignore_outside: bool = False,
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    walls: Any = None,
) -> SurfaceNet:
    """Generalized surface nets: the surfaces between the regions of labelled points.

    Pipeline: Voronoi cells of the selected regions' points (the others clip
    as outside points), the faces between different selected regions (with
    ``capping`` also those against the domain box and unselected points),
    constrained smoothing, optional triangulation.

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
    labels : array_like of int, shape (N,)
        A region label per point; labels < 0 are outside points.
    select : int or sequence of int, optional
        The inside labels (each must occur); default every label >= 0 present.
        Points with other labels clip the cells as outside points.
    background_label : int
        BoundaryLabels value of the domain box side (< 0).
    capping : bool
        Close the regions with the faces on the box and against unselected points.
    smooth : int
        Smoothing iterations (0: none; the faces stay the exact Voronoi faces).
    relax : float
        Relaxation factor in (0, 1]: each iteration moves a vertex that
        fraction of the way to the mean of its stencil.
    constraint : float
        No vertex moves farther than this from its Voronoi position, as a
        fraction of its local point spacing (its distance to its generators),
        or as a distance with ``constraint_is_absolute``.
    constraint_is_absolute : bool
    triangles : bool
        3D: split each polygon into triangles (labels and sides copied).
    bounds, padding, threads, ignore_outside
        As in :func:`tessera.voronoi`.
    periodic, tilt
        A periodic box, as in :func:`tessera.voronoi` (``bounds`` is the box):
        the regions wrap around it, each face lies where its side-0 cell is
        (:attr:`side_shifts` names side 1's image), and the copies of a vertex
        seen from several frames are smoothed as one, so every region's
        surface closes up across the box's faces.
    walls
        A convex domain, as in :func:`tessera.voronoi`: capped regions close
        on the walls, and a vertex on a wall stays on it through the smoothing.

    Returns
    -------
    SurfaceNet

    Raises
    ------
    ValueError
        Bad points or labels (as :func:`voronoi`), missing labels, a selected
        label no point carries, an empty selection, background_label >= 0, bad
        smoothing options.
    KeyboardInterrupt
        Ctrl-C (the run stops between batches of cells or between stages).
    """
    pts = _inputs.as_points(points)
    dim = pts.shape[1]
    if labels is None:
        raise ValueError("labels: surface nets need one region label per point")
    per, tilts = periodic_box(periodic, tilt, bounds, dim)
    lab = _inputs.as_labels(labels, pts.shape[0])
    sel = [] if select is None else _inputs.as_label_list(select, "select")
    if select is not None and not sel:
        raise ValueError("select: empty selection (None selects every label >= 0)")
    bg = _inputs.as_label_value(background_label, "background_label", negative=True)
    iterations = _inputs.as_int(smooth, "smooth", 0, 2**31 - 1, "a number of iterations >= 0 (0 = no smoothing)")
    relaxation = _inputs.as_float(relax, "relax", "a number in (0, 1]")
    if not 0 < relaxation <= 1:
        raise ValueError(f"relax: expected a number in (0, 1], got {relax!r}")
    limit = _inputs.as_float(constraint, "constraint", "a finite number >= 0")
    if not (np.isfinite(limit) and limit >= 0):
        raise ValueError(f"constraint: expected a finite number >= 0, got {constraint!r}")
    cap = _inputs.as_flag(capping, "capping")
    absolute = _inputs.as_flag(constraint_is_absolute, "constraint_is_absolute")
    tri = _inputs.as_flag(triangles, "triangles")
    options = dict(select=sel or None, background_label=bg, capping=cap, smooth=iterations, relax=relaxation,
                   constraint=limit, constraint_is_absolute=absolute, triangles=tri)
    net = _inputs.call(
        _core.surface_nets, pts, lab, sel, bg, cap, iterations, relaxation, limit, absolute, tri,
        _inputs.as_bounds(bounds, dim), _inputs.as_padding(padding), _inputs.as_flag(ignore_outside, "ignore_outside"),
        _inputs.as_threads(threads), per, tilts, _inputs.as_walls(walls, dim))
    return SurfaceNet(net, pts, lab, options)
