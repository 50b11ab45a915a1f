"""Point preparation: images to points, and points to labels.

:func:`sample_image` turns a label image into labelled points concentrated
near the label boundaries; :func:`fill` adds background points where a cloud
is empty; :func:`joggle` breaks exact ties; :func:`threshold` turns a scalar
per point into labels; :func:`probe` samples an image's scalars at points;
:func:`read_image` reads the image files the library reads, :func:`read_points`
its point files.

Images as numpy arrays are C-ordered, shape ``(ny, nx)`` or ``(nz, ny, nx)``:
``image[k, j, i]`` is voxel ``(i, j, k)``, x varies fastest (as in VTK, NRRD
and MetaImage), and it sits at ``origin + (i, j, k) * spacing`` (voxel
centres), with ``spacing`` and ``origin`` in x, y[, z] order.

The outputs are new arrays that take over the library's buffers (no copy) and
may be written.
"""

from __future__ import annotations

import os
from typing import Any, Iterator, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core, _inputs

PathLike = Union[str, "os.PathLike[str]"]
ImageLike = Union[np.ndarray, PathLike]


def _is_path(x: Any) -> bool:
    return isinstance(x, (str, bytes, os.PathLike))


def _image_array(image: Any, kinds: str, what: str) -> np.ndarray:
    a = _inputs.read_array(image, "image", "an array")
    if a.dtype.kind not in kinds:
        raise ValueError(f"image: expected {what}, got dtype {a.dtype}")
    if a.ndim not in (2, 3):
        raise ValueError(f"image: expected shape (ny, nx) or (nz, ny, nx) (C order, x fastest), got {a.shape}")
    if a.size == 0:
        raise ValueError(f"image: no voxels (shape {a.shape})")
    return a


def _geometry(spacing: Any, origin: Any, dim: Optional[int]) -> Tuple[Optional[list], Optional[list]]:
    """spacing / origin as lists for the compiled readers: one value (every
    axis) or one per axis (x, y[, z]); dim None (a file) checks only 2 or 3."""

    def one(v: Any, name: str, positive: bool) -> Optional[list]:
        if v is None:
            return None
        if np.ndim(v) == 0:
            x = _inputs.as_float(v, name, "a number or one per axis")
            if not np.isfinite(x) or (positive and not x > 0):
                raise ValueError(f"{name}: expected a {'positive ' if positive else ''}finite number, got {v!r}")
            return [x]
        return _inputs.as_geometry(v, name, dim, positive=positive)

    return one(spacing, "spacing", True), one(origin, "origin", False)


def _label_image(image: Any, spacing: Any, origin: Any) -> Any:
    if _is_path(image):
        sp, org = _geometry(spacing, origin, None)
        return _inputs.call(_core.read_label_image, _inputs.as_path(image), sp, org)
    # A boolean mask is the labels 0 and 1, as a bool .npy read from its file.
    a = _image_array(image, "biu", "integer labels (a label image); threshold a scalar image first")
    info = np.iinfo(np.int32)
    if a.min() < info.min or a.max() > info.max:
        raise ValueError(f"image: labels must fit in 32 bits ([{info.min}, {info.max}])")
    sp, org = _geometry(spacing, origin, a.ndim)
    return _core.label_image(np.ascontiguousarray(a, dtype=np.int32), sp, org)


def _scalar_image(image: Any, spacing: Any, origin: Any) -> Any:
    if _is_path(image):
        sp, org = _geometry(spacing, origin, None)
        return _inputs.call(_core.read_scalar_image, _inputs.as_path(image), sp, org)
    a = _image_array(image, "bfiu", "real numbers")
    sp, org = _geometry(spacing, origin, a.ndim)
    return _core.scalar_image(np.ascontiguousarray(a, dtype=np.float64), sp, org)


# ---------------------------------------------------------------- read_image

