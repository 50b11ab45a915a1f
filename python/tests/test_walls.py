"""tessera.voronoi(walls=...): cells in a convex domain, the box cut by
half-spaces. Measures against domains known by hand (a triangle of area 1/2,
half the unit cube), the walls' spokes in the graph and the boundary face
set, validation with exact measures, 1 vs 2 threads, bad walls; hull_walls
(the points' convex hull as walls)."""

import math

import numpy as np
import pytest

import tessera
from conftest import UNIT_BOX


def inside_points(n, dim, offset, seed):
    p = np.random.default_rng(seed).random((n, dim))
    return p[p.sum(axis=1) <= offset]


def test_triangle_and_half_cube():
    for dim, offset, measure in ((2, 1.0, 0.5), (3, 1.5, 0.5)):
        pts = inside_points(3000, dim, offset, dim)
        wall = [1.0] * dim + [offset]
        vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim], walls=[wall])
        assert vor.n_cells == len(pts)
        assert vor.volumes.sum() == pytest.approx(measure, rel=1e-13)
        assert vor.walls.tolist() == [wall]
        report = vor.validate()
        assert report.ok, report
        # One flat row is one wall; the same cells.
        again = tessera.voronoi(pts, bounds=UNIT_BOX[dim], walls=np.array(wall), threads=2)
        assert np.array_equal(again.volumes, vor.volumes)
        assert np.array_equal(again.centroids, vor.centroids)
        # The wall is spoke -7, a domain boundary.
        g = tessera.adjacency(vor)
        assert np.any(g.spokes == -7)
        assert np.all(g.spoke_class[g.spokes == -7] == 2)
        # Without walls: an empty (0, D + 1) array.
        assert tessera.voronoi(pts, bounds=UNIT_BOX[dim]).walls.shape == (0, dim + 1)


def test_boundary_of_the_triangle():
    pts = inside_points(2000, 2, 1.0, 7)
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[2], walls=[(1, 1, 1)])
    fs = tessera.faces(vor, "boundary")
    v = fs.vertices
    seg = fs.face_vertices.reshape(-1, 2)
    length = np.linalg.norm(v[seg[:, 1]] - v[seg[:, 0]], axis=1).sum()
    assert length == pytest.approx(2 + math.sqrt(2), rel=1e-13)


def test_bad_walls_and_points_outside():
    pts = inside_points(500, 3, 1.5, 3)
    with pytest.raises(ValueError, match="lies outside wall 0"):
        tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=[(1, 1, 1, 1.0)])
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=[(1, 1, 1, 1.0)], ignore_outside=True)
    assert len(vor.ignored_outside_bounds) == int(np.sum(pts.sum(axis=1) > 1.0))
    with pytest.raises(ValueError, match="its normal is zero"):
        tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=[(0, 0, 0, 1.0)])
    with pytest.raises(ValueError, match="rows of 4 numbers"):
        tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=[(1, 1, 1.0)])
    with pytest.raises(TypeError):
        tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=[("a", 1, 1, 1.0)])
    with pytest.raises(ValueError, match="periodic"):
        tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=[(1, 1, 1, 2.5)], periodic=True)


def test_products_of_points_take_walls():
    pts = inside_points(1500, 3, 1.5, 11)
    wall = [(1, 1, 1, 1.5)]
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[3], walls=wall)
    g = tessera.adjacency(pts, bounds=UNIT_BOX[3], walls=wall)
    assert np.array_equal(g.spokes, tessera.adjacency(vor).spokes)
    f = tessera.faces(pts, "boundary", bounds=UNIT_BOX[3], walls=wall)
    whole = tessera.faces(vor, "boundary")
    assert np.array_equal(f.face_vertices, whole.face_vertices)
    assert np.array_equal(f.vertices, whole.vertices)
    with pytest.raises(ValueError, match="walls"):
        tessera.adjacency(vor, walls=wall)  # already computed
    # A flower of points: the cells asked for and their neighbours', as all cells give them.
    i = int(np.argmax(pts.sum(axis=1)))  # the point nearest the wall
    fl = tessera.flower(pts, [i], bounds=UNIT_BOX[3], walls=wall)[0]
    assert np.any(fl.face_neighbor == -7)
    assert np.array_equal(fl.face_neighbor, tessera.flower(vor, [i])[0].face_neighbor)
    # Lloyd in the convex domain: every point stays inside the wall, exactly.
    r = tessera.lloyd(pts, 3, bounds=UNIT_BOX[3], walls=wall)
    from fractions import Fraction
    assert all(sum(Fraction(float(x)) for x in p) <= Fraction(3, 2) for p in r.points)
    assert not np.array_equal(r.points, pts)
    assert r.spacing == pytest.approx((0.5 / len(pts)) ** (1 / 3), rel=1e-12)


