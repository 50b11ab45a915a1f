"""adjacency(), faces() and flower(): the products read off the merged mesh.

meshio 5.0 (Debian) has no reader for VTK PolyData (.vtp), the only format the
library writes these products in, so the files are read back with VTK only
(see also test_files.py).
"""

import gc

import numpy as np
import pytest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader

import tessera
from conftest import UNIT_BOX, random_points

BOX_PLANES = 6


def labelled(n, dim, seed=0, outside=True):
    """Points in the unit box with three regions by x, and (optionally) outside
    points (label -1) in a ball that carves a hole."""
    pts = random_points(n, dim, seed)
    lab = np.minimum((pts[:, 0] * 3).astype(int), 2)
    if outside:
        lab[np.linalg.norm(pts - 0.5, axis=1) < 0.2] = -1
    return pts, lab


def read_vtp(path):
    reader = vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def cell_data(data, name):
    return vtk_to_numpy(data.GetCellData().GetArray(name))


def spoke_table(g):
    """(source, target, class, measure) of every spoke."""
    src = np.repeat(np.arange(g.n_points), np.diff(g.wheel_offsets))
    return src, g.spokes, g.spoke_class, g.spoke_measure


def enclosed(fs, faces=None, flip=None):
    """Signed volume (3D, divergence theorem) or area (2D, shoelace) enclosed by
    faces (all by default), each reversed where `flip` is set."""
    faces = np.arange(fs.n_faces) if faces is None else np.asarray(faces)
    flip = np.zeros(len(faces), bool) if flip is None else np.asarray(flip)
    v = fs.vertices
    total = 0.0
    for f, rev in zip(faces, flip):
        ids = fs.face(f)
        p = v[ids[::-1] if rev else ids]
        if fs.ndim == 2:
            total += 0.5 * (p[0, 0] * p[1, 1] - p[1, 0] * p[0, 1])
        else:
            total += np.einsum("ij,ij->", np.broadcast_to(p[0], p[1:-1].shape), np.cross(p[1:-1], p[2:])) / 6
    return total


# ----------------------------------------------------------------- the graph

@pytest.mark.parametrize("dim", [2, 3])
def test_graph_is_symmetric_and_equals_the_cell_neighbours(dim):
    pts, lab = labelled(2000, dim)
    vor = tessera.voronoi(pts, labels=lab)
    g = tessera.adjacency(vor)
    assert g.voronoi is vor and g.n_points == len(pts) and g.ndim == dim
    assert g.wheel_offsets.shape == (len(pts) + 1,) and g.wheel_offsets[-1] == g.n_spokes
    # Every cell's wheel: its box planes (negative), then exactly vor.neighbors.
    for c, p in enumerate(vor.generators):
        w = g.wheel(p)
        assert np.array_equal(w[w >= 0], vor.cell_neighbors(c))
        assert np.all(np.diff(w) > 0) and np.all(w[w < 0] >= -2 * dim)
    # Points without a cell (the outside points) have empty wheels.
    assert np.all(np.diff(g.wheel_offsets)[vor.cell_of < 0] == 0)
    # Cell-cell spokes come in twins with the same face measure.
    src, dst, cls, meas = spoke_table(g)
    cc = (dst >= 0) & (cls != tessera.OUTSIDE)
    fwd = {(a, b): m for a, b, m in zip(src[cc], dst[cc], meas[cc])}
    assert all(fwd[(b, a)] == m for (a, b), m in fwd.items())
    # Classes: box planes are DOMAIN_BOUNDARY, outside points OUTSIDE, cells by region.
    assert np.all(cls[dst < 0] == tessera.DOMAIN_BOUNDARY)
    assert np.all(cls[(dst >= 0)] == np.where(lab[dst[dst >= 0]] < 0, tessera.OUTSIDE,
                                              np.where(lab[dst[dst >= 0]] == lab[src[dst >= 0]],
                                                       tessera.SAME_REGION, tessera.REGION_BOUNDARY)))
    assert np.all(meas > 0)


def test_graph_edges_one_per_face_between_generators():
    pts, lab = labelled(1500, 3, seed=1)
    g = tessera.adjacency(pts, labels=lab)
    src, dst, cls, _ = spoke_table(g)
    ends = g.edges()
    assert ends.shape[1] == 2 and ends.dtype == np.int32
    n_cell_cell = np.count_nonzero((dst >= 0) & (cls != tessera.OUTSIDE))
    n_outside = np.count_nonzero(cls == tessera.OUTSIDE)
    assert len(ends) == n_cell_cell // 2 + n_outside
    # Each edge is its spoke; cell-cell edges go from the lower id to the higher.
    assert np.array_equal(ends[:, 0], src[g.edge_spokes]) and np.array_equal(ends[:, 1], dst[g.edge_spokes])
    cc = cls[g.edge_spokes] != tessera.OUTSIDE
    assert np.all(ends[cc, 0] < ends[cc, 1])
    assert len({tuple(e) for e in ends.tolist()}) == len(ends)


