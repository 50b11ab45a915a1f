"""Regular (weighted Delaunay) triangulations: tessera.delaunay(..., radii=...),
the dual of the power cells, checked against brute force, the power cells'
empty cells and the ordinary triangulation."""

import itertools

import numpy as np
import pytest

import tessera
from conftest import UNIT_BOX, random_points


def spheres(n, dim, seed=0, rmax=None):
    """n uniform points in the unit box and radii in [0, rmax): about as large
    as the spacing (or larger), so that some points are hidden."""
    rng = np.random.default_rng(seed + 2000)
    rmax = 2 * (1.0 / n) ** (1.0 / dim) if rmax is None else rmax
    return random_points(n, dim, seed), rng.random(n) * rmax


def orthocentres(pts, w, rows):
    """Per row of vertex ids: the orthocentre c (equal power |p - c|^2 - w to
    every vertex), solving 2 (p_k - p_0) . c = |p_k|^2 - |p_0|^2 - (w_k - w_0);
    and that power."""
    p = pts[rows]                      # (m, D+1, D)
    ww = w[rows]                       # (m, D+1)
    sq = (p ** 2).sum(axis=2)
    a = 2 * (p[:, 1:, :] - p[:, :1, :])
    b = sq[:, 1:] - sq[:, :1] - (ww[:, 1:] - ww[:, :1])
    c = np.linalg.solve(a, b[..., None])[..., 0]
    power = ((p[:, 0, :] - c) ** 2).sum(axis=1) - ww[:, 0]
    return c, power


