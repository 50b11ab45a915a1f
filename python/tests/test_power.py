"""Power (radical) cells: tessera.voronoi(..., radii=...) and the products
read off them (adjacency, faces); flower refuses them."""

import numpy as np
import pytest

import tessera
from conftest import UNIT_BOX, random_points


def spheres(n, dim, seed=0, rmax=None):
    """n uniform points in the unit box and radii in [0, rmax): about as large
    as the spacing, so that some power cells are empty."""
    rng = np.random.default_rng(seed + 1000)
    rmax = (1.0 / n) ** (1.0 / dim) if rmax is None else rmax
    return random_points(n, dim, seed), rng.random(n) * rmax


def least_power(x, pts, radii):
    """Per row of x, the least power |x - p|^2 - r^2 over all points, and its point."""
    pw = ((x[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2) - radii[None, :] ** 2
    return pw.min(axis=1), pw.argmin(axis=1)


@pytest.mark.parametrize("dim", [2, 3])
def test_power_cells_tile_the_box_and_list_their_empty_cells(dim):
    pts, r = spheres(2000, dim, seed=dim)
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim], radii=r)
    assert vor.power and "power cells" in repr(vor)
    assert vor.volumes.sum() == pytest.approx(1.0, rel=1e-12)
    assert (vor.volumes > 0).all()
    # empty_cells: int32, ascending, exactly the points without a cell.
    empty = vor.empty_cells
    assert empty.dtype == np.int32 and empty.ndim == 1 and (np.diff(empty) > 0).all()
    assert empty.size > 0, "radii this large should leave some cells empty"
    assert np.array_equal(empty, np.flatnonzero(vor.cell_of == -1))
    assert vor.n_cells + empty.size == len(pts)
    assert (vor.cell_of[vor.generators] == np.arange(vor.n_cells)).all()
    # Nobody lists an empty cell's point as a neighbour, nor a face across to it.
    assert not np.isin(vor.neighbors, empty).any()
    assert not np.isin(vor.face_neighbor, empty).any()
    # An empty cell's point has, at its own position, a power above another's.
    assert (least_power(pts[empty], pts, r)[0] < -(r[empty] ** 2)).all()
    # Each cell's centroid lies in it: its generator's power is the least there.
    least, _ = least_power(vor.centroids, pts, r)
    g = vor.generators
    own = ((vor.centroids - pts[g]) ** 2).sum(axis=1) - r[g] ** 2
    assert (own <= least + 1e-12).all()
    report = vor.validate()
    assert report.ok, report.messages
    # Power cells can be slivers (1e-10 of the median): relative to such a
    # cell's own measure the error is larger; its corners stay as accurate.
    assert report.measures_checked > 0 and report.measure_rel_error < 1e-9
    assert report.vertex_rel_error < 1e-12


@pytest.mark.parametrize("dim", [2, 3])
def test_power_cells_merged_vertices_have_equal_powers(dim):
    pts, r = spheres(500, dim, seed=10 + dim)
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim], radii=r)
    keys, verts = vor.vertex_keys, vor.vertices
    inner = (keys >= 0).all(axis=1)  # vertices where D+1 power planes meet
    assert inner.any()
    p = ((verts[inner][:, None, :] - pts[keys[inner]]) ** 2).sum(axis=2) - r[keys[inner]] ** 2
    assert np.ptp(p, axis=1).max() < 1e-12
    # ... and no point has a lower power there.
    least, _ = least_power(verts[inner], pts, r)
    assert (p.min(axis=1) <= least + 1e-12).all()


@pytest.mark.parametrize("dim", [2, 3])
def test_equal_radii_give_exactly_the_ordinary_cells(dim):
    pts = random_points(1500, dim, seed=20 + dim)
    plain = tessera.voronoi(pts, bounds=UNIT_BOX[dim])
    for radius in (0.0, 0.25, 3.0):
        vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim], radii=np.full(len(pts), radius))
        assert not vor.power and vor.empty_cells.size == 0
        for attr in ("generators", "cell_of", "volumes", "centroids", "neighbor_offsets", "neighbors",
                     "vertices", "vertex_keys", "cell_face_offsets", "face_vertex_offsets", "face_vertices",
                     "face_neighbor", "face_class"):
            assert np.array_equal(getattr(vor, attr), getattr(plain, attr)), attr
        assert vor.validate().ok


