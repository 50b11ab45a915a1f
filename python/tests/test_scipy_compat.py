"""The scipy-compatible view and the Delaunay result against scipy.spatial.

On general-position input the bounded cells and scipy's (unbounded) diagram
agree wherever the box does not cut in: a ridge whose vertices all lie strictly
inside the box is the same ridge in both. Delaunay simplices agree everywhere
(without labels tessera closes the triangulation up to the convex hull, as
qhull does).
"""

import numpy as np
import pytest
from scipy.spatial import Delaunay as ScipyDelaunay
from scipy.spatial import Voronoi as ScipyVoronoi

import tessera
from conftest import UNIT_BOX, random_points


def sorted_pairs(pairs):
    return {(min(a, b), max(a, b)) for a, b in np.asarray(pairs).tolist()}


def sorted_tuples(rows):
    return set(map(tuple, np.sort(np.asarray(rows), axis=1).tolist()))


@pytest.mark.parametrize("dim,n", [(2, 3000), (3, 1500)])
def test_ridge_points_match_scipy_inside_the_box(dim, n):
    pts = random_points(n, dim, seed=11)
    sp = ScipyVoronoi(pts)
    # scipy's ridges that are finite and lie strictly inside the unit box.
    inside = np.all((sp.vertices > 0) & (sp.vertices < 1), axis=1)
    theirs = {(min(a, b), max(a, b))
              for (a, b), rv in zip(sp.ridge_points.tolist(), sp.ridge_vertices)
              if -1 not in rv and inside[rv].all()}
    # Ours whose vertices are all bisector vertices (no box plane in the key).
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim])
    view = vor.scipy
    interior = (vor.vertex_keys >= 0).all(axis=1)
    ours = {(min(a, b), max(a, b))
            for (a, b), rv in zip(view.ridge_points.tolist(), view.ridge_vertices)
            if interior[rv].all()}
    assert len(theirs) > n  # the comparison is not vacuous
    assert ours == theirs
    # The ridge vertices are the same points too.
    theirs_v = {(min(a, b), max(a, b)): np.sort(sp.vertices[rv], axis=0)
                for (a, b), rv in zip(sp.ridge_points.tolist(), sp.ridge_vertices)
                if -1 not in rv and inside[rv].all()}
    for (a, b), rv in list(zip(view.ridge_points.tolist(), view.ridge_vertices))[:500]:
        key = (min(a, b), max(a, b))
        if key in theirs_v:
            assert np.allclose(np.sort(view.vertices[rv], axis=0), theirs_v[key], atol=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_scipy_view_shapes_and_meanings(dim):
    pts = random_points(400, dim, seed=2)
    vor = tessera.voronoi(pts)
    view = vor.scipy
    assert view is vor.scipy  # computed once
    assert view.points is vor.points and view.ndim == dim and view.npoints == 400
    assert view.ridge_points.shape[1] == 2 and view.ridge_points.dtype == np.intc
    assert len(view.ridge_vertices) == len(view.ridge_points)
    assert len(view.regions) == vor.n_cells
    assert view.point_region.shape == (400,)
    assert view.point_region.dtype == ScipyVoronoi(pts).point_region.dtype  # intp, as scipy's
    # Each pair of adjacent cells is one ridge.
    assert len(view.ridge_points) == len(vor.neighbors) // 2
    assert sorted_pairs(view.ridge_points) == {
        (min(i, j), max(i, j)) for c, i in enumerate(vor.generators.tolist()) for j in vor.cell_neighbors(c).tolist()}
    # No infinite vertices; region of point i contains the vertices of its cell.
    for i in (0, 10, 399):
        region = view.regions[view.point_region[i]]
        assert -1 not in region
        assert (vor.vertex_keys[region] == i).any(axis=1).all()
    if dim == 2:  # regions are the polygons, counter-clockwise: shoelace area = cell area
        x, y = view.vertices[view.regions[5]].T
        assert 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum() == pytest.approx(vor.volumes[5])
    d = view.ridge_dict
    (p, q), rv = next(iter(d.items()))
    assert d[(p, q)] == rv and q in vor.cell_neighbors(vor.cell_of[p]).tolist()


@pytest.mark.parametrize("dim", [2, 3])
def test_scipy_view_lists_match_the_cells_and_leave_the_collector_as_it_was(dim):
    # The lists are built from one tolist with the garbage collector paused:
    # each is the cell's or face's own, and the collector is left as found.
    import gc

    vor = tessera.voronoi(random_points(300, dim, seed=4))
    for enabled in (True, False):
        (gc.enable if enabled else gc.disable)()
        try:
            view = tessera._scipy.ScipyVoronoi(vor)
            rv, regions, d = view.ridge_vertices, view.regions, view.ridge_dict
            assert gc.isenabled() == enabled
        finally:
            gc.enable()
        faces = view._ridge_faces
        fvo = vor.face_vertex_offsets
        assert rv == [vor.face_vertices[fvo[f]:fvo[f + 1]].tolist() for f in faces]
        for c in (0, 7, vor.n_cells - 1):
            cell_vertices = vor.face_vertices[fvo[vor.cell_face_offsets[c]]:fvo[vor.cell_face_offsets[c + 1]]]
            assert sorted(set(regions[c])) == sorted(set(cell_vertices.tolist()))
        assert list(d.values()) == rv and list(d) == [tuple(r) for r in view.ridge_points.tolist()]


def test_ridges_towards_outside_points_are_kept_once():
    pts = random_points(500, 2, seed=5)
    labels = np.where(pts[:, 0] < 0.2, -1, 0)
    vor = tessera.voronoi(pts, labels=labels)
    rp = vor.scipy.ridge_points
    assert len(sorted_pairs(rp)) == len(rp)  # no ridge twice
    outside = set(np.flatnonzero(labels < 0).tolist())
    to_outside = [(a, b) for a, b in rp.tolist() if b in outside]
    assert to_outside and all(a not in outside for a, _ in to_outside)
    assert (vor.scipy.point_region[labels < 0] == -1).all()


@pytest.mark.parametrize("dim,n", [(2, 5000), (3, 2000)])
def test_delaunay_simplices_match_scipy(dim, n):
    pts = random_points(n, dim, seed=21)
    dt = tessera.delaunay(pts)
    sp = ScipyDelaunay(pts)
    assert dt.simplices.shape == (sp.nsimplex, dim + 1)
    assert sorted_tuples(dt.simplices) == sorted_tuples(sp.simplices)


@pytest.mark.parametrize("dim", [2, 3])
def test_delaunay_neighbors_match_scipy(dim):
    pts = random_points(800, dim, seed=4)
    dt = tessera.delaunay(pts)
    sp = ScipyDelaunay(pts)

    def adjacency(simplices, neighbors):
        # {simplex as a sorted tuple: {vertex opposite: neighbour as a sorted tuple or None}}
        out = {}
        for s, nb in zip(simplices.tolist(), neighbors.tolist()):
            out[tuple(sorted(s))] = {v: (tuple(sorted(simplices[j].tolist())) if j >= 0 else None)
                                     for v, j in zip(s, nb)}
        return out

    assert dt.neighbors.shape == dt.simplices.shape
    assert adjacency(dt.simplices, dt.neighbors) == adjacency(sp.simplices, sp.neighbors)


@pytest.mark.parametrize("dim", [2, 3])
def test_delaunay_derived_attributes_match_scipy(dim):
    pts = random_points(1500, dim, seed=70 + dim)
    dt = tessera.delaunay(pts)
    sp = ScipyDelaunay(pts)
    assert sorted_tuples(np.sort(dt.convex_hull, axis=1)) == sorted_tuples(np.sort(sp.convex_hull, axis=1))
    # Hull facets face out: their normals point away from the points' centroid.
    f = pts[dt.convex_hull]
    if dim == 3:
        normal = np.cross(f[:, 1] - f[:, 0], f[:, 2] - f[:, 0])
    else:
        e = f[:, 1] - f[:, 0]
        normal = np.stack([e[:, 1], -e[:, 0]], axis=1)  # right of the edge: interior on the left
    assert (np.einsum("ij,ij->i", normal, f.mean(axis=1) - pts.mean(axis=0)) > 0).all()
    indptr, indices = dt.vertex_neighbor_vertices
    sindptr, sindices = sp.vertex_neighbor_vertices
    assert (indptr.dtype, indices.dtype) == (sindptr.dtype, sindices.dtype)  # int32, as scipy's
    for v in range(len(pts)):
        ours = indices[indptr[v] : indptr[v + 1]]
        assert (np.diff(ours) > 0).all()
        assert set(ours.tolist()) == set(sindices[sindptr[v] : sindptr[v + 1]].tolist())
    v2s = dt.vertex_to_simplex
    assert all(v in dt.simplices[v2s[v]] for v in range(len(pts)))
    assert (v2s == [np.nonzero((dt.simplices == v).any(axis=1))[0].min() for v in range(len(pts))]).all()


@pytest.mark.parametrize("dim", [2, 3])
def test_find_simplex_and_transform_match_scipy(dim):
    rng = np.random.default_rng(80 + dim)
    pts = rng.random((1500, dim))
    dt = tessera.delaunay(pts)
    sp = ScipyDelaunay(pts)
    q = rng.random((4000, dim)) * 1.2 - 0.1  # about a third outside the hull
    ours, theirs = dt.find_simplex(q), sp.find_simplex(q)
    assert ours.dtype == np.int32 and ours.shape == (4000,)
    assert ((ours >= 0) == (theirs >= 0)).all()
    assert 0 < (ours < 0).sum() < 4000
    inside = ours >= 0
    # Random queries lie strictly inside one simplex: the same points as scipy's.
    assert (np.sort(dt.simplices[ours[inside]], axis=1) == np.sort(sp.simplices[theirs[inside]], axis=1)).all()
    # scipy's barycentric recipe works on ours: coordinates in [0, 1], summing to 1.
    t = dt.transform
    assert t.shape == (dt.nsimplex, dim + 1, dim)
    s, x = ours[inside], q[inside]
    c = np.einsum("ijk,ik->ij", t[s, :dim], x - t[s, dim])
    c = np.c_[c, 1 - c.sum(axis=1)]
    assert (c > -1e-12).all() and (c < 1 + 1e-12).all()
    np.testing.assert_allclose(np.einsum("ij,ijk->ik", c, pts[dt.simplices[s]]), x, atol=1e-12)
    # Any leading shape, as scipy's; input points lie in their lowest simplex.
    assert dt.find_simplex(q.reshape(40, 100, dim)).shape == (40, 100)
    assert (dt.find_simplex(pts) == dt.vertex_to_simplex).all()


def test_transform_of_simplices_too_thin_for_doubles():
    # Exactly non-flat, but the rounded LU of v_k - v_D has a zero pivot
    # (points an ulp apart): NaN rows there, as scipy's degenerate
    # simplices, and the others finite (numpy's inv raised for all).
    h = ["0x1.d1a94e3d7d0d3p-1", "0x1.3cf7a4fa23980p-6", "0x1.d1a94e3d7d0d2p-1", "0x1.3cf7a4fa23981p-6",
         "0x1.7fa9ec5aac111p-5", "0x1.34a72e6f75a1fp-5"]
    thin = np.array([float.fromhex(x) for x in h]).reshape(3, 2)
    dt = tessera.delaunay(thin)
    assert dt.validate() and dt.nsimplex == 1
    t = dt.transform
    assert np.isnan(t[0, :2]).all() and (t[0, 2] == thin[dt.simplices[0, 2]]).all()
    pts = np.r_[thin, random_points(40, 2, seed=4) * 0.01 + 0.5]
    dt = tessera.delaunay(pts)
    t = dt.transform
    bad = np.isnan(t[:, :2]).any(axis=(1, 2))
    assert bad.sum() >= 1 and np.isfinite(t[~bad]).all()
    # Tiny scales: no underflow of the test (det ~1e-480), every row finite.
    assert np.isfinite(tessera.delaunay(random_points(50, 3, seed=5) * 1e-160).transform).all()


def test_find_simplex_with_labels_holes_and_bad_queries():
    pts = random_points(3000, 3, seed=90)
    r2 = ((pts - 0.5) ** 2).sum(axis=1)
    labels = np.where((r2 > 0.04) & (r2 < 0.16), 0, -1)  # a shell: not convex
    dt = tessera.delaunay(pts, labels)
    assert dt.find_simplex([[0.5, 0.5, 0.5]])[0] == -1  # in the hole
    shell = pts[labels == 0][:50]
    assert (dt.find_simplex(shell) >= 0).all()
    assert (dt.find_simplex([[np.nan, 0.5, 0.5], [0.5, np.inf, 0.5]]) == -1).all()
    with pytest.raises(ValueError, match="tol"):
        dt.find_simplex(shell, tol=1e-6)
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 3\)"):
        dt.find_simplex(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="real numbers"):
        dt.find_simplex(np.array([["a", "b", "c"]]))


def test_coplanar_lists_duplicates_as_scipy():
    pts = np.vstack([random_points(200, 3, seed=91), [[0.25, 0.5, 0.75]] * 3])
    dt = tessera.delaunay(pts)
    cop = dt.coplanar
    assert cop.shape == (2, 3) and cop.dtype == np.int32
    assert sorted(cop[:, 0].tolist()) == [201, 202] and (cop[:, 2] == 200).all()
    assert all(200 in dt.simplices[s] for s in cop[:, 1])