def least_power(c, pts, w):
    """Per row of c, the least power |c - q|^2 - w_q over all points q."""
    return (((c[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2) - w[None, :]).min(axis=1)


def simplex_measures(pts, rows):
    """Signed areas (2D) or volumes (3D) of the simplices."""
    p = pts[rows]
    e = p[:, 1:, :] - p[:, :1, :]
    fact = 2.0 if pts.shape[1] == 2 else 6.0
    return np.linalg.det(e) / fact


def in_no_simplex(dt):
    """The points that are no simplex's vertex and not duplicates."""
    used = np.zeros(dt.npoints, dtype=bool)
    used[dt.simplices.ravel()] = True
    used[dt.duplicates[:, 0]] = True
    return np.flatnonzero(~used)


@pytest.mark.parametrize("dim", [2, 3])
def test_regular_triangulation_validates_and_lists_its_hidden_points(dim):
    pts, r = spheres(3000, dim, seed=dim)
    dt = tessera.delaunay(pts, radii=r)
    assert dt.power and dt.radii is r
    assert "regular" in repr(dt)
    hidden = dt.hidden
    assert hidden.dtype == np.int32 and hidden.ndim == 1 and (np.diff(hidden) > 0).all()
    assert hidden.size > 0, "radii this large should hide some points"
    # Exactly the points in no simplex (no duplicates here).
    assert dt.duplicates.size == 0
    assert np.array_equal(hidden, in_no_simplex(dt))
    assert (dt.vertex_to_simplex[hidden] == -1).all()
    assert (dt.vertex_to_simplex[np.setdiff1d(np.arange(len(pts)), hidden)] >= 0).all()
    assert (simplex_measures(pts, dt.simplices) > 0).all()
    report = dt.validate()
    assert report.ok, report.messages
    assert report.local_delaunay_violations == 0
    assert report.hidden_not_hidden == 0 and report.hidden_in_conflict == 0
    assert report.missing_points == 0
    assert report.volume_sum == pytest.approx(report.enclosed_volume, rel=1e-12)
    # A hidden point's power cell is empty, in any box.
    vor = tessera.voronoi(pts, radii=r)
    assert np.isin(hidden, vor.empty_cells).all()
    # Hull vertices are never hidden: each hidden point lies in a simplex, whose
    # orthosphere it is not in conflict with.
    s = dt.find_simplex(pts[hidden])
    assert (s >= 0).all()
    c, power = orthocentres(pts, r ** 2, dt.simplices[s])
    own = ((pts[hidden] - c) ** 2).sum(axis=1) - r[hidden] ** 2
    assert (own >= power - 1e-9 * (1 + (c ** 2).sum(axis=1))).all()


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_regular_triangulation_against_brute_force(dim, seed):
    """All D+1 subsets of a few points: the regular simplices (no point with a
    lower power to the orthocentre) are exactly the triangulation's."""
    n = 30 if dim == 2 else 22
    pts, r = spheres(n, dim, seed=10 * seed + dim, rmax=0.35 if dim == 2 else 0.5)
    w = r ** 2
    dt = tessera.delaunay(pts, radii=r)
    assert dt.power and dt.validate().ok
    # Every simplex is regular (orthosphere empty in the power sense).
    c, power = orthocentres(pts, w, dt.simplices)
    scale = 1 + (c ** 2).sum(axis=1)
    assert (least_power(c, pts, w) >= power - 1e-9 * scale).all()
    # ... and every regular subset is a simplex.
    rows = np.array(list(itertools.combinations(range(n), dim + 1)), dtype=np.int64)
    vol = simplex_measures(pts, rows)
    rows = rows[np.abs(vol) > 1e-12]
    c, power = orthocentres(pts, w, rows)
    scale = 1 + (c ** 2).sum(axis=1)
    least = least_power(c, pts, w)
    regular = least >= power - 1e-9 * scale
    assert not (np.abs(least - power) < 1e-7 * scale)[~regular].any(), "a near tie: choose another seed"
    assert {tuple(x) for x in np.sort(rows[regular], axis=1)} == {tuple(x) for x in np.sort(dt.simplices, axis=1)}
    # The hidden points are the ones in no regular simplex.
    assert np.array_equal(dt.hidden, np.setdiff1d(np.arange(n), rows[regular].ravel()))
    # The simplices tile the convex hull of the points that are not hidden.
    try:
        from scipy.spatial import ConvexHull
    except ImportError:
        return
    keep = np.setdiff1d(np.arange(n), dt.hidden)
    total = simplex_measures(pts, dt.simplices).sum()
    assert total == pytest.approx(ConvexHull(pts[keep]).volume, rel=1e-12)
    assert total == pytest.approx(ConvexHull(pts).volume, rel=1e-12)  # hull vertices are never hidden


@pytest.mark.parametrize("dim", [2, 3])
def test_one_sphere_far_larger_than_the_box(dim):
    """One sphere 1e12 (or 1e200) times the others: its power is the least all
    over the box, so no orthocentre lies in it, nor in any box a cells pass
    could grow to. Every method gives the cone from its centre over the hull,
    every inner point hidden (until stop 79 method="cells" called the points
    flat)."""
    pts, r = spheres(200, dim, seed=40 + dim, rmax=0.05)
    try:
        from scipy.spatial import ConvexHull
    except ImportError:
        ConvexHull = None
    for big in (1e12, 1e200):
        r[7] = big
        rows = {m: tessera.delaunay(pts, radii=r, method=m) for m in ("cells", "insertion", "auto")}
        for m, dt in rows.items():
            assert dt.validate().ok, m
            assert np.array_equal(dt.simplices, rows["insertion"].simplices), m
            assert (dt.simplices == 7).any(axis=1).all(), m  # every simplex has the big sphere's centre
            if ConvexHull is not None:
                hull = ConvexHull(pts)
                inner = np.setdiff1d(np.arange(200), np.append(hull.vertices, 7))
                assert np.array_equal(dt.hidden, inner), m


def test_brute_force_sees_hidden_points():
    """The brute-force seeds above do hide points (else they test little)."""
    hidden = {2: 0, 3: 0}
    for seed in (0, 1, 2):
        for dim in (2, 3):
            pts, r = spheres(30 if dim == 2 else 22, dim, seed=10 * seed + dim, rmax=0.35 if dim == 2 else 0.5)
            hidden[dim] += tessera.delaunay(pts, radii=r).hidden.size
    assert hidden[2] > 0 and hidden[3] > 0


@pytest.mark.parametrize("dim", [2, 3])
def test_equal_radii_give_exactly_the_ordinary_triangulation(dim):
    pts = random_points(1500, dim, seed=20 + dim)
    plain = tessera.delaunay(pts)
    assert not plain.power and plain.hidden.size == 0 and plain.radii is None
    for radius in (0.0, 0.25, 3.0):
        rr = np.full(len(pts), radius)
        dt = tessera.delaunay(pts, radii=rr)
        assert not dt.power and dt.hidden.size == 0 and dt.radii is rr
        assert np.array_equal(dt.simplices, plain.simplices)
        assert dt.validate().ok  # checked as the ordinary triangulation, without the radii
    # Equal radii are the ordinary triangulation by any method.
    ins = tessera.delaunay(pts, radii=np.full(len(pts), 0.1), method="insertion")
    assert not ins.power and np.array_equal(ins.simplices, plain.simplices)


@pytest.mark.parametrize("dim", [2, 3])
def test_regular_triangulation_is_the_same_for_any_thread_count(dim):
    pts, r = spheres(4000, dim, seed=30 + dim)
    one = tessera.delaunay(pts, radii=r, threads=1)
    two = tessera.delaunay(pts, radii=r, threads=2)
    cells = tessera.delaunay(pts, radii=r, method="cells", threads=2)
    insertion = tessera.delaunay(pts, radii=r, method="insertion", threads=2)
    for dt in (two, cells, insertion):
        assert np.array_equal(dt.simplices, one.simplices)
        assert np.array_equal(dt.hidden, one.hidden)
        assert np.array_equal(dt.neighbors, one.neighbors)
    assert cells.from_insertion == 0 and insertion.from_cells == 0


def test_radii_array_is_kept_without_a_copy_and_array_likes_are_taken():
    pts, r = spheres(400, 2, seed=3)
    dt = tessera.delaunay(pts, radii=r)
    assert dt.radii is r
    from_list = tessera.delaunay(pts, radii=r.tolist())
    assert from_list.radii.dtype == np.float64 and np.array_equal(from_list.simplices, dt.simplices)
    strided = np.repeat(r, 2)[::2]  # not contiguous: converted
    conv = tessera.delaunay(pts, radii=strided)
    assert conv.radii is not strided and np.array_equal(conv.simplices, dt.simplices)
    assert conv.validate().ok
    ints = np.arange(400) % 2  # integer radii are numbers too
    assert tessera.delaunay(pts * 20, radii=ints).power


def test_coincident_points_the_largest_radius_is_the_vertex():
    pts = random_points(200, 3, seed=5)
    r = np.full(203, 0.01)
    r[:200] = np.random.default_rng(6).random(200) * 0.05
    pts = np.vstack([pts, pts[[5, 7, 9]]])  # ids 200, 201, 202 coincide with 5, 7, 9
    r[200], r[5] = 0.2, 0.1     # 200 is larger: the vertex, 5 its duplicate
    r[201], r[7] = 0.02, 0.02   # equal: the lowest id (7)
    r[202], r[9] = 0.0, 0.03    # 9 is larger
    dt = tessera.delaunay(pts, radii=r)
    assert dt.power
    dup = dict(map(tuple, dt.duplicates.tolist()))
    assert dup[5] == 200 and dup[201] == 7 and dup[202] == 9
    assert not np.isin(dt.hidden, dt.duplicates[:, 0]).any()
    vertices = np.unique(dt.simplices)
    assert not np.isin(dt.duplicates[:, 0], vertices).any()
    assert np.array_equal(np.sort(np.concatenate([vertices, dt.hidden, dt.duplicates[:, 0]])), np.arange(203))
    report = dt.validate()
    assert report.ok, report.messages


def test_regular_triangulation_with_labels():
    pts, r = spheres(2000, 3, seed=7)
    lab = (pts[:, 0] > 0.5).astype(np.int32)
    lab[np.linalg.norm(pts - 0.5, axis=1) < 0.2] = -1
    whole = tessera.delaunay(pts, radii=r)
    dt = tessera.delaunay(pts, labels=lab, radii=r)
    assert dt.power
    inside = (lab[whole.simplices] >= 0).all(axis=1)
    assert np.array_equal(dt.simplices, whole.simplices[inside])
    assert np.array_equal(dt.hidden, whole.hidden[lab[whole.hidden] >= 0])
    assert dt.hidden.size > 0
    report = dt.validate()
    assert report.ok, report.messages


def test_regular_triangulation_without_hull_completion_and_ignore_outside():
    pts, r = spheres(1500, 2, seed=8)
    full = tessera.delaunay(pts, radii=r)
    part = tessera.delaunay(pts, radii=r, complete_hull=False)
    assert part.power and part.hidden.size == 0  # hidden needs hull completion
    assert 0 < part.nsimplex < full.nsimplex
    full_rows = {tuple(x) for x in full.simplices}
    assert all(tuple(x) in full_rows for x in part.simplices)
    moved = pts.copy()
    moved[:10, 0] += 2
    drop = tessera.delaunay(moved, bounds=UNIT_BOX[2], radii=r, ignore_outside=True)
    assert drop.ignored_outside_bounds.tolist() == list(range(10))
    ref = tessera.delaunay(pts[10:], radii=r[10:])
    assert np.array_equal(drop.hidden, ref.hidden + 10)
    assert np.array_equal(np.sort(drop.simplices.ravel()), np.sort(ref.simplices.ravel() + 10))
    assert drop.validate().ok


@pytest.mark.parametrize("dim", [2, 3])
def test_bad_radii_raise(dim):
    pts, r = spheres(100, dim, seed=9)
    box = UNIT_BOX[dim]
    with pytest.raises(ValueError, match=r"radii: expected one radius per point, shape \(100,\), got \(99,\)"):
        tessera.delaunay(pts, radii=r[:-1])
    with pytest.raises(ValueError, match=r"radii: expected one radius per point"):
        tessera.delaunay(pts, radii=r.reshape(-1, 1))
    with pytest.raises(ValueError, match="radii: expected real numbers"):
        tessera.delaunay(pts, radii=["a"] * 100)
    for bad, shown in ((-0.5, "-0.5"), (np.nan, "NaN"), (np.inf, "inf")):
        rr = r.copy()
        rr[17] = bad
        with pytest.raises(tessera.InputError, match=f"radius of point 17 is {shown}.*finite and non-negative"):
            tessera.delaunay(pts, radii=rr)
    # Periodic boxes take radii (every image has its point's radius).
    per = tessera.delaunay(pts, bounds=box, radii=r, periodic=True)
    assert per.power and per.validate().ok
    hidden = np.setdiff1d(np.arange(100), per.simplices)
    np.testing.assert_array_equal(per.hidden, hidden)
    # Equal radii are the ordinary triangulation: periodic too.
    per = tessera.delaunay(pts, bounds=box, radii=np.full(100, 0.1), periodic=True)
    assert not per.power and per.nsimplex == tessera.delaunay(pts, bounds=box, periodic=True).nsimplex


def test_validate_delaunay_needs_the_radii_of_a_regular_triangulation():
    pts, r = spheres(500, 2, seed=11)
    dt = tessera.delaunay(pts, radii=r)
    core = tessera._core
    assert core.validate_delaunay(dt._dt, pts, None, r).ok
    with pytest.raises(tessera.InputError, match="needs their 500 radii, got 0"):
        core.validate_delaunay(dt._dt, pts, None)
    with pytest.raises(tessera.InputError, match="needs their 500 radii, got 499"):
        core.validate_delaunay(dt._dt, pts, None, r[:-1])
    plain = tessera.delaunay(pts)
    assert core.validate_delaunay(plain._dt, pts, None).ok
    with pytest.raises(tessera.InputError, match="radii given for a triangulation computed without them"):
        core.validate_delaunay(plain._dt, pts, None, r)
    # Other radii: the triangulation is not theirs.
    assert not core.validate_delaunay(dt._dt, pts, None, np.zeros(500)).ok


@pytest.mark.parametrize("dim", [2, 3])
def test_regular_triangulation_views_and_files(tmp_path, dim):
    pts, r = spheres(600, dim, seed=14)
    dt = tessera.delaunay(pts, radii=r)
    assert dt.hidden.size > 0
    nb = dt.neighbors
    m = dt.nsimplex
    # Symmetric adjacency.
    for s in range(m):
        for k in range(dim + 1):
            t = nb[s, k]
            if t >= 0:
                assert s in nb[t]
    indptr, indices = dt.vertex_neighbor_vertices
    assert (np.diff(indptr)[dt.hidden] == 0).all()
    assert not np.isin(indices, dt.hidden).any()
    assert not np.isin(dt.convex_hull, dt.hidden).any()
    # Barycentric transform and find_simplex agree with the simplices.
    centroids = pts[dt.simplices].mean(axis=1)
    assert np.array_equal(dt.find_simplex(centroids), np.arange(m))
    bary = np.einsum("sij,sj->si", dt.transform[:, :dim], centroids - dt.transform[:, dim])
    assert np.allclose(bary, 1.0 / (dim + 1))
    path = tmp_path / "regular.vtu"
    dt.save(path)
    assert path.stat().st_size > 0


@pytest.mark.parametrize("dim,ext", [(2, ".vtp"), (2, ".vtu"), (3, ".vtu")])
def test_regular_triangulation_saves_its_radii(tmp_path, dim, ext):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader

    pts, r = spheres(500, dim, seed=40 + dim)
    dt = tessera.delaunay(pts, radii=r)
    path = tmp_path / ("regular" + ext)
    dt.save(path)
    reader = vtkXMLPolyDataReader() if ext == ".vtp" else vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfCells() == dt.nsimplex
    np.testing.assert_array_equal(vtk_to_numpy(data.GetPointData().GetArray("Radius")), r)
    # An ordinary triangulation has no Radius array.
    plain = tessera.delaunay(pts)
    plain.save(path)
    reader.Modified()
    reader.Update()
    assert reader.GetOutput().GetPointData().GetArray("Radius") is None