def test_radii_array_is_kept_without_a_copy_and_array_likes_are_taken():
    pts, r = spheres(300, 3, seed=3)
    vor = tessera.voronoi(pts, radii=r)
    assert vor.radii is r
    assert tessera.voronoi(pts).radii is None
    from_list = tessera.voronoi(pts, radii=r.tolist())
    from_f32 = tessera.voronoi(pts, radii=r.astype(np.float32))
    assert np.array_equal(from_list.volumes, vor.volumes)
    assert from_f32.radii.dtype == np.float64 and from_f32.power
    assert np.array_equal(from_f32.volumes, tessera.voronoi(pts, radii=r.astype(np.float32).astype(float)).volumes)
    strided = np.repeat(r, 2)[::2]  # not contiguous: converted
    assert np.array_equal(tessera.voronoi(pts, radii=strided).volumes, vor.volumes)
    ints = np.arange(300) % 2  # integer radii are numbers too
    assert tessera.voronoi(pts * 20, radii=ints).power


@pytest.mark.parametrize("dim", [2, 3])
def test_power_cells_are_the_same_for_any_thread_count_and_method_search(dim):
    pts, r = spheres(3000, dim, seed=30 + dim)
    one = tessera.voronoi(pts, radii=r, threads=1)
    many = tessera.voronoi(pts, radii=r, threads=4)
    assert np.array_equal(many.volumes, one.volumes)
    assert np.array_equal(many.neighbors, one.neighbors)
    assert np.array_equal(many.empty_cells, one.empty_cells)
    assert np.array_equal(many.face_vertices, one.face_vertices)
    # The automatic method chooses as without radii (2D: the insertion's
    # stars; 3D uniform points: the search); either way the same cells, the
    # volumes up to the clip order's last bits.
    assert one.from_insertion == (dim == 2)
    for method in ("search", "insertion"):
        v = tessera.voronoi(pts, radii=r, method=method)
        assert np.array_equal(v.neighbors, one.neighbors)
        assert np.array_equal(v.empty_cells, one.empty_cells)
        np.testing.assert_allclose(v.volumes, one.volumes, rtol=1e-10, atol=1e-15)


def test_coincident_points_the_largest_radius_owns_the_cell():
    pts = random_points(200, 3, seed=5)
    r = np.full(203, 0.01)
    r[:200] = np.random.default_rng(6).random(200) * 0.05
    pts = np.vstack([pts, pts[[5, 7, 9]]])  # ids 200, 201, 202 coincide with 5, 7, 9
    r[200], r[5] = 0.2, 0.1     # 200 is larger: it owns the cell, 5 duplicates it
    r[201], r[7] = 0.02, 0.02   # equal: the lowest id (7) owns it
    r[202], r[9] = 0.0, 0.03    # 9 is larger
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[3], radii=r)
    dup = dict(map(tuple, vor.duplicates.tolist()))
    assert dup[5] == 200 and dup[201] == 7 and dup[202] == 9
    assert vor.cell_of[5] == -1 and vor.cell_of[201] == -1 and vor.cell_of[202] == -1
    assert vor.validate().ok


def test_power_cells_with_labels_and_ignore_outside():
    pts, r = spheres(1500, 3, seed=7)
    lab = (pts[:, 0] > 0.5).astype(int)
    lab[np.linalg.norm(pts - 0.5, axis=1) < 0.15] = -1
    vor = tessera.voronoi(pts, labels=lab, bounds=UNIT_BOX[3], radii=r)
    assert vor.power and (vor.regions >= 0).all()
    assert (vor.regions == lab[vor.generators]).all()
    assert vor.validate().ok
    # Points outside the bounds dropped: the others' radii stay at their ids.
    moved = pts.copy()
    moved[:10, 0] += 2
    drop = tessera.voronoi(moved, bounds=UNIT_BOX[3], radii=r, ignore_outside=True)
    assert drop.ignored_outside_bounds.tolist() == list(range(10))
    ref = tessera.voronoi(pts[10:], bounds=UNIT_BOX[3], radii=r[10:])
    assert np.array_equal(drop.generators, ref.generators + 10)
    assert np.array_equal(drop.volumes, ref.volumes)
    assert drop.volumes.sum() == pytest.approx(1.0, rel=1e-12)
    assert drop.validate().ok