def read_image(
    path: PathLike, spacing: Any = None, origin: Any = None
) -> Tuple[np.ndarray, Tuple[float, ...], Tuple[float, ...]]:
    """Read an image file: ``.npy``, NRRD (``.nrrd`` / ``.nhdr``, raw or
    gzip), MetaImage (``.mha`` / ``.mhd``), VTK XML image data (``.vti``),
    legacy VTK structured points (``.vtk``) or
    NIfTI (``.nii``, ``.nii.gz``, ``.hdr`` with its ``.img``; an axis stored
    with a negative step is reversed, so spacings are positive).

    Returns ``(array, spacing, origin)``: the voxels as a C-ordered array of
    shape (ny, nx) or (nz, ny, nx) — int32 for integer data that fits, else
    float64 — and the geometry in x, y[, z] order. ``spacing`` / ``origin``
    override the file's (a ``.npy`` has none: 1 and 0 by default).
    ValueError (:class:`tessera.InputError`) for a missing or malformed file.
    """
    if not _is_path(path):
        raise ValueError(f"path: expected a file name, got {type(path).__name__}")
    name = _inputs.as_path(path)
    sp, org = _geometry(spacing, origin, None)
    try:
        im = _inputs.call(_core.read_label_image, name, sp, org)
    except _core.InputError:
        # Not an integer image (or not readable at all: the scalar reader then
        # says why, naming the file).
        im = _inputs.call(_core.read_scalar_image, name, sp, org)
    geometry = (im.spacing, im.origin)
    return (im.release_array(),) + geometry


# --------------------------------------------------------------- read_points

def read_points(
    path: PathLike,
    dim: Optional[int] = None,
    labels: Optional[PathLike] = None,
    keep_non_finite: bool = False,
    frame: int = 0,
) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """Read a point file as the ``tessera`` command reads it: ``.npy`` (an
    (N, 2) or (N, 3) array in C or Fortran order, or a structured array with
    fields x, y[, z]), ``.csv`` / ``.xyz`` / ``.txt`` (the columns a header
    names x, y[, z], else the first ones), ``.ply``, ``.vtp`` / ``.vtu``
    (VTK XML points), ``.vtk`` (legacy VTK points), ``.pcd`` (PCL's point
    clouds), ``.las`` (lidar; ``labels="classification"``) or ``.dump`` /
    ``.lammpstrj`` (a LAMMPS dump's frame: columns x y z, xu yu zu or
    scaled xs ys zs; atoms in file order; its box: :func:`read_box`). An
    ``.xyz`` / ``.txt`` that starts with a lone count is XYZ (count,
    comment, ``species x y z`` per atom; extended XYZ's ``Properties`` name
    its columns, an integer one can be the labels).

    ``frame``: of a trajectory (a dump, an XYZ file), the frame to read: 0
    the first, 1 the next, negative from the end (-1 the last); the frames
    before it are skipped by their line counts. :func:`read_frames` walks
    them all.

    ``dim`` forces 2 or 3 (2 keeps x, y). ``labels``: a ``.npy`` file of N
    integers, or the name of an integer column, property, point data array
    or field of the file itself. Returns ``(points, labels)``: float64 of
    shape (N, dim), and int32 of shape (N,) or None; both writable, taken
    over from the library without a copy. ValueError
    (:class:`tessera.InputError`) for a missing or malformed file.

    Points with a NaN or infinite coordinate (an organized cloud's missing
    returns) are an error, unless ``keep_non_finite``: then they are kept,
    for :func:`voronoi` and the others to set aside with
    ``ignore_outside=True`` (ids unchanged).
    """
    if not _is_path(path):
        raise ValueError(f"path: expected a file name, got {type(path).__name__}")
    dim = _inputs.as_dim(dim) or None
    if labels is not None and not _is_path(labels):
        raise ValueError(f"labels: expected a file or field name, got {type(labels).__name__}")
    lab = "" if labels is None else _inputs.as_path(labels)
    return _inputs.call(_core.read_points, _inputs.as_path(path), dim or 0, lab,
                        _inputs.as_flag(keep_non_finite, "keep_non_finite"), _inputs.as_frame(frame))


