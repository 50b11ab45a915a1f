"""Every kind of bad input raises ValueError with a message that names the problem."""

import os

import numpy as np
import pytest

import tessera
from conftest import random_points

P3 = random_points(50, 3)
P2 = random_points(50, 2)


def with_nan(p, value=np.nan):
    p = p.copy()
    p[7, 1] = value
    return p


# (keyword arguments, regular expression the message must match)
CASES = {
    "4 columns": (dict(points=np.zeros((5, 4))), r"points: expected shape \(N, 2\) or \(N, 3\), got \(5, 4\)"),
    "1-D single point": (dict(points=[0.0, 1.0, 2.0]), r"a single point is points=\[\[\.\.\.\]\]"),
    "3-D array": (dict(points=np.zeros((4, 3, 2))), r"expected shape \(N, 2\) or \(N, 3\), got \(4, 3, 2\)"),
    "transposed": (dict(points=P3.T), r"transposed\? use points\.T"),
    "no points": (dict(points=np.zeros((0, 3))), r"points: no points"),
    "complex": (dict(points=P3.astype(complex)), r"points: expected real numbers .* got dtype complex128"),
    "strings": (dict(points=[["a", "b"], ["c", "d"]]), r"points: expected real numbers"),
    "bool": (dict(points=P3 > 0.5), r"points: expected real numbers .* got dtype bool"),
    "ragged": (dict(points=[[0.0, 1.0], [2.0]]), r"points: cannot be read"),
    "NaN": (dict(points=with_nan(P3)), r"point 7 has a NaN or infinite coordinate"),
    "inf": (dict(points=with_nan(P2, np.inf)), r"point 7 has a NaN or infinite coordinate"),
    "single point": (dict(points=[[0.5, 0.5, 0.5]]), r"single point has no extent.*bounds="),
    "flat 3D": (dict(points=np.column_stack([P2, np.zeros(50)])),
                r"same z coordinate.*zero extent; for planar input use \(N, 2\) points, or give bounds="),
    "labels length": (dict(points=P3, labels=np.zeros(49, int)), r"labels: expected one label per point, shape \(50,\), got \(49,\)"),
    "labels 2-D": (dict(points=P3, labels=np.zeros((50, 1), int)), r"labels: expected one label per point"),
    "labels float": (dict(points=P3, labels=np.zeros(50)), r"labels: expected integers .* float64; convert with labels\.astype\(int\)"),
    "labels big": (dict(points=P3, labels=np.full(50, 2**40)), r"labels: values must fit in 32 bits"),
    "labels all outside": (dict(points=P3, labels=np.full(50, -1)), r"every point is outside"),
    "bounds length": (dict(points=P3, bounds=(0, 1, 0, 1)), r"bounds: expected 6 numbers \(x0, x1, y0, y1, z0, z1\) for 3D points"),
    "bounds text": (dict(points=P2, bounds="0 1 0 1"), r"bounds: expected 4 numbers"),
    "bounds empty": (dict(points=P2, bounds=(1, 0, 0, 1)), r"bounds: x range \[1, 0\] is empty"),
    "bounds NaN": (dict(points=P2, bounds=(0, 1, 0, np.nan)), r"bounds: y range .* not finite"),
    "outside bounds": (dict(points=P2 + 2, bounds=(0, 1, 0, 1)), r"lies outside the bounds: x = 2\.\d+ is not in \[0, 1\] \(use ignore_outside=True"),
    "threads 0": (dict(points=P2, threads=0), r"threads: expected a positive integer or None, got 0"),
    "threads float": (dict(points=P2, threads=1.5), r"threads: expected a positive integer or None, got 1\.5"),
    "threads text": (dict(points=P2, threads="2"), r"threads: expected a positive integer"),
    "padding negative": (dict(points=P2, padding=-0.1), r"padding must be a finite number >= 0"),
    "padding text": (dict(points=P2, padding="wide"), r"padding: expected a number >= 0"),
    # Beyond a C int: pybind11 raised a TypeError listing the whole signature.
    "threads huge": (dict(points=P2, threads=10**12), r"threads: at most 2147483647, got 1000000000000"),
    # The front end names its command-line flag; Python says the keyword.
    "padding overflow": (dict(points=P2, padding=1e308), r"overflows double \(padding 1e\+308 of the points' extent\); give a smaller padding=, or bounds="),
}


