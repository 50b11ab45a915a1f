"""tessera.lloyd: one step is the cells' centroids, its arguments as
voronoi's, the history it returns, bad arguments, Ctrl-C, and the same
numbers as the command line's `tessera lloyd` on one input."""

import os
import pathlib
import subprocess
import time

import numpy as np
import pytest

import tessera
from conftest import UNIT_BOX, random_points, sigint_after


def test_one_step_moves_each_point_to_its_centroid():
    for dim in (2, 3):
        pts = random_points(500, dim, seed=dim)
        vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim], merge=False)
        r = tessera.lloyd(pts, 1, bounds=UNIT_BOX[dim])
        assert isinstance(r, tessera.LloydResult)
        assert r.points.dtype == np.float64 and r.points.shape == pts.shape and r.points.flags.writeable
        assert np.array_equal(r.points[vor.generators], vor.centroids)
        assert r.iterations == 1
        assert r.moved.tolist() == [500]
        assert r.domain == UNIT_BOX[dim]
        assert r.spacing == pytest.approx(500 ** (-1 / dim), rel=1e-14)
        step = np.linalg.norm(vor.centroids - pts, axis=1)
        assert r.largest[0] == pytest.approx(step.max(), rel=1e-15)
        assert r.rms[0] == pytest.approx(np.sqrt(np.mean(step ** 2)), rel=1e-13)


def test_default_domain_is_kept_and_outside_points_stay():
    pts = random_points(400, 2, seed=7)
    labels = np.where(np.arange(400) % 8 == 0, -1, 3)
    r = tessera.lloyd(pts, 5, labels=labels)
    first = tessera.voronoi(pts, labels=labels, merge=False).bounds
    assert r.domain == first
    assert np.array_equal(r.points[labels < 0], pts[labels < 0])
    assert not np.any(np.all(r.points[labels >= 0] == pts[labels >= 0], axis=1))
    again = tessera.lloyd(pts, 5, labels=labels, bounds=first)
    assert again.points.tobytes() == r.points.tobytes()
    assert r.moved.tolist() == [350] * 5 and r.largest.shape == (5,) and r.rms.shape == (5,)


def test_periodic_tilt_radii_threads_and_tolerance():
    pts = random_points(1500, 3, seed=8)
    box = UNIT_BOX[3]
    per = tessera.lloyd(pts + [2.0, 0, -1.0], 3, bounds=box, periodic=True, tilt=(0.2, 0.0, 0.1), threads=1)
    two = tessera.lloyd(pts + [2.0, 0, -1.0], 3, bounds=box, periodic="xyz", tilt=(0.2, 0.0, 0.1), threads=2)
    assert per.points.tobytes() == two.points.tobytes()
    assert np.all(per.points[:, 2] >= 0) and np.all(per.points[:, 2] < 1)  # z: along c alone
    walls = tessera.lloyd(pts, 2, bounds=box, periodic="xy")
    assert np.all((walls.points >= 0) & (walls.points <= 1))
    radii = np.random.default_rng(2).random(1500) * 0.05
    pw = tessera.lloyd(pts, 2, bounds=box, radii=radii)
    ordinary = tessera.lloyd(pts, 2, bounds=box)
    assert not np.array_equal(pw.points, ordinary.points)
    assert tessera.lloyd(pts, 2, bounds=box, radii=np.full(1500, 0.02)).points.tobytes() == ordinary.points.tobytes()
    stop = tessera.lloyd(pts[:300], 1000, tolerance=0.02, bounds=box)
    assert 1 < stop.iterations < 1000 and len(stop.largest) == stop.iterations
    assert stop.largest[-1] <= 0.02 * stop.spacing < stop.largest[-2]
    none = tessera.lloyd(pts, 0)
    assert none.points.tobytes() == pts.tobytes() and none.points is not pts
    assert none.iterations == 0 and none.domain is None and none.spacing == 0.0 and len(none.largest) == 0


P = random_points(50, 3, seed=1)

