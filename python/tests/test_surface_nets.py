"""surface_nets(): closed, consistently oriented region surfaces with the
documented BoundaryLabels; smoothing within its constraint; files; bad input."""

import threading
import time
from collections import Counter

import numpy as np
import pytest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

import tessera
from conftest import UNIT_BOX, random_points, sigint_after

CENTRES = {2: np.array([[0.35, 0.4], [0.65, 0.4], [0.5, 0.66]]),
           3: np.array([[0.35, 0.4, 0.5], [0.65, 0.4, 0.5], [0.5, 0.66, 0.5]])}


def spheres(n, dim, seed=0, radius=0.2, outside=-1):
    """Three overlapping (touching) balls labelled 0, 1, 2 by the nearest
    centre; points in no ball get `outside`."""
    pts = random_points(n, dim, seed)
    d = np.linalg.norm(pts[:, None, :] - CENTRES[dim][None], axis=2)
    lab = np.where(d.min(axis=1) < radius, d.argmin(axis=1), outside).astype(np.int32)
    return pts, lab


def oriented_faces(net, label):
    """Vertex loops of region `label`'s surface, each facing out of the region."""
    ids, flip = net.region_faces(label)
    return [net.face(f)[::-1] if rev else net.face(f) for f, rev in zip(ids, flip)]


def assert_closed(net, label):
    """Every directed edge of the region's faces appears once, with its twin:
    a closed surface, consistently oriented (2D: closed loops)."""
    edges = Counter()
    for loop in oriented_faces(net, label):
        pairs = zip(loop, loop[1:]) if net.ndim == 2 else zip(loop, np.roll(loop, -1))
        edges.update((int(a), int(b)) for a, b in pairs)
    assert edges, label
    assert max(edges.values()) == 1, label
    if net.ndim == 3:
        assert all(edges[(b, a)] == 1 for a, b in edges), label
    else:  # each vertex of a loop: one segment in, one out
        starts = Counter(a for a, _ in edges)
        ends = Counter(b for _, b in edges)
        assert starts == ends and max(starts.values()) == 1, label


def enclosed(net, label):
    total = 0.0
    for loop in oriented_faces(net, label):
        p = net.vertices[loop]
        if net.ndim == 2:
            total += 0.5 * (p[0, 0] * p[1, 1] - p[1, 0] * p[0, 1])
        else:
            total += np.einsum("ij,ij->", np.broadcast_to(p[0], p[1:-1].shape), np.cross(p[1:-1], p[2:])) / 6
    return total


NET_ARRAYS = ["vertices", "vertex_keys", "face_offsets", "face_vertices", "sides", "boundary_labels", "face_class",
              "vertex_kind", "polygon_of_face"]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("smooth", [0, 20])
def test_capped_region_surfaces_are_closed_and_enclose_the_cells(dim, smooth):
    pts, lab = spheres(20000 if dim == 3 else 4000, dim, seed=1)
    net = tessera.surface_nets(pts, lab, capping=True, smooth=smooth, bounds=UNIT_BOX[dim])
    assert net.selected == [0, 1, 2] and net.kind == "surface-net" and net.ndim == dim
    vor = tessera.voronoi(pts, labels=lab, bounds=UNIT_BOX[dim])
    assert net.n_cells == vor.n_cells
    for r in range(3):
        assert_closed(net, r)
        exact = vor.volumes[vor.regions == r].sum()
        if smooth == 0:
            assert enclosed(net, r) == pytest.approx(exact, rel=1e-10)
        else:
            assert enclosed(net, r) == pytest.approx(exact, rel=0.05)


def test_unsmoothed_net_is_the_surface_net_face_set():
    pts, lab = spheres(8000, 3, seed=2)
    net = tessera.surface_nets(pts, lab, smooth=0, capping=True)
    fs = tessera.faces(pts, labels=lab, kind="surface-net", capping=True)
    for name in ("vertices", "vertex_keys", "face_offsets", "face_vertices", "sides", "boundary_labels",
                 "face_class"):
        assert np.array_equal(getattr(net, name), getattr(fs, name)), name
    assert net.max_displacement == 0
    assert np.array_equal(net.polygon_of_face, np.arange(net.n_faces))