def test_polygon_walls():
    # A regular hexagon, either way round: its cells tile it, and every
    # corner lies inside every wall exactly.
    ang = np.arange(6) * np.pi / 3
    hexagon = np.c_[0.5 + 0.4 * np.cos(ang), 0.5 + 0.4 * np.sin(ang)]
    for corners in (hexagon, hexagon[::-1]):
        w = tessera.polygon_walls(corners)
        assert w.shape == (6, 3)
        from fractions import Fraction
        for nx, ny, d in w:
            for x, y in corners:
                assert Fraction(nx) * Fraction(float(x)) + Fraction(ny) * Fraction(float(y)) <= Fraction(d)
        pts = np.random.default_rng(5).random((4000, 2))
        vor = tessera.voronoi(pts, bounds=UNIT_BOX[2], walls=w, ignore_outside=True)
        area = 1.5 * math.sqrt(3) * 0.4 ** 2
        assert vor.volumes.sum() == pytest.approx(area, rel=1e-12)
        assert vor.validate().ok
    # The unit square's own walls change no cell.
    sq = tessera.polygon_walls([(0, 0), (1, 0), (1, 1), (0, 1)])
    pts = np.random.default_rng(6).random((500, 2))
    a = tessera.voronoi(pts, bounds=UNIT_BOX[2], walls=sq)
    b = tessera.voronoi(pts, bounds=UNIT_BOX[2])
    assert np.array_equal(a.volumes, b.volumes)
    with pytest.raises(ValueError, match="not convex"):
        tessera.polygon_walls([(0, 0), (1, 0), (0.2, 0.2), (0, 1)])
    with pytest.raises(ValueError, match="k >= 3"):
        tessera.polygon_walls([(0, 0), (1, 0)])
    with pytest.raises(ValueError, match="repeats"):
        tessera.polygon_walls([(0, 0), (1, 0), (1, 0), (0, 1)])
    with pytest.raises(ValueError, match="no area"):
        tessera.polygon_walls([(0, 0), (1, 1), (2, 2)])


def test_surface_nets_in_walls():
    rng = np.random.default_rng(12)
    pts = rng.random((6000, 3))
    pts = pts[pts.sum(axis=1) <= 2.0]
    labels = (np.linalg.norm(pts - 0.5, axis=1) < 0.3).astype(np.int32)
    net = tessera.surface_nets(pts, labels, capping=True, bounds=UNIT_BOX[3], walls=[(1, 1, 1, 2.0)])
    on = np.any(net.vertex_keys == -7, axis=1)  # the vertices on the wall
    assert on.sum() > 10
    assert np.abs(net.vertices[on].sum(axis=1) - 2.0).max() < 1e-12


def test_hull_walls():
    rng = np.random.default_rng(12)
    for dim in (2, 3):
        b = rng.normal(size=(2000, dim))
        pts = b * (rng.random((2000, 1)) ** (1 / dim)) / np.linalg.norm(b, axis=1)[:, None]
        walls = tessera.hull_walls(pts)
        assert walls.dtype == np.float64 and walls.shape[1] == dim + 1 and len(walls) > 16
        # Every point inside (floats: exactly, the C++ tests check in 113 bits).
        assert np.all(pts @ walls[:, :dim].T <= walls[:, dim])
        vor = tessera.voronoi(pts, walls=walls, threads=2)
        assert vor.n_cells == len(pts)
        report = vor.validate()
        assert report.ok, report
        # Dilated: every wall moves out by the distance (the box must hold it).
        grown = tessera.hull_walls(pts, dilation=0.5)
        norm = np.linalg.norm(walls[:, :dim], axis=1)
        assert np.allclose((grown[:, dim] - walls[:, dim]) / norm, 0.5, rtol=1e-12)
        wide = tessera.voronoi(pts, walls=grown, bounds=[-2, 2] * dim)
        assert wide.volumes.sum() > vor.volumes.sum() * 1.5
    # A lattice's hull: one wall per face, through its border points exactly.
    g = np.stack(np.meshgrid(*[np.arange(5.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
    walls = tessera.hull_walls(g, threads=1)
    assert len(walls) == 6
    assert tessera.voronoi(g, walls=walls).volumes.sum() == 64.0
    with pytest.raises(ValueError, match="at least 3 points"):
        tessera.hull_walls([[0.0, 0.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match="no area"):
        tessera.hull_walls([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [5.0, 5.0]])
    with pytest.raises(ValueError, match="dilation"):
        tessera.hull_walls(g, dilation=-1)
    with pytest.raises(ValueError, match="not finite"):
        tessera.hull_walls([[0.0, 0.0], [1.0, 0.0], [0.0, np.nan]])