def test_merge_false_power_cells():
    pts, r = spheres(1000, 3, seed=8)
    full = tessera.voronoi(pts, bounds=UNIT_BOX[3], radii=r)
    lean = tessera.voronoi(pts, bounds=UNIT_BOX[3], radii=r, merge=False)
    assert lean.power and not lean.has_mesh
    assert np.array_equal(full.volumes, lean.volumes)
    assert np.array_equal(full.empty_cells, lean.empty_cells)
    assert lean.validate().ok


@pytest.mark.parametrize("dim", [2, 3])
def test_bad_radii_raise(dim):
    pts, r = spheres(100, dim, seed=9)
    box = UNIT_BOX[dim]
    with pytest.raises(ValueError, match=r"radii: expected one radius per point, shape \(100,\), got \(99,\)"):
        tessera.voronoi(pts, bounds=box, radii=r[:-1])
    with pytest.raises(ValueError, match=r"radii: expected one radius per point"):
        tessera.voronoi(pts, bounds=box, radii=r.reshape(-1, 1))
    with pytest.raises(ValueError, match=r"radii: expected one radius per point"):
        tessera.voronoi(pts, bounds=box, radii=0.1)
    with pytest.raises(ValueError, match="radii: expected real numbers"):
        tessera.voronoi(pts, bounds=box, radii=["a"] * 100)
    with pytest.raises(ValueError, match="radii: cannot be read"):
        tessera.voronoi(pts, bounds=box, radii=[[0.1], [0.1, 0.2]])
    for bad, shown in ((-0.5, "-0.5"), (np.nan, "NaN"), (np.inf, "inf")):
        rr = r.copy()
        rr[17] = bad
        with pytest.raises(tessera.InputError, match=f"radius of point 17 is {shown}.*finite and non-negative"):
            tessera.voronoi(pts, bounds=box, radii=rr)
    # The regular triangulation's stars give the search's cells.
    by_stars = tessera.voronoi(pts, bounds=box, radii=r, method="insertion")
    searched = tessera.voronoi(pts, bounds=box, radii=r, method="search")
    assert by_stars.from_insertion and not searched.from_insertion
    np.testing.assert_array_equal(by_stars.empty_cells, searched.empty_cells)
    np.testing.assert_allclose(by_stars.volumes, searched.volumes, rtol=1e-10, atol=1e-15)


def test_validate_cells_needs_the_radii_of_power_cells():
    pts, r = spheres(300, 3, seed=11)
    vor = tessera.voronoi(pts, radii=r)
    core = tessera._core
    assert core.validate_cells(vor._cells, None).ok  # no points: no exact measures, no radii needed
    assert core.validate_cells(vor._cells, None, pts, r).ok
    with pytest.raises(ValueError, match="power cells need their radii"):
        core.validate_cells(vor._cells, None, pts)
    with pytest.raises(ValueError, match="radii are not the ones"):
        core.validate_cells(vor._cells, None, pts, r[:-1])
    # Radii other than the cells' make the exact measures disagree.
    assert not core.validate_cells(vor._cells, None, pts, r * 0.5).ok


@pytest.mark.parametrize("dim", [2, 3])
def test_adjacency_and_faces_of_power_cells(dim):
    pts, r = spheres(800, dim, seed=40 + dim)
    box = UNIT_BOX[dim]
    vor = tessera.voronoi(pts, bounds=box, radii=r)
    assert vor.empty_cells.size > 0
    g = tessera.adjacency(pts, bounds=box, radii=r)
    assert g.voronoi.power and g.voronoi.radii is r
    ref = tessera.adjacency(vor)
    assert np.array_equal(g.wheel_offsets, ref.wheel_offsets) and np.array_equal(g.spokes, ref.spokes)
    wheel_sizes = np.diff(g.wheel_offsets)
    assert (wheel_sizes[vor.empty_cells] == 0).all()
    assert not np.isin(g.spokes, vor.empty_cells).any()
    e = g.edges()
    assert len(e) == len(vor.neighbors) // 2  # symmetric, no outside points
    fs = tessera.faces(pts, kind="complex", bounds=box, radii=r)
    fref = tessera.faces(vor, kind="complex")
    assert fs.voronoi.power
    assert np.array_equal(fs.face_vertices, fref.face_vertices) and np.array_equal(fs.sides, fref.sides)
    assert fs.n_faces == len(e) + int((vor.face_neighbor < 0).sum())
    bnd = tessera.faces(pts, bounds=box, radii=r)
    assert (bnd.sides[:, 1] < 0).all()
    # Equal radii: the ordinary cells' graph and faces.
    plain = tessera.adjacency(pts, bounds=box)
    same = tessera.adjacency(pts, bounds=box, radii=np.full(len(pts), 0.1))
    assert np.array_equal(plain.spokes, same.spokes) and not same.voronoi.power