@pytest.mark.parametrize("capping", [False, True])
def test_boundary_labels_as_documented(capping):
    pts, lab = spheres(12000, 3, seed=3)
    net = tessera.surface_nets(pts, lab, capping=capping, background_label=-7)
    l0, l1 = net.boundary_labels.T
    s0, s1 = net.sides.T
    assert np.array_equal(l0, lab[s0]) and np.all(np.isin(l0, [0, 1, 2]))
    between = np.isin(l1, [0, 1, 2])
    assert np.all(l0[between] < l1[between])  # (lo, hi) between selected regions
    assert np.all(net.face_class[between] == tessera.REGION_BOUNDARY)
    assert {(0, 1), (0, 2), (1, 2)} <= set(zip(l0[between].tolist(), l1[between].tolist()))
    if not capping:
        assert np.all(between)
    else:
        cap = ~between
        assert np.any(cap)
        box = s1 < 0
        assert np.all(l1[box] == -7)  # the domain box side
        assert np.array_equal(l1[cap & ~box], lab[s1[cap & ~box]])  # an outside point's own label
        assert set(np.unique(l1[cap]).tolist()) <= {-1, -7}


def test_selection_makes_other_labels_outside():
    pts, lab = spheres(12000, 3, seed=4)
    net = tessera.surface_nets(pts, lab, select=[0, 2], capping=True)
    assert net.selected == [0, 2]
    l0, l1 = net.boundary_labels.T
    assert set(np.unique(l0).tolist()) == {0, 2}
    # Region 1's points clip as outside points; their faces carry label 1.
    assert 1 in set(l1.tolist())
    assert np.all(net.face_class[l1 == 1] == tessera.OUTSIDE)
    for r in (0, 2):
        assert_closed(net, r)
    only = tessera.surface_nets(pts, lab, select=1)
    assert only.n_faces == 0 and only.selected == [1]  # no second selected region, no capping


def test_smoothing_respects_its_constraint_and_fixes_corners():
    pts, lab = spheres(15000, 3, seed=5)
    raw = tessera.surface_nets(pts, lab, smooth=0, capping=True)
    keys = raw.vertex_keys
    gen = keys[np.arange(len(keys)), np.argmax(keys >= 0, axis=1)]  # a generator of each vertex
    spacing = np.linalg.norm(raw.vertices - pts[gen], axis=1)
    for constraint in (0.1, 0.5):
        net = tessera.surface_nets(pts, lab, capping=True, smooth=30, constraint=constraint)
        assert np.array_equal(net.vertex_keys, keys)
        moved = np.linalg.norm(net.vertices - raw.vertices, axis=1)
        assert np.all(moved <= constraint * spacing * (1 + 1e-9) + 1e-15)
        assert net.max_displacement == pytest.approx(moved.max(), rel=1e-12)
        assert moved.max() > 0
        assert np.all(moved[net.vertex_kind == tessera.NET_CORNER] == 0)
        assert np.all(np.isin(net.vertex_kind, [tessera.NET_SURFACE, tessera.NET_JUNCTION, tessera.NET_CORNER]))
        assert np.any(net.vertex_kind == tessera.NET_JUNCTION)  # the three balls meet along a curve
    absolute = tessera.surface_nets(pts, lab, capping=True, constraint=1e-3, constraint_is_absolute=True)
    assert np.all(np.linalg.norm(absolute.vertices - raw.vertices, axis=1) <= 1e-3 * (1 + 1e-9))


def test_triangles_split_the_polygons():
    pts, lab = spheres(8000, 3, seed=6)
    poly = tessera.surface_nets(pts, lab, smooth=0, capping=True)
    tri = tessera.surface_nets(pts, lab, smooth=0, capping=True, triangles=True)
    assert tri.triangles and np.all(np.diff(tri.face_offsets) == 3)
    assert tri.n_faces == len(poly.face_vertices) - 2 * poly.n_faces
    src = tri.polygon_of_face
    assert np.array_equal(np.bincount(src, minlength=poly.n_faces), np.diff(poly.face_offsets) - 2)
    assert np.array_equal(tri.boundary_labels, poly.boundary_labels[src])
    assert np.array_equal(tri.sides, poly.sides[src])
    assert np.array_equal(tri.vertices, poly.vertices)
    for r in range(3):
        assert_closed(tri, r)
        assert enclosed(tri, r) == pytest.approx(enclosed(poly, r), rel=1e-10)


def test_surface_net_vtp_read_by_vtk(tmp_path):
    pts, lab = spheres(6000, 3, seed=7)
    net = tessera.surface_nets(pts, lab, capping=True, triangles=True)
    net.save(tmp_path / "net.vtp")
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "net.vtp"))
    reader.Update()
    data = reader.GetOutput()
    assert np.array_equal(vtk_to_numpy(data.GetPoints().GetData()), net.vertices)
    assert data.GetNumberOfPolys() == net.n_faces
    assert np.array_equal(vtk_to_numpy(data.GetPolys().GetConnectivityArray()), net.face_vertices)
    cd, pd = data.GetCellData(), data.GetPointData()
    assert np.array_equal(vtk_to_numpy(cd.GetArray("BoundaryLabels")), net.boundary_labels)
    assert np.array_equal(vtk_to_numpy(cd.GetArray("Sides")), net.sides)
    assert np.array_equal(vtk_to_numpy(cd.GetArray("SpokeClass")), net.face_class)
    assert np.array_equal(vtk_to_numpy(cd.GetArray("PolygonId")), net.polygon_of_face)
    assert np.array_equal(vtk_to_numpy(pd.GetArray("VertexKind")), net.vertex_kind)
    mem = net.to_vtk()
    assert mem.GetNumberOfPolys() == net.n_faces
    for name in ("BoundaryLabels", "PolygonId"):
        assert np.array_equal(vtk_to_numpy(mem.GetCellData().GetArray(name)), vtk_to_numpy(cd.GetArray(name)))
    assert np.array_equal(vtk_to_numpy(mem.GetPointData().GetArray("VertexKind")), net.vertex_kind)