BAD = {
    "iterations negative": (lambda: tessera.lloyd(P, -1), r"iterations: expected an integer >= 0"),
    "iterations float": (lambda: tessera.lloyd(P, 1.5), r"iterations: expected an integer >= 0"),
    "iterations bool": (lambda: tessera.lloyd(P, True), r"iterations: expected an integer >= 0"),
    "tolerance negative": (lambda: tessera.lloyd(P, tolerance=-1), r"tolerance: expected a finite number >= 0"),
    "tolerance nan": (lambda: tessera.lloyd(P, tolerance=float("nan")), r"tolerance: expected a finite number"),
    "tolerance text": (lambda: tessera.lloyd(P, tolerance="0.1"), r"tolerance: expected a finite number"),
    "method": (lambda: tessera.lloyd(P, method="fast"), r"method: expected one of 'auto', 'search', 'insertion'"),
    "labels": (lambda: tessera.lloyd(P, labels=np.zeros(3, int)), r"labels: expected one label per point"),
    "radii": (lambda: tessera.lloyd(P, radii=np.ones(3)), r"radii: expected one radius per point"),
    "negative radius": (lambda: tessera.lloyd(P, radii=-np.ones(50)), r"radius"),
    "bounds": (lambda: tessera.lloyd(P, bounds=(0, 1)), r"bounds: expected 6 numbers"),
    "outside bounds": (lambda: tessera.lloyd(P + 2, bounds=UNIT_BOX[3]), r"outside the bounds"),
    "periodic without bounds": (lambda: tessera.lloyd(P, periodic=True), r"periodic: give bounds"),
    "shape": (lambda: tessera.lloyd(np.zeros((4, 5))), r"points: expected shape \(N, 2\) or \(N, 3\)"),
    "threads": (lambda: tessera.lloyd(P, threads=0), r"threads: expected a positive integer"),
    "NaN": (lambda: tessera.lloyd(np.where(P == P[4, 2], np.nan, P)), r"point 4 has a NaN"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_arguments(name):
    call, pattern = BAD[name]
    with pytest.raises(ValueError, match=pattern):
        call()


def test_ctrl_c_stops_between_and_inside_iterations():
    pts = random_points(200_000, 3, seed=3)  # ~1 s an iteration on one thread: 40 of them

    class Interrupted(Exception):
        pass

    def handler(signum, frame):
        raise Interrupted()

    with sigint_after(0.3, handler):
        t0 = time.perf_counter()
        with pytest.raises(Interrupted):
            tessera.lloyd(pts, 40, threads=1)
        elapsed = time.perf_counter() - t0
    assert elapsed < 5.0  # stopped soon after the signal, not at the end
    assert tessera.lloyd(pts[:100], 1).iterations == 1  # usable afterwards


def _cli():
    """The `tessera` command of the build tree this module was built in
    (build/python/tessera -> build/tessera), or None (an installed module)."""
    exe = pathlib.Path(tessera.__file__).resolve().parents[2] / "tessera"
    return str(exe) if exe.is_file() and os.access(exe, os.X_OK) else None


@pytest.mark.skipif(_cli() is None, reason="no tessera command beside the module (not a build tree)")
def test_same_numbers_as_the_command_line(tmp_path):
    pts = random_points(800, 3, seed=9)
    labels = np.where(np.arange(800) % 5 == 0, -1, 0).astype(np.int32)  # every fifth outside
    np.save(tmp_path / "p.npy", pts)
    np.save(tmp_path / "l.npy", labels)
    env = dict(os.environ)
    env.pop("TESSERA_NUM_THREADS", None)
    out = subprocess.run([_cli(), "lloyd", str(tmp_path / "p.npy"), "--labels", str(tmp_path / "l.npy"),
                          "--iterations", "7", "--periodic", "xz", "--bounds", "0", "1", "0", "1", "0", "1",
                          "-o", str(tmp_path / "r.npy")], capture_output=True, text=True, env=env)
    assert out.returncode == 0, out.stderr
    r = tessera.lloyd(pts, 7, labels=labels, bounds=UNIT_BOX[3], periodic="xz")
    assert np.load(tmp_path / "r.npy").tobytes() == r.points.tobytes()
    assert np.array_equal(np.load(tmp_path / "r_labels.npy"), labels)
    assert "iterations         7 of 7" in out.stdout
    assert f"largest {r.largest[-1]:.3g} ({r.largest[-1] / r.spacing:.3g} of the spacing)" in out.stdout
