"""Files: save() read back by VTK's XML readers and by meshio; to_vtk().

meshio 5.0 (Debian) reads .vtu but not .vtp, and it misgroups the cell data of
polyhedra of different sizes unless the sizes first appear in ascending order
(nschloe/meshio#1463, open), so general 3D cell files are read back with VTK
and meshio reads the files it can: triangulations, and cells that are all
boxes.
"""

import gc
import os

import meshio
import numpy as np
import pytest
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersVerdict import vtkCellSizeFilter
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader

import tessera
from conftest import UNIT_BOX, random_points


def read_vtk(path):
    reader = vtkXMLUnstructuredGridReader() if str(path).endswith(".vtu") else vtkXMLPolyDataReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def cell_array(data, name):
    return vtk_to_numpy(data.GetCellData().GetArray(name))


def measured_sizes(data, name):
    """Cell sizes as VTK computes them (exact for simplices; for polyhedra it
    tetrahedralizes with a tolerance and is off by up to ~1e-2 on some cells,
    hence cell_measures below for the Voronoi cells)."""
    f = vtkCellSizeFilter()
    f.SetInputData(data)
    f.Update()
    return cell_array(f.GetOutput(), name)


def cell_measures(data):
    """Volume (3D, divergence theorem over the faces) or area (2D, shoelace) of
    every cell, from the points and cells VTK holds."""
    pts = vtk_to_numpy(data.GetPoints().GetData())
    out = np.empty(data.GetNumberOfCells())
    for c in range(data.GetNumberOfCells()):
        cell = data.GetCell(c)
        if cell.GetNumberOfFaces() == 0:  # a polygon
            x, y = pts[[cell.GetPointId(k) for k in range(cell.GetNumberOfPoints())], :2].T
            out[c] = 0.5 * (x * np.roll(y, -1) - np.roll(x, -1) * y).sum()
            continue
        total = 0.0
        for f in range(cell.GetNumberOfFaces()):
            face = cell.GetFace(f)
            p = pts[[face.GetPointId(k) for k in range(face.GetNumberOfPoints())]]
            total += np.einsum("ij,ij->", np.broadcast_to(p[0], p[1:-1].shape), np.cross(p[1:-1], p[2:]))
        out[c] = total / 6
    return out


def test_3d_cells_vtu_read_by_vtk(tmp_path):
    vor = tessera.voronoi(random_points(800, 3), bounds=UNIT_BOX[3])
    path = tmp_path / "cells.vtu"
    vor.save(path)
    data = read_vtk(path)
    assert data.GetNumberOfCells() == vor.n_cells
    assert np.array_equal(vtk_to_numpy(data.GetPoints().GetData()), vor.vertices)
    assert np.array_equal(cell_array(data, "GeneratorId"), vor.generators)
    assert np.array_equal(cell_array(data, "Volume"), vor.volumes)
    assert np.array_equal(cell_array(data, "NumberOfFaces"), vor.num_faces)
    assert np.array_equal(cell_array(data, "NumberOfNeighbors"), np.diff(vor.neighbor_offsets))
    assert set(vtk_to_numpy(data.GetCellTypesArray()).tolist()) == {42}  # VTK_POLYHEDRON
    assert np.allclose(cell_measures(data), vor.volumes, rtol=1e-9, atol=1e-15)


def test_2d_cells_vtp_read_by_vtk(tmp_path):
    vor = tessera.voronoi(random_points(800, 2), labels=np.arange(800) % 3)
    path = tmp_path / "cells.vtp"
    vor.save(str(path))
    data = read_vtk(path)
    assert data.GetNumberOfPolys() == vor.n_cells
    assert np.array_equal(cell_array(data, "Region"), vor.regions)
    assert np.array_equal(cell_array(data, "Area"), vor.volumes)
    assert np.allclose(cell_measures(data), vor.volumes, rtol=1e-9, atol=1e-15)


