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
import os
from typing import Any, Optional, Sequence, Tuple

import numpy as np

from . import _core

#: Dtype kinds accepted for points: floats (float32 and others are converted
#: to float64) and integers (exact in float64 up to 2**53).
_POINT_KINDS = "fiu"


def read_array(value: Any, name: str, what: str) -> np.ndarray:
    """``np.asarray(value)``, with a ValueError naming the argument when numpy
    cannot make an array of it (ragged nested lists and the like)."""
    try:
        return np.asarray(value)
    except (ValueError, TypeError) as e:
        raise ValueError(f"{name}: cannot be read as {what} ({e})") from None


def as_points(points: Any) -> np.ndarray:
    """Points as a float64 C-contiguous (N, 2) or (N, 3) array.

    No copy when ``points`` already is one: the result is then the caller's
    array itself, which keeps ``result.points`` zero-copy too.
    """
    a = read_array(points, "points", "an (N, 2) or (N, 3) array of numbers")
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
    """Labels as ``None`` or an int32 C-contiguous (n,) array, always a copy:
    results keep their labels (``faces`` and ``adjacency`` of a Voronoi read
    them later), and a caller refilling one buffer frame after frame changed
    the labels of every earlier result (4 bytes a point; points and radii,
    8 to 24, are the caller's arrays as documented).

    A label < 0 marks an outside point: it clips its neighbours but owns no cell.
    """
    if labels is None:
        return None
    a = read_array(labels, "labels", "an array of integers")
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
    out = np.array(a, dtype=np.int32, order="C", copy=True)
    out.setflags(write=False)
    return out


