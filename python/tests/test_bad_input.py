"""Every kind of bad input raises ValueError with a message that names the problem."""

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
    "outside bounds": (dict(points=P2 + 2, bounds=(0, 1, 0, 1)), r"lies outside the bounds \(use ignore_outside=True"),
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