def read_scalars(path: PathLike, name: str, frame: int = 0) -> np.ndarray:
    """One number per point of a point file, as the command line reads
    ``--radii NAME`` and ``threshold --scalars NAME``: ``name`` is a numeric
    column of a ``.csv`` or a LAMMPS dump (its ``frame``), a ``.ply``
    property, a ``.vtp`` / ``.vtu`` / ``.vtk`` point data array, a ``.las``
    field (``intensity``, ``gps_time``, ...) or a ``.pcd`` or structured
    ``.npy`` field. (A separate ``.npy`` of values is ``np.load``'s.)
    Returns float64 (N,) in the points' order (:func:`read_points`), NaN
    and infinities kept; ValueError (:class:`tessera.InputError`) for a
    missing name or a malformed file.

    >>> p, types = tessera.read_points("run.dump", labels="type")    # doctest: +SKIP
    >>> r = tessera.read_scalars("run.dump", "radius")               # doctest: +SKIP
    >>> cells = tessera.voronoi(p, radii=r, **tessera.read_box("run.dump"))  # doctest: +SKIP
    """
    if not _is_path(path):
        raise ValueError(f"path: expected a file name, got {type(path).__name__}")
    if not isinstance(name, str):
        raise ValueError(f"name: expected the name of a column, property, array or field, got {type(name).__name__}")
    if name.lower().endswith(".npy"):
        raise ValueError(f"name: {name!r} is a file, not a field of {_inputs.as_path(path)!r} (np.load reads it)")
    return _inputs.call(_core.read_scalars, _inputs.as_path(path), name, _inputs.as_frame(frame))


class Frame(NamedTuple):
    """One frame of a trajectory (:func:`read_frames`)."""

    points: np.ndarray
    """float64 (N, D): the atoms, in file order."""
    labels: Optional[np.ndarray]
    """int32 (N,) from the ``labels`` column, or None."""
    box: Optional[dict]
    """The frame's box as :func:`read_box` gives it (``voronoi(points, **box)``), or None."""
    timestep: Optional[int]
    """A LAMMPS dump's TIMESTEP; None for XYZ."""


def read_frames(path: PathLike, labels: Optional[str] = None, dim: Optional[int] = None,
                frames: Optional[Union[slice, Sequence[int]]] = None) -> Iterator[Frame]:
    """The frames of a trajectory, one after another: a LAMMPS dump
    (``.dump`` / ``.lammpstrj``) or an XYZ file (frames back to back). Each
    frame is read when the loop asks for it (a trajectory may be far larger
    than memory)::

        for f in tessera.read_frames("run.lammpstrj", labels="type"):
            vor = tessera.voronoi(f.points, labels=f.labels, **f.box, merge=False)

    ``labels`` names an integer column (dump) or ``I:1`` property (extended
    XYZ); ``dim=2`` keeps x, y. Each frame is checked as :func:`read_points`
    checks the first (ValueError, :class:`tessera.InputError`, naming the
    line), when the loop reaches it.

    ``frames``: some of the frames, by a slice (``slice(-10, None)`` the last
    ten, ``slice(None, None, 5)`` every fifth) or a sequence of indices
    (negative from the end), in that order. The file is first walked once
    for where its frames start (their lines counted, not parsed); the frames
    not asked for are not read. ``--frame`` takes the same selections on the
    command line.
    """
    if not _is_path(path):
        raise ValueError(f"path: expected a file name, got {type(path).__name__}")
    dim = _inputs.as_dim(dim) or None
    if labels is not None and not isinstance(labels, str):
        raise ValueError(f"labels: expected a column name, got {type(labels).__name__}")
    name = _inputs.as_path(path)
    places = None
    if frames is not None:
        if not isinstance(frames, slice) and (isinstance(frames, (str, bytes)) or
                                              not isinstance(frames, (Sequence, np.ndarray))):
            raise ValueError(f"frames: expected a slice or a sequence of frame indices, got {type(frames).__name__}")
        every = _inputs.call(_core.find_frames, name)
        if isinstance(frames, slice):
            places = every[frames]
        else:
            places = [every[_inputs.as_index(k, len(every), "frames", "frames")] for k in frames]

    def read(offset: int, line: int) -> Tuple[Frame, int, int, bool]:
        pts, lab, box, step, offset, line, last = _inputs.call(_core.read_frame, name, offset, line, dim or 0,
                                                               labels or "")
        return Frame(pts, lab, None if box is None else _box_arguments(name, box, dim), step), offset, line, last

    if places is not None:
        def chosen() -> Iterator[Frame]:
            for offset, line in places:
                yield read(offset, line)[0]

        return chosen()

    # The first frame now: a missing file or another format is said here,
    # not at the loop's first step.
    first = read(0, 1)

    def frames() -> Iterator[Frame]:
        frame, offset, line, last = first
        yield frame
        while not last:
            frame, offset, line, last = read(offset, line)
            yield frame

    return frames()