def test_2d_net_saves_lines(tmp_path):
    pts, lab = spheres(3000, 2, seed=8)
    net = tessera.surface_nets(pts, lab, capping=True)
    net.save(str(tmp_path / "net2d.vtp"))
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "net2d.vtp"))
    reader.Update()
    assert reader.GetOutput().GetNumberOfLines() == net.n_faces == net.to_vtk().GetNumberOfLines()


@pytest.mark.parametrize("dim", [2, 3])
def test_periodic_nets_close_up_across_the_box(dim, tmp_path):
    # Three bands across x + y that wrap around a periodic (triclinic in 3D)
    # box: with copies of a vertex identified by their keys up to a common
    # shift, every region's surface is closed, oriented, and the copies stay
    # lattice translations apart after smoothing; the .vtp has SideShift.
    rng = np.random.default_rng(21)
    pts = np.ldexp(np.floor(np.ldexp(rng.random((800, dim)) * (1 - 2e-6) + 1e-6, 30)), -30)
    lab = (np.floor(3 * (pts[:, 0] + pts[:, 1])) % 3).astype(np.int32)
    tilt = (0.25, 0.0, -0.125) if dim == 3 else None
    net = tessera.surface_nets(pts, lab, bounds=UNIT_BOX[dim], periodic=True, tilt=tilt)
    assert net.periodic == (True,) * dim and net.side_shifts.shape == (net.n_faces, dim)
    keys, shifts = net.vertex_keys, net.vertex_key_shifts.astype(int)
    lead = shifts[:, 0, :]  # no walls: every entry is a point
    canon = {}
    group = np.array([canon.setdefault((tuple(k), tuple((s - t).ravel())), len(canon))
                      for k, s, t in zip(keys.tolist(), shifts, lead)])
    lattice = np.eye(dim)
    if dim == 3:
        lattice[1, 0], lattice[2, 0], lattice[2, 1] = 0.25, 0.0, -0.125
    first = {}
    for v, g in enumerate(group):
        first.setdefault(g, v)
    for v, g in enumerate(group):
        f = first[g]
        np.testing.assert_allclose(net.vertices[v], net.vertices[f] + (lead[v] - lead[f]) @ lattice, rtol=0, atol=1e-15)
    for label in (0, 1, 2):
        edges = Counter()
        for loop in oriented_faces(net, label):
            pairs = zip(loop, loop[1:]) if dim == 2 else zip(loop, np.roll(loop, -1))
            for a, b in pairs:
                edges[(group[a], group[b], tuple(lead[b] - lead[a]))] += 1
        assert edges and max(edges.values()) == 1, label
        if dim == 3:
            assert all(edges[(b, a, tuple(-x for x in d))] == 1 for a, b, d in edges), label
        else:
            assert Counter(a for a, _, _ in edges) == Counter(b for _, b, _ in edges), label
    net.save(str(tmp_path / "net.vtp"))
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / "net.vtp"))
    reader.Update()
    side = vtk_to_numpy(reader.GetOutput().GetCellData().GetArray("SideShift"))
    assert np.array_equal(side.reshape(net.side_shifts.shape), net.side_shifts)


def test_net_arrays_are_read_only_views():
    pts, lab = spheres(4000, 3, seed=9)
    net = tessera.surface_nets(pts, lab, capping=True)
    for name in NET_ARRAYS:
        a = getattr(net, name)
        assert a.size > 0 and not a.flags.owndata and not a.flags.writeable, name
        assert isinstance(a.base, tessera._core.SurfaceNet), name
        assert a.__array_interface__["data"][0] == getattr(net, name).__array_interface__["data"][0], name


def test_threads_1_and_2_give_identical_nets():
    pts, lab = spheres(30000, 3, seed=10)
    a, b = (tessera.surface_nets(pts, lab, capping=True, triangles=True, threads=t) for t in (1, 2))
    for name in NET_ARRAYS:
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), name