@pytest.mark.parametrize("func", [tessera.voronoi, tessera.delaunay])
@pytest.mark.parametrize("case", list(CASES))
def test_bad_input_raises_value_error(func, case):
    kwargs, message = CASES[case]
    with pytest.raises(ValueError, match=message):
        func(**kwargs)


def test_library_checks_raise_input_error_a_value_error():
    assert issubclass(tessera.InputError, ValueError)
    with pytest.raises(tessera.InputError, match="NaN"):
        tessera.voronoi(with_nan(P3))


def test_errors_quoting_bad_bytes_keep_their_message(tmp_path):
    # A header with a byte that is not UTF-8: the message (which quotes it)
    # was empty in Python; now the byte shows as '?'.
    np.save(tmp_path / "a.npy", np.zeros((2, 3)))
    raw = bytearray((tmp_path / "a.npy").read_bytes())
    raw[raw.index(b"fortran_order") + 2] = 0xFF
    (tmp_path / "b.npy").write_bytes(bytes(raw))
    for call in (tessera.read_image, tessera.read_points):
        with pytest.raises(tessera.InputError, match=r"unexpected key 'fo\?tran_order'"):
            call(tmp_path / "b.npy")


def test_arguments_found_by_a_fuzz_of_the_module(tmp_path):
    p = np.random.default_rng(1).random((30, 3))
    # periodic: strings are not flags (["False"] * 3 made every axis
    # periodic), a bare number is neither; tilt and bounds name themselves.
    box = (0, 1, 0, 1, 0, 1)
    for bad in (["False"] * 3, [1, 0, 1], 0, 1.0, [None, True, True]):
        with pytest.raises(ValueError, match="periodic: expected"):
            tessera.voronoi(p, bounds=box, periodic=bad)
    for bad in (0.3, "abc", (None, 0, 0), (1j, 0, 0)):
        with pytest.raises(ValueError, match="tilt: expected"):
            tessera.voronoi(p, bounds=box, periodic=True, tilt=bad)
    with pytest.raises(ValueError, match="bounds: expected"):
        tessera.voronoi(p, bounds=(0, 10**400, 0, 1, 0, 1))
    assert tessera.voronoi(p, bounds=box, periodic=[True, np.True_, False]).periodic == (True, True, False)
    # Indices: negative ones count from the end, past either end an
    # IndexError naming the argument (slices gave [] or another cell's).
    vor = tessera.voronoi(p)
    n = vor.n_cells
    assert np.array_equal(vor.cell_neighbors(-1), vor.cell_neighbors(n - 1))
    assert len(vor.cell_faces(-n)) == len(vor.cell_faces(0))
    for bad in (n, -n - 1):
        with pytest.raises(IndexError, match="c: index"):
            vor.cell_neighbors(bad)
    with pytest.raises(TypeError, match="c: expected an integer"):
        vor.cell_faces(1.0)
    g = tessera.adjacency(vor)
    assert np.array_equal(g.wheel(-1), g.wheel(len(p) - 1))
    with pytest.raises(IndexError, match="i: index 30"):
        g.wheel(30)
    # A path with a NUL byte: refused, not cut at the NUL (the cells were
    # written to another file); a bytes path is a path.
    with pytest.raises(ValueError, match="embedded null byte"):
        vor.save(str(tmp_path / "a\0.vtu"))
    assert not (tmp_path / "a").exists()
    vor.save(os.fsencode(tmp_path / "b.vtu"))
    assert (tmp_path / "b.vtu").exists()
    with pytest.raises(ValueError, match="embedded null byte"):
        tessera.read_points(str(tmp_path / "b.vtu") + "\0.npy")


