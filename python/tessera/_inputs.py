"""Checking and converting user input for the compiled functions.

Contract with ``tessera._core``: it takes points as a float64 C-contiguous
(N, D) array with D in {2, 3}, labels as ``None`` or an int32 C-contiguous (N,)
array, bounds as ``None`` or 2*D floats, threads as an int >= 0 (0: the
default). Everything a user can get wrong is caught here, or by the C++ front
end (NaN, bounds ranges, points outside the bounds, padding), and raised as
``ValueError`` with a message naming the argument.
"""

from __future__ import annotations

import operator
from typing import Any, Optional, Sequence

import numpy as np

from . import _core

#: Dtype kinds accepted for points: floats (float32 and others are converted
#: to float64) and integers (exact in float64 up to 2**53).
_POINT_KINDS = "fiu"


def as_points(points: Any) -> np.ndarray:
    """Points as a float64 C-contiguous (N, 2) or (N, 3) array.

    No copy when ``points`` already is one: the result is then the caller's
    array itself, which keeps ``result.points`` zero-copy too.
    """
    try:
        a = np.asarray(points)
    except (ValueError, TypeError) as e:  # ragged nested lists and the like
        raise ValueError(f"points: cannot be read as an (N, 2) or (N, 3) array of numbers ({e})") from None
    if a.dtype.kind not in _POINT_KINDS:
        raise ValueError(f"points: expected real numbers (float or int), got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        hint = ""
        if a.ndim == 1 and a.shape[0] in (2, 3):
            hint = f"; a single point is points=[[...]] (shape (1, {a.shape[0]}))"
        elif a.ndim == 2 and a.shape[0] in (2, 3) and a.shape[1] not in (2, 3):
            hint = "; transposed? use points.T"
        raise ValueError(f"points: expected shape (N, 2) or (N, 3), got {a.shape}{hint}")
    if a.shape[0] == 0:
        raise ValueError("points: no points (shape (0, D))")
    return np.ascontiguousarray(a, dtype=np.float64)


def as_labels(labels: Any, n: int) -> Optional[np.ndarray]:
    """Labels as ``None`` or an int32 C-contiguous (n,) array.

    A label < 0 marks an outside point: it clips its neighbours but owns no cell.
    """
    if labels is None:
        return None
    try:
        a = np.asarray(labels)
    except (ValueError, TypeError) as e:
        raise ValueError(f"labels: cannot be read as an array of integers ({e})") from None
    if a.dtype.kind not in "iu":
        raise ValueError(
            f"labels: expected integers (label < 0 marks an outside point), got dtype {a.dtype}"
            + ("; convert with labels.astype(int)" if a.dtype.kind in "fb" else "")
        )
    if a.ndim != 1 or a.shape[0] != n:
        raise ValueError(f"labels: expected one label per point, shape ({n},), got {a.shape}")
    info = np.iinfo(np.int32)
    if n and (a.min() < info.min or a.max() > info.max):
        raise ValueError(f"labels: values must fit in 32 bits ([{info.min}, {info.max}])")
    return np.ascontiguousarray(a, dtype=np.int32)


def as_bounds(bounds: Optional[Sequence[float]], dim: int) -> Optional[list]:
    """Bounds in the CLI's order (x0, x1, y0, y1[, z0, z1]) as 2*dim floats."""
    if bounds is None:
        return None
    try:
        b = np.asarray(bounds, dtype=np.float64)
    except (ValueError, TypeError):
        raise ValueError(f"bounds: expected {2 * dim} numbers (x0, x1, y0, y1{', z0, z1' if dim == 3 else ''}), "
                         f"got {bounds!r}") from None
    if b.shape != (2 * dim,):
        raise ValueError(f"bounds: expected {2 * dim} numbers (x0, x1, y0, y1{', z0, z1' if dim == 3 else ''}) "
                         f"for {dim}D points, got shape {b.shape}")
    return b.tolist()


def as_threads(threads: Optional[int]) -> int:
    """threads=None -> 0 (TESSERA_NUM_THREADS if set, else every core)."""
    if threads is None:
        return 0
    try:
        t = operator.index(threads)
    except TypeError:
        raise ValueError(f"threads: expected a positive integer or None, got {threads!r}") from None
    if isinstance(threads, bool) or t < 1:
        raise ValueError(f"threads: expected a positive integer or None, got {threads!r}")
    return t


def as_padding(padding: float) -> float:
    try:
        return float(padding)
    except (ValueError, TypeError):
        raise ValueError(f"padding: expected a number >= 0, got {padding!r}") from None


# The front end's messages are written for the command line and may name its
# flags; a Python caller sets keywords instead.
_CLI_WORDING = (
    ("--bounds", "bounds="),
    ("--dim 2", "(N, 2) points"),
    ("--ignore-outside", "ignore_outside=True"),
)


def python_wording(message: str) -> str:
    for cli, py in _CLI_WORDING:
        message = message.replace(cli, py)
    return message


def call(fn, *args):
    """Call a compiled function, re-raising its input errors in Python's words."""
    try:
        return fn(*args)
    except _core.InputError as e:
        raise _core.InputError(python_wording(str(e))) from None
