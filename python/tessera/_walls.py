"""Walls for the ``walls`` argument of :func:`tessera.voronoi`: from a convex
polygon (one wall per edge), or from the convex hull of points (one per
facet)."""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any, Optional

import numpy as np

from . import _core, _inputs


def polygon_walls(vertices: Any) -> np.ndarray:
    """The walls of a convex polygon, for ``voronoi(points, walls=...)``.

    Parameters
    ----------
    vertices : array_like, shape (k, 2)
        The polygon's corners in order around it (either way round), k >= 3,
        convex (three corners on a line are allowed), none repeated.

    Returns
    -------
    numpy.ndarray, float64 (k, 3)
        One row (nx, ny, d) per edge, the half-plane ``nx*x + ny*y <= d``
        holding the polygon: the normal is the edge turned outwards, and the
        offset is the larger of the edge's two corners' ``n . v``, computed
        exactly and rounded up, so that every corner lies inside or on every
        wall exactly. The lines pass within rounding of the corners: a point
        given on an edge may lie an ulp outside (``ignore_outside`` drops it).

    Raises
    ------
    ValueError
        Fewer than 3 corners, a repeated corner, not finite, or not convex.
    """
    v = _inputs.numbers_array(vertices) if not isinstance(vertices, np.ndarray) else np.asarray(vertices, float)
    if v.ndim != 2 or v.shape[1] != 2 or v.shape[0] < 3:
        raise ValueError(f"polygon_walls: expected (k, 2) corners with k >= 3, got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError("polygon_walls: a corner is not finite")
    k = v.shape[0]
    q = [(Fraction(float(x)), Fraction(float(y))) for x, y in v]
    # Orientation from the exact signed area; then every turn must agree.
    area = sum(q[i][0] * q[(i + 1) % k][1] - q[(i + 1) % k][0] * q[i][1] for i in range(k))
    if area == 0:
        raise ValueError("polygon_walls: the corners enclose no area")
    sign = 1 if area > 0 else -1  # counter-clockwise: +1
    for i in range(k):
        a, b, c = q[i], q[(i + 1) % k], q[(i + 2) % k]
        if a == b:
            raise ValueError(f"polygon_walls: corner {(i + 1) % k} repeats corner {i}")
        turn = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if turn * sign < 0:
            raise ValueError(f"polygon_walls: the polygon is not convex at corner {(i + 1) % k}")
    out = np.empty((k, 3))
    for i in range(k):
        (x0, y0), (x1, y1) = v[i], v[(i + 1) % k]
        # Outward normal of edge a -> b: (dy, -dx) for a counter-clockwise polygon.
        nx, ny = (float(y1 - y0), float(x0 - x1)) if sign > 0 else (float(y0 - y1), float(x1 - x0))
        if nx == 0 and ny == 0:  # corners an ulp apart: no direction in floats
            raise ValueError(f"polygon_walls: corners {i} and {(i + 1) % k} are too close for an edge's direction")
        n = (Fraction(nx), Fraction(ny))
        # The offset holds every corner (the rounded normal tilts the line a little).
        reach = max(n[0] * p[0] + n[1] * p[1] for p in q)
        d = float(reach)
        if Fraction(d) < reach:
            d = math.nextafter(d, math.inf)
        out[i] = (nx, ny, d)
    return out


def hull_walls(points: Any, dilation: float = 0.0, threads: Optional[int] = None) -> np.ndarray:
    """The convex hull of ``points`` as walls, for ``voronoi(points, walls=...)``:
    cells bounded by the hull of their points instead of a box (optionally a
    dilated hull).

    Parameters
    ----------
    points : array_like, shape (n, 2) or (n, 3)
        At least dim + 1 points spanning an area (2D) or a volume (3D).
    dilation : float
        Push each wall out by this distance (>= 0) along its normal.
    threads : int, optional
        Worker threads (default: TESSERA_NUM_THREADS, else every core).

    Returns
    -------
    numpy.ndarray, float64 (k, dim + 1)
        One row (normal..., d) per hull facet (edge in 2D; facets in one
        plane merged), the half-space ``normal . x <= d``, normal outwards
        and not of unit length. Every point lies inside every wall exactly;
        each wall passes within ~1e-14 of the coordinates' size of its
        facet's plane (through it exactly on lattices), plus ``dilation``.
        The default box (the points' bounding box grown by ``padding``)
        still cuts: give ``bounds`` or a larger ``padding`` to hold a
        dilated hull.

    Raises
    ------
    ValueError
        Fewer than dim + 1 points, a non-finite coordinate, points that span
        no area (volume), or a negative dilation.
    """
    p = _inputs.as_points(points)
    d = _inputs.as_float(dilation, "dilation", "a distance >= 0")
    return _inputs.call(_core.hull_walls, p, d, _inputs.as_threads(threads))
