"""tessera.delaunay: the result's own guarantees (comparison with scipy: test_scipy_compat.py)."""

import numpy as np
import pytest

import tessera
from conftest import random_points


def signed_volumes(points, simplices):
    p = points[simplices]
    edges = p[:, 1:] - p[:, :1]
    return np.linalg.det(edges)  # 2D: twice the area; 3D: six times the volume


@pytest.mark.parametrize("dim", [2, 3])
def test_validate_orientation_and_hull(dim):
    pts = random_points(3000, dim, seed=8)
    dt = tessera.delaunay(pts)
    report = dt.validate()
    assert report.ok and bool(report), report.messages
    assert report.simplices == dt.nsimplex
    assert dt.ndim == dim and dt.npoints == 3000
    assert dt.simplices.dtype == np.int32 and dt.simplices.shape == (dt.nsimplex, dim + 1)
    assert (signed_volumes(pts, dt.simplices) > 0).all()  # positively oriented
    assert (dt.simplices[:, 0] == dt.simplices.min(axis=1)).all()  # lowest id first
    assert dt.hull_completed and dt.from_cells + dt.from_hull_completion + dt.from_insertion == dt.nsimplex
    assert set(np.unique(dt.simplices).tolist()) == set(range(3000))  # every point used
    assert 0 < report.volume_tolerance < 1e-6 * report.volume_sum
    assert abs(report.volume_sum - report.enclosed_volume) <= report.volume_tolerance


def test_validate_near_line_volumes_agree_within_tolerance():
    # 3D points within 1e-17 of a line: both volumes are rounding noise (either
    # may be negative); the report says how far they may differ.
    rng = np.random.default_rng(3)
    t = rng.random(1000)
    pts = np.outer(t, [0.3, 0.5, 0.7]) + rng.normal(scale=1e-17, size=(1000, 3))
    report = tessera.delaunay(pts).validate()
    assert report.ok, report.messages
    assert report.volume_tolerance > 0
    assert abs(report.volume_sum - report.enclosed_volume) <= report.volume_tolerance
    assert abs(report.enclosed_volume) <= report.volume_tolerance


def test_neighbors_are_symmetric():
    dt = tessera.delaunay(random_points(1000, 3, seed=1))
    nb = dt.neighbors
    assert nb is not None and nb.shape == dt.simplices.shape
    rows, ks = np.nonzero(nb >= 0)
    for r, k in list(zip(rows.tolist(), ks.tolist()))[:2000]:
        j = nb[r, k]
        assert r in nb[j].tolist()
        # They share the facet opposite vertex k of r.
        facet = set(dt.simplices[r].tolist()) - {int(dt.simplices[r, k])}
        assert facet <= set(dt.simplices[j].tolist())


@pytest.mark.parametrize("labelled", [False, True])
def test_neighbors_and_find_simplex_share_one_adjacency(labelled):
    # The walking locator steps through the simplex adjacency that .neighbors
    # shows: whichever is asked first computes it for both. Either order
    # gives the same arrays and answers; a labelled triangulation's grid
    # locator keeps none, and .neighbors computes its own. (That one array
    # is shared is checked in C++, test_locate.cpp's SharedAdjacency: Python
    # cannot see the locator's.)
    pts = random_points(2000, 3, seed=12)
    labels = np.where(pts[:, 0] < 0.2, -1, 0) if labelled else None
    q = random_points(500, 3, seed=13)
    first_nb = tessera.delaunay(pts, labels=labels)
    nb = first_nb.neighbors
    found = first_nb.find_simplex(q)
    first_find = tessera.delaunay(pts, labels=labels)
    assert (first_find.find_simplex(q) == found).all()
    assert (first_find.neighbors == nb).all()


def test_labels_keep_the_simplices_of_inside_points():
    pts = random_points(2000, 2, seed=9)
    labels = np.where(np.linalg.norm(pts - 0.5, axis=1) < 0.25, -1, 0)
    dt = tessera.delaunay(pts, labels=labels)
    assert not dt.hull_completed  # a region with a hole, not the convex hull
    assert (labels[dt.simplices] >= 0).all()
    assert dt.validate().ok, dt.validate().messages
    # The whole triangulation's inside simplices, in its row order.
    whole = tessera.delaunay(pts)
    inside = (labels[whole.simplices] >= 0).all(axis=1)
    assert np.array_equal(dt.simplices, whole.simplices[inside])
    assert dt.outside_simplices == whole.nsimplex - dt.nsimplex
    assert np.array_equal(tessera.delaunay(pts, labels=labels, method="insertion").simplices, dt.simplices)


