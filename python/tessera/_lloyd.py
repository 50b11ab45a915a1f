"""tessera.lloyd(): Lloyd relaxation towards a centroidal Voronoi tessellation."""

from __future__ import annotations

from typing import Any, NamedTuple, Optional, Sequence, Tuple

import numpy as np

from . import _core, _inputs
from ._voronoi import periodic_box

_METHODS = ("auto", "search", "insertion")


class LloydResult(NamedTuple):
    """What :func:`lloyd` returns."""

    points: np.ndarray
    """float64 (N, D): the moved points, in input order (a new, writable array)."""
    iterations: int
    """Iterations done: fewer than asked where ``tolerance`` stopped them."""
    largest: np.ndarray
    """float64 (iterations,): each iteration's largest displacement."""
    rms: np.ndarray
    """float64 (iterations,): each iteration's root-mean-square displacement
    over the points that moved."""
    moved: np.ndarray
    """int64 (iterations,): the points that moved in each iteration (those
    that owned a cell)."""
    domain: Optional[Tuple[float, ...]]
    """The domain of every iteration, (x0, x1, y0, y1[, z0, z1]): ``bounds``
    (a periodic box as rounded to its grid), else the padded bounding box of
    the input as the first iteration computed it; None with 0 iterations."""
    spacing: float
    """The mean spacing ``tolerance`` is relative to: (domain volume /
    generators of the first iteration) ** (1 / D); 0.0 with 0 iterations."""


def lloyd(
    points: Any,
    iterations: int = 10,
    tolerance: float = 0.0,
    labels: Any = None,
    bounds: Optional[Sequence[float]] = None,
    padding: float = 0.01,
    threads: Optional[int] = None,
    *,
    ignore_outside: bool = False,
    method: str = "auto",
    periodic: Any = False,
    tilt: Optional[Sequence[float]] = None,
    radii: Any = None,
    walls: Any = None,
) -> LloydResult:
    """Lloyd relaxation: move every point to its cell's centroid, iteration
    after iteration, towards a centroidal Voronoi tessellation (Lloyd 1982;
    Du, Faber and Gunzburger, SIAM Review 1999). Each iteration computes
    the cells as :func:`voronoi` does (without the mesh) and lowers the
    energy ``sum over cells of the integral of |x - p|^2`` within one domain.

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
    iterations : int
        Iterations to run (>= 0; 0 returns the points unchanged).
    tolerance : float
        Stop after the first iteration whose largest displacement is at most
        ``tolerance * spacing`` (:attr:`LloydResult.spacing`); 0 runs every
        iteration.
    labels : array_like of int, shape (N,), optional
        As :func:`voronoi`'s: points labelled < 0 are outside points, which
        clip their neighbours, own no cell and stay where they are (fixed
        boundary samples, say). Labels stay with their points.
    bounds, padding :
        The domain, as :func:`voronoi`'s, fixed for every iteration: the
        default (the padded bounding box) is the first iteration's, kept,
        since the box of the moved points would shrink.
    threads : int, optional
        Worker threads (None: ``TESSERA_NUM_THREADS``, else every core). The
        result is identical for any count.
    ignore_outside, method, periodic, tilt, radii, walls :
        As :func:`voronoi`'s. In a periodic box a centroid may lie across a
        face: the moved point is wrapped back into the box (and rounded to
        its grid). With ``radii`` each point moves to its power cell's
        centroid; the radii stay as given. With ``walls`` (a convex domain)
        a centroid that rounds past a wall leaves its point where it was.

    Points that own no cell stay where they are, bit for bit: outside points,
    the copies of exact duplicates that do not own their cell (the owner
    moves, which separates them), points set aside by ``ignore_outside``, and
    points whose power cell is empty.

    Returns
    -------
    LloydResult
        ``(points, iterations, largest, rms, moved, domain, spacing)``.

    Raises
    ------
    ValueError
        Bad arguments, or what :func:`voronoi` refuses.
    KeyboardInterrupt
        Ctrl-C (it stops inside or between iterations).
    """
    pts = _inputs.as_points(points)
    dim = pts.shape[1]
    its = _inputs.as_int(iterations, "iterations", 0, 2**31 - 1, "an integer >= 0")
    tol = _inputs.as_float(tolerance, "tolerance", "a finite number >= 0")
    if not (np.isfinite(tol) and tol >= 0):
        raise ValueError(f"tolerance: expected a finite number >= 0, got {tolerance!r}")
    lab = _inputs.as_labels(labels, pts.shape[0])
    per, tilts = periodic_box(periodic, tilt, bounds, dim)
    rad = _inputs.as_radii(radii, pts.shape[0])
    moved_points, done, largest, rms, moved, domain, spacing, _threads = _inputs.call(
        _core.lloyd,
        pts,
        lab,
        _inputs.as_bounds(bounds, dim),
        _inputs.as_padding(padding),
        _inputs.as_flag(ignore_outside, "ignore_outside"),
        _inputs.as_threads(threads),
        _inputs.as_choice(method, "method", _METHODS),
        per,
        tilts,
        rad,
        its,
        tol,
        _inputs.as_walls(walls, dim),
    )
    return LloydResult(moved_points, done, largest, rms, moved, domain, spacing)