def _box_arguments(name: str, box: tuple, dim: Optional[int]) -> dict:
    """A file's box (lo, hi, tilt, periodic, timestep) as voronoi()'s keyword arguments."""
    lo, hi, tilt, periodic, _timestep = box
    d = dim or 3
    if d == 2 and (tilt[1] != 0 or tilt[2] != 0):
        raise _core.InputError(f"{name}: dim=2, but the box tilts along z (xz, yz not 0)")
    tilts = tuple(float(t) for t in tilt[: 3 if d == 3 else 1])
    return {
        "bounds": tuple(float(v) for a in range(d) for v in (lo[a], hi[a])),
        "periodic": tuple(bool(p) for p in periodic[:d]),
        "tilt": tilts if any(t != 0 for t in tilts) else None,
    }


def read_box(path: PathLike, dim: Optional[int] = None, frame: int = 0) -> Optional[dict]:
    """The simulation box a point file declares (a LAMMPS dump's ``BOX
    BOUNDS``, an extended XYZ's ``Lattice``, ``Origin`` and ``pbc``; other
    formats declare none: None), as the keyword arguments
    ``bounds``, ``periodic`` and ``tilt`` of :func:`voronoi` and the others::

        points, types = tessera.read_points("run.lammpstrj", labels="type")
        vor = tessera.voronoi(points, labels=types, **tessera.read_box("run.lammpstrj"))

    ``bounds`` is the box's lower corner and its edge lengths along the axes
    (x0, x1, y0, y1[, z0, z1]); ``periodic`` one bool per axis (LAMMPS's
    ``pp`` flags, f, s and m being walls; extended XYZ's pbc, T T T where it
    is absent); ``tilt`` the triclinic tilts xy, xz,
    yz as lengths, or None for an orthogonal box. Only the header is read,
    of ``frame`` (as :func:`read_points`' ``frame``; the first by default).
    ``dim=2`` gives the x, y part (ValueError where the box tilts along z).
    ValueError (:class:`tessera.InputError`) for a malformed header.
    """
    if not _is_path(path):
        raise ValueError(f"path: expected a file name, got {type(path).__name__}")
    dim = _inputs.as_dim(dim) or None
    box = _inputs.call(_core.read_box, _inputs.as_path(path), _inputs.as_frame(frame))
    return None if box is None else _box_arguments(_inputs.as_path(path), box, dim)


# -------------------------------------------------------------- sample_image

_SCHEDULES = ("exponential", "linear")
_OUTPUTS = ("all", "labelled", "background")


