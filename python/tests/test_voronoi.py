"""tessera.voronoi: what the result holds and how its parts fit together."""

import math
import re
from pathlib import Path

import numpy as np
import pytest

import tessera
from conftest import UNIT_BOX, random_points


def box_volume(bounds):
    return math.prod(hi - lo for lo, hi in zip(bounds[0::2], bounds[1::2]))


@pytest.mark.parametrize("dim", [2, 3])
def test_volumes_sum_to_the_given_box(dim):
    vor = tessera.voronoi(random_points(5000, dim), bounds=UNIT_BOX[dim])
    assert vor.bounds == UNIT_BOX[dim]
    assert vor.n_cells == 5000
    assert vor.volumes.sum() == pytest.approx(1.0, rel=1e-12)
    assert (vor.volumes > 0).all()


@pytest.mark.parametrize("dim", [2, 3])
def test_volumes_sum_to_the_padded_default_box(dim):
    pts = random_points(3000, dim) * 10 - 3
    vor = tessera.voronoi(pts, padding=0.05)
    b = vor.bounds
    assert len(b) == 2 * dim
    for d in range(dim):  # at least the requested margin on every side
        assert b[2 * d] <= pts[:, d].min() - 0.05 * 10 * 0.999
        assert b[2 * d + 1] >= pts[:, d].max() + 0.05 * 10 * 0.999
    assert vor.volumes.sum() == pytest.approx(box_volume(b), rel=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_far_outliers_are_counted_and_cells_stay_whole(dim):
    pts = random_points(3000, dim)
    assert tessera.voronoi(pts, merge=False).far_points == 0
    far = np.zeros((2, dim))
    far[0, 0], far[1, -1] = 1e4, -1e6  # stretch the default box to ~1e6 the bulk
    vor = tessera.voronoi(np.vstack([pts, far + 0.5]), merge=False)
    assert vor.far_points == 2
    assert vor.n_cells == 3002
    assert vor.volumes.sum() == pytest.approx(box_volume(vor.bounds), rel=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_validate_passes_and_is_truthy(dim):
    report = tessera.voronoi(random_points(2000, dim)).validate()
    assert report.ok and bool(report), report.messages
    assert report.volume_rel_error < 1e-12
    assert "ok=True" in repr(report)
    # a sample of cells measured exactly (the smallest, the longest, a spread)
    assert report.measures_checked >= 64
    assert report.measure_rel_error < 1e-13 and report.measure_worst >= 0
    assert report.vertex_rel_error < 1e-12 and report.vertex_worst >= 0


def test_validate_cells_checks_measures_only_with_the_points():
    pts = random_points(300, 3)
    vor = tessera.voronoi(pts)
    without = tessera._core.validate_cells(vor._cells, None)
    assert without.ok and without.measures_checked == 0
    with pytest.raises(ValueError, match="points are not the ones"):
        tessera._core.validate_cells(vor._cells, None, pts[:-1])


def test_shapes_dtypes_and_csr_consistency():
    pts = random_points(500, 3)
    vor = tessera.voronoi(pts)
    n, nv = vor.n_cells, vor.n_vertices
    assert vor.ndim == 3 and vor.has_mesh
    assert vor.centroids.shape == (n, 3) and vor.centroids.dtype == np.float64
    assert vor.volumes.shape == (n,) and vor.regions.shape == (n,) and vor.num_faces.shape == (n,)
    assert vor.generators.dtype == np.int32 and vor.cell_of.shape == (500,)
    assert vor.vertices.shape == (nv, 3) and vor.vertex_keys.shape == (nv, 4)
    # CSR: offsets start at 0, end at the data length, never decrease.
    for off, data in [(vor.neighbor_offsets, vor.neighbors),
                      (vor.cell_face_offsets, vor.face_neighbor),
                      (vor.face_vertex_offsets, vor.face_vertices)]:
        assert off.dtype == np.int64 and off[0] == 0 and off[-1] == len(data)
        assert (np.diff(off) >= 0).all()
    assert len(vor.cell_face_offsets) == n + 1 and len(vor.neighbor_offsets) == n + 1
    assert (np.diff(vor.cell_face_offsets) == vor.num_faces).all()
    assert vor.face_vertices.min() >= 0 and vor.face_vertices.max() < nv
    # cell_of and generators are inverse maps.
    assert (vor.cell_of[vor.generators] == np.arange(n)).all()
    # Neighbours: ascending per cell, the non-box faces' neighbours.
    for c in (0, 17, n - 1):
        nb = vor.cell_neighbors(c)
        assert (np.diff(nb) > 0).all()
        fn = vor.face_neighbor[vor.cell_face_offsets[c]:vor.cell_face_offsets[c + 1]]
        assert sorted(fn[fn >= 0]) == list(nb)
        assert len(vor.cell_faces(c)) == vor.num_faces[c]
    # Every vertex of a cell has the cell's generator in its topological coordinate.
    c = 42
    verts = np.unique(np.concatenate(vor.cell_faces(c)))
    assert (vor.vertex_keys[verts] == vor.generators[c]).any(axis=1).all()
    # Centroids lie in the box.
    lo, hi = np.array(vor.bounds[0::2]), np.array(vor.bounds[1::2])
    assert ((vor.centroids > lo) & (vor.centroids < hi)).all()


def test_box_faces_have_negative_plane_ids_and_domain_class():
    vor = tessera.voronoi(random_points(300, 3), bounds=UNIT_BOX[3])
    box = vor.face_neighbor < 0
    assert set(np.unique(vor.face_neighbor[box])) == {-1, -2, -3, -4, -5, -6}
    assert (vor.face_class[box] == tessera.DOMAIN_BOUNDARY).all()
    assert (vor.face_class[~box] == tessera.SAME_REGION).all()


def test_labels_regions_and_outside_points():
    pts = random_points(4000, 2, seed=3)
    labels = (pts[:, 0] > 0.5).astype(np.int64)  # regions 0 and 1
    hole = np.linalg.norm(pts - 0.5, axis=1) < 0.2
    labels[hole] = -1  # outside points carve a hole
    vor = tessera.voronoi(pts, labels=labels, bounds=UNIT_BOX[2])
    assert vor.n_cells == int((~hole).sum())
    assert (vor.cell_of[hole] == -1).all()
    assert (vor.regions == labels[vor.generators]).all()
    assert vor.labels.dtype == np.int32 and (vor.labels == labels).all()
    # The cells leave out (about) the hole's area.
    assert 1 - vor.volumes.sum() == pytest.approx(math.pi * 0.2**2, rel=0.1)
    classes = set(np.unique(vor.face_class).tolist())
    assert {tessera.SAME_REGION, tessera.REGION_BOUNDARY, tessera.OUTSIDE, tessera.DOMAIN_BOUNDARY} == classes
    assert vor.validate().ok


def test_merge_false_has_measures_but_no_mesh():
    pts = random_points(1000, 3)
    full = tessera.voronoi(pts)
    lean = tessera.voronoi(pts, merge=False)
    assert not lean.has_mesh and lean.n_vertices == 0
    assert np.array_equal(full.volumes, lean.volumes)
    assert np.array_equal(full.neighbors, lean.neighbors)
    for attr in ("vertices", "face_vertices", "cell_face_offsets"):
        with pytest.raises(ValueError, match="merge=False"):
            getattr(lean, attr)
    with pytest.raises(ValueError, match="merge=True"):
        lean.scipy
    assert "no mesh" in repr(lean)


def test_duplicates_are_reported_and_own_no_cell():
    pts = random_points(200, 3)
    pts = np.vstack([pts, pts[[5, 7]]])  # ids 200, 201 duplicate 5, 7
    vor = tessera.voronoi(pts)
    assert vor.duplicates.tolist() == [[200, 5], [201, 7]]
    assert vor.cell_of[200] == -1 and vor.cell_of[201] == -1
    assert vor.n_cells == 200


def test_method_insertion_gives_the_searched_cells():
    # Points nearly on one sphere: searched, every cell tests every point at
    # the centre; "auto" builds them from the Delaunay triangulation instead.
    v = np.random.default_rng(4).normal(size=(600, 3))
    v /= np.linalg.norm(v, axis=1)[:, None]
    searched = tessera.voronoi(v, method="search")
    auto = tessera.voronoi(v)
    assert not searched.from_insertion and auto.from_insertion
    assert np.array_equal(searched.neighbors, auto.neighbors)
    assert np.array_equal(searched.neighbor_offsets, auto.neighbor_offsets)
    np.testing.assert_allclose(searched.volumes, auto.volumes, rtol=1e-12)
    assert auto.validate()
    small = tessera.voronoi(random_points(500, 3))
    assert not small.from_insertion
    # The pilot built up to half of these cells; they are kept, not built
    # again, and the result is the search's.
    assert 0 < small.cells_from_pilot < 500
    assert auto.cells_from_pilot == 0 and searched.cells_from_pilot == 0
    again = tessera.voronoi(random_points(500, 3), method="search")
    assert np.array_equal(small.volumes, again.volumes)
    assert np.array_equal(small.neighbors, again.neighbors)
    # Points on a sphere are all on the hull: their cells are assembled from
    # open stars, closed by a far plane that the box cuts away. So are
    # uniform points' cells, inside the hull and on it.
    assert auto.assembled_from_stars == 600
    p = random_points(500, 3)
    ins = tessera.voronoi(p, method="insertion")
    assert 490 < ins.assembled_from_stars <= 500
    assert np.array_equal(ins.neighbors, tessera.voronoi(p, method="search").neighbors)
    # 2D: points on a circle, whose searched cells each test every point.
    t = np.random.default_rng(5).random(1500) * 2 * np.pi
    c = np.c_[np.cos(t), np.sin(t)]
    searched2, auto2 = tessera.voronoi(c, method="search"), tessera.voronoi(c)
    assert not searched2.from_insertion and auto2.from_insertion
    assert np.array_equal(searched2.neighbors, auto2.neighbors)
    assert np.array_equal(searched2.neighbor_offsets, auto2.neighbor_offsets)
    np.testing.assert_allclose(searched2.volumes, auto2.volumes, rtol=1e-12)
    assert not tessera.voronoi(random_points(500, 2)).from_insertion
    with pytest.raises(ValueError, match="method must be 'auto', 'search' or 'insertion'"):
        tessera.voronoi(v, method="cells")


def test_ignore_outside_drops_points_outside_the_bounds():
    pts = random_points(300, 2) * 2  # in [0, 2)^2
    with pytest.raises(ValueError, match=r"outside the bounds: [xy] = 1\.\d+ is not in \[0, 1\] \(use ignore_outside=True"):
        tessera.voronoi(pts, bounds=UNIT_BOX[2])
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[2], ignore_outside=True)
    outside = np.flatnonzero((pts > 1).any(axis=1))
    assert vor.ignored_outside_bounds.tolist() == outside.tolist()
    assert vor.volumes.sum() == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("convert", [
    lambda p: p.astype(np.float32),
    lambda p: p.tolist(),
    lambda p: np.asfortranarray(p),
    lambda p: (p * 1000).astype(np.int64),
])
def test_accepts_array_likes(convert):
    pts = random_points(400, 3)
    given = convert(pts)
    vor = tessera.voronoi(given)
    expected = np.asarray(given, dtype=np.float64)
    assert vor.points.dtype == np.float64 and vor.points.flags.c_contiguous
    assert np.array_equal(vor.points, expected)
    assert vor.volumes.sum() == pytest.approx(box_volume(vor.bounds), rel=1e-12)


def test_2d_faces_are_edges_walking_the_polygon_counter_clockwise():
    vor = tessera.voronoi(random_points(300, 2))
    fvo, fv, cfo = vor.face_vertex_offsets, vor.face_vertices, vor.cell_face_offsets
    assert (np.diff(fvo) == 2).all()
    edges = fv.reshape(-1, 2)
    for c in (0, 100, 299):
        e = edges[cfo[c]:cfo[c + 1]]
        assert (e[:, 1] == np.roll(e[:, 0], -1)).all()  # closed chain
        x, y = vor.vertices[e[:, 0]].T
        area = 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum()
        assert area == pytest.approx(vor.volumes[c], rel=1e-9)  # positive: ccw


def test_version_is_the_cmake_project_version():
    cmake = (Path(__file__).resolve().parents[2] / "CMakeLists.txt").read_text()
    version = re.search(r"project\(tessera\s+VERSION\s+([0-9.]+)", cmake).group(1)
    assert tessera.__version__ == version


def test_repr():
    vor = tessera.voronoi(random_points(10, 2))
    assert repr(vor).startswith("<tessera.Voronoi 2D: 10 points, 10 cells")


def test_periodic_box():
    # A periodic box: the cells tile it, every neighbour entry (i, j, s) has
    # its twin (j, i, -s), and the argument's forms agree.
    pts = random_points(2000, 3, seed=31)
    v = tessera.voronoi(pts, bounds=[0, 1, 0, 1, 0, 1], periodic=True)
    assert v.periodic == (True, True, True) and v.periodic_images > 0
    assert abs(v.volumes.sum() - 1.0) < 1e-12
    shifts = v.neighbor_shifts
    assert shifts.dtype == np.int8 and shifts.shape == (len(v.neighbors), 3)
    off, ids = v.neighbor_offsets, v.neighbors
    seen = {}
    for c in range(v.n_cells):
        g = int(v.generators[c])
        for e in range(off[c], off[c + 1]):
            key = (g, int(ids[e]), tuple(int(x) for x in shifts[e]))
            seen[key] = seen.get(key, 0) + 1
    for (i, j, s), m in seen.items():
        assert seen.get((j, i, tuple(-x for x in s))) == m
    assert v.validate()
    w = tessera.voronoi(pts, bounds=[0, 1, 0, 1, 0, 1], periodic="xyz")
    np.testing.assert_array_equal(w.volumes, v.volumes)
    x = tessera.voronoi(pts, bounds=[0, 1, 0, 1, 0, 1], periodic=[True, False, False])
    assert x.periodic == (True, False, False)
    assert (x.neighbor_shifts[:, 1:] == 0).all()
    plain = tessera.voronoi(pts, bounds=[0, 1, 0, 1, 0, 1])
    assert plain.neighbor_shifts.size == 0 and plain.periodic == (False, False, False)
    with pytest.raises(ValueError, match="periodic"):
        v.scipy
    with pytest.raises(ValueError, match="bounds"):
        tessera.voronoi(pts, periodic=True)
    with pytest.raises(ValueError, match="periodic"):
        tessera.voronoi(pts[:, :2].copy(), bounds=[0, 1, 0, 1], periodic="xz")


def test_triclinic_box_against_scipy():
    # A sheared 2D box: each cell's area equals that of its point's region
    # in scipy's (Qhull's) diagram of the points with their images by the
    # lattice vectors a = (Lx, 0) and b = (xy, Ly), and the neighbour
    # entries (j, s) are the ridges of that diagram.
    from scipy.spatial import Voronoi as ScipyVoronoi

    rng = np.random.default_rng(33)
    lx, ly, xy = 2.0, 1.0, 0.625
    f = rng.random((300, 2)) * (1 - 2e-6) + 1e-6
    pts = np.stack([f[:, 0] * lx + f[:, 1] * xy, f[:, 1] * ly], axis=1)
    pts = np.ldexp(np.floor(np.ldexp(pts, 30)), -30)  # on the box's grid: the library keeps them
    v = tessera.voronoi(pts, bounds=[0, lx, 0, ly], periodic=True, tilt=[xy])
    assert v.tilt == (xy,) and v.periodic == (True, True)
    shifts = [(i, j) for i in (-1, 0, 1) for j in (-1, 0, 1)]
    images = np.concatenate([pts + i * np.array([lx, 0]) + j * np.array([xy, ly]) for i, j in shifts])
    sv = ScipyVoronoi(images)
    zero = shifts.index((0, 0))
    n = len(pts)
    ridges = {}
    for (p, q) in sv.ridge_points:
        for u, w in ((p, q), (q, p)):
            if u // n == zero:
                ridges.setdefault(u % n, set()).add((int(w % n), shifts[w // n]))
    for k in range(n):
        region = sv.regions[sv.point_region[zero * n + k]]
        assert -1 not in region
        poly = sv.vertices[region]
        hull = poly[np.argsort(np.arctan2(*(poly - poly.mean(axis=0)).T[::-1]))]
        x, y = hull[:, 0], hull[:, 1]
        area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
        c = v.cell_of[k]
        assert abs(v.volumes[c] - area) < 1e-9 * area
        off = v.neighbor_offsets
        got = {(int(v.neighbors[e]), tuple(int(s) for s in v.neighbor_shifts[e])) for e in range(off[c], off[c + 1])}
        assert got == ridges[k]
    assert abs(v.volumes.sum() - lx * ly) < 1e-12
    assert v.validate()
    with pytest.raises(ValueError, match="tilt"):
        tessera.voronoi(pts, bounds=[0, lx, 0, ly], tilt=[xy])
    with pytest.raises(ValueError, match="tilt"):
        tessera.voronoi(pts, bounds=[0, lx, 0, ly], periodic=True, tilt=[xy, 0, 0])
    with pytest.raises(ValueError, match="tilt"):
        tessera.voronoi(pts, bounds=[0, lx, 0, ly], periodic="x", tilt=[xy])