def test_flags_and_numbers_are_not_taken_by_truthiness(tmp_path):
    # Yes/no arguments take bools (numpy's too) and 0/1; an array raised
    # numpy's "truth value ... is ambiguous", naming no argument, and a
    # string such as "False" was true. Numbers are not strings or bools.
    p = np.random.default_rng(2).random((40, 3))
    lab = np.arange(40) % 2
    for call, name in ((lambda v: tessera.voronoi(p, merge=v), "merge"),
                       (lambda v: tessera.voronoi(p, ignore_outside=v), "ignore_outside"),
                       (lambda v: tessera.delaunay(p, complete_hull=v), "complete_hull"),
                       (lambda v: tessera.faces(p, labels=lab, kind="surface-net", capping=v), "capping"),
                       (lambda v: tessera.surface_nets(p, lab, constraint_is_absolute=v), "constraint_is_absolute"),
                       (lambda v: tessera.surface_nets(p, lab, triangles=v), "triangles"),
                       (lambda v: tessera.joggle(p, keep_non_finite=v), "keep_non_finite")):
        for bad in (np.array([True, False]), "False", 2, None, 0.0):
            with pytest.raises(ValueError, match=name + ": expected True or False"):
                call(bad)
        for good in (True, np.False_, 1, np.int64(0)):
            call(good)
    with pytest.raises(ValueError, match="padding: expected a number >= 0, got True"):
        tessera.voronoi(p, padding=True)
    with pytest.raises(ValueError, match="padding: expected a number >= 0, got '0.1'"):
        tessera.voronoi(p, padding="0.1")
    with pytest.raises(ValueError, match="prune_tolerance: expected a finite number >= 0, got '0.1'"):
        tessera.adjacency(p, prune_tolerance="0.1")
    assert tessera.voronoi(p, padding=np.float32(0.5)).n_cells == 40
    # The same for numbers in sequences, numpy's bools in periodic and
    # threads, 0-d arrays as flags (as an .npz gives them), and dim.
    for bad, name in (({"bounds": ("0", "1") * 3}, "bounds"), ({"bounds": (False, True) * 3}, "bounds"),
                      ({"bounds": (0, 1, 0, 1, 0, 1), "periodic": True, "tilt": ("0.1", "0", "0")}, "tilt"),
                      ({"bounds": (0, 1, 0, 1, 0, 1), "periodic": True, "tilt": (1j, 0, 0)}, "tilt"),
                      ({"threads": np.True_}, "threads")):
        with pytest.raises(ValueError, match=name + ": expected"):
            tessera.voronoi(p, **bad)
    box = (0, 1, 0, 1, 0, 1)
    assert tessera.voronoi(p, bounds=box, periodic=np.True_).periodic == (True, True, True)
    assert tessera.voronoi(p, bounds=box, periodic=np.False_).periodic == (False, False, False)
    assert tessera.voronoi(p, merge=np.array(False)).has_mesh is False
    vor = tessera.voronoi(p)
    with pytest.raises(ValueError, match="ignore_outside: expected True or False"):
        tessera.adjacency(vor, ignore_outside=np.array([True, False]))
    tessera.adjacency(vor, periodic=np.False_)
    np.save(tmp_path / "p.npy", p)
    for bad in (2.0, True, "2"):
        with pytest.raises(ValueError, match="dim: expected 2, 3 or None"):
            tessera.read_points(tmp_path / "p.npy", dim=bad)
    assert tessera.read_points(tmp_path / "p.npy", dim=np.int64(2))[0].shape == (40, 2)


def test_validate_after_the_arrays_changed():
    # The points and radii are kept without a copy: changed to NaN or inf
    # after the cells, validate raised SIGFPE in GMP (the process died).
    p = np.random.default_rng(1).random((30, 3))
    r = np.linspace(0, 0.1, 30)
    vor = tessera.voronoi(p, radii=r)
    assert vor.validate()
    r[5] = np.nan
    with pytest.raises(tessera.InputError, match="radius of point 5"):
        vor.validate()
    q = p.copy()
    vor = tessera.voronoi(q)
    q[3] = np.inf
    with pytest.raises(tessera.InputError, match="point 3 has a non-finite coordinate"):
        vor.validate()


def test_radii_with_points_set_aside():
    # A point set aside (NaN, or far outside the bounds) made radii refuse
    # the input for its magnitude ("need coordinates within ~1e-150..1e150").
    p = np.random.default_rng(1).random((30, 3))
    r = np.linspace(0, 0.1, 30)
    for bad in (np.nan, 1e200):
        q = p.copy()
        q[1] = bad
        vor = tessera.voronoi(q, radii=r, bounds=(0, 1, 0, 1, 0, 1), ignore_outside=True)
        assert vor.n_cells == 29 and list(vor.ignored_outside_bounds) == [1] and vor.validate()
        dt = tessera.delaunay(q, radii=r, bounds=(0, 1, 0, 1, 0, 1), ignore_outside=True)
        assert dt.validate()