def sample_image(
    image: ImageLike,
    spacing: Any = None,
    origin: Any = None,
    select: Optional[Union[int, Sequence[int]]] = None,
    schedule: str = "exponential",
    step: int = 2,
    randomize: bool = True,
    probability_range: Sequence[float] = (0.0, 1.0),
    seed: int = 0,
    output: str = "all",
    background_label: Optional[int] = None,
    joggle: float = 0.0,
    threads: Optional[int] = None,
) -> Tuple[np.ndarray, np.ndarray]:
    """Sample a label image into points concentrated near the label boundaries.

    1. A voxel is a boundary voxel (distance 1) when a face neighbour has
       another label and one of the two labels is selected; every other voxel
       gets 1 + its city-block distance in voxels to the nearest boundary voxel.
    2. A voxel is a candidate when its distance ``d`` is a power of ``step``
       (``schedule="exponential"``: 1, N, N², ...) or 1 or a multiple of
       ``step`` (``"linear"``).
    3. With ``randomize`` a candidate is kept with probability
       ``clip(1/d, *probability_range)``, seeded by (``seed``, voxel): the
       output does not depend on the thread count.
    4. Points at voxel centres, in voxel order, with their labels.

    Parameters
    ----------
    image : array_like of int, shape (ny, nx) or (nz, ny, nx), or a path
        A label image (C order, x fastest; labels < 0 are background), or a
        file :func:`read_image` reads.
    spacing, origin : float or sequence of float, optional
        Voxel size and position of voxel (0, 0[, 0]), x, y[, z] order (default
        1 and 0; for a file they override its own).
    select : int or sequence of int, optional
        The labels to sample around (each must occur); default every label >= 0.
    schedule : {'exponential', 'linear'}
        Which distances are candidates (step 2 above).
    step : int
        The schedule's base N: at least 2 for ``exponential``, 1 for
        ``linear`` (every voxel).
    randomize : bool
        Keep each candidate with probability ``clip(1/d, *probability_range)``
        (step 3); False keeps every candidate.
    probability_range : (lo, hi)
        Bounds of that probability, 0 <= lo <= hi <= 1.
    seed : int
        Seeds the random choice, per voxel.
    output : {'all', 'labelled', 'background'}
        Points of selected voxels, of the others, or both.
    background_label : int, optional
        Label (< 0) for the points of unselected voxels; default: their own.
    joggle : float
        Random offset radius as a fraction of the smallest spacing (at most
        0.5: points stay in their voxel); 0 = exact voxel centres.
    threads : int, optional
        Worker threads (None: all cores); the output is the same for any.

    Returns
    -------
    (points, labels) : float64 (M, D) and int32 (M,)
    """
    im = _label_image(image, spacing, origin)
    sel = [] if select is None else _inputs.as_label_list(select, "select")
    if select is not None and not sel:
        raise ValueError("select: empty selection (None selects every label >= 0)")
    sched = _inputs.as_choice(schedule, "schedule", _SCHEDULES)
    out = _inputs.as_choice(output, "output", _OUTPUTS)
    st = _inputs.as_int(step, "step", 1, 2**31 - 1, "an integer >= 2 (exponential) or >= 1 (linear)")
    try:
        pr = [float(x) for x in _inputs.numbers_array(probability_range).ravel()]
    except (TypeError, ValueError):
        pr = []
    if len(pr) != 2 or not (0 <= pr[0] <= pr[1] <= 1):
        raise ValueError(f"probability_range: expected (lo, hi) with 0 <= lo <= hi <= 1, got {probability_range!r}")
    bg = None if background_label is None else _inputs.as_label_value(background_label, "background_label",
                                                                       negative=True)
    jog = _inputs.as_float(joggle, "joggle", "a number in [0, 0.5]")
    if not (np.isfinite(jog) and jog >= 0):
        raise ValueError(f"joggle: expected a number in [0, 0.5], got {joggle!r}")
    pts, lab = _inputs.call(_core.sample_image, im, sel, sched, st, _inputs.as_flag(randomize, "randomize"), pr,
                            _inputs.as_seed(seed), out,
                            bg, jog, _inputs.as_threads(threads))
    return pts, lab


# -------------------------------------------------------------------- joggle

_JOGGLE_MODES = ("ball", "xy", "xz", "yz")