def test_the_gil_is_released_during_surface_nets():
    pts, lab = spheres(200_000, 3, seed=13, radius=0.3)
    stamps = []
    stop = threading.Event()

    def spin():  # runs only while nobody holds the GIL
        while not stop.is_set():
            stamps.append(time.perf_counter())
            for _ in range(100):
                pass

    t = threading.Thread(target=spin)
    t.start()
    try:
        t0 = time.perf_counter()
        tessera.surface_nets(pts, lab, capping=True, threads=1)
        t1 = time.perf_counter()
    finally:
        stop.set()
        t.join()
    assert t1 - t0 > 0.1
    margin = 0.2 * (t1 - t0)
    assert len([s for s in stamps if t0 + margin < s < t1 - margin]) > 100


class Interrupted(Exception):
    pass


def test_ctrl_c_interrupts_surface_nets():
    pts, lab = spheres(300_000, 3, seed=11, radius=0.3)

    def handler(signum, frame):
        raise Interrupted()

    with sigint_after(0.3, handler):
        t0 = time.perf_counter()
        with pytest.raises(Interrupted):
            tessera.surface_nets(pts, lab, threads=1)
        elapsed = time.perf_counter() - t0
    assert elapsed < 3.0


# ----------------------------------------------------------------- bad input

PTS, LAB = spheres(3000, 3, seed=12)

BAD = {
    "no labels": (dict(labels=None), r"labels: surface nets need one region label per point"),
    "labels length": (dict(labels=LAB[:-1]), r"labels: expected one label per point, shape \(3000,\)"),
    "labels float": (dict(labels=LAB.astype(float)), r"labels: expected integers"),
    "all outside": (dict(labels=np.full(3000, -1)), r"every point is outside|empty selection"),
    "unknown label": (dict(select=[0, 5]), r"unknown label 5: no point carries it"),
    "negative select": (dict(select=[-1]), r"selected label -1 is negative"),
    "empty select": (dict(select=[]), r"select: empty selection"),
    "select float": (dict(select=[0.5]), r"select: expected an integer or a sequence of integers"),
    "background label": (dict(background_label=0), r"background_label: expected a negative integer"),
    "smooth negative": (dict(smooth=-1), r"smooth: expected a number of iterations >= 0"),
    "smooth float": (dict(smooth=2.5), r"smooth: expected a number of iterations"),
    "relax zero": (dict(relax=0), r"relax: expected a number in \(0, 1\]"),
    "relax big": (dict(relax=1.5), r"relax: expected a number in \(0, 1\]"),
    "constraint negative": (dict(constraint=-0.1), r"constraint: expected a finite number >= 0"),
    "constraint inf": (dict(constraint=np.inf), r"constraint: expected a finite number >= 0"),
    "points shape": (dict(points=PTS[:, :1]), r"points: expected shape \(N, 2\) or \(N, 3\)"),
    "points NaN": (dict(points=np.where(np.arange(3000)[:, None] == 9, np.nan, PTS)), r"point 9 has a NaN"),
    "bounds": (dict(bounds=(0, 1, 0, 1)), r"bounds: expected 6 numbers"),
    "threads": (dict(threads=0), r"threads: expected a positive integer"),
    "periodic without bounds": (dict(periodic=True), r"periodic: give bounds"),
    "tilt without periodic": (dict(bounds=(0, 1, 0, 1, 0, 1), tilt=(0.1, 0, 0)), r"tilt: give periodic axes"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_raises_value_error(case):
    kwargs, message = BAD[case]
    args = dict(points=PTS, labels=LAB)
    args.update(kwargs)
    with pytest.raises(ValueError, match=message):
        tessera.surface_nets(**args)


def test_save_needs_vtp(tmp_path):
    net = tessera.surface_nets(PTS, LAB)
    with pytest.raises(ValueError, match=r"save: a surface net is written as VTK PolyData \(\.vtp\)"):
        net.save(tmp_path / "net.vtu")


def test_far_from_the_origin_the_net_still_smooths():
    """Rounding sets vertices that should coincide ulps apart, so the raw net
    of a box far from the origin with anisotropic voxels overlaps itself by
    ulps; the untangling counted those as crossings that pinning could not
    undo, and kept every vertex unsmoothed (largest move 0). Such pairs are
    left alone now, and the net smooths as it did before the check."""
    box = np.zeros((32, 32, 32), np.int32)
    box[8:24, 6:20, 10:26] = 1
    for capping in (True, False):
        pts, labels = tessera.sample_image(box, spacing=(0.1, 0.2, 0.3), origin=(1e6, 1e6, 1e6))
        net = tessera.surface_nets(pts, labels, capping=capping, triangles=True)
        assert net.max_displacement > 0.05, capping
