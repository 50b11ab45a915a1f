"""tessera.spherical_voronoi: scipy's SphericalVoronoi as the oracle, lon/lat input,
duplicates and hidden points, files read back, threads, bad input."""

import numpy as np
import pytest
from scipy.spatial import SphericalVoronoi as ScipySphericalVoronoi

import tessera


def on_sphere(n, seed, radius=1.0, center=(0.0, 0.0, 0.0)):
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return np.asarray(center) + radius * v / np.linalg.norm(v, axis=1)[:, None]


def test_equals_scipy():
    pts = on_sphere(4000, 1, 3.0, (0.5, -1.0, 2.0))
    sv = tessera.spherical_voronoi(pts, center=(0.5, -1.0, 2.0))
    ref = ScipySphericalVoronoi(pts, radius=3.0, center=np.array([0.5, -1.0, 2.0]))
    ref.sort_vertices_of_regions()
    assert sv.radius == pytest.approx(3.0, rel=1e-14)
    np.testing.assert_allclose(sv.calculate_areas(), ref.calculate_areas(), rtol=1e-9)
    assert sv.area_sum == pytest.approx(4 * np.pi * 9, rel=1e-13)
    report = sv.validate(sample=500)
    assert report and report.ok and report.vertices_checked == 500 and report.euler == 2, report.messages
    assert len(sv.vertices) == len(ref.vertices) == 2 * 4000 - 4
    for i in range(0, 4000, 13):
        ours = {tuple(np.round(v, 8)) for v in sv.vertices[sv.regions[i]]}
        theirs = {tuple(np.round(v, 8)) for v in ref.vertices[ref.regions[i]]}
        assert ours == theirs
    # Centroids on the sphere, nearer their own point than any neighbour.
    g = sv.centroids
    np.testing.assert_allclose(np.linalg.norm(g - [0.5, -1.0, 2.0], axis=1), 3.0, rtol=1e-12)
    for i in range(0, 4000, 101):
        d = np.linalg.norm(pts[sv.neighbors_of(i)] - g[i], axis=1)
        assert np.linalg.norm(pts[i] - g[i]) < d.min()


def test_lonlat_grid_duplicates_and_hidden():
    ll = np.array([(lon, lat) for lat in range(-90, 91, 10) for lon in range(-180, 180, 30)], dtype=float)
    ll = np.vstack([ll, ll[50]])  # a repeat of point 50
    sv = tessera.spherical_voronoi(ll, lonlat=True, radius=6371.0)
    assert sv.status[-1] == tessera.SPHERE_DUPLICATE and sv.duplicate_of[-1] == 50
    assert sv.duplicates == 1
    assert sv.area_sum == pytest.approx(4 * np.pi * 6371.0**2, rel=1e-12)
    assert sv.exact_tests > 0  # the grid's cocircular rows
    # A point just inside the hull: no cell.
    pts = on_sphere(300, 2)
    pts = np.vstack([pts, pts[0] * (1 - 1e-9)])
    sv = tessera.spherical_voronoi(pts)
    assert sv.status[300] == tessera.SPHERE_HIDDEN and sv.hidden == 1 and sv.areas[300] == 0
    assert len(sv.regions[300]) == 0


def test_files_and_threads(tmp_path):
    pts = on_sphere(5000, 3)
    a = tessera.spherical_voronoi(pts, threads=1)
    b = tessera.spherical_voronoi(pts, threads=2)
    for name in ("vertices", "region_vertices", "neighbors", "areas", "centroids", "triangles"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    a.save(tmp_path / "c.vtp")
    a.save_triangles(tmp_path / "t.npy")
    t = np.load(tmp_path / "t.npy")
    assert t.shape == (len(a.vertices), 3)
    normals = np.cross(pts[t[:, 1]] - pts[t[:, 0]], pts[t[:, 2]] - pts[t[:, 0]])
    assert (np.einsum("ij,ij->i", normals, pts[t[:, 0]]) > 0).all()  # outward
    vtk = pytest.importorskip("vtk")
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(tmp_path / "c.vtp"))
    r.Update()
    assert r.GetOutput().GetNumberOfCells() == 5000
    with pytest.raises(tessera.InputError):
        a.save(tmp_path / "c.vtu")


def test_bad_input():
    with pytest.raises(ValueError):
        tessera.spherical_voronoi(np.zeros((0, 3)))
    with pytest.raises(ValueError):
        tessera.spherical_voronoi(on_sphere(10, 1)[:, :2])
    with pytest.raises(tessera.InputError, match="off the sphere"):
        tessera.spherical_voronoi(np.array([[0, 0, 1.0], [0, 0, 2.0], [1.0, 0, 0]]))
    with pytest.raises(tessera.InputError, match="latitude"):
        tessera.spherical_voronoi([[0.0, 100.0]], lonlat=True)
    with pytest.raises(ValueError):
        tessera.spherical_voronoi(on_sphere(10, 1), radius=-2)
    with pytest.raises(ValueError):
        tessera.spherical_voronoi(on_sphere(10, 1), center=(0, 0))
    sv = tessera.spherical_voronoi(np.array([[0, 0, 1.0], [0, 0, 1.05], [1.0, 0, 0]]), tolerance=0.1)
    assert sv.area_sum == pytest.approx(4 * np.pi * sv.radius**2)