def joggle(
    points: Any,
    radius: float = 1e-4,
    absolute: bool = False,
    mode: str = "ball",
    mask: Any = None,
    seed: int = 0,
    threads: Optional[int] = None,
    keep_non_finite: bool = False,
) -> np.ndarray:
    """A joggled copy of the points: a small deterministic random displacement
    that breaks the exact ties of lattice-like input (tessera needs none for
    correctness; this is for users who want general-position output).

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
    radius : float
        Largest displacement, as a fraction of the bounding-box diagonal, or a
        distance with ``absolute=True``.
    absolute : bool
        ``radius`` is a distance, not a fraction of the diagonal.
    mode : {'ball', 'xy', 'xz', 'yz'}
        Uniform in the ball (disk in 2D), or in a disk in a coordinate plane (3D only).
    mask : array_like of bool, shape (N,), optional
        Only these points move; the others are copied bit for bit.
    seed : int
        Each point's displacement depends only on (seed, point id): the same
        for any thread count and any mask.
    threads : int, optional
        Worker threads (None: all cores).
    keep_non_finite : bool
        Points with a NaN or infinite coordinate (an organized cloud's missing
        returns) are copied through unmoved instead of refused, so ids stay;
        the relative radius then measures the finite points' box.
        ``voronoi(..., ignore_outside=True)`` sets such points aside.

    Returns
    -------
    float64 (N, D), a new array.
    """
    pts = _inputs.as_points(points)
    r = _inputs.as_float(radius, "radius", "a finite number >= 0")
    if not (np.isfinite(r) and r >= 0):
        raise ValueError(f"radius: expected a finite number >= 0, got {radius!r}")
    m = _inputs.as_choice(mode, "mode", _JOGGLE_MODES)
    if m != "ball" and pts.shape[1] == 2:
        raise ValueError(f"mode: {m!r} needs 3D points; 2D points joggle in their plane (mode='ball')")
    mk = _inputs.as_mask(mask, pts.shape[0])
    return _inputs.call(_core.joggle, pts, r, _inputs.as_flag(absolute, "absolute"), m, mk, _inputs.as_seed(seed),
                        _inputs.as_threads(threads), _inputs.as_flag(keep_non_finite, "keep_non_finite"))


# ---------------------------------------------------------------------- fill

_STRATEGIES = ("uniform", "adaptive")


def fill(
    points: Any,
    labels: Any = None,
    strategy: str = "uniform",
    background_label: int = -1,
    in_label: int = 0,
    points_per_bin: float = 2.0,
    bounds: Optional[Sequence[float]] = None,
    joggle: float = 0.0,
    seed: int = 0,
    threads: Optional[int] = None,
    keep_non_finite: bool = False,
) -> Tuple[np.ndarray, np.ndarray]:
    """Fill a point cloud's empty space with background points (label < 0),
    so the outside carves concave shapes and the cells' searches stay short.

    The region (``bounds``, else the points' bounding box) is cut into bins of
    about ``points_per_bin`` input points each; ``uniform`` puts one point at
    the centre of every empty bin, ``adaptive`` samples the empty bins densely
    next to the data and sparsely far from it.

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
    labels : array_like of int, shape (N,), optional
        Kept for the input points; without them they get ``in_label``.
    strategy : {'uniform', 'adaptive'}
        One point per empty bin, or dense next to the data and sparse far
        from it.
    background_label : int
        Label of the added points (< 0).
    in_label : int
        Label of the input points when ``labels`` is None.
    points_per_bin : float
        Mean input points per bin: the bins' size.
    bounds : sequence of float, optional
        (x0, x1, y0, y1[, z0, z1]); must contain every point.
    joggle : float
        Offset of the added points as a fraction of the bin edge (at most 0.5).
    seed : int
    threads : int, optional
        Worker threads (None: all cores); the output is the same for any.
    keep_non_finite : bool
        Points with a NaN or infinite coordinate are kept in place with their
        labels instead of refused; they mark no bin and are not held to
        ``bounds``, and the bounding box is the finite points'.

    Returns
    -------
    (points, labels) : float64 (M, D) and int32 (M,)
        The input points first, unchanged, then the added ones.
    """
    pts = _inputs.as_points(points)
    dim = pts.shape[1]
    lab = _inputs.as_labels(labels, pts.shape[0])
    strat = _inputs.as_choice(strategy, "strategy", _STRATEGIES)
    bg = _inputs.as_label_value(background_label, "background_label", negative=True)
    inl = _inputs.as_label_value(in_label, "in_label")
    ppb = _inputs.as_float(points_per_bin, "points_per_bin", "a finite number > 0")
    if not (np.isfinite(ppb) and ppb > 0):
        raise ValueError(f"points_per_bin: expected a finite number > 0, got {points_per_bin!r}")
    jog = _inputs.as_float(joggle, "joggle", "a number in [0, 0.5]")
    if not 0 <= jog <= 0.5:
        raise ValueError(f"joggle: expected a number in [0, 0.5] (a fraction of the bin edge), got {joggle!r}")
    return _inputs.call(_core.fill, pts, lab, strat, bg, inl, ppb, _inputs.as_bounds(bounds, dim), jog,
                        _inputs.as_seed(seed), _inputs.as_threads(threads),
                        _inputs.as_flag(keep_non_finite, "keep_non_finite"))