def as_radii(radii: Any, n: int) -> Optional[np.ndarray]:
    """Radii of power cells as ``None`` or a float64 C-contiguous (n,) array.

    No copy when ``radii`` already is one: the result is the caller's array,
    which the compiled cells view during the call and ``Voronoi.radii`` keeps.
    Finite and >= 0 is checked by the front end (InputError naming the point).
    """
    if radii is None:
        return None
    a = read_array(radii, "radii", "an array of numbers")
    if a.dtype.kind not in _POINT_KINDS:
        raise ValueError(f"radii: expected real numbers (one radius >= 0 per point), got dtype {a.dtype}")
    if a.ndim != 1 or a.shape[0] != n:
        raise ValueError(f"radii: expected one radius per point, shape ({n},), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def as_walls(walls: Any, dim: int) -> Optional[np.ndarray]:
    """Walls as ``None`` or a float64 C-contiguous (k, dim + 1) array, each
    row a half-space ``normal . x <= offset`` as (normal..., offset). One
    wall may be given as a flat row. Finite and non-zero normals are checked
    by the front end (InputError naming the wall)."""
    if walls is None:
        return None
    try:
        a = numbers_array(walls)
    except (TypeError, ValueError):
        raise TypeError(f"walls: expected rows (normal..., offset) of numbers, got {walls!r}") from None
    if a.ndim == 1 and a.shape[0] == dim + 1:
        a = a.reshape(1, dim + 1)
    if a.ndim != 2 or a.shape[1] != dim + 1:
        raise ValueError(f"walls: expected rows of {dim + 1} numbers (normal..., offset) for {dim}D points, "
                         f"got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def numbers_array(values: Any) -> np.ndarray:
    """`values` as a float64 array, refusing strings, bools, None and
    complex numbers among them as the scalar arguments do (np.asarray(
    ["0.1"], float) would parse text, None become NaN, a complex number
    lose its imaginary part); TypeError or ValueError otherwise."""
    a = np.asarray(values)
    if a.dtype.kind in "USbcMm" or (a.dtype.kind == "O" and any(
            v is None or isinstance(v, (str, bytes, bool, np.bool_)) for v in a.ravel())):
        raise TypeError("not numbers")
    return np.asarray(a, dtype=np.float64)


def as_dim(dim: Any) -> int:
    """A read function's ``dim``: None, 2 or 3 (ints, numpy's too) -> 0, 2, 3."""
    if dim is None:
        return 0
    if isinstance(dim, (bool, np.bool_)) or not isinstance(dim, (int, np.integer)) or dim not in (2, 3):
        raise ValueError(f"dim: expected 2, 3 or None, got {dim!r}")
    return int(dim)


def as_bounds(bounds: Optional[Sequence[float]], dim: int) -> Optional[list]:
    """Bounds in the CLI's order (x0, x1, y0, y1[, z0, z1]) as 2*dim floats."""
    if bounds is None:
        return None
    try:
        b = numbers_array(bounds)
    except (ValueError, TypeError, OverflowError):
        raise ValueError(f"bounds: expected {2 * dim} numbers (x0, x1, y0, y1{', z0, z1' if dim == 3 else ''}), "
                         f"got {bounds!r}") from None
    if b.shape != (2 * dim,):
        raise ValueError(f"bounds: expected {2 * dim} numbers (x0, x1, y0, y1{', z0, z1' if dim == 3 else ''}) "
                         f"for {dim}D points, got shape {b.shape}")
    return b.tolist()


def as_path(path: Any) -> str:
    """A file name as str; ValueError for an embedded NUL, which the C++
    side would cut the name at (writing or reading another file)."""
    name = os.fsdecode(path)
    if "\0" in name:
        raise ValueError(f"path: embedded null byte in {name!r}")
    return name


def as_index(i: Any, n: int, name: str, what: str) -> int:
    """An index into n items, negative ones counting from the end (as
    Python's sequences); IndexError naming the argument past either end
    (slices of the CSR offsets gave [] or another item's entries)."""
    if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer index, got {type(i).__name__}")
    k = int(i)
    if not -n <= k < n:
        raise IndexError(f"{name}: index {k} is out of range for {n} {what}")
    return k + n if k < 0 else k


def as_frame(frame: Any) -> int:
    """A trajectory's frame index (0 the first, negative from the end), in
    int64's range; ValueError naming ``frame`` otherwise."""
    if isinstance(frame, (bool, np.bool_)) or not isinstance(frame, (int, np.integer)):
        raise ValueError(f"frame: expected an integer (0 the first frame, -1 the last), got {type(frame).__name__}")
    k = int(frame)
    if not -(2**63) <= k < 2**63:
        raise ValueError(f"frame: {k} is out of range")
    return k


def as_threads(threads: Optional[int]) -> int:
    """threads=None -> 0 (TESSERA_NUM_THREADS if set, else every core)."""
    if threads is None:
        return 0
    if isinstance(threads, (bool, np.bool_)):
        raise ValueError(f"threads: expected a positive integer or None, got {threads!r}")
    try:
        t = operator.index(threads)
    except TypeError:
        raise ValueError(f"threads: expected a positive integer or None, got {threads!r}") from None
    if t < 1:
        raise ValueError(f"threads: expected a positive integer or None, got {threads!r}")
    if t > _INT32.max:
        raise ValueError(f"threads: at most {_INT32.max}, got {threads!r}")
    return t


def as_padding(padding: float) -> float:
    # (Its sign and size are the library's to check, which names --padding.)
    return as_float(padding, "padding", "a number >= 0")


def as_flag(value: Any, name: str) -> bool:
    """A yes/no argument: a bool (numpy's too, or a 0-d array of one, as an
    .npz gives it back) or the integers 0 and 1. Not truthiness: an array
    raised numpy's "truth value ... is ambiguous", which names no argument,
    and a string such as "False" is true."""
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "biu":
        value = value[()]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)) and value in (0, 1):
        return bool(value)
    raise ValueError(f"{name}: expected True or False, got {value!r}")