def test_graph_of_points_equals_graph_of_their_voronoi():
    pts = random_points(800, 3, seed=2)
    a = tessera.adjacency(pts, bounds=UNIT_BOX[3])
    b = tessera.adjacency(tessera.voronoi(pts, bounds=UNIT_BOX[3]))
    for name in ("wheel_offsets", "spokes", "spoke_class", "spoke_measure"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_prune_tolerance_drops_small_faces_symmetrically():
    pts = random_points(2000, 3, seed=3)
    full = tessera.adjacency(pts)
    pruned = tessera.adjacency(pts, prune_tolerance=0.05)
    assert full.pruned_spokes == 0 and full.prune_threshold == 0
    assert pruned.pruned_spokes > 0 and pruned.prune_threshold > 0
    assert pruned.n_spokes == full.n_spokes - pruned.pruned_spokes
    assert np.all(pruned.spoke_measure >= pruned.prune_threshold)
    src, dst, _, _ = spoke_table(pruned)
    pairs = set(zip(src[dst >= 0].tolist(), dst[dst >= 0].tolist()))
    assert all((b, a) in pairs for a, b in pairs)


def test_graph_vtp_read_by_vtk(tmp_path):
    pts, lab = labelled(600, 3, seed=4)
    g = tessera.adjacency(pts, labels=lab)
    g.save(tmp_path / "graph.vtp")
    data = read_vtp(tmp_path / "graph.vtp")
    assert np.array_equal(vtk_to_numpy(data.GetPoints().GetData()), pts)
    assert data.GetNumberOfLines() == len(g.edges())
    conn = vtk_to_numpy(data.GetLines().GetConnectivityArray()).reshape(-1, 2)
    assert np.array_equal(conn, g.edges())
    assert np.array_equal(vtk_to_numpy(data.GetPointData().GetArray("Region")), lab)
    assert np.array_equal(cell_data(data, "SpokeClass"), g.spoke_class[g.edge_spokes])
    assert np.array_equal(cell_data(data, "FaceArea"), g.spoke_measure[g.edge_spokes])
    mem = g.to_vtk()
    assert mem.GetNumberOfLines() == data.GetNumberOfLines()
    assert np.array_equal(vtk_to_numpy(mem.GetLines().GetConnectivityArray()).reshape(-1, 2), conn)
    for name in ("SpokeClass", "FaceArea"):
        assert np.array_equal(cell_data(mem, name), cell_data(data, name))


def test_graph_of_periodic_cells(tmp_path):
    # Spokes lead to images: the wheels are the cells' neighbour entries with
    # their shifts; edges list each face once; the .vtp (and to_vtk) end
    # lines to images at extra points placed there.
    pts = random_points(500, 3, seed=12)
    tilt = (0.25, 0.0, -0.125)
    v = tessera.voronoi(pts, bounds=UNIT_BOX[3], periodic=True, tilt=tilt)
    g = tessera.adjacency(v)
    assert np.array_equal(g.spokes, v.neighbors) and np.array_equal(g.spoke_shifts, v.neighbor_shifts)
    assert 2 * len(g.edges()) == g.n_spokes and g.edge_shifts.shape == (len(g.edges()), 3)
    lattice = np.array([[1.0, 0, 0], [v.tilt[0], 1, 0], [v.tilt[1], v.tilt[2], 1]])
    g.save(tmp_path / "graph.vtp")
    data = read_vtp(tmp_path / "graph.vtp")
    xyz = vtk_to_numpy(data.GetPoints().GetData())
    pid = vtk_to_numpy(data.GetPointData().GetArray("PointId"))
    conn = vtk_to_numpy(data.GetLines().GetConnectivityArray()).reshape(-1, 2)
    wrapped = v.periodic_points
    assert np.array_equal(xyz[:500], wrapped)
    ends = g.edges()
    assert np.array_equal(conn[:, 0], ends[:, 0]) and np.array_equal(pid[conn[:, 1]], ends[:, 1])
    np.testing.assert_allclose(xyz[conn[:, 1]], wrapped[ends[:, 1]] + g.edge_shifts @ lattice, rtol=0, atol=1e-15)
    mem = g.to_vtk()
    assert np.array_equal(vtk_to_numpy(mem.GetLines().GetConnectivityArray()).reshape(-1, 2), conn)
    plain = tessera.adjacency(tessera.voronoi(pts, bounds=UNIT_BOX[3]))
    assert plain.spoke_shifts.size == 0 and plain.edge_shifts.size == 0


# ----------------------------------------------------------------- face sets

@pytest.mark.parametrize("dim", [2, 3])
def test_face_counts_match_the_graph(dim):
    pts, lab = labelled(1500, dim, seed=5)
    vor = tessera.voronoi(pts, labels=lab)
    g = tessera.adjacency(vor)
    _, dst, cls, _ = spoke_table(g)
    n_box = np.count_nonzero(dst < 0)
    n_out = np.count_nonzero(cls == tessera.OUTSIDE)
    n_same = np.count_nonzero(cls == tessera.SAME_REGION)
    n_iface = np.count_nonzero(cls == tessera.REGION_BOUNDARY)
    assert n_same % 2 == 0 and n_iface % 2 == 0
    counts = {
        ("boundary", False): n_box + n_out,
        ("complex", False): n_box + n_out + (n_same + n_iface) // 2,
        ("surface-net", False): n_iface // 2,
        ("surface-net", True): n_iface // 2 + n_box + n_out,
    }
    for (kind, capping), n in counts.items():
        fs = tessera.faces(vor, kind=kind, capping=capping)
        assert fs.n_faces == n, (kind, capping)
        assert fs.kind == kind and fs.ndim == dim
        assert fs.face_offsets[-1] == len(fs.face_vertices)
        if dim == 2:
            assert np.all(np.diff(fs.face_offsets) == 2)
        else:
            assert np.all(np.diff(fs.face_offsets) >= 3)
        # Face classes agree with the graph's, face for face.
        assert np.count_nonzero(fs.face_class == tessera.REGION_BOUNDARY) == (n_iface // 2 if kind != "boundary" else 0)


@pytest.mark.parametrize("dim", [2, 3])
def test_boundary_faces_enclose_the_cells(dim):
    # Without outside points: exactly the box, outward.
    pts = random_points(1000, dim, seed=6)
    fs = tessera.faces(pts, bounds=UNIT_BOX[dim])
    assert enclosed(fs) == pytest.approx(1.0, rel=1e-12)
    assert np.all(fs.sides[:, 1] < 0) and np.all(fs.face_class == tessera.DOMAIN_BOUNDARY)
    # With a carved hole: the union of the cells (box minus the hole's cells).
    pts, lab = labelled(3000, dim, seed=7)
    vor = tessera.voronoi(pts, labels=lab, bounds=UNIT_BOX[dim])
    fs = tessera.faces(vor, kind="boundary")
    assert np.any(fs.face_class == tessera.OUTSIDE)
    assert enclosed(fs) == pytest.approx(vor.volumes.sum(), rel=1e-12)
    assert vor.volumes.sum() < 0.99


@pytest.mark.parametrize("dim", [2, 3])
def test_capped_surface_net_encloses_every_region(dim):
    pts, lab = labelled(3000, dim, seed=8)
    vor = tessera.voronoi(pts, labels=lab, bounds=UNIT_BOX[dim])
    fs = tessera.faces(vor, kind="surface-net", capping=True)
    bl = fs.boundary_labels
    for r in range(3):
        # Region r's surface: its faces on side 0, and reversed those on side 1.
        mine = np.flatnonzero((bl[:, 0] == r) | (bl[:, 1] == r))
        vol = enclosed(fs, mine, bl[mine, 1] == r)
        assert vol == pytest.approx(vor.volumes[vor.regions == r].sum(), rel=1e-10), r


@pytest.mark.parametrize("kind", ["boundary", "complex", "surface-net"])
def test_boundary_labels_and_sides_as_documented(kind):
    pts, lab = labelled(1500, 3, seed=9)
    lab[lab == 2] = 7  # labels need not be consecutive
    vor = tessera.voronoi(pts, labels=lab)
    fs = tessera.faces(vor, kind=kind, background_label=-9)
    s0, s1 = fs.sides.T
    l0, l1 = fs.boundary_labels.T
    assert np.all(vor.cell_of[s0] >= 0) and np.array_equal(l0, lab[s0]) and np.all(l0 >= 0)
    box = s1 < 0
    assert np.all(l1[box] == -9) and np.all(fs.face_class[box] == tessera.DOMAIN_BOUNDARY)
    nb = ~box
    assert np.array_equal(l1[nb], lab[s1[nb]])  # a cell's region or an outside point's own label
    cc = nb & (lab[np.where(nb, s1, 0)] >= 0)
    # Between two cells side 0 has the smaller (label, generator).
    assert np.all((l0[cc] < l1[cc]) | ((l0[cc] == l1[cc]) & (s0[cc] < s1[cc])))
    assert np.array_equal(fs.face_class[cc] == tessera.REGION_BOUNDARY, l0[cc] != l1[cc])
    assert np.all(fs.face_class[nb & ~cc] == tessera.OUTSIDE)
    # Orientation: the polygon's normal points from side 0's generator to side 1.
    for f in np.flatnonzero(cc)[:300]:
        p = fs.vertices[fs.face(f)]
        normal = np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(axis=0)
        assert normal @ (pts[s1[f]] - pts[s0[f]]) > 0


def test_faces_vtp_read_by_vtk(tmp_path):
    pts, lab = labelled(800, 3, seed=10)
    fs = tessera.faces(pts, labels=lab, kind="surface-net", capping=True)
    fs.save(str(tmp_path / "net.vtp"))
    data = read_vtp(tmp_path / "net.vtp")
    assert np.array_equal(vtk_to_numpy(data.GetPoints().GetData()), fs.vertices)
    assert data.GetNumberOfPolys() == fs.n_faces
    assert np.array_equal(vtk_to_numpy(data.GetPolys().GetConnectivityArray()), fs.face_vertices)
    assert np.array_equal(vtk_to_numpy(data.GetPolys().GetOffsetsArray()), fs.face_offsets)
    assert np.array_equal(cell_data(data, "BoundaryLabels"), fs.boundary_labels)
    assert np.array_equal(cell_data(data, "Sides"), fs.sides)
    assert np.array_equal(cell_data(data, "SpokeClass"), fs.face_class)
    mem = fs.to_vtk()
    assert mem.GetNumberOfPolys() == fs.n_faces
    for name in ("BoundaryLabels", "Sides", "SpokeClass"):
        assert np.array_equal(cell_data(mem, name), cell_data(data, name))


@pytest.mark.parametrize("dim", [2, 3])
def test_faces_of_periodic_cells(tmp_path, dim):
    # A periodic box (triclinic in 3D): the complex lists each face once,
    # and with its twin each neighbour entry (j, s) of the cells; every
    # corner lies on the bisector of side 0's point and side 1's image;
    # the .vtp and to_vtk carry SideShift.
    pts = random_points(300, dim, seed=14)
    tilt = (0.25, 0.0, -0.125) if dim == 3 else (0.375,)
    v = tessera.voronoi(pts, bounds=UNIT_BOX[dim], periodic=True, tilt=tilt, merge=True)
    fs = tessera.faces(v, kind="complex")
    assert fs.periodic == (True,) * dim and fs.side_shifts.shape == (fs.n_faces, dim)
    assert fs.vertex_key_shifts.shape == (fs.n_vertices, dim + 1, dim)
    faces = set()
    for (i, j), s in zip(fs.sides.tolist(), fs.side_shifts.tolist()):
        faces |= {(i, j, tuple(s)), (j, i, tuple(-x for x in s))}
    entries = set()
    for c in range(v.n_cells):
        for e in range(v.neighbor_offsets[c], v.neighbor_offsets[c + 1]):
            entries.add((int(v.generators[c]), int(v.neighbors[e]), tuple(v.neighbor_shifts[e].tolist())))
    assert faces == entries and 2 * fs.n_faces == len(v.neighbors)
    lattice = np.eye(dim)
    lattice[1, 0] = v.tilt[0]
    if dim == 3:
        lattice[2, :2] = v.tilt[1:]
    p = v.periodic_points
    for f in range(fs.n_faces):
        i, j = fs.sides[f]
        image = p[j] + fs.side_shifts[f] @ lattice
        x = fs.vertices[fs.face(f)]
        np.testing.assert_allclose(np.linalg.norm(x - p[i], axis=1), np.linalg.norm(x - image, axis=1), atol=1e-12)
    fs.save(str(tmp_path / "faces.vtp"))
    data = read_vtp(tmp_path / "faces.vtp")
    assert np.array_equal(cell_data(data, "SideShift"), fs.side_shifts)
    assert np.array_equal(cell_data(fs.to_vtk(), "SideShift"), fs.side_shifts)
    plain = tessera.faces(tessera.voronoi(pts, bounds=UNIT_BOX[dim], merge=True), kind="complex")
    assert plain.side_shifts.size == 0 and plain.vertex_key_shifts.size == 0
    # From points, with the box's options: the same faces.
    direct = tessera.faces(pts, kind="complex", bounds=UNIT_BOX[dim], periodic=True, tilt=tilt)
    assert np.array_equal(direct.face_vertices, fs.face_vertices) and np.array_equal(direct.side_shifts, fs.side_shifts)
    assert np.array_equal(tessera.adjacency(pts, bounds=UNIT_BOX[dim], periodic=True, tilt=tilt).spoke_shifts,
                          tessera.adjacency(v).spoke_shifts)
    assert np.array_equal(tessera.flower(pts, [3], bounds=UNIT_BOX[dim], periodic=True, tilt=tilt)[0].face_shifts,
                          tessera.flower(v, [3])[0].face_shifts)
    with pytest.raises(ValueError, match="periodic"):
        tessera.faces(v, kind="complex", periodic=True)
    with pytest.raises(ValueError, match="periodic: give bounds"):
        tessera.faces(pts, kind="complex", periodic=True)


def test_flowers_of_periodic_cells(tmp_path):
    # The flower of a periodic cell: its site is the point as wrapped, its
    # neighbours sit at the images across its faces (shifts as the cells'),
    # and the saved flower draws them there.
    pts = random_points(300, 3, seed=15)
    v = tessera.voronoi(pts, bounds=UNIT_BOX[3], periodic=True, merge=True)
    fl = tessera.flower(v, [0, 7])
    for f in fl:
        g = f.generator
        np.testing.assert_array_equal(f.site, v.periodic_points[g])
        off = v.neighbor_offsets
        assert np.array_equal(f.neighbor_shifts, v.neighbor_shifts[off[v.cell_of[g]]:off[v.cell_of[g] + 1]])
        np.testing.assert_allclose(f.neighbor_positions, v.periodic_points[f.neighbors] + f.neighbor_shifts,
                                   rtol=0, atol=1e-15)
        assert f.face_shifts.shape == (len(f.face_neighbor), 3)
        assert np.all(np.linalg.norm(f.neighbor_positions - f.site, axis=1) <= f.circumflower_radius)
    fl.save(str(tmp_path / "fl.vtp"))
    data = read_vtp(tmp_path / "fl.vtp")
    xyz = vtk_to_numpy(data.GetPoints().GetData())
    role = vtk_to_numpy(data.GetPointData().GetArray("Role"))
    np.testing.assert_array_equal(xyz[role == 2], np.concatenate([f.neighbor_positions for f in fl]))
    plain = tessera.flower(tessera.voronoi(pts, bounds=UNIT_BOX[3], merge=True), [0])[0]
    assert plain.neighbor_shifts.size == 0 and np.array_equal(plain.neighbor_positions, pts[plain.neighbors])


def test_2d_faces_vtp_are_lines(tmp_path):
    pts, lab = labelled(500, 2, seed=11)
    fs = tessera.faces(pts, labels=lab, kind="complex")
    fs.save(tmp_path / "complex.vtp")
    data = read_vtp(tmp_path / "complex.vtp")
    assert data.GetNumberOfLines() == fs.n_faces and data.GetNumberOfPolys() == 0
    xyz = vtk_to_numpy(data.GetPoints().GetData())
    assert np.array_equal(xyz[:, :2], fs.vertices) and np.all(xyz[:, 2] == 0)
    assert fs.to_vtk().GetNumberOfLines() == fs.n_faces


# ------------------------------------------------------------------- flowers

@pytest.mark.parametrize("dim", [2, 3])
def test_flower_petals_and_circumflower(dim):
    pts = random_points(500, dim, seed=12)
    vor = tessera.voronoi(pts)
    ids = [0, 17, 499]
    fl = tessera.flower(vor, ids)
    assert len(fl) == 3 and fl.ids == ids
    for p, f in zip(ids, fl):
        c = vor.cell_of[p]
        assert f.generator == p and np.array_equal(f.site, pts[p])
        assert np.array_equal(f.petal_centres, vor.vertices[f.vertex_ids])
        assert np.allclose(f.petal_radii, np.linalg.norm(f.petal_centres - pts[p], axis=1), rtol=1e-12)
        assert f.circumflower_radius == 2 * f.petal_radii.max()
        assert np.array_equal(f.neighbors, vor.cell_neighbors(c))
        # The cell's faces, over petal indices, are the Voronoi result's.
        faces = [f.vertex_ids[f.face_vertices[a:b]] for a, b in zip(f.face_offsets[:-1], f.face_offsets[1:])]
        assert [x.tolist() for x in faces] == [x.tolist() for x in vor.cell_faces(c)]
        # Every clipping neighbour lies within the circumflower.
        assert np.all(np.linalg.norm(pts[f.neighbors] - pts[p], axis=1) <= f.circumflower_radius)
    assert tessera.flower(pts, 17)[0].n_petals == fl[1].n_petals


FLOWER_FIELDS = ["petal_centres", "petal_radii", "face_offsets", "face_vertices", "face_neighbor", "neighbors",
                 "neighbor_positions", "neighbor_shifts", "face_shifts"]


def _lattice(k, dim):
    g = np.arange(k) * 0.125
    return np.array(np.meshgrid(*[g] * dim, indexing="ij")).reshape(dim, -1).T.copy()


def _dup(pts):
    pts = pts.copy()
    pts[9] = pts[4]  # 9 duplicates 4, which owns the cell
    return pts


FEW_CELLS = {  # name: (points, ids, keyword arguments)
    "uniform3": (lambda: random_points(3000, 3, seed=861), [5, 0, 2999], {}),
    "uniform2": (lambda: random_points(3000, 2, seed=862), [5, 0, 2999], {}),
    "lattice3": (lambda: _lattice(9, 3), [0, 364], {}),
    "lattice2": (lambda: _lattice(20, 2), [0, 210], {}),
    "duplicates": (lambda: _dup(random_points(2000, 3, seed=863)), [4], {}),
    "labels": (lambda: random_points(2000, 3, seed=864), [11, 12],
               {"labels": np.where(np.arange(2000) % 3 == 1, -1, np.arange(2000) % 4)}),
    "periodic": (lambda: random_points(2000, 3, seed=865), [0, 77], {"bounds": UNIT_BOX[3], "periodic": True}),
    "tilted": (lambda: random_points(2000, 3, seed=866), [0, 77],
               {"bounds": UNIT_BOX[3], "periodic": True, "tilt": (0.25, -0.125, 0.5)}),
}


@pytest.mark.parametrize("case", sorted(FEW_CELLS))
def test_flower_of_points_builds_a_few_cells(tmp_path, case):
    # flower(points) builds the cells asked for and their neighbours' only
    # (VoronoiOptions::only): the same flowers as from all cells, file for
    # file; the vertex ids index the partial result's vertices.
    make, ids, kw = FEW_CELLS[case]
    pts = make()
    full = tessera.voronoi(pts, merge=True, **kw)
    ref = tessera.flower(full, ids)
    few = tessera.flower(pts, ids, **kw)
    assert few.voronoi.n_cells < full.n_cells
    for a, b in zip(ref, few):
        assert a.generator == b.generator and a.circumflower_radius == b.circumflower_radius
        assert np.array_equal(a.site, b.site)
        for name in FLOWER_FIELDS:
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
        assert np.array_equal(b.petal_centres, few.voronoi.vertices[b.vertex_ids])
    ref.save(tmp_path / "all.vtp")
    few.save(tmp_path / "few.vtp")
    assert (tmp_path / "all.vtp").read_bytes() == (tmp_path / "few.vtp").read_bytes()


def test_flower_of_points_in_a_layer_widened_by_other_cells():
    # Half a periodic box empty: the cells facing the gap reach far, and all
    # cells need a wider layer of images than these few do. The same cells
    # (neighbours, petals as a set, to the last bits or nearly); the petals
    # may come in another order (VoronoiOptions::only).
    pts = random_points(5000, 3, seed=5)
    pts[:, 0] *= 0.5
    kw = {"bounds": UNIT_BOX[3], "periodic": True}
    full = tessera.voronoi(pts, **kw)
    ids = [1, 2, 3]
    few = tessera.flower(pts, ids, **kw)
    assert few.voronoi.periodic_images < full.periodic_images
    for a, b in zip(tessera.flower(full, ids), few):
        assert np.array_equal(a.neighbors, b.neighbors) and np.array_equal(a.neighbor_shifts, b.neighbor_shifts)
        order = [np.lexsort(f.petal_centres.T) for f in (a, b)]
        np.testing.assert_allclose(a.petal_centres[order[0]], b.petal_centres[order[1]], rtol=0, atol=1e-15)
        assert a.circumflower_radius == pytest.approx(b.circumflower_radius, rel=1e-15)


def test_flower_of_points_refuses_as_before():
    pts = _dup(random_points(500, 3, seed=867))
    lab = np.zeros(500, dtype=np.int32)
    lab[10] = -1
    for ids, words in (([9], "duplicates point 4"), ([3, 10], "outside point (label < 0)")):
        with pytest.raises(tessera.InputError, match=r"owns no cell: it (duplicates|is an)"):
            tessera.flower(pts, ids, labels=lab)
        with pytest.raises(tessera.InputError) as e:
            tessera.flower(pts, ids, labels=lab)
        assert words in str(e.value)
    with pytest.raises(ValueError, match="point 500 does not exist"):
        tessera.flower(pts, [0, 500])
    with pytest.raises(ValueError, match="ids"):
        tessera.flower(pts, [0.5])


def test_partial_result_of_flower_is_refused_by_the_products():
    # Flowers.voronoi of flower(points, ...) holds the asked cells and their
    # neighbours only: a graph of it was asymmetric, its boundary faces those
    # of a few cells, and a flower of another point called it an outside one.
    pts = random_points(3000, 3, seed=10)
    few = tessera.flower(pts, [0])
    assert few.voronoi.n_cells < 100
    for call in (lambda v: tessera.adjacency(v), lambda v: tessera.faces(v, "boundary"),
                 lambda v: tessera.flower(v, [1])):
        with pytest.raises(ValueError, match="holds some cells only"):
            call(few.voronoi)
    whole = tessera.voronoi(pts)
    assert tessera.flower(whole, [1])[0].generator == 1  # (a whole result is taken as before)


FACE_ARRAYS = ("vertices", "vertex_keys", "face_offsets", "face_vertices", "sides", "boundary_labels", "face_class")
FACE_SETS = (("boundary", False), ("surface-net", False), ("surface-net", True), ("complex", False))


def expect_faces_of_some_cells(tmp_path, pts, name, **kw):
    """faces(points, ...) builds the cells with a face of the set alone
    (VoronoiOptions::only_with_faces): the face set, and its .vtp, are those
    of all cells byte for byte; the partial result is refused where every
    cell is needed. Returns how many kinds left some cell out."""
    vor = tessera.voronoi(pts, merge=True, **kw)
    partial = 0
    for kind, capping in FACE_SETS:
        what = f"{name}, {kind}{' capped' if capping else ''}"
        few = tessera.faces(pts, kind=kind, capping=capping, background_label=-4, **kw)
        full = tessera.faces(vor, kind=kind, capping=capping, background_label=-4)
        for a in FACE_ARRAYS:
            assert getattr(few, a).tobytes() == getattr(full, a).tobytes(), (what, a)
        few.save(tmp_path / "few.vtp")
        full.save(tmp_path / "full.vtp")
        assert (tmp_path / "few.vtp").read_bytes() == (tmp_path / "full.vtp").read_bytes(), what
        built = few.voronoi
        assert built._partial == (built.n_cells < vor.n_cells), what
        # The cells with a face of the set's classes: built alone where they
        # are at most about half (a sample says, above 2,048 cells; all are
        # built otherwise).
        classes = tessera._core.face_set_classes(kind, capping)
        owner = np.repeat(np.arange(vor.n_cells), np.diff(vor.cell_face_offsets))
        has = np.zeros(vor.n_cells, bool)
        has[owner[((classes >> vor.face_class.astype(int)) & 1) == 1]] = True
        if kind == "complex" or (vor.n_cells > 2048 and has.mean() > 0.6) or any(vor.periodic):
            assert not built._partial, what
        elif has.mean() < 0.4:
            assert built._partial, what
        if built._partial:
            partial += 1
            assert np.array_equal(built.generators, vor.generators[has]), what
            assert np.array_equal(built.volumes, vor.volumes[has]), what
            for call in (lambda v: v.validate(), lambda v: tessera.adjacency(v),
                         lambda v: tessera.faces(v, "boundary")):
                with pytest.raises(ValueError, match="holds some cells only"):
                    call(built)
    return partial


@pytest.mark.parametrize("dim", [2, 3])
def test_faces_of_points_build_the_cells_with_such_faces_alone(tmp_path, dim):
    pts, lab = labelled(4000, dim, seed=20 + dim)
    for threads in (1, 2):
        assert expect_faces_of_some_cells(tmp_path, pts, f"{dim}D, {threads} threads", labels=lab,
                                          threads=threads) >= 2
    assert expect_faces_of_some_cells(tmp_path, pts, f"{dim}D unlabelled") >= 2  # (a net of no cells)
    # Exact ties (a lattice), points set aside outside the bounds, power cells.
    g = np.arange(10) * 0.1
    lattice = np.array(np.meshgrid(*[g] * dim, indexing="ij")).reshape(dim, -1).T.copy()
    expect_faces_of_some_cells(tmp_path, lattice, f"{dim}D lattice", labels=(lattice[:, 0] < 0.45).astype(np.int32))
    wide = pts * 1.2 - 0.1
    expect_faces_of_some_cells(tmp_path, wide, f"{dim}D set aside", labels=lab, bounds=UNIT_BOX[dim],
                               ignore_outside=True)
    radii = np.random.default_rng(dim).random(len(pts)) * (0.06 if dim == 3 else 0.02)
    assert expect_faces_of_some_cells(tmp_path, pts, f"{dim}D power", labels=lab, bounds=UNIT_BOX[dim],
                                      radii=radii) >= 2


def test_faces_of_points_in_a_periodic_box_build_every_cell(tmp_path):
    pts, lab = labelled(1500, 3, seed=23)
    assert expect_faces_of_some_cells(tmp_path, pts, "periodic", labels=lab, bounds=UNIT_BOX[3],
                                      periodic="xy") == 0


@pytest.mark.parametrize("glyphs", [False, True])
def test_flower_vtp_read_by_vtk(tmp_path, glyphs):
    pts = random_points(300, 3, seed=13)
    fl = tessera.flower(pts, [5, 6], glyphs=glyphs)
    fl.save(tmp_path / "flower.vtp")
    data = read_vtp(tmp_path / "flower.vtp")
    role = vtk_to_numpy(data.GetPointData().GetArray("Role"))
    assert np.count_nonzero(role == 0) == 2  # the sites
    assert np.count_nonzero(role == 1) == sum(f.n_petals for f in fl)
    assert np.count_nonzero(role == 2) == sum(len(f.neighbors) for f in fl)
    assert (np.count_nonzero(role >= 5) > 0) == glyphs
    cell_role = cell_data(data, "Role")
    assert np.count_nonzero(cell_role == 4) == sum(len(f.face_neighbor) for f in fl)
    mem = fl.to_vtk()
    assert mem.GetNumberOfCells() == data.GetNumberOfCells() and mem.GetNumberOfPoints() == data.GetNumberOfPoints()


# ---------------------------------------------------------- arrays, threads

DUAL_ARRAYS = {
    "graph": (lambda vor: tessera.adjacency(vor), ["wheel_offsets", "spokes", "spoke_class", "spoke_measure",
                                                     "edge_spokes"], "Graph"),
    "faces": (lambda vor: tessera.faces(vor, kind="complex"),
              ["vertices", "vertex_keys", "face_offsets", "face_vertices", "sides", "boundary_labels", "face_class"],
              "FaceSet"),
    "flower": (lambda vor: tessera.flower(vor, 3)[0],
               ["vertex_ids", "petal_centres", "petal_radii", "face_offsets", "face_vertices", "face_neighbor",
                "neighbors"], "Flower"),
}


@pytest.mark.parametrize("product", list(DUAL_ARRAYS))
def test_dual_arrays_are_read_only_views(product):
    make, names, owner = DUAL_ARRAYS[product]
    result = make(tessera.voronoi(random_points(300, 3)))
    for name in names:
        a = getattr(result, name)
        assert a.size > 0 and not a.flags.owndata and not a.flags.writeable, name
        assert type(a.base).__name__ == owner, name
        assert a.__array_interface__["data"][0] == getattr(result, name).__array_interface__["data"][0], name
    if product == "graph":
        e = result.edges()
        assert not e.flags.owndata and not e.flags.writeable and e.base is not None


def test_dual_views_outlive_their_results():
    pts = random_points(1000, 3)
    spokes = tessera.adjacency(pts).spokes.copy()
    view = tessera.adjacency(pts).spokes
    radii = tessera.flower(pts, 1)[0].petal_radii
    expected = radii.copy()
    gc.collect()
    junk = [np.ones(1000, dtype=np.int32) for _ in range(100)]
    assert np.array_equal(view, spokes) and np.array_equal(radii, expected)
    del junk


def test_threads_1_and_2_give_identical_products():
    pts, lab = labelled(20000, 3, seed=14)
    graphs = [tessera.adjacency(pts, labels=lab, threads=t) for t in (1, 2)]
    assert [g.voronoi.threads_used for g in graphs] == [1, 2]
    for name in ("wheel_offsets", "spokes", "spoke_class", "spoke_measure", "edge_spokes"):
        assert getattr(graphs[0], name).tobytes() == getattr(graphs[1], name).tobytes(), name
    assert graphs[0].edges().tobytes() == graphs[1].edges().tobytes()
    for kind in ("boundary", "complex", "surface-net"):
        a, b = (tessera.faces(pts, labels=lab, kind=kind, threads=t) for t in (1, 2))
        for name in ("vertices", "vertex_keys", "face_offsets", "face_vertices", "sides", "boundary_labels",
                     "face_class"):
            assert getattr(a, name).tobytes() == getattr(b, name).tobytes(), (kind, name)


# ----------------------------------------------------------------- bad input

P3 = random_points(50, 3)
VOR = tessera.voronoi(P3)
VOR_NO_MESH = tessera.voronoi(P3, merge=False)
VOR_OUT = tessera.voronoi(P3, labels=np.where(np.arange(50) == 4, -1, 0))

BAD = {
    "points shape": (lambda: tessera.adjacency(np.zeros((5, 4))), r"points: expected shape \(N, 2\) or \(N, 3\)"),
    "points NaN": (lambda: tessera.faces(np.where(P3 == P3[3, 0], np.nan, P3)), r"point 3 has a NaN"),
    "labels length": (lambda: tessera.faces(P3, labels=np.zeros(7, int)), r"labels: expected one label per point"),
    "labels with a Voronoi": (lambda: tessera.adjacency(VOR, labels=np.zeros(50, int)),
                              r"adjacency: labels is for computing cells from points; this Voronoi result"),
    "bounds, threads with a Voronoi": (lambda: tessera.faces(VOR, bounds=UNIT_BOX[3], threads=2),
                                       r"faces: bounds, threads are for computing cells"),
    "no mesh graph": (lambda: tessera.adjacency(VOR_NO_MESH), r"adjacency: .*merge=False \(no mesh\)"),
    "no mesh faces": (lambda: tessera.faces(VOR_NO_MESH), r"faces: .*merge=False"),
    "no mesh flower": (lambda: tessera.flower(VOR_NO_MESH, 0), r"flower: .*merge=False"),
    "prune negative": (lambda: tessera.adjacency(P3, prune_tolerance=-1), r"prune_tolerance: expected a finite"),
    "prune NaN": (lambda: tessera.adjacency(P3, prune_tolerance=np.nan), r"prune_tolerance: expected a finite"),
    "prune text": (lambda: tessera.adjacency(P3, prune_tolerance="x"), r"prune_tolerance: expected a finite"),
    "kind": (lambda: tessera.faces(VOR, kind="interior"),
             r"kind: expected one of 'boundary', 'complex', 'surface-net', got 'interior'"),
    "capping boundary": (lambda: tessera.faces(VOR, kind="boundary", capping=True),
                         r"capping: applies to kind='surface-net' only"),
    "background label >= 0": (lambda: tessera.faces(VOR, background_label=0),
                              r"background_label: expected a negative integer .* got 0"),
    "background label float": (lambda: tessera.faces(VOR, background_label=-1.5), r"background_label: expected"),
    "flower id range": (lambda: tessera.flower(VOR, [3, 50]), r"ids: point 50 does not exist \(there are 50 points"),
    "flower id negative": (lambda: tessera.flower(VOR, -1), r"ids: point -1 does not exist"),
    "flower ids float": (lambda: tessera.flower(VOR, [1.5]), r"ids: expected a point id"),
    "flower ids empty": (lambda: tessera.flower(VOR, []), r"ids: expected a point id or a non-empty"),
    "flower outside point": (lambda: tessera.flower(VOR_OUT, 4), r"point 4 owns no cell: it is an outside point"),
    "graph save ext": (lambda: tessera.adjacency(VOR).save("graph.vtu"), r"save: a graph is written as VTK PolyData"),
    "faces save ext": (lambda: tessera.faces(VOR).save("f.vtk"), r"save: a face set is written as VTK PolyData"),
    "flower save ext": (lambda: tessera.flower(VOR, 0).save("f"), r"save: a flower is written as VTK PolyData"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_raises_value_error(case):
    call, message = BAD[case]
    with pytest.raises(ValueError, match=message):
        call()


def test_unwritable_file_is_an_os_error(tmp_path):
    with pytest.raises(OSError):
        tessera.faces(VOR).save(tmp_path / "no" / "such" / "dir" / "f.vtp")
