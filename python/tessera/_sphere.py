"""tessera.spherical_voronoi() and its result, :class:`SphericalVoronoi`."""

from __future__ import annotations

import os
from typing import Any, List, Optional, Sequence, Union

import numpy as np

from . import _core, _inputs

PathLike = Union[str, "os.PathLike[str]"]

#: Values of :attr:`SphericalVoronoi.status`.
SPHERE_CELL: int = 0
SPHERE_DUPLICATE: int = 1
SPHERE_HIDDEN: int = 2


class SphericalVoronoi:
    """Voronoi cells on a sphere and their dual, the spherical Delaunay triangles.

    Made by :func:`tessera.spherical_voronoi`. Much as ``scipy.spatial.SphericalVoronoi``:
    :attr:`vertices` (on the sphere), :attr:`regions` (vertex indices per point,
    counter-clockwise seen from outside, already sorted), :meth:`calculate_areas`;
    and beyond it :attr:`neighbors` (CSR, the point across each edge, edge k running
    from region vertex k to k + 1), :attr:`centroids` (on the sphere),
    :attr:`triangles` (the convex hull's facets, outward, one per vertex) and
    :attr:`status` (0 a cell, 1 a duplicate of a lower id, 2 inside the hull of the
    others: no cell). Arrays are read-only views of the compiled result.
    """

    def __init__(self, sv: Any, points: np.ndarray):
        self._sv = sv
        self._points = points

    @property
    def points(self) -> np.ndarray:
        """float64 (N, 3): the points (from ``lonlat``: their unit vectors times the radius)."""
        return self._points

    @property
    def center(self) -> np.ndarray:
        return np.array(self._sv.center)

    @property
    def radius(self) -> float:
        return self._sv.radius

    @property
    def vertices(self) -> np.ndarray:
        """float64 (V, 3): the cells' vertices, on the sphere."""
        return self._sv.vertices

    @property
    def triangles(self) -> np.ndarray:
        """int32 (V, 3): per vertex its three points, counter-clockwise seen from outside."""
        return self._sv.triangles

    @property
    def region_offsets(self) -> np.ndarray:
        """int64 (N + 1,): point i's vertices are ``region_vertices[region_offsets[i]:region_offsets[i+1]]``."""
        return self._sv.region_offsets

    @property
    def region_vertices(self) -> np.ndarray:
        return self._sv.region_vertices

    @property
    def regions(self) -> List[np.ndarray]:
        """Per point, its vertex indices counter-clockwise seen from outside (scipy's layout)."""
        off = self.region_offsets
        rv = self.region_vertices
        return [rv[off[i]:off[i + 1]] for i in range(len(off) - 1)]

    @property
    def neighbor_offsets(self) -> np.ndarray:
        return self._sv.neighbor_offsets

    @property
    def neighbors(self) -> np.ndarray:
        """int32: point i's neighbours are ``neighbors[neighbor_offsets[i]:neighbor_offsets[i+1]]``."""
        return self._sv.neighbors

    def neighbors_of(self, i: int) -> np.ndarray:
        i = _inputs.as_index(i, len(self._points), "i", "a point index")
        off = self.neighbor_offsets
        return self.neighbors[off[i]:off[i + 1]]

    @property
    def areas(self) -> np.ndarray:
        """float64 (N,): the cells' areas (R^2 x solid angle); 0 for points without a cell."""
        return self._sv.areas

    def calculate_areas(self) -> np.ndarray:
        """The areas, as scipy's method of that name."""
        return self.areas

    def sort_vertices_of_regions(self) -> None:
        """Nothing to do: regions come sorted (scipy compatibility)."""

    @property
    def centroids(self) -> np.ndarray:
        """float64 (N, 3): the cells' centroids projected to the sphere."""
        return self._sv.centroids

    @property
    def status(self) -> np.ndarray:
        """uint8 (N,): 0 a cell, 1 a duplicate of a lower id (:attr:`duplicate_of`), 2 inside the hull."""
        return self._sv.status

    @property
    def duplicate_of(self) -> np.ndarray:
        return self._sv.duplicate_of

    @property
    def hidden(self) -> int:
        return self._sv.hidden

    @property
    def duplicates(self) -> int:
        return self._sv.duplicates

    @property
    def max_deviation(self) -> float:
        """The largest | |p - center| - radius | / radius over the points."""
        return self._sv.max_deviation

    @property
    def area_sum(self) -> float:
        return self._sv.area_sum

    @property
    def exact_tests(self) -> int:
        return self._sv.exact_tests

    def validate(self, sample: int = 256) -> Any:
        """Independent checks (symmetric neighbours, rings, V - E + F = 2, areas adding to 4 pi R^2,
        ``sample`` facets against every point): a :class:`SphereReport`, truthy when all pass."""
        return self._sv.validate(self._points, _inputs.as_int(sample, "sample", 0, None, "a count >= 0"))

    def save(self, path: PathLike) -> None:
        """The cells as polygons on the sphere (.vtp; cell data GeneratorId, Area, Neighbors)."""
        _inputs.call(self._sv.save_cells, _inputs.as_path(path))

    def save_triangles(self, path: PathLike) -> None:
        """The spherical Delaunay triangles over the points: .vtp, or .npy (int64 (T, 3))."""
        _inputs.call(self._sv.save_triangles, _inputs.as_path(path), self._points)

    def __repr__(self) -> str:
        return (f"<tessera.SphericalVoronoi: {len(self._points)} points, {len(self.vertices)} vertices, "
                f"radius {self.radius:g}>")