# The front end's messages are written for the command line and may name its
# flags; a Python caller sets keywords instead.
_CLI_WORDING = (
    ("--bounds", "bounds="),
    # A reader's words (read_points has dim=) before the computation's.
    ("--dim 2 or 3", "dim=2 or dim=3"),
    ("--dim 2: ", "dim=2: "),
    ("--dim 2", "(N, 2) points"),
    ("give it to `sample-image` (or `surface-nets --image`)",
     "read it with tessera.read_image (or give it to tessera.sample_image)"),
    ("--ignore-outside", "ignore_outside=True"),
    ("--method insertion", "method='insertion'"),
    ("--padding", "padding="),
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


# ---- helpers of the dual products and the preparation tools ----------------

_INT32 = np.iinfo(np.int32)


def as_int(value: Any, name: str, lo: Optional[int] = None, hi: Optional[int] = None, what: str = "an integer") -> int:
    """A Python int in [lo, hi] (bools rejected: they are almost always a mistake)."""
    v = None
    if not isinstance(value, (bool, np.bool_)):  # (numpy warns on a bool as an index)
        try:
            v = operator.index(value)
        except TypeError:
            pass
    if v is None or (lo is not None and v < lo) or (hi is not None and v > hi):
        raise ValueError(f"{name}: expected {what}, got {value!r}")
    return v


def as_label_value(value: Any, name: str, negative: bool = False) -> int:
    """One label (fits int32); ``negative=True``: must be < 0 (a background label)."""
    if negative:
        return as_int(value, name, _INT32.min, -1, "a negative integer (labels >= 0 are regions)")
    return as_int(value, name, _INT32.min, _INT32.max, "an integer that fits in 32 bits")


def as_seed(seed: Any) -> int:
    return as_int(seed, "seed", 0, 2**64 - 1, "an integer in [0, 2**64)")


def as_float(value: Any, name: str, what: str = "a number") -> float:
    """A number as a float: not a bool, and not a string (float("0.1") would
    take one that a caller meant to be something else)."""
    try:
        if isinstance(value, (bool, np.bool_, str, bytes)):
            raise TypeError
        return float(value)
    except (ValueError, TypeError):
        raise ValueError(f"{name}: expected {what}, got {value!r}") from None


def as_label_list(values: Any, name: str) -> list:
    """A list of labels (ints that fit int32): one int or a sequence of them."""
    try:
        a = np.asarray(values)
    except (ValueError, TypeError) as e:
        raise ValueError(f"{name}: expected an integer or a sequence of integers ({e})") from None
    if a.ndim == 0:
        a = a.reshape(1)
    if a.ndim != 1 or (a.size and a.dtype.kind not in "iu"):
        raise ValueError(f"{name}: expected an integer or a sequence of integers, got {values!r}")
    if a.size and (a.min() < _INT32.min or a.max() > _INT32.max):
        raise ValueError(f"{name}: labels must fit in 32 bits")
    return [int(x) for x in a]


def as_choice(value: Any, name: str, choices: Sequence[str]) -> str:
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{name}: expected one of {', '.join(repr(c) for c in choices)}, got {value!r}")
    return value


def as_scalars(values: Any, name: str = "scalars") -> np.ndarray:
    """A float64 C-contiguous 1-D array (NaN allowed)."""
    a = read_array(values, name, "a 1-D array of numbers")
    if a.dtype.kind not in _POINT_KINDS:
        raise ValueError(f"{name}: expected real numbers, got dtype {a.dtype}")
    if a.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array (one value per point), got shape {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def as_queries(xi: Any, dim: int) -> Tuple[np.ndarray, Tuple[int, ...]]:
    """Query points of shape (..., dim) as a float64 C-contiguous (M, dim)
    array, and their leading shape (...) for the answers."""
    x = read_array(xi, "xi", "an array of numbers")
    if x.dtype.kind not in "fiu":
        raise ValueError(f"xi: expected real numbers, got dtype {x.dtype}")
    if x.ndim == 0 or x.shape[-1] != dim:
        raise ValueError(f"xi: expected shape (..., {dim}), got {x.shape}")
    return np.ascontiguousarray(x.reshape(-1, dim), dtype=np.float64), x.shape[:-1]


def as_mask(mask: Any, n: int) -> Optional[np.ndarray]:
    """None or a uint8 (n,) array (nonzero = selected) from booleans or integers."""
    if mask is None:
        return None
    a = read_array(mask, "mask", "an array of booleans")
    if a.dtype.kind not in "biu":
        raise ValueError(f"mask: expected booleans (or 0/1 integers), got dtype {a.dtype}")
    if a.ndim != 1 or a.shape[0] != n:
        raise ValueError(f"mask: expected one value per point, shape ({n},), got {a.shape}")
    return np.ascontiguousarray(a != 0, dtype=np.uint8)


def as_geometry(values: Any, name: str, dim: Optional[int], positive: bool = False) -> Optional[list]:
    """spacing / origin: None or dim numbers in x, y[, z] order (dim None: 2 or 3)."""
    if values is None:
        return None
    try:
        a = numbers_array(values)
    except (ValueError, TypeError, OverflowError):
        a = None
    want = f"{dim}" if dim else "2 or 3"
    if a is None or a.ndim != 1 or (a.shape[0] != dim if dim else a.shape[0] not in (2, 3)):
        raise ValueError(f"{name}: expected {want} numbers in x, y{', z' if dim != 2 else ''} order, got {values!r}")
    if not np.all(np.isfinite(a)) or (positive and not np.all(a > 0)):
        raise ValueError(f"{name}: expected {'positive ' if positive else ''}finite numbers, got {values!r}")
    return a.tolist()