def test_3d_cells_vtu_read_by_meshio(tmp_path):
    # Points on a line across the box: every cell is a box slab (8 vertices,
    # 6 faces), a file meshio 5.0 groups correctly (see the module docstring).
    pts = np.column_stack([np.linspace(0.1, 0.9, 5), np.full(5, 0.5), np.full(5, 0.5)])
    vor = tessera.voronoi(pts, bounds=UNIT_BOX[3])
    vor.save(tmp_path / "slabs.vtu")
    mesh = meshio.read(tmp_path / "slabs.vtu")
    assert np.array_equal(mesh.points, vor.vertices)
    [block] = mesh.cells
    assert block.type == "polyhedron8" and len(block.data) == 5
    for c, faces in enumerate(block.data):
        assert [sorted(f.tolist()) for f in faces] == [sorted(f.tolist()) for f in vor.cell_faces(c)]
    assert np.array_equal(mesh.cell_data["GeneratorId"][0], vor.generators)
    assert np.allclose(mesh.cell_data["Volume"][0], vor.volumes)


@pytest.mark.parametrize("dim", [2, 3])
def test_delaunay_vtu_read_by_vtk_and_meshio(tmp_path, dim):
    pts = random_points(600, dim, seed=3)
    dt = tessera.delaunay(pts)
    path = tmp_path / "delaunay.vtu"
    dt.save(path)
    data = read_vtk(path)
    assert data.GetNumberOfCells() == dt.nsimplex
    assert set(vtk_to_numpy(data.GetCellTypesArray()).tolist()) == {10 if dim == 3 else 5}
    conn = vtk_to_numpy(data.GetCells().GetConnectivityArray())
    assert np.array_equal(conn.reshape(-1, dim + 1), dt.simplices)
    assert np.array_equal(cell_array(data, "SimplexId"), np.arange(dt.nsimplex))
    mesh = meshio.read(path)
    [block] = mesh.cells
    assert block.type == ("tetra" if dim == 3 else "triangle")
    assert np.array_equal(block.data, dt.simplices)
    assert np.array_equal(mesh.points[:, :dim], pts)


def test_2d_delaunay_vtp_read_by_vtk(tmp_path):
    dt = tessera.delaunay(random_points(300, 2, seed=4))
    dt.save(tmp_path / "delaunay.vtp")
    data = read_vtk(tmp_path / "delaunay.vtp")
    assert data.GetNumberOfPolys() == dt.nsimplex
    conn = vtk_to_numpy(data.GetPolys().GetConnectivityArray())
    assert np.array_equal(conn.reshape(-1, 3), dt.simplices)


@pytest.mark.parametrize("dim", [2, 3])
def test_to_vtk_matches_the_cells_and_outlives_the_result(dim):
    vor = tessera.voronoi(random_points(500, dim))
    volumes = vor.volumes.copy()
    data = vor.to_vtk()
    del vor
    gc.collect()  # the VTK object keeps what it shares with numpy alive
    name = "Volume" if dim == 3 else "Area"
    assert np.array_equal(cell_array(data, name), volumes)
    assert np.allclose(cell_measures(data), volumes, rtol=1e-9, atol=1e-15)


def test_delaunay_to_vtk():
    dt = tessera.delaunay(random_points(300, 3))
    data = dt.to_vtk()
    assert data.GetNumberOfCells() == dt.nsimplex
    assert measured_sizes(data, "Volume").sum() == pytest.approx(
        np.abs(np.linalg.det(dt.points[dt.simplices][:, 1:] - dt.points[dt.simplices][:, :1])).sum() / 6)


def test_save_errors_leave_nothing_behind(tmp_path):
    vor3 = tessera.voronoi(random_points(100, 3))
    vor2 = tessera.voronoi(random_points(100, 2))
    with pytest.raises(ValueError, match=r"3D cells are written as VTK UnstructuredGrid \(\.vtu\)"):
        vor3.save(tmp_path / "x.vtp")
    with pytest.raises(ValueError, match=r"2D cells are written as VTK PolyData \(\.vtp\)"):
        vor2.save(tmp_path / "x.vtu")
    with pytest.raises(OSError, match="cannot write"):
        vor3.save(tmp_path / "missing" / "x.vtu")
    with pytest.raises(ValueError, match="merge=False"):
        tessera.voronoi(random_points(100, 3), merge=False).save(tmp_path / "x.vtu")
    dt = tessera.delaunay(random_points(100, 3))
    with pytest.raises(ValueError, match=r"\.vtu"):
        dt.save(tmp_path / "x.vtp")
    with pytest.raises(OSError, match="cannot write"):
        dt.save(tmp_path / "missing" / "x.vtu")
    assert os.listdir(tmp_path) == []