# ----------------------------------------------------------------- threshold

def threshold(scalars: Any, intervals: Sequence[Tuple[float, float, int]], background_label: int = -1) -> np.ndarray:
    """Labels from a scalar per point by half-open intervals.

    ``intervals`` is a list of ``(lo, hi, label)``: a value ``v`` with
    ``lo <= v < hi`` gets ``label`` (``lo`` may be ``-inf``, ``hi`` ``+inf``);
    values in no interval, and NaN, get ``background_label``. Intervals must
    not overlap. Returns int32 (N,), a new array.
    """
    s = _inputs.as_scalars(scalars)
    try:
        items = list(intervals)
    except TypeError:
        raise ValueError(f"intervals: expected a list of (lo, hi, label), got {intervals!r}") from None
    if not items:
        raise ValueError("intervals: no intervals given")
    clean = []
    for k, iv in enumerate(items):
        try:
            lo, hi, label = iv
        except (TypeError, ValueError):
            raise ValueError(f"intervals[{k}]: expected (lo, hi, label), got {iv!r}") from None
        lo = _inputs.as_float(lo, f"intervals[{k}] lo")
        hi = _inputs.as_float(hi, f"intervals[{k}] hi")
        if np.isnan(lo) or np.isnan(hi) or not lo < hi:
            raise ValueError(f"intervals[{k}]: expected lo < hi, got [{lo}, {hi})")
        clean.append((lo, hi, _inputs.as_label_value(label, f"intervals[{k}] label")))
    bg = _inputs.as_label_value(background_label, "background_label")
    return _inputs.call(_core.threshold, s, clean, bg)


# --------------------------------------------------------------------- probe

def probe(
    image: ImageLike,
    points: Any,
    spacing: Any = None,
    origin: Any = None,
    outside_value: float = float("nan"),
    threads: Optional[int] = None,
    keep_non_finite: bool = False,
) -> Tuple[np.ndarray, np.ndarray]:
    """Sample an image's scalars at points by linear interpolation between
    voxel centres (bilinear in 2D, trilinear in 3D).

    Parameters
    ----------
    image : array_like, shape (ny, nx) or (nz, ny, nx), or a path
        Real values (C order, x fastest), or a file :func:`read_image` reads.
    points : array_like, shape (N, D)
        D must be the image's dimension.
    spacing, origin : as in :func:`sample_image`.
    outside_value : float
        The value at points outside the box of the voxel centres (a point on
        its far face is inside, and so is one within 1e-9 voxel spacings of
        it, plus a few ulps of the image's largest coordinate, which takes
        the face's value).
    threads : int, optional
        Worker threads (None: all cores).
    keep_non_finite : bool
        A point with a NaN coordinate is outside instead of refused (one with
        an infinite coordinate is outside either way).

    Returns
    -------
    (values, valid) : float64 (N,) and bool (N,) (True inside the image box)
    """
    im = _scalar_image(image, spacing, origin)
    pts = _inputs.as_points(points)
    if pts.shape[1] != im.dim:
        raise ValueError(f"points: {pts.shape[1]}D points for a {im.dim}D image (shape {im.shape})")
    ov = _inputs.as_float(outside_value, "outside_value")
    values, valid = _inputs.call(_core.probe, im, pts, ov, _inputs.as_threads(threads),
                                 _inputs.as_flag(keep_non_finite, "keep_non_finite"))
    return values, valid.view(np.bool_)
