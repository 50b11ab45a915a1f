"""tessera.delaunay() and its result, :class:`Delaunay`."""

from __future__ import annotations

import os
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core, _inputs

PathLike = Union[str, "os.PathLike[str]"]


class Delaunay:
    """The Delaunay triangulation of a point set (triangles in 2D, tetrahedra in 3D).

    Made by :func:`tessera.delaunay`. The attributes a ``scipy.spatial.Delaunay``
    user expects are here with the same meanings: :attr:`points`,
    :attr:`simplices`, :attr:`neighbors`, :attr:`ndim`, :attr:`npoints`,
    :attr:`nsimplex`. Arrays are read-only views of buffers the compiled result
    owns (no copy).

    Without labels the simplices cover the convex hull of the points exactly
    (hull completion); with labels they are the simplices whose points are all
    inside points (label >= 0).
    """

    def __init__(self, dt: Any, points: np.ndarray, labels: Optional[np.ndarray]):
        self._dt = dt
        self._points = points
        self._labels = labels

    @property
    def points(self) -> np.ndarray:
        """float64 (N, D): the input points."""
        return self._points

    @property
    def labels(self) -> Optional[np.ndarray]:
        """The region labels given (int32 (N,)), or None."""
        return self._labels

    @property
    def ndim(self) -> int:
        return self._dt.dim

    @property
    def npoints(self) -> int:
        return self._points.shape[0]

    @property
    def nsimplex(self) -> int:
        return self._dt.n_simplices

    @property
    def bounds(self) -> Tuple[float, ...]:
        """The domain box of the cells pass, (x0, x1, y0, y1[, z0, z1])."""
        return self._dt.bounds

    @property
    def simplices(self) -> np.ndarray:
        """int32 (nsimplex, D+1): point ids of each simplex; positively oriented
        (2D: counter-clockwise), lowest id first, rows in ascending order."""
        return self._dt.simplices

    @property
    def neighbors(self) -> np.ndarray:
        """int32 (nsimplex, D+1): ``neighbors[r, k]`` is the simplex across the
        facet opposite vertex ``k`` of simplex ``r``, -1 on the boundary (as scipy).
        Computed on first use."""
        return self._dt.neighbors

    @property
    def from_cells(self) -> int:
        """Simplices found by the cells pass (circumcentre inside the domain box)."""
        return self._dt.from_cells

    @property
    def from_hull_completion(self) -> int:
        """Simplices added by hull completion (circumcentre outside the box)."""
        return self._dt.from_hull_completion

    @property
    def hull_completed(self) -> bool:
        return self._dt.hull_completed

    @property
    def duplicates(self) -> np.ndarray:
        """int32 (k, 2): (duplicate id, owner id); duplicates are in no simplex."""
        return self._dt.duplicates

    @property
    def ignored_outside_bounds(self) -> np.ndarray:
        return self._dt.ignored_outside_bounds

    @property
    def exact_predicate_calls(self) -> int:
        return self._dt.exact_predicate_calls

    @property
    def threads_used(self) -> int:
        return self._dt.threads_used

    def validate(self) -> "_core.DelaunayReport":
        """Checks: orientation, manifold facets, closed and (without labels)
        convex boundary, every point used, empty circumspheres (local Delaunay).
        The report is truthy when all pass; ``report.messages`` says what failed."""
        return _core.validate_delaunay(self._dt, self._points, self._labels)

    def save(self, path: PathLike) -> None:
        """Write the simplices for ParaView: ``.vtu`` (VTK_TETRA / VTK_TRIANGLE
        cells over all input points, 2D points with z = 0) or, in 2D, ``.vtp``
        (triangles as polygons); binary, written atomically. Cell data
        SimplexId, point data PointId. ValueError for a wrong extension,
        OSError when the file cannot be written."""
        path = os.fspath(path)
        allowed = (".vtu",) if self.ndim == 3 else (".vtu", ".vtp")
        if not path.lower().endswith(allowed):
            raise ValueError(f"save: a {self.ndim}D triangulation is written as {' or '.join(allowed)}, got {path!r}")
        _core.write_simplices_vtk(path, self._dt, self._points)

    def to_vtk(self) -> Any:
        """The triangulation as a ``vtkUnstructuredGrid`` (needs ``vtk``)."""
        from ._vtk import simplices_to_vtk

        return simplices_to_vtk(self)

    def __repr__(self) -> str:
        return f"<tessera.Delaunay {self.ndim}D: {self.npoints} points, {self.nsimplex} simplices>"


def delaunay(
    points: Any,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: float = 0.01,
    threads: Optional[int] = None,
    *,
    complete_hull: bool = True,
    ignore_outside: bool = False,
) -> Delaunay:
    """Delaunay triangulation of 2D or 3D points, the dual of the Voronoi cells.

    Parameters are those of :func:`tessera.voronoi` (``bounds`` and ``padding``
    set the domain of the cells pass), plus:

    complete_hull : bool
        Without labels, add the thin simplices near the convex hull whose
        circumcentres lie outside the domain box, so the simplices cover the
        hull exactly (as scipy's). Ignored with labels.

    Exact predicates and a symbolic perturbation decide every simplex, so
    degenerate input (lattices, cospherical points) gets a valid triangulation
    without joggling. Runs with the GIL released; Ctrl-C stops it.
    """
    pts = _inputs.as_points(points)
    dim = pts.shape[1]
    lab = _inputs.as_labels(labels, pts.shape[0])
    dt = _inputs.call(
        _core.delaunay,
        pts,
        lab,
        _inputs.as_bounds(bounds, dim),
        _inputs.as_padding(padding),
        bool(ignore_outside),
        _inputs.as_threads(threads),
        bool(complete_hull),
    )
    return Delaunay(dt, pts, lab)