# A script killed while saving: it ends by the signal, as by default, but
# leaves neither the file nor its temporary (OUTPUT.tmp-XXXXXX), which it
# used to leave behind (python/src/signal_cleanup.hpp).
KILLED_WHILE_SAVING = """
import signal, sys
import numpy as np
import tessera
if sys.argv[2] == "handled":
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(7))
vor = tessera.voronoi(np.random.default_rng(5).random((200000, 3)))
print("saving", flush=True)
vor.save(sys.argv[1])
vor.save(sys.argv[1] + ".again.vtu")
"""


def save_and_signal(tmp_path, sig, mode):
    """Run KILLED_WHILE_SAVING, send `sig` once the first file's temporary
    appears; returns the exit code and the directory's names (None: the
    write finished before the signal could be sent)."""
    import signal
    import subprocess
    import sys
    import time
    out = tmp_path / "c.vtu"
    proc = subprocess.Popen([sys.executable, "-c", KILLED_WHILE_SAVING, str(out), mode],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout.readline() == b"saving\n"
    deadline = time.monotonic() + 120
    sent = False
    while proc.poll() is None and time.monotonic() < deadline:
        if any(".tmp-" in name for name in os.listdir(tmp_path)):
            proc.send_signal(sig)
            sent = True
            break
        time.sleep(0.0005)
    proc.communicate(timeout=120)
    if not sent:
        return None, None
    return proc.returncode, sorted(os.listdir(tmp_path))


@pytest.mark.parametrize("signame", ["SIGTERM", "SIGHUP"])
def test_a_script_killed_while_saving_leaves_nothing(tmp_path, signame):
    import signal
    sig = getattr(signal, signame)
    code, names = save_and_signal(tmp_path, sig, "default")
    if code is None:
        pytest.skip("the save finished before the signal")
    assert code == -sig
    assert names == []


def test_a_scripts_own_handler_is_kept_and_the_file_completed(tmp_path):
    """With a handler of its own, SIGTERM is the script's: Python runs it once
    the save returns, so the file is complete and the second save never
    starts."""
    import signal
    code, names = save_and_signal(tmp_path, signal.SIGTERM, "handled")
    if code is None:
        pytest.skip("the save finished before the signal")
    assert code == 7
    assert names == ["c.vtu"]
    assert read_vtk(tmp_path / "c.vtu").GetNumberOfCells() == 200000


def test_read_points_reads_what_the_command_reads(tmp_path):
    # The same points and labels from a Fortran-order .npy, a structured .npy
    # and a CSV led by an index column.
    pts = random_points(200, 3, seed=11)
    lab = np.arange(200, dtype=np.int32) % 3
    np.save(tmp_path / "f.npy", np.asfortranarray(pts))
    rec = np.zeros(200, dtype=[("id", "<i8"), ("Z", "<f8"), ("X", "<f8"), ("Y", "<f8"), ("region", "<i2")])
    rec["Z"], rec["X"], rec["Y"], rec["region"] = pts[:, 2], pts[:, 0], pts[:, 1], lab
    np.save(tmp_path / "r.npy", rec)
    with open(tmp_path / "p.csv", "w") as f:
        f.write(",region,x,y,z\n")
        for i, (p, l) in enumerate(zip(pts, lab)):
            f.write("%d,%d,%r,%r,%r\n" % (i, l, p[0], p[1], p[2]))
    np.save(tmp_path / "lab.npy", lab)
    with open(tmp_path / "p.vtk", "w") as f:  # legacy VTK, as LAMMPS's dump vtk writes it
        f.write("# vtk DataFile Version 3.0\nLAMMPS\nASCII\nDATASET POLYDATA\nPOINTS 200 double\n")
        f.write("\n".join("%r %r %r" % tuple(p) for p in pts))
        f.write("\nPOINT_DATA 200\nSCALARS region int 1\nLOOKUP_TABLE default\n")
        f.write(" ".join(str(v) for v in lab) + "\n")
    for name, labels in (("f.npy", tmp_path / "lab.npy"), ("r.npy", "region"), ("p.csv", "region"),
                         ("p.vtk", "region")):
        p, l = tessera.read_points(tmp_path / name, labels=labels)
        assert p.shape == (200, 3) and p.dtype == np.float64 and p.flags.writeable
        np.testing.assert_array_equal(p, pts)
        np.testing.assert_array_equal(l, lab)
        assert l.dtype == np.int32
    p, l = tessera.read_points(tmp_path / "r.npy", dim=2)
    np.testing.assert_array_equal(p, pts[:, :2])
    assert l is None
    with pytest.raises(ValueError, match="no field 'nope'"):
        tessera.read_points(tmp_path / "r.npy", labels="nope")
    with pytest.raises(ValueError, match="cannot open"):
        tessera.read_points(tmp_path / "missing.pcd")
    with pytest.raises(ValueError, match="dim"):
        tessera.read_points(tmp_path / "r.npy", dim=4)
    # The readers' words for the command line are put in Python's.
    with open(tmp_path / "q4.txt", "w") as f:
        f.write("4 rbox 5 D4\n5\n0 0 0 0\n1 0 0 1\n0 1 0 2\n0 0 1 0\n1 1 1 1\n")
    with pytest.raises(ValueError, match=r"\(dim=2 or dim=3 keeps the first coordinates\)$"):
        tessera.read_points(tmp_path / "q4.txt")
    with open(tmp_path / "img.vtk", "w") as f:
        f.write("# vtk DataFile Version 3.0\nimg\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 1\n"
                "ORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 4\nSCALARS s int 1\n0 1 0 1\n")
    with pytest.raises(ValueError, match="tessera.read_image") as e:
        tessera.read_points(tmp_path / "img.vtk")
    assert "`" not in str(e.value) and "--" not in str(e.value)


def test_lammps_dump_points_and_box(tmp_path):
    # A triclinic periodic dump in scaled coordinates: read_points places the
    # atoms in the box, read_box gives voronoi() the box, and the cells equal
    # those of the box given by hand; the volumes tile it.
    lo = np.array([0.0, -1.0, 2.0])
    vec = np.array([[3.0, 0, 0], [0.5, 2.5, 0], [0.25, -0.75, 2.0]])
    frac = np.random.default_rng(12).random((300, 3))
    xy, xz, yz = vec[1, 0], vec[2, 0], vec[2, 1]
    with open(tmp_path / "run.lammpstrj", "w") as f:
        f.write("ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n300\nITEM: BOX BOUNDS xy xz yz pp pp pp\n")
        f.write("%r %r %r\n" % (lo[0] + min(0, xy, xz, xy + xz), lo[0] + 3 + max(0, xy, xz, xy + xz), xy))
        f.write("%r %r %r\n" % (lo[1] + min(0, yz), lo[1] + 2.5 + max(0, yz), xz))
        f.write("%r %r %r\nITEM: ATOMS id type xs ys zs\n" % (lo[2], lo[2] + 2, yz))
        for k, r in enumerate(frac):
            f.write("%d %d %r %r %r\n" % (k + 1, 1 + k % 2, r[0], r[1], r[2]))
    path = tmp_path / "run.lammpstrj"
    p, types = tessera.read_points(path, labels="type")
    np.testing.assert_allclose(p, lo + frac @ vec, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(types, 1 + np.arange(300) % 2)
    # Per-atom numbers by column name, as --radii NAME reads them.
    np.testing.assert_array_equal(tessera.read_scalars(path, "type"), 1 + np.arange(300) % 2)
    with pytest.raises(ValueError, match="radius"):
        tessera.read_scalars(path, "radius")
    with pytest.raises(ValueError, match="np.load reads it"):  # its length would go unchecked
        tessera.read_scalars(path, "radii.npy")
    box = tessera.read_box(path)
    assert box == {"bounds": (0.0, 3.0, -1.0, 1.5, 2.0, 4.0), "periodic": (True, True, True), "tilt": (0.5, 0.25, -0.75)}
    vor = tessera.voronoi(p, labels=types, **box)
    by_hand = tessera.voronoi(p, labels=types, bounds=(0, 3, -1, 1.5, 2, 4), periodic=True, tilt=(0.5, 0.25, -0.75))
    np.testing.assert_array_equal(vor.volumes, by_hand.volumes)
    assert abs(vor.volumes.sum() - 15.0) < 1e-12
    with pytest.raises(ValueError, match="tilts along z"):
        tessera.read_box(path, dim=2)
    np.save(tmp_path / "p.npy", p)
    assert tessera.read_box(tmp_path / "p.npy") is None
    # The same cell as an extended XYZ's Lattice (rows a, b, c) and Origin.
    with open(tmp_path / "run.xyz", "w") as f:
        f.write("300\nLattice=\"%s\" Origin=\"%s\" Properties=species:S:1:pos:R:3:type:I:1\n" % (
            " ".join(repr(v) for v in vec.ravel()), " ".join(repr(v) for v in lo)))
        for k, q in enumerate(p):
            f.write("Ar %r %r %r %d\n" % (q[0], q[1], q[2], types[k]))
    q, t = tessera.read_points(tmp_path / "run.xyz", labels="type")
    np.testing.assert_array_equal(q, p)
    np.testing.assert_array_equal(t, types)
    assert tessera.read_box(tmp_path / "run.xyz") == box
    with open(tmp_path / "bad.dump", "w") as f:
        f.write("ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp\n0 1\n0 1\n0 1\n")
    with pytest.raises(ValueError, match="three boundary flags"):
        tessera.read_box(tmp_path / "bad.dump")


def test_read_frames_of_a_trajectory(tmp_path):
    # A dump of three frames, each with its box and atom count: frames one
    # after another, usable as voronoi's arguments; errors at the first call
    # for the file, at its frame for a broken later frame.
    rng = np.random.default_rng(13)
    frames = []
    with open(tmp_path / "t.lammpstrj", "w") as f:
        for s, n in enumerate((40, 55, 30)):
            box = 1.0 + s
            pts = rng.random((n, 3)) * box
            frames.append((pts, box))
            f.write("ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS pp pp pp\n" % (10 * s, n))
            f.write("0 %r\n0 %r\n0 %r\nITEM: ATOMS id type x y z\n" % (box, box, box))
            for k, q in enumerate(pts):
                f.write("%d %d %r %r %r\n" % (k + 1, 1 + k % 3, q[0], q[1], q[2]))
    got = list(tessera.read_frames(tmp_path / "t.lammpstrj", labels="type"))
    assert [f.timestep for f in got] == [0, 10, 20]
    for f, (pts, box) in zip(got, frames):
        np.testing.assert_array_equal(f.points, pts)
        np.testing.assert_array_equal(f.labels, 1 + np.arange(len(pts)) % 3)
        assert f.box == {"bounds": (0.0, box, 0.0, box, 0.0, box), "periodic": (True, True, True), "tilt": None}
        vor = tessera.voronoi(f.points, labels=f.labels, **f.box, merge=False)
        assert abs(vor.volumes.sum() - box**3) < 1e-9 * box**3
    with pytest.raises(ValueError, match="cannot open"):
        tessera.read_frames(tmp_path / "missing.dump")
    np.save(tmp_path / "p.npy", frames[0][0])
    with pytest.raises(ValueError, match="not a trajectory"):
        tessera.read_frames(tmp_path / "p.npy")
    with pytest.raises(ValueError, match="not a trajectory"):
        tessera.read_points(tmp_path / "p.npy", frame=-1)
    assert tessera.read_points(tmp_path / "p.npy", frame=0)[0].shape == (40, 3)
    # One frame by its index, from either end: read_points and read_box.
    for index in range(-3, 3):
        pts, lab = tessera.read_points(tmp_path / "t.lammpstrj", labels="type", frame=index)
        np.testing.assert_array_equal(pts, got[index].points)
        np.testing.assert_array_equal(lab, got[index].labels)
        assert tessera.read_box(tmp_path / "t.lammpstrj", frame=index) == got[index].box
    with pytest.raises(ValueError, match=r"no frame 3: it has 3 frames \(0 to 2, or -3 to -1 from the end\)"):
        tessera.read_points(tmp_path / "t.lammpstrj", frame=3)
    with pytest.raises(ValueError, match="no frame -4"):
        tessera.read_box(tmp_path / "t.lammpstrj", frame=-4)
    for bad in (1.5, True, "1", None):
        with pytest.raises(ValueError, match="frame: expected an integer"):
            tessera.read_points(tmp_path / "t.lammpstrj", frame=bad)
    assert tessera.read_points(tmp_path / "t.lammpstrj", frame=np.int64(-1))[0].shape == (30, 3)
    # Some of the frames, by a slice or indices, in that order.
    for sel in (slice(None, None, 2), slice(-2, None), slice(None, None, -1), [2, 0, -1], np.array([1]), range(1, 3)):
        want = list(range(3))[sel] if isinstance(sel, slice) else [int(k) % 3 for k in sel]
        some = list(tessera.read_frames(tmp_path / "t.lammpstrj", labels="type", frames=sel))
        assert [f.timestep for f in some] == [10 * k for k in want]
        for f, k in zip(some, want):
            np.testing.assert_array_equal(f.points, got[k].points)
            np.testing.assert_array_equal(f.labels, got[k].labels)
    with pytest.raises(IndexError, match="frames: index 3 is out of range for 3 frames"):
        tessera.read_frames(tmp_path / "t.lammpstrj", frames=[0, 3])
    with pytest.raises(ValueError, match="frames: expected a slice or a sequence"):
        tessera.read_frames(tmp_path / "t.lammpstrj", frames="::2")
    text = (tmp_path / "t.lammpstrj").read_text()
    broken = text[: text.index("ITEM: TIMESTEP\n20")] + "ITEM: TIMESTEP\n20\nITEM: NUMBER OF ATOMS\nmany\n"
    (tmp_path / "b.lammpstrj").write_text(broken)
    it = tessera.read_frames(tmp_path / "b.lammpstrj")
    assert next(it).points.shape == (40, 3) and next(it).points.shape == (55, 3)
    with pytest.raises(ValueError, match="number of atoms is not a count"):
        next(it)


def test_non_finite_points_kept_and_set_aside(tmp_path):
    # An organized cloud's missing returns: an error, or kept and then set
    # aside by ignore_outside, ids unchanged.
    pts = random_points(300, 3, seed=12)
    pts[[4, 100]] = np.nan
    np.save(tmp_path / "o.npy", pts)
    with pytest.raises(tessera.InputError, match="non-finite"):
        tessera.read_points(tmp_path / "o.npy")
    p, _ = tessera.read_points(tmp_path / "o.npy", keep_non_finite=True)
    assert np.isnan(p[4]).all() and np.isnan(p[100]).all()
    vor = tessera.voronoi(p, ignore_outside=True)
    np.testing.assert_array_equal(vor.ignored_outside_bounds, [4, 100])
    assert vor.n_cells == 298
    assert 4 not in vor.generators and 100 not in vor.generators
    assert np.isfinite(vor.volumes).all()


def test_non_finite_points_through_the_point_tools():
    # joggle, fill and probe keep an organized cloud's missing returns in
    # place with keep_non_finite (refused otherwise); voronoi then sets them
    # aside, and the cells are those of the finite points' pipeline.
    pts = random_points(500, 3, seed=13)
    lost = np.zeros(500, bool)
    lost[[3, 77, 250, 499]] = True
    bad = pts.copy()
    bad[lost] = np.nan
    bad[77, 0] = np.inf
    for tool in (tessera.joggle, tessera.fill):
        with pytest.raises(ValueError, match="keep_non_finite"):
            tool(bad)
    j = tessera.joggle(bad, radius=1e-3, keep_non_finite=True)
    np.testing.assert_array_equal(j[lost], bad[lost])
    assert (j[~lost] != bad[~lost]).all()
    f, lab = tessera.fill(j, keep_non_finite=True)
    fk, labk = tessera.fill(j[~lost])
    np.testing.assert_array_equal(f[:500], j)
    np.testing.assert_array_equal(f[500:], fk[len(fk) - (len(f) - 500):])
    vor = tessera.voronoi(f, labels=lab, ignore_outside=True)
    ref = tessera.voronoi(fk, labels=labk)
    np.testing.assert_array_equal(vor.ignored_outside_bounds, np.flatnonzero(lost))
    np.testing.assert_array_equal(ref.generators, np.arange(496))  # the input points own the cells
    np.testing.assert_array_equal(vor.generators, np.flatnonzero(~lost))
    np.testing.assert_array_equal(vor.volumes, ref.volumes)
    image = np.arange(27, dtype=float).reshape(3, 3, 3)
    with pytest.raises(ValueError, match="NaN"):
        tessera.probe(image, bad)
    v, ok = tessera.probe(image, bad, outside_value=-1.0, keep_non_finite=True)
    assert not ok[lost].any() and (v[lost] == -1).all() and ok[~lost].all()