def test_products_refuse_radii_for_a_computed_voronoi():
    pts, r = spheres(200, 3, seed=12)
    vor = tessera.voronoi(pts, radii=r)
    for fn, args in ((tessera.adjacency, ()), (tessera.faces, ("complex",))):
        with pytest.raises(ValueError, match="radii is for computing cells from points"):
            fn(vor, *args, radii=r)
    g = tessera.adjacency(pts, bounds=UNIT_BOX[3], radii=r, periodic=True)  # computed from points: taken
    assert g is not None
    with pytest.raises(ValueError, match="radii: expected one radius per point"):
        tessera.faces(pts, radii=r[:5])


def test_flower_refuses_power_cells():
    pts, r = spheres(200, 3, seed=13)
    vor = tessera.voronoi(pts, radii=r)
    gen = int(vor.generators[0])
    with pytest.raises(tessera.InputError, match=r"flowers of power cells \(radii\) are not supported"):
        tessera.flower(vor, [gen])
    with pytest.raises(TypeError):  # flower takes no radii to compute power cells with
        tessera.flower(pts, [gen], radii=r)
    # Equal radii are the ordinary cells: their flowers are drawn.
    same = tessera.voronoi(pts, radii=np.full(len(pts), 0.5))
    assert len(tessera.flower(same, [gen])) == 1


@pytest.mark.parametrize("dim", [2, 3])
def test_power_cells_scipy_view_and_files(tmp_path, dim):
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader

    pts, r = spheres(400, dim, seed=14)
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[dim], radii=r)
    assert vor.empty_cells.size > 0
    sv = vor.scipy
    assert (sv.point_region[vor.empty_cells] == -1).all()
    assert len(sv.regions) == vor.n_cells
    assert not np.isin(sv.ridge_points, vor.empty_cells).any()
    path = tmp_path / ("power.vtu" if dim == 3 else "power.vtp")
    vor.save(path)
    reader = vtkXMLUnstructuredGridReader() if dim == 3 else vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfCells() == vor.n_cells
    ids = vtk_to_numpy(data.GetCellData().GetArray("GeneratorId"))
    assert np.array_equal(ids, vor.generators)
    measure = vtk_to_numpy(data.GetCellData().GetArray("Volume" if dim == 3 else "Area"))
    assert measure.sum() == pytest.approx(1.0, rel=1e-12)
    assert vor.to_vtk().GetNumberOfCells() == vor.n_cells


@pytest.mark.parametrize("dim", [2, 3])
def test_power_cells_in_a_periodic_box(dim):
    """Power cells in periodic boxes (every image has its point's radius): they
    tile the box, validate (exact measures among the images), equal radii
    give the ordinary periodic cells, and the triclinic box works too."""
    pts, r = spheres(800, dim, seed=31)
    box = UNIT_BOX[dim]
    vor = tessera.voronoi(pts, bounds=box, radii=r, periodic=True)
    assert vor.power
    assert abs(vor.volumes.sum() - 1) < 1e-12
    assert vor.validate().ok
    mixed = tessera.voronoi(pts, bounds=box, radii=r, periodic="x")
    assert abs(mixed.volumes.sum() - 1) < 1e-12 and mixed.validate().ok
    same = tessera.voronoi(pts, bounds=box, radii=np.full(len(pts), 0.01), periodic=True)
    plain = tessera.voronoi(pts, bounds=box, periodic=True)
    assert not same.power
    np.testing.assert_array_equal(same.volumes, plain.volumes)
    np.testing.assert_array_equal(same.neighbors, plain.neighbors)
    tilt = (0.25,) if dim == 2 else (0.25, -0.125, 0.375)
    tri = tessera.voronoi(pts, bounds=box, radii=r, periodic=True, tilt=tilt)
    assert abs(tri.volumes.sum() - 1) < 1e-12 and tri.validate().ok