def test_duplicates_are_in_no_simplex():
    pts = random_points(300, 3)
    pts = np.vstack([pts, pts[:2]])
    dt = tessera.delaunay(pts)
    assert dt.duplicates.tolist() == [[300, 0], [301, 1]]
    assert not np.isin(dt.simplices, [300, 301]).any()


def test_lattice_gets_a_valid_triangulation():
    g = np.arange(6, dtype=np.float64)
    pts = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    dt = tessera.delaunay(pts)
    assert dt.validate().ok, dt.validate().messages
    assert np.abs(signed_volumes(pts, dt.simplices)).sum() / 6 == pytest.approx(5.0**3)


def test_repr():
    dt = tessera.delaunay(random_points(20, 2))
    assert repr(dt).startswith("<tessera.Delaunay 2D: 20 points,")


def test_insertion_method_gives_the_same_simplices():
    pts = random_points(2000, 3, seed=7)
    cells = tessera.delaunay(pts, method="cells")
    ins = tessera.delaunay(pts, method="insertion")
    assert np.array_equal(cells.simplices, ins.simplices)
    assert ins.from_insertion == ins.nsimplex and cells.from_insertion == 0
    with pytest.raises(ValueError, match="method"):
        tessera.delaunay(pts, method="qhull")
    # 2D: points on a circle (whose cells each reach the centre) and random ones.
    t = np.random.default_rng(3).random(3000) * 2 * np.pi
    for p2 in (np.c_[np.cos(t), np.sin(t)], random_points(3000, 2, seed=1)):
        by_cells = tessera.delaunay(p2, method="cells")
        by_insertion = tessera.delaunay(p2, method="insertion")
        assert np.array_equal(by_cells.simplices, by_insertion.simplices)
        assert by_insertion.from_insertion == by_insertion.nsimplex and by_cells.from_insertion == 0
    with pytest.raises(ValueError, match="whole convex hull: it needs complete_hull=True"):
        tessera.delaunay(random_points(100, 2, seed=1), method="insertion", complete_hull=False)