def spherical_voronoi(
    points: Any,
    radius: Optional[float] = None,
    center: Optional[Sequence[float]] = None,
    *,
    lonlat: bool = False,
    tolerance: float = 1e-6,
    threads: Optional[int] = None,
) -> SphericalVoronoi:
    """Voronoi cells of points on a sphere, by the meshless method (each point
    clips its own spherical polygon, in parallel), with an exact topology.

    ``points``: (N, 3) on the sphere, or with ``lonlat=True`` (N, 2) longitudes
    and latitudes in degrees (then ``radius`` defaults to 1). ``radius``: by
    default the points' mean distance from ``center`` (default the origin);
    every point must lie within ``tolerance * radius`` of the sphere
    (:class:`InputError` names the farthest otherwise; ``float('inf')``: no check).
    Cocircular points (a lon/lat grid) are decided by a symbolic perturbation:
    every vertex has three points. Exact duplicates: the lowest index owns the cell.
    """
    c = [0.0, 0.0, 0.0]
    if center is not None:
        cc = _inputs.read_array(center, "center", "three numbers")
        if cc.shape != (3,):
            raise ValueError(f"center: expected three numbers, got shape {cc.shape}")
        c = [_inputs.as_float(x, "center") for x in cc]
    r = 0.0 if radius is None else _inputs.as_float(radius, "radius")
    if radius is not None and not (r > 0 and np.isfinite(r)):
        raise ValueError(f"radius: expected a positive finite number, got {radius!r}")
    tol = _inputs.as_float(tolerance, "tolerance")
    if lonlat:
        a = _inputs.read_array(points, "points", "an (N, 2) array of longitudes and latitudes")
        if a.ndim != 2 or a.shape[1] != 2 or a.shape[0] == 0:
            raise ValueError(f"points: with lonlat=True expected shape (N, 2) (longitude, latitude), got {a.shape}")
        if a.dtype.kind not in "fiu":
            raise ValueError(f"points: expected real numbers, got dtype {a.dtype}")
        pts = _inputs.call(_core.lonlat_to_points, np.ascontiguousarray(a, dtype=np.float64), r if r > 0 else 1.0, c)
    else:
        pts = _inputs.as_points(points)
        if pts.shape[1] != 3:
            raise ValueError(f"points: expected shape (N, 3) on a sphere (or lonlat=True for (N, 2)), got {pts.shape}")
    sv = _inputs.call(_core.spherical_voronoi, pts, c, r, tol, _inputs.as_threads(threads))
    return SphericalVoronoi(sv, pts)