def test_periodic_triangulation_against_scipy():
    # A sheared 2D box: the simplices, up to a common translation of their
    # vertices' images, are scipy's (Qhull's) triangles of the points with
    # their images by a = (Lx, 0), b = (xy, Ly) that have a vertex at shift 0;
    # each once, counter-clockwise with the shifts applied; a torus has 2N.
    from scipy.spatial import Delaunay as ScipyDelaunay

    rng = np.random.default_rng(44)
    lx, ly, xy = 2.0, 1.0, 0.625
    f = rng.random((400, 2)) * (1 - 2e-6) + 1e-6
    pts = np.ldexp(np.floor(np.ldexp(np.stack([f[:, 0] * lx + f[:, 1] * xy, f[:, 1] * ly], 1), 30)), -30)
    dt = tessera.delaunay(pts, bounds=[0, lx, 0, ly], periodic=True, tilt=[xy])
    assert dt.is_periodic and dt.tilt == (xy,) and dt.nsimplex == 2 * len(pts)
    lattice = np.array([[lx, 0.0], [xy, ly]])
    sh = dt.simplex_shifts
    assert sh.dtype == np.int8 and sh.shape == (dt.nsimplex, 3, 2)
    corners = dt.periodic_points[dt.simplices] + sh @ lattice
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    assert np.all(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] > 0)

    def canonical(entries):
        entries = sorted(entries)
        s0 = entries[0][1]
        return tuple((i, (s[0] - s0[0], s[1] - s0[1])) for i, s in entries)

    ours = {canonical([(int(i), tuple(int(x) for x in s)) for i, s in zip(row, shifts)])
            for row, shifts in zip(dt.simplices, sh)}
    assert len(ours) == dt.nsimplex
    shifts = [(i, j) for i in (-2, -1, 0, 1, 2) for j in (-2, -1, 0, 1, 2)]
    images = np.concatenate([pts + np.array(s) @ lattice for s in shifts])
    n = len(pts)
    theirs = set()
    for row in ScipyDelaunay(images).simplices:
        if any(shifts[v // n] == (0, 0) for v in row):
            c = canonical([(int(v % n), shifts[v // n]) for v in row])
            # Triangles far out in the images are clipped by the hull of the
            # 5 x 5 copies; those meeting shift 0 are whole.
            theirs.add(c)
    assert ours == theirs
    assert dt.validate()
    grid = dt.to_vtk()
    assert grid.GetNumberOfCells() == dt.nsimplex and grid.GetNumberOfPoints() > len(pts)
    # Refused in the words of the attribute used (the library's functions,
    # simplex_neighbors, vertex_neighbors and locate, were named).
    for name, get in (("neighbors", lambda: dt.neighbors), ("convex_hull", lambda: dt.convex_hull),
                      ("vertex_neighbor_vertices", lambda: dt.vertex_neighbor_vertices),
                      ("find_simplex", lambda: dt.find_simplex(pts[:1])), ("transform", lambda: dt.transform),
                      ("polygons", lambda: dt.alpha_shape(0.1).polygons()),
                      ("save", lambda: dt.alpha_shape(0.1).save("a.vtp"))):
        with pytest.raises(tessera.InputError, match="^" + name + ": not available for a periodic triangulation"):
            get()
    assert tessera.delaunay(pts).simplex_shifts.shape == (0, 3, 2)


def test_validate_without_hull_completion():
    # complete_hull=False keeps the simplices whose circumcentre lies in the
    # box: concave, some points in none. validate checks what holds there
    # (orientation, facets, local Delaunay), not the hull (it always failed).
    for dim in (2, 3):
        p = np.random.default_rng(dim).random((300, dim))
        dt = tessera.delaunay(p, complete_hull=False)
        r = dt.validate()
        assert r, list(r.messages)
        assert dt.nsimplex < tessera.delaunay(p).nsimplex


def _circumradii(points, simplices):
    p = points[simplices]
    e = p[:, 1:] - p[:, :1]
    c = np.linalg.solve(e, 0.5 * (e * e).sum(axis=2)[..., None])[..., 0]
    return np.sqrt((c * c).sum(axis=1))


@pytest.mark.parametrize("dim", [2, 3])
def test_alpha_shape(dim):
    pts = random_points(2000, dim, seed=91)
    dt = tessera.delaunay(pts)
    r = _circumradii(pts, dt.simplices)
    np.testing.assert_allclose(np.sqrt(dt.squared_radii()), r, rtol=1e-9)
    alpha = float(np.quantile(r, 0.6))
    a = dt.alpha_shape(alpha)
    assert isinstance(a, tessera.AlphaShape) and a.alpha == alpha
    np.testing.assert_array_equal(a.simplex_ids, np.nonzero(r <= alpha)[0])
    np.testing.assert_array_equal(a.simplices, dt.simplices[a.simplex_ids])
    assert a.volume == pytest.approx(np.abs(signed_volumes(pts, a.simplices)).sum() / (2 if dim == 2 else 6), rel=1e-12)
    # The boundary: facets of one kept simplex, each bounding the simplex named.
    assert a.boundary.shape[1] == dim and len(a.boundary_simplices) == len(a.boundary)
    for f, s in zip(a.boundary[:50], a.boundary_simplices[:50]):
        assert set(f.tolist()) < set(dt.simplices[s].tolist())
        assert s in set(a.simplex_ids.tolist())
    assert a.singular.shape[1] == dim
    assert not a.simplex_ids.flags.writeable
    # inf: every simplex, and the boundary is the convex hull.
    whole = dt.alpha_shape(float("inf"))
    assert len(whole.simplex_ids) == dt.nsimplex and whole.components == 1
    def rotated(facets):  # each facet turned to start at its lowest id: its orientation kept
        return {tuple(np.roll(f, -int(np.argmin(f))).tolist()) for f in facets}

    assert rotated(whole.boundary) == rotated(dt.convex_hull)
    with pytest.raises(tessera.InputError, match="alpha"):
        dt.alpha_shape(-1.0)
    with pytest.raises(tessera.InputError, match="alpha"):
        dt.alpha_shape(float("nan"))


def test_alpha_shape_polygons():
    rng = np.random.default_rng(5)
    t = rng.uniform(0, 2 * np.pi, 3000)
    r = np.sqrt(rng.uniform(0.25, 1, 3000))
    pts = np.c_[r * np.cos(t), r * np.sin(t)]
    dt = tessera.delaunay(pts)
    for alpha in (0.015, 0.03, 0.08):
        a = dt.alpha_shape(alpha)
        polys = a.polygons()
        assert len(polys) == a.components
        assert a.piece.shape == a.simplex_ids.shape and a.piece.max() == a.components - 1

        def area(ring):
            x, y = pts[ring, 0], pts[ring, 1]
            return 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum()
        total = 0.0
        for rings in polys:
            assert area(rings[0]) > 0 and all(area(h) < 0 for h in rings[1:])
            total += sum(area(ring) for ring in rings)
        assert total == pytest.approx(a.volume, rel=1e-12)
    assert [len(rings) for rings in dt.alpha_shape(0.08).polygons()] == [2]  # the annulus and its hole


def test_alpha_shape_save(tmp_path):
    import json

    rng = np.random.default_rng(6)
    t = rng.uniform(0, 2 * np.pi, 2000)
    r = np.sqrt(rng.uniform(0.25, 1, 2000))
    pts = np.c_[r * np.cos(t), r * np.sin(t)]
    a = tessera.delaunay(pts).alpha_shape(0.05)
    a.save(tmp_path / "b.npy", singular=False)
    np.testing.assert_array_equal(np.load(tmp_path / "b.npy"), a.boundary)
    a.save(tmp_path / "all.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "all.npy"), np.concatenate([a.boundary, a.singular]))
    a.save(tmp_path / "b.geojson")
    g = json.loads((tmp_path / "b.geojson").read_text())
    polys = g["features"][0]["geometry"]["coordinates"]
    assert [len(p) for p in polys] == [len(rings) for rings in a.polygons()]
    np.testing.assert_array_equal(np.array(polys[0][0])[:-1], pts[a.polygons()[0][0]])
    a.save(tmp_path / "b.vtp")
    assert (tmp_path / "b.vtp").stat().st_size > 0
    with pytest.raises(ValueError, match="written as"):
        a.save(tmp_path / "b.txt")
    a3 = tessera.delaunay(random_points(200, 3, seed=2)).alpha_shape(0.3)
    with pytest.raises(ValueError, match="3D"):
        a3.save(tmp_path / "c.geojson")
    with pytest.raises(OSError):
        a3.save(tmp_path / "no" / "c.vtp")
    with pytest.raises(tessera.InputError, match="2D"):
        tessera.delaunay(random_points(100, 3, seed=1)).alpha_shape(0.3).polygons()


def test_alpha_shape_of_a_periodic_triangulation():
    pts = random_points(2000, 3, seed=93)
    dt = tessera.delaunay(pts, bounds=(0, 1, 0, 1, 0, 1), periodic=True)
    r2 = dt.squared_radii()
    alpha = float(np.sqrt(np.quantile(r2, 0.5)))
    a = dt.alpha_shape(alpha)
    np.testing.assert_array_equal(a.simplex_ids, np.nonzero(r2 <= alpha * alpha)[0])
    assert a.boundary_shifts.shape == (len(a.boundary), 3, 3) and a.boundary_shifts.dtype == np.int8
    assert a.singular_shifts.shape == (len(a.singular), 3, 3)
    assert 0 < a.volume < 1
    assert dt.alpha_shape(float("inf")).volume == pytest.approx(1, rel=1e-12)
    plain = tessera.delaunay(pts).alpha_shape(alpha)
    assert plain.boundary_shifts.shape == (0, 3, 3)


def test_alpha_shape_of_a_regular_triangulation():
    pts = random_points(1500, 3, seed=92)
    radii = np.random.default_rng(3).uniform(0, 0.05, 1500)
    dt = tessera.delaunay(pts, radii=radii)
    assert dt.power
    rho2 = dt.squared_radii()
    a = dt.alpha_shape(0.0)  # the dual of the balls' union: orthospheres of negative squared radius
    np.testing.assert_array_equal(a.simplex_ids, np.nonzero(rho2 <= 0)[0])
    assert 0 < len(a.simplex_ids) < dt.nsimplex
