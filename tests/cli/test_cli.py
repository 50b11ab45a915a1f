#!/usr/bin/python3
"""End-to-end tests of the `tessera` command.

Usage: /usr/bin/python3 tests/cli/test_cli.py PATH_TO_tessera [unittest args...]

Runs the binary on small generated inputs and checks what it writes by reading
it back: VTK files through VTK's own XML readers (Debian python3-vtk9), tables
and neighbour lists through numpy. Also checks that every kind of bad input
fails cleanly: non-zero exit, one line "tessera: error: ..." on stderr, and no
output file (not even a temporary) left behind.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import io
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np

try:
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy
except ImportError:  # pragma: no cover - reported as failures of the VTK tests
    vtk = None

TESSERA = None  # set from argv in main()
BOX3 = ["0", "1", "0", "1", "0", "1"]
BOX2 = ["0", "1", "0", "1"]


def run(args, env=None, timeout=600):
    full_env = dict(os.environ)
    full_env.pop("TESSERA_NUM_THREADS", None)
    if env:
        full_env.update(env)
    return subprocess.run([TESSERA] + [str(a) for a in args], capture_output=True, text=True,
                          env=full_env, timeout=timeout)


def run_bytes(args, data=b"", timeout=600):
    """`run` with bytes in and out (standard input `data`)."""
    env = dict(os.environ)
    env.pop("TESSERA_NUM_THREADS", None)
    return subprocess.run([TESSERA] + [str(a) for a in args], input=data, capture_output=True, env=env, timeout=timeout)


def read_vtu(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def cell_array(data, name):
    a = data.GetCellData().GetArray(name)
    if a is None:
        raise AssertionError("cell data array %r missing" % name)
    return a


def cell_faces(faces, loc):
    """The faces (arrays of point ids) of the polyhedron whose record starts at
    `loc` in a VTK face stream."""
    k = int(loc)
    out = []
    for _ in range(int(faces[k])):
        m = int(faces[k + 1])
        out.append(faces[k + 2:k + 2 + m])
        k += 1 + m
    return out


def faces_volume(pts, cell):
    """Signed volume enclosed by a cell's faces (divergence theorem over fan
    triangles): positive iff they are counter-clockwise seen from outside."""
    return sum(np.dot(p[0], np.cross(p[1:-1], p[2:]).sum(axis=0)) for p in (pts[ids] for ids in cell)) / 6.0


def polyhedron_volumes(grid):
    """Signed volume of every polyhedron from the VTK face stream, as VTK
    expects it (see faces_volume), and its number of faces."""
    pts = vtk_to_numpy(grid.GetPoints().GetData())
    faces = vtk_to_numpy(grid.GetFaces())
    cells = [cell_faces(faces, loc) for loc in vtk_to_numpy(grid.GetFaceLocations())]
    return (np.array([faces_volume(pts, c) for c in cells]),
            np.array([len(c) for c in cells], dtype=np.int64))


def polygon_areas(poly):
    pts = vtk_to_numpy(poly.GetPoints().GetData())
    conn = vtk_to_numpy(poly.GetPolys().GetConnectivityArray())
    offs = vtk_to_numpy(poly.GetPolys().GetOffsetsArray())
    areas = np.zeros(len(offs) - 1)
    nverts = np.diff(offs)
    for c in range(len(offs) - 1):
        p = pts[conn[offs[c]:offs[c + 1]]]
        x, y = p[:, 0], p[:, 1]
        areas[c] = 0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y)
    return areas, nverts


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def load_neighbors(path):
    a = np.load(path)
    if a.dtype != np.int64 or a.ndim != 1:
        raise AssertionError("neighbours array must be 1-D int64, got %s %s" % (a.dtype, a.shape))
    n = int(a[0])
    off = a[1:n + 2]
    ids = a[n + 2:]
    return n, off, ids

def cells_of(cell_array_obj):
    """Connectivity of a vtkCellArray as a list of id arrays."""
    conn = vtk_to_numpy(cell_array_obj.GetConnectivityArray())
    offs = vtk_to_numpy(cell_array_obj.GetOffsetsArray())
    return [conn[offs[i]:offs[i + 1]] for i in range(len(offs) - 1)]


def read_ply(path):
    """Vertex properties of a binary little-endian .ply as a numpy structured array."""
    data = read_bytes(path)
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    assert header[1] == "format binary_little_endian 1.0", header[1]
    types = {"double": "<f8", "float": "<f4", "int": "<i4", "uchar": "u1"}
    fields, n = [], None
    for line in header:
        w = line.split()
        if w[:2] == ["element", "vertex"]:
            n = int(w[2])
        elif w[0] == "property":
            fields.append((w[2], types[w[1]]))
    arr = np.frombuffer(data[end:], dtype=np.dtype(fields))
    assert len(arr) == n, (len(arr), n)
    return arr


def cli_main(script, requirements=(), bind=None):
    """The main() of every tests/cli script: argv[1] is the tessera binary, the
    rest goes to unittest. `requirements` are (available, message) pairs
    checked first; `bind(path)` hands the binary to a script with its own run().
    Prints "N passed, M failed, K skipped" last; returns the exit status."""
    global TESSERA
    if len(sys.argv) < 2:
        print("usage: %s PATH_TO_tessera [unittest args]" % script, file=sys.stderr)
        return 2
    TESSERA = os.path.abspath(sys.argv[1])
    if not os.access(TESSERA, os.X_OK):
        print("not an executable: %s" % TESSERA, file=sys.stderr)
        return 2
    for available, message in requirements:
        if not available:
            print(message, file=sys.stderr)
            return 2
    if bind:
        bind(TESSERA)
    argv = [sys.argv[0]] + sys.argv[2:]
    res = unittest.main(module="__main__", argv=argv, exit=False, verbosity=2).result
    failed = len(res.failures) + len(res.errors) + len(res.unexpectedSuccesses)
    passed = res.testsRun - failed - len(res.skipped)
    print("%d passed, %d failed, %d skipped" % (passed, failed, len(res.skipped)))
    return 0 if failed == 0 else 1


class TempDirCase(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="tessera-cli-")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def p(self, name):
        return os.path.join(self.dir, name)

    def save(self, name, arr):
        path = self.p(name)
        np.save(path, arr)
        return path

    def ok(self, args, **kw):
        r = run(args, **kw)
        self.assertEqual(r.returncode, 0, "tessera %s failed:\n%s%s" % (" ".join(map(str, args)), r.stdout, r.stderr))
        return r


class Voronoi3D(TempDirCase):
    N = 400

    def setUp(self):
        super().setUp()
        self.pts = np.random.default_rng(3).random((self.N, 3))
        self.inp = self.save("pts.npy", self.pts)

    def test_vtu_read_back(self):
        out = self.p("cells.vtu")
        r = self.ok(["voronoi", self.inp, "-o", out, "--bounds"] + BOX3)
        self.assertEqual(r.stderr, "", "no progress bar / messages when stderr is not a terminal")
        self.assertIn("cells", r.stdout)
        g = read_vtu(out)
        self.assertEqual(g.GetNumberOfCells(), self.N)
        types = {g.GetCellType(i) for i in range(g.GetNumberOfCells())}
        self.assertEqual(types, {42}, "every cell must be a VTK_POLYHEDRON")
        for name, cls in [("GeneratorId", "vtkIntArray"), ("Region", "vtkIntArray"), ("Volume", "vtkDoubleArray"),
                          ("NumberOfFaces", "vtkIntArray"), ("NumberOfNeighbors", "vtkIntArray")]:
            self.assertEqual(cell_array(g, name).GetClassName(), cls, name)
        gid = vtk_to_numpy(cell_array(g, "GeneratorId"))
        np.testing.assert_array_equal(gid, np.arange(self.N))
        np.testing.assert_array_equal(vtk_to_numpy(cell_array(g, "Region")), 0)
        vol = vtk_to_numpy(cell_array(g, "Volume"))
        self.assertTrue(np.all(vol > 0))
        self.assertAlmostEqual(vol.sum(), 1.0, delta=1e-9)
        # The face stream describes closed, outward-oriented polyhedra whose
        # volumes are the reported ones.
        geo_vol, nfaces = polyhedron_volumes(g)
        np.testing.assert_allclose(geo_vol, vol, rtol=1e-9, atol=1e-15)
        np.testing.assert_array_equal(nfaces, vtk_to_numpy(cell_array(g, "NumberOfFaces")))
        # Points are the merged vertices: every one is used, none repeated.
        pts = vtk_to_numpy(g.GetPoints().GetData())
        self.assertEqual(len(np.unique(pts, axis=0)), len(pts))
        self.assertTrue(np.all(pts >= -1e-12) and np.all(pts <= 1 + 1e-12))

    def test_tables_and_neighbors(self):
        vtu, csv, tnpy, nb = self.p("c.vtu"), self.p("t.csv"), self.p("t.npy"), self.p("nb.npy")
        self.ok(["voronoi", self.inp, "-o", vtu, "--cell-table", csv, "--neighbors", nb, "--bounds"] + BOX3)
        self.ok(["voronoi", self.inp, "--cell-table", tnpy, "--bounds"] + BOX3 + ["-q"])
        with open(csv) as f:
            header = f.readline().strip()
        self.assertEqual(header, "id,region,volume,cx,cy,cz,faces,neighbors")
        t = np.loadtxt(csv, delimiter=",", skiprows=1)
        tn = np.load(tnpy)
        self.assertEqual(tn.dtype, np.float64)
        self.assertEqual(tn.shape, (self.N, 8))
        self.assertEqual(t.shape, (self.N, 8))
        np.testing.assert_array_equal(t, tn)  # csv keeps 17 significant digits
        np.testing.assert_array_equal(t[:, 0], np.arange(self.N))
        self.assertAlmostEqual(t[:, 2].sum(), 1.0, delta=1e-9)
        # centroids lie inside the box and near their generator
        self.assertTrue(np.all((t[:, 3:6] > 0) & (t[:, 3:6] < 1)))

        g = read_vtu(vtu)
        np.testing.assert_array_equal(vtk_to_numpy(cell_array(g, "Volume")), t[:, 2])
        n, off, ids = load_neighbors(nb)
        self.assertEqual(n, self.N)
        self.assertEqual(off[0], 0)
        self.assertEqual(off[-1], len(ids))
        self.assertTrue(np.all(np.diff(off) >= 0))
        np.testing.assert_array_equal(np.diff(off), t[:, 7])
        np.testing.assert_array_equal(np.diff(off), vtk_to_numpy(cell_array(g, "NumberOfNeighbors")))
        pairs = set()
        for c in range(n):
            lst = ids[off[c]:off[c + 1]]
            self.assertTrue(np.all(np.diff(lst) > 0), "neighbours must be ascending, unique")
            self.assertNotIn(c, lst)
            pairs.update((c, int(j)) for j in lst)
        for (i, j) in pairs:
            self.assertIn((j, i), pairs, "neighbour relation must be symmetric")
        # box faces are counted in faces but not listed as neighbours
        self.assertTrue(np.all(t[:, 6] >= t[:, 7]))

    def test_threads_byte_identical(self):
        pts = np.random.default_rng(11).random((5000, 3))
        inp = self.save("big.npy", pts)
        outs = {}
        for th in (1, 2):
            vtu, csv, nb = self.p("t%d.vtu" % th), self.p("t%d.csv" % th), self.p("n%d.npy" % th)
            self.ok(["voronoi", inp, "-o", vtu, "--cell-table", csv, "--neighbors", nb, "--threads", th, "-q"])
            outs[th] = [read_bytes(f) for f in (vtu, csv, nb)]
        for a, b, what in zip(outs[1], outs[2], ("vtu", "csv", "neighbors")):
            self.assertTrue(a == b, "%s differs between --threads 1 and --threads 2" % what)
        # the environment variable is honoured the same way
        vtu = self.p("env.vtu")
        self.ok(["voronoi", inp, "-o", vtu, "-q"], env={"TESSERA_NUM_THREADS": "2"})
        self.assertTrue(read_bytes(vtu) == outs[1][0])
        # More threads than cores run as asked (oversubscribed), with the same
        # bytes and nothing from oneTBB on stderr ("TBB Warning: The number of
        # workers is currently limited ...", while the summary claimed them).
        many = len(os.sched_getaffinity(0)) + 2
        vtu = self.p("many.vtu")
        r = self.ok(["voronoi", inp, "-o", vtu, "--threads", many])
        self.assertNotIn("TBB", r.stderr)
        self.assertIn("on %d threads" % many, r.stdout)
        self.assertTrue(read_bytes(vtu) == outs[1][0])

    def test_one_thread_means_one_thread(self):
        # --threads 1 (and TESSERA_NUM_THREADS=1) bounds the writers too: the
        # .vtu writer formatted its chunks on every core (a second thread
        # with ~0.1 s of CPU on 200k points). Per-thread CPU from /proc.
        pts = np.random.default_rng(12).random((200000, 3))
        inp = self.save("one.npy", pts)

        def busy_threads(args, env):
            full_env = dict(os.environ)
            full_env.pop("TESSERA_NUM_THREADS", None)
            full_env.update(env)
            p = subprocess.Popen([TESSERA] + args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=full_env)
            cpu = {}
            while p.poll() is None:
                try:
                    for tid in os.listdir("/proc/%d/task" % p.pid):
                        try:
                            with open("/proc/%d/task/%s/stat" % (p.pid, tid)) as f:
                                fields = f.read().rsplit(")", 1)[1].split()
                            cpu[tid] = (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
                        except (OSError, IndexError, ValueError):
                            pass
                except OSError:
                    pass
                time.sleep(0.01)
            self.assertEqual(p.returncode, 0)
            return sorted(cpu.values(), reverse=True)

        for args, env in ((["--threads", "1"], {}), ([], {"TESSERA_NUM_THREADS": "1"})):
            cpu = busy_threads(["voronoi", inp, "-o", self.p("one.vtu"), "--cell-table", self.p("one.csv"), "-q"] + args, env)
            self.assertGreater(cpu[0], 0.3, cpu)
            self.assertTrue(all(c < 0.03 for c in cpu[1:]), "more than one thread worked: %s (%s %s)" % (cpu, args, env))

    def test_chunked_writers_read_back(self):
        # The .vtu's connectivity and faces, and the .csv's rows, are written
        # in chunks of 4096 cells and 8192 rows formatted in parallel: the
        # cells on both sides of each seam must read back whole.
        n = 9000
        pts = np.random.default_rng(12).random((n, 3))
        vtu, csv, tnpy = self.p("k.vtu"), self.p("k.csv"), self.p("k.npy")
        self.ok(["voronoi", self.save("k_in.npy", pts), "-o", vtu, "--cell-table", csv, "--threads", "2", "-q"])
        self.ok(["voronoi", self.p("k_in.npy"), "--cell-table", tnpy, "--threads", "2", "-q"])
        np.testing.assert_array_equal(np.loadtxt(csv, delimiter=",", skiprows=1), np.load(tnpy))
        g = read_vtu(vtu)
        self.assertEqual(g.GetNumberOfCells(), n)
        pts_out = vtk_to_numpy(g.GetPoints().GetData())
        faces = vtk_to_numpy(g.GetFaces())
        locs = vtk_to_numpy(g.GetFaceLocations())
        vol = vtk_to_numpy(cell_array(g, "Volume"))
        for c in [0, 1, 4094, 4095, 4096, 4097, 8190, 8191, 8192, 8193, n - 1]:
            cell = cell_faces(faces, locs[c])
            order = []
            for ids in cell:
                order.extend(int(i) for i in ids if int(i) not in order)
            self.assertAlmostEqual(faces_volume(pts_out, cell), vol[c], delta=1e-12, msg="cell %d" % c)
            cell_ids = g.GetCell(c).GetPointIds()
            self.assertEqual([cell_ids.GetId(i) for i in range(cell_ids.GetNumberOfIds())], order,
                             "cell %d: its points are its face vertices in first-appearance order" % c)

    def test_default_bounds_and_validate(self):
        out = self.p("cells.vtu")
        r = self.ok(["voronoi", self.inp, "-o", out, "--validate"])
        self.assertIn("validation: OK", r.stdout)
        self.assertRegex(r.stdout, r"exact measures +\d+ sampled cells against exact arithmetic: "
                                   r"largest relative volume error")
        self.assertRegex(r.stdout, r"exact corners +their merged vertices against exact positions: "
                                   r"largest offset \S+ of the cell radius \(vertex \d+\)")
        g = read_vtu(out)
        self.assertEqual(g.GetNumberOfCells(), self.N)
        # default domain: bounding box padded by 1% of the largest extent, then
        # rounded outward to a multiple of 2^(e-7), ext = f * 2^e (docs/design.md)
        lo, hi = self.pts.min(0), self.pts.max(0)
        ext = (hi - lo).max()
        pad = 0.01 * ext
        step = 2.0 ** (np.frexp(ext)[1] - 7)
        blo = np.floor((lo - pad) / step) * step
        bhi = np.ceil((hi + pad) / step) * step
        expected = np.prod(bhi - blo)
        vol = vtk_to_numpy(cell_array(g, "Volume"))
        self.assertAlmostEqual(vol.sum() / expected, 1.0, delta=1e-9)

    def test_duplicates_reported(self):
        pts = self.pts.copy()
        pts[17] = pts[3]
        inp = self.save("dup.npy", pts)
        out = self.p("d.vtu")
        r = self.ok(["voronoi", inp, "-o", out, "--bounds"] + BOX3)
        self.assertIn("point 17 duplicates point 3", r.stdout)
        g = read_vtu(out)
        self.assertEqual(g.GetNumberOfCells(), self.N - 1)
        gid = vtk_to_numpy(cell_array(g, "GeneratorId"))
        self.assertNotIn(17, gid)
        self.assertAlmostEqual(vtk_to_numpy(cell_array(g, "Volume")).sum(), 1.0, delta=1e-9)

    def test_tie_heavy_input_hint(self):
        # Points normalized onto one sphere tie (to rounding) at its centre:
        # searched, thousands of exact calls per cell, which the summary
        # points out along with the remedies; ordinary input gets no such
        # remark. The automatic method builds them from the Delaunay
        # triangulation instead (and says so), with the same cells.
        v = np.random.default_rng(5).normal(size=(200, 3))
        v /= np.linalg.norm(v, axis=1)[:, None]
        sph = self.save("sphere.npy", v)
        r = self.ok(["voronoi", sph, "--method", "search", "-o", self.p("s.vtu"), "--neighbors", self.p("s.npy")])
        self.assertIn("over 1000 per cell", r.stdout)
        self.assertIn("--method insertion", r.stdout)
        self.assertIn("tessera joggle", r.stdout)
        self.assertNotIn("Delaunay neighbours", r.stdout)
        r = self.ok(["voronoi", sph, "-o", self.p("a.vtu"), "--neighbors", self.p("a.npy")])
        self.assertNotIn("over 1000 per cell", r.stdout)
        # All 200 sphere points lie on the hull: open stars, assembled too.
        self.assertIn("method             insertion (200 cells assembled from their Delaunay stars, 0 clipped by "
                      "their Delaunay neighbours)", r.stdout)
        self.assertTrue(np.array_equal(np.load(self.p("s.npy")), np.load(self.p("a.npy"))))
        r = self.ok(["voronoi", self.inp, "-o", self.p("u.vtu")])
        self.assertNotIn("over 1000 per cell", r.stdout)
        self.assertNotIn("Delaunay neighbours", r.stdout)

    def test_extreme_scale_validates(self):
        # Coordinates near 1e-124: the cells are exact, but their volumes
        # (~1e-375) underflow. --validate checks the topology, says the
        # volumes cannot be compared, and passes; the summary says so too.
        tiny = np.ldexp(self.pts, -410)
        r = self.ok(["voronoi", self.save("tiny.npy", tiny), "-o", self.p("t.vtu"), "--validate"])
        self.assertIn("validation: OK", r.stdout)
        self.assertIn("outside double's range", r.stdout)
        self.assertIn("volume sum         not checked", r.stdout)
        r = self.ok(["voronoi", self.inp, "-o", self.p("u.vtu"), "--validate"])
        self.assertNotIn("outside double's range", r.stdout)
        # Near 1e110 the volumes overflow: the summary's sum is inf, not the
        # compensated sum's NaN (inf - inf).
        huge = np.ldexp(self.pts[:50], 366)
        r = self.ok(["voronoi", self.save("huge.npy", huge), "-o", self.p("h.vtu")])
        self.assertIn("volume sum         inf (domain inf", r.stdout)

    def test_anisotropic_lattice_validates(self):
        # A lattice 1e-8 apart across and 1 apart along (voxel centres of an
        # image with anisotropic spacing): every vertex is an exact tie, the
        # planes' magnitudes differ by 1e8. Until stop 17 its bins were sized
        # for the volume density and the run took 49 s.
        g = np.stack(np.meshgrid(*[np.arange(8.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
        g[:, 0] *= 1e-8
        r = self.ok(["voronoi", self.save("slab.npy", g), "-o", self.p("slab.vtu"), "--validate",
                     "--bounds", "-0.5e-8", "7.5e-8", "-0.5", "7.5", "-0.5", "7.5"])
        self.assertIn("validation: OK", r.stdout)
        vol = vtk_to_numpy(cell_array(read_vtu(self.p("slab.vtu")), "Volume"))
        np.testing.assert_allclose(vol, 1e-8, rtol=1e-9)

    def test_extent_beyond_double_validates(self):
        # Points spanning -1e308..1e308: their extent overflows double, but
        # their domain (padded by 1%) does not. Cells and Delaunay are
        # computed and validated (until stop 17: a segfault, and a Delaunay
        # volume check that compared NaNs and passed).
        huge = self.save("huge.npy", (self.pts * 2 - 1) * 1e308)
        r = self.ok(["voronoi", huge, "-o", self.p("h.vtu"), "--validate"])
        self.assertIn("validation: OK", r.stdout)
        r = self.ok(["delaunay", huge, "-o", self.p("hd.vtu"), "--validate"])
        self.assertIn("validation passed", r.stdout + r.stderr)
        self.assertNotIn("nan", (r.stdout + r.stderr).lower())

    def test_labels(self):
        labels = np.random.default_rng(5).integers(-1, 3, self.N).astype(np.int32)
        lab = self.save("labels.npy", labels)
        out = self.p("l.vtu")
        self.ok(["voronoi", self.inp, "--labels", lab, "-o", out, "--bounds"] + BOX3)
        g = read_vtu(out)
        inside = np.flatnonzero(labels >= 0)
        self.assertEqual(g.GetNumberOfCells(), len(inside))
        gid = vtk_to_numpy(cell_array(g, "GeneratorId"))
        np.testing.assert_array_equal(gid, inside)
        np.testing.assert_array_equal(vtk_to_numpy(cell_array(g, "Region")), labels[inside])
        vol = vtk_to_numpy(cell_array(g, "Volume")).sum()
        self.assertLess(vol, 1.0)  # outside points own the rest of the box

    def test_ignore_outside(self):
        pts = self.pts * 2 - 0.5  # about 7/8 of the points leave the unit box
        inp = self.save("wide.npy", pts)
        out = self.p("i.vtu")
        inside = np.flatnonzero(np.all((pts >= 0) & (pts <= 1), axis=1))
        r = self.ok(["voronoi", inp, "-o", out, "--ignore-outside", "--bounds"] + BOX3)
        self.assertIn("ignored", r.stdout)
        g = read_vtu(out)
        self.assertEqual(g.GetNumberOfCells(), len(inside))
        np.testing.assert_array_equal(vtk_to_numpy(cell_array(g, "GeneratorId")), inside)
        self.assertAlmostEqual(vtk_to_numpy(cell_array(g, "Volume")).sum(), 1.0, delta=1e-9)

    def test_csv_input_and_summary(self):
        csv_in = self.p("pts.csv")
        np.savetxt(csv_in, self.pts, delimiter=",", fmt="%.17g")
        out = self.p("c.vtu")
        r = self.ok(["voronoi", csv_in, "-o", out, "--bounds"] + BOX3)
        for word in ("points", "cells", "duplicates", "volume sum", "compute", "thread", out):
            self.assertIn(word, r.stdout)
        self.assertEqual(read_vtu(out).GetNumberOfCells(), self.N)

    def test_non_finite_points_set_aside(self):
        # An organized cloud (PCL's .pcd) marks missing returns with NaN
        # points: refused, or with --ignore-outside set aside by id, the
        # default domain and the cells those of the other points.
        pts = self.pts.copy()
        missing = [0, 7, 123, self.N - 1]
        pts[missing] = np.nan
        pcd = self.p("organized.pcd")
        with open(pcd, "w") as f:
            f.write("VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 20\nHEIGHT %d\n"
                    "POINTS %d\nDATA ascii\n" % (self.N // 20, self.N))
            for p in pts:
                f.write("%.17g %.17g %.17g\n" % tuple(p))
        r = run(["voronoi", pcd, "--cell-table", self.p("x.csv")])
        self.assertEqual(r.returncode, 2)
        self.assertIn("--ignore-outside", r.stderr)
        t = self.p("t.csv")
        r = self.ok(["voronoi", pcd, "--cell-table", t, "--ignore-outside"])
        self.assertIn("ignored (outside)  4 (points 0, 7, 123, %d)" % (self.N - 1), r.stdout)
        kept = np.delete(np.arange(self.N), missing)
        ref = self.p("ref.csv")
        self.ok(["voronoi", self.save("kept.npy", self.pts[kept]), "--cell-table", ref])
        a = np.loadtxt(t, delimiter=",", skiprows=1)
        b = np.loadtxt(ref, delimiter=",", skiprows=1)
        self.assertTrue(np.array_equal(a[:, 0], kept))  # the input's ids
        self.assertTrue(np.array_equal(a[:, 1:], b[:, 1:]))

    def test_fortran_order_records_and_named_columns(self):
        # The same points as a Fortran-order .npy (np.save of a transposed
        # array, or of a pandas DataFrame's to_numpy()), as a structured .npy
        # (PDAL's arrays, to_records()) and as a CSV led by an unnamed index
        # column with the axes out of order (pandas' to_csv): the same cells
        # as the C-order .npy.
        ref = self.p("ref.csv")
        self.ok(["voronoi", self.inp, "--cell-table", ref, "-q", "--bounds"] + BOX3)
        f_npy = self.p("f.npy")
        np.save(f_npy, np.asfortranarray(self.pts))
        with open(f_npy, "rb") as f:
            self.assertIn(b"'fortran_order': True", f.read(128))
        csv_in = self.p("indexed.csv")
        with open(csv_in, "w") as f:
            f.write(",id,z,y,x\n")
            for i, (x, y, z) in enumerate(self.pts):
                f.write("%d,%d,%.17g,%.17g,%.17g\n" % (i, 1000 + i, z, y, x))
        rec = np.zeros(len(self.pts), dtype=[("Id", "<i8"), ("Z", "<f8"), ("Y", "<f8"), ("X", "<f8"), ("cls", "u1")])
        rec["Id"] = np.arange(len(self.pts))
        rec["X"], rec["Y"], rec["Z"] = self.pts.T
        r_npy = self.p("records.npy")
        np.save(r_npy, rec)
        for k, inp in enumerate((f_npy, csv_in, r_npy)):
            t = self.p("t%d.csv" % k)
            self.ok(["voronoi", inp, "--cell-table", t, "-q", "--bounds"] + BOX3)
            with open(ref) as a, open(t) as b:
                self.assertEqual(a.read(), b.read(), inp)

    def test_vtk_point_files(self):
        # Points saved by VTK's own XML writers (ParaView's "Save Data"), in
        # every data mode, with and without zlib, 32- and 64-bit headers, in
        # pieces, float32 in a .vtu; labels and scalars from point data: the
        # same cells as the same points and labels from .npy files.
        labels = np.random.default_rng(5).integers(-1, 3, self.N).astype(np.int32)
        lab_npy = self.save("lab.npy", labels)

        def dataset(kind, pts):
            d = vtk.vtkPolyData() if kind == "vtp" else vtk.vtkUnstructuredGrid()
            p = vtk.vtkPoints()
            p.SetData(numpy_to_vtk(pts, deep=1))
            d.SetPoints(p)
            for name, values in (("RegionId", labels), ("temp", pts[:, 0] * 2)):
                a = numpy_to_vtk(values, deep=1)
                a.SetName(name)
                d.GetPointData().AddArray(a)
            return d

        def table(inp, *extra):
            t = self.p("t.csv")
            self.ok(["voronoi", inp, "--cell-table", t, "-q", "--bounds"] + BOX3 + list(extra))
            with open(t) as f:
                return f.read()

        ref = table(self.inp, "--labels", lab_npy)
        ref32 = table(self.save("p32.npy", self.pts.astype(np.float32)), "--labels", lab_npy)
        cases = [("vtp", mode, zlib, h64, pieces) for mode in ("Ascii", "Binary", "Appended")
                 for zlib in (False, True) for h64 in (False, True) for pieces in (1, 3)
                 if not (mode == "Ascii" and (zlib or h64))]
        cases.append(("vtu", "Appended", True, False, 1))
        for kind, mode, zlib, h64, pieces in cases:
            name = self.p("%s_%s_%d_%d_%d.%s" % (kind, mode, zlib, h64, pieces, kind))
            pts = self.pts if kind == "vtp" else self.pts.astype(np.float32)
            w = vtk.vtkXMLPolyDataWriter() if kind == "vtp" else vtk.vtkXMLUnstructuredGridWriter()
            w.SetFileName(name)
            w.SetInputData(dataset(kind, pts))
            getattr(w, "SetDataModeTo" + mode)()
            if zlib:
                w.SetCompressorTypeToZLib()
            else:
                w.SetCompressorTypeToNone()
            if h64:
                w.SetHeaderTypeToUInt64()
            w.SetNumberOfPieces(pieces)
            self.assertEqual(w.Write(), 1)
            self.assertEqual(table(name, "--labels", "RegionId"), ref if kind == "vtp" else ref32, name)
            if pieces > 1:
                # VTK's writer repeats an input it cannot split in every
                # piece: all pieces are read, the copies found duplicates.
                r = self.ok(["voronoi", name, "--cell-table", self.p("d.csv"), "--bounds"] + BOX3)
                self.assertIn("duplicates         %d" % ((pieces - 1) * self.N), r.stdout)
        # Scalars from point data (threshold), and the errors.
        vtp = self.p("vtp_Appended_1_0_1.vtp")
        out = self.p("th.npy")
        self.ok(["threshold", vtp, "--scalars", "temp", "--interval", "0,1,1", "--interval", "1,inf,2", "-o", out, "-q"])
        np.testing.assert_array_equal(np.load(self.p("th_labels.npy")), np.where(self.pts[:, 0] * 2 < 1, 1, 2))
        r = run(["voronoi", vtp, "--labels", "temp", "-o", self.p("x.vtu")])
        self.assertEqual(r.returncode, 2)
        self.assertIn("floating-point", r.stderr)
        self.assertFalse(os.path.exists(self.p("x.vtu")))

    def test_legacy_vtk_point_files(self):
        # Points saved by VTK's legacy writers (.vtk: ParaView's "Legacy VTK",
        # LAMMPS's dump vtk, OpenFOAM's foamToVTK), as PolyData and as an
        # unstructured grid, ASCII and binary, file versions 4.2 and 5.1
        # (OFFSETS and CONNECTIVITY), with cell data and vectors on the way:
        # the same cells as the points, labels and radii VTK's own legacy
        # reader reads from them; standard input too.
        rng = np.random.default_rng(8)
        labels = rng.integers(-1, 3, self.N).astype(np.int32)
        radii = rng.random(self.N) * 0.02
        for kind in ("poly", "ugrid"):
            for binary in (False, True):
                for version in (42, 51):
                    d = vtk.vtkPolyData() if kind == "poly" else vtk.vtkUnstructuredGrid()
                    p = vtk.vtkPoints()
                    p.SetData(numpy_to_vtk(self.pts, deep=1))
                    d.SetPoints(p)
                    if kind == "poly":
                        cells = vtk.vtkCellArray()
                        for i in range(self.N):
                            cells.InsertNextCell(1)
                            cells.InsertCellPoint(i)
                        d.SetVerts(cells)
                    else:
                        for i in range(self.N):
                            d.InsertNextCell(vtk.VTK_VERTEX, 1, [i])
                    for name, values in (("grain", labels), ("radius", radii), ("vel", rng.random((self.N, 3)))):
                        a = numpy_to_vtk(values, deep=1)
                        a.SetName(name)
                        d.GetPointData().AddArray(a)
                    d.GetPointData().SetActiveScalars("radius")  # a SCALARS attribute; the others in a FIELD
                    c = numpy_to_vtk(np.arange(self.N, dtype=np.float32), deep=1)
                    c.SetName("cell")
                    d.GetCellData().AddArray(c)
                    w = vtk.vtkPolyDataWriter() if kind == "poly" else vtk.vtkUnstructuredGridWriter()
                    name = self.p("%s_%d_%d.vtk" % (kind, binary, version))
                    w.SetFileName(name)
                    w.SetInputData(d)
                    w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
                    w.SetFileVersion(version)
                    self.assertEqual(w.Write(), 1)
                    # What VTK reads back (ASCII keeps 11 digits) is the reference.
                    rd = vtk.vtkDataSetReader()
                    rd.SetFileName(name)
                    rd.ReadAllScalarsOn()
                    rd.ReadAllFieldsOn()
                    rd.Update()
                    got = rd.GetOutput()
                    pts = vtk_to_numpy(got.GetPoints().GetData()).astype(np.float64)
                    lab = vtk_to_numpy(got.GetPointData().GetArray("grain")).astype(np.int32)
                    rad = vtk_to_numpy(got.GetPointData().GetArray("radius")).astype(np.float64)
                    common = ["--cell-table", self.p("t.csv"), "-q", "--bounds"] + BOX3
                    self.ok(["voronoi", self.save("p.npy", pts), "--labels", self.save("l.npy", lab), "--radii",
                             self.save("r.npy", rad)] + common)
                    ref = read_bytes(self.p("t.csv"))
                    self.ok(["voronoi", name, "--labels", "grain", "--radii", "radius"] + common)
                    self.assertEqual(read_bytes(self.p("t.csv")), ref, name)
                    with open(name, "rb") as f:
                        r = run_bytes(["voronoi", "-", "--labels", "grain", "--radii", "radius", "--cell-table", "-",
                                       "-q", "--bounds"] + BOX3, f.read())
                    self.assertEqual(r.returncode, 0, r.stderr)
                    self.assertEqual(r.stdout, ref, name)
        # What a fuzz against VTK's reader found: vtkIdType arrays (4 bytes in
        # BINARY files), string arrays and names VTK encodes (a space as %20)
        # on the way, and byte colours (COLOR_SCALARS, byte / 255 in ASCII).
        for binary in (False, True):
            d = vtk.vtkPolyData()
            p = vtk.vtkPoints()
            p.SetData(numpy_to_vtk(self.pts, deep=1))
            d.SetPoints(p)
            grade = (np.arange(self.N) * 37 % 256).astype(np.uint8)
            g = numpy_to_vtk(grade, deep=1)
            g.SetName("grade")
            d.GetPointData().SetScalars(g)  # written as COLOR_SCALARS
            ids = vtk.vtkIdTypeArray()
            ids.SetName("ids")
            tags = vtk.vtkStringArray()
            tags.SetName("tag")
            for i in range(self.N):
                ids.InsertNextValue(3 * i)
                tags.InsertNextValue("t" * (i % 90))
            d.GetPointData().AddArray(ids)
            d.GetPointData().AddArray(tags)
            spaced = numpy_to_vtk(labels, deep=1)
            spaced.SetName("grain id")
            d.GetPointData().AddArray(spaced)
            w = vtk.vtkPolyDataWriter()
            name = self.p("extra_%d.vtk" % binary)
            w.SetFileName(name)
            w.SetInputData(d)
            w.SetFileTypeToBinary() if binary else w.SetFileTypeToASCII()
            self.assertEqual(w.Write(), 1)
            rd = vtk.vtkDataSetReader()
            rd.SetFileName(name)
            rd.Update()
            back = self.save("back.npy", vtk_to_numpy(rd.GetOutput().GetPoints().GetData()).astype(np.float64))
            common = ["--cell-table", self.p("t.csv"), "-q", "--bounds"] + BOX3
            for array, values in (("grade", grade), ("ids", 3 * np.arange(self.N)), ("grain id", labels)):
                self.ok(["voronoi", back, "--labels", self.save("l.npy", values.astype(np.int32))] + common)
                ref = read_bytes(self.p("t.csv"))
                self.ok(["voronoi", name, "--labels", array] + common)
                self.assertEqual(read_bytes(self.p("t.csv")), ref, (name, array))

        def fails(args, fragment):
            r = run(args)
            self.assertEqual(r.returncode, 2, args)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
            self.assertIn(fragment, r.stderr)
            self.assertFalse(os.path.exists(self.p("x.csv")))

        fails(["voronoi", self.p("extra_1.vtk"), "--labels", "tag", "--cell-table", self.p("x.csv")],
              "point data 'tag' holds strings, not numbers")

        for args, fragment in ((["--labels", "radius"], "labels array 'radius' holds floating-point values"),
                               (["--labels", "vel"], "point data 'vel' has 3 components, expected 1"),
                               (["--labels", "none"], "no point data array 'none' (arrays: 'radius', 'grain', 'vel')")):
            fails(["voronoi", self.p("poly_1_51.vtk"), "--cell-table", self.p("x.csv")] + args, fragment)
        with open(self.p("poly_1_51.vtk"), "rb") as f:
            whole = f.read()
        with open(self.p("cut.vtk"), "wb") as f:
            f.write(whole[:1000])
        fails(["voronoi", self.p("cut.vtk"), "--cell-table", self.p("x.csv")], "cut.vtk: POINTS: the file ends before its")

    def test_las_point_files(self):
        # LAS lidar files written field by field from the specification (1.2
        # with format 1, 1.4 with format 6 and extra bytes per record, a VLR
        # before the points): the coordinates are the records' integers
        # times the scale plus the offset (in doubles, as PDAL and laspy
        # compute them), the labels a field by name (classification).
        rng = np.random.default_rng(9)
        n = self.N
        ints = rng.integers(0, 1000000, (n, 3)).astype(np.int32)
        scale, offset = np.array([0.001, 0.001, 0.0005]), np.array([512000.0, 4100000.0, 120.0])
        xyz = ints * scale + offset
        cls = rng.integers(1, 7, n).astype(np.uint8)
        intensity = rng.integers(0, 65535, n).astype(np.uint16)

        def las(name, minor, fmt, extra):
            header_size = 375 if minor == 4 else 227
            vlr = struct.pack("<H16sHH32s", 0, b"tessera-test", 1, 4, b"a record before the points") + b"abcd"
            record = {1: 28, 6: 30}[fmt] + extra
            h = bytearray(header_size)
            h[0:4] = b"LASF"
            h[24], h[25] = 1, minor
            struct.pack_into("<HIIBHI", h, 94, header_size, header_size + len(vlr), 1, fmt, record,
                             0 if minor == 4 else n)
            struct.pack_into("<3d3d", h, 131, *scale, *offset)
            struct.pack_into("<6d", h, 179, *np.ravel([xyz.max(0), xyz.min(0)], order="F"))
            if minor == 4:
                struct.pack_into("<Q", h, 247, n)
            recs = bytearray()
            for i in range(n):
                r = bytearray(record)
                struct.pack_into("<3iH", r, 0, *ints[i], intensity[i])
                if fmt == 1:
                    r[14], r[15] = 0x09, cls[i] | 0x20  # return 1 of 1; classification with a flag bit above
                    struct.pack_into("<d", r, 20, float(i))
                else:
                    r[14], r[16] = 0x11, cls[i]
                    struct.pack_into("<d", r, 22, float(i))
                recs += r
            with open(self.p(name), "wb") as f:
                f.write(bytes(h) + vlr + bytes(recs))

        common = ["--cell-table", self.p("t.csv"), "-q"]
        self.ok(["voronoi", self.save("ref.npy", xyz), "--labels", self.save("cls.npy", cls.astype(np.int32))] + common)
        ref = read_bytes(self.p("t.csv"))
        for name, minor, fmt, extra in (("a.las", 2, 1, 0), ("b.las", 4, 6, 3)):
            las(name, minor, fmt, extra)
            self.ok(["voronoi", self.p(name), "--labels", "classification"] + common)
            self.assertEqual(read_bytes(self.p("t.csv")), ref, name)
            with open(self.p(name), "rb") as f:
                r = run_bytes(["voronoi", "-", "--labels", "classification", "--cell-table", "-", "-q"], f.read())
            self.assertEqual(r.stdout, ref, name)
            self.ok(["threshold", self.p(name), "--scalars", "intensity", "--interval", "0,30000,1", "-o",
                     self.p("th.npy"), "-q"])
            np.testing.assert_array_equal(np.load(self.p("th_labels.npy")), np.where(intensity < 30000, 1, -1))
        r = run(["voronoi", self.p("b.las"), "--labels", "gps_time", "--cell-table", self.p("x.csv")])
        self.assertIn("holds floating-point values", r.stderr)
        r = run(["voronoi", self.p("a.las"), "--labels", "color", "--cell-table", self.p("x.csv")])
        self.assertIn("no LAS field 'color' (point format 1 has 'intensity', 'return_number'", r.stderr)
        with open(self.p("a.las"), "rb") as f:
            whole = bytearray(f.read())
        whole[104] |= 0x80  # LAZ's compressed formats
        with open(self.p("c.laz"), "wb") as f:
            f.write(whole)
        r = run(["voronoi", self.p("c.laz"), "--cell-table", self.p("x.csv")])
        self.assertEqual(r.returncode, 2)
        self.assertIn("LAZ (compressed LAS) is not supported: decompress it first", r.stderr)
        whole[104] &= 0x7F
        with open(self.p("cut.las"), "wb") as f:
            f.write(bytes(whole[:-100]))
        r = run(["voronoi", self.p("cut.las"), "--cell-table", self.p("x.csv")])
        self.assertIn("(data shorter than the header says)", r.stderr)
        self.assertFalse(os.path.exists(self.p("x.csv")))

    def test_summary_names_far_points(self):
        # Two points far beyond the bulk are reported (outliers?); none otherwise.
        pts = np.vstack([self.pts, [[5e3, 0.5, 0.5], [0.5, -2e4, 0.5]]])
        inp = self.save("far.npy", pts)
        r = self.ok(["voronoi", inp, "-o", self.p("f.vtu")])
        self.assertIn("far points         2", r.stdout)
        r = self.ok(["voronoi", self.inp, "-o", self.p("g.vtu")])
        self.assertNotIn("far points", r.stdout)

    def test_quiet(self):
        r = self.ok(["voronoi", self.inp, "-o", self.p("q.vtu"), "--quiet"])
        self.assertEqual(r.stdout, "")
        self.assertEqual(r.stderr, "")


class Voronoi2D(TempDirCase):
    N = 500

    def setUp(self):
        super().setUp()
        self.pts = np.random.default_rng(7).random((self.N, 2)) * [2.0, 1.0]
        self.inp = self.save("pts2.npy", self.pts)

    def test_vtp_read_back(self):
        out = self.p("cells.vtp")
        self.ok(["voronoi", self.inp, "-o", out, "--bounds", "0", "2", "0", "1"])
        pd = read_vtp(out)
        self.assertEqual(pd.GetNumberOfPolys(), self.N)
        self.assertEqual(pd.GetNumberOfCells(), self.N)
        for name in ("GeneratorId", "Region", "Area", "NumberOfEdges", "NumberOfNeighbors"):
            cell_array(pd, name)
        area = vtk_to_numpy(cell_array(pd, "Area"))
        self.assertAlmostEqual(area.sum(), 2.0, delta=2e-9)
        geo, nverts = polygon_areas(pd)
        self.assertTrue(np.all(geo > 0), "polygons must be counter-clockwise")
        np.testing.assert_allclose(geo, area, rtol=1e-9, atol=1e-15)
        np.testing.assert_array_equal(nverts, vtk_to_numpy(cell_array(pd, "NumberOfEdges")))
        pts = vtk_to_numpy(pd.GetPoints().GetData())
        self.assertEqual(pts.shape[1], 3)
        self.assertTrue(np.all(pts[:, 2] == 0))

    def test_2d_tables(self):
        csv, tnpy, nb = self.p("t.csv"), self.p("t.npy"), self.p("nb.npy")
        self.ok(["voronoi", self.inp, "--cell-table", csv, "--neighbors", nb, "-q"])
        self.ok(["voronoi", self.inp, "--cell-table", tnpy, "-q"])
        with open(csv) as f:
            self.assertEqual(f.readline().strip(), "id,region,area,cx,cy,edges,neighbors")
        t = np.loadtxt(csv, delimiter=",", skiprows=1)
        self.assertEqual(t.shape, (self.N, 7))
        self.assertEqual(np.load(tnpy).shape, (self.N, 7))
        n, off, ids = load_neighbors(nb)
        self.assertEqual(n, self.N)
        np.testing.assert_array_equal(np.diff(off), t[:, 6])

    def test_dim2_from_3_columns(self):
        pts3 = np.column_stack([self.pts, np.random.default_rng(1).random(self.N)])
        inp = self.save("p3.npy", pts3)
        out = self.p("c.vtp")
        self.ok(["voronoi", inp, "--dim", "2", "-o", out, "--bounds", "0", "2", "0", "1"])
        self.assertEqual(read_vtp(out).GetNumberOfPolys(), self.N)

    def test_bounds_before_input(self):
        # CLI11 hands the input to a 2D --bounds; the command must take it back.
        out = self.p("c.vtp")
        self.ok(["voronoi", "--bounds", "0", "2", "0", "1", self.inp, "-o", out, "-q"])
        self.ok(["voronoi", "--bounds=0,2,0,1", self.inp, "-o", out, "-q"])
        self.assertEqual(read_vtp(out).GetNumberOfPolys(), self.N)

    def test_bounds_of_subnormal_size(self):
        # strtod's ERANGE for a subnormal made "'1e-310' is not a number",
        # where Python's bounds= and the default domain take such values.
        pts = self.save("sub.npy", np.array([[1e-311, 2e-311], [5e-311, 6e-311], [3e-311, 9e-311]]))
        t = self.p("t.csv")
        self.ok(["voronoi", pts, "--bounds", "0", "1e-310", "0", "1e-310", "--cell-table", t, "-q"])
        self.assertEqual(len(np.loadtxt(t, delimiter=",", skiprows=1)), 3)
        r = run(["voronoi", pts, "--bounds", "0", "1e400", "0", "1", "--cell-table", t])
        self.assertEqual(r.returncode, 2)
        self.assertIn("'1e400' is beyond double's range", r.stderr)
        # A word that is not wholly a number: the INPUT after a 2D --bounds,
        # or not a number, even where its numeric prefix overflows.
        import shutil
        shutil.copy(pts, self.p("1e-400.npy"))
        r = subprocess.run([TESSERA, "voronoi", "--bounds", "0", "1e-310", "0", "1e-310", "1e-400.npy", "--cell-table",
                            t, "-q"], capture_output=True, text=True, cwd=self.dir)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run(["voronoi", pts, "--bounds", "0", "1", "0", "1e400abc", "--cell-table", t])
        self.assertIn("'1e400abc' is not a number", r.stderr)

    def test_numbers_without_a_leading_zero(self):
        # CLI11 took -.5 for an option: "--bounds: At least 4 required but
        # received 2"; -0.5 was a value. Both are now, in every command.
        t, a = self.p("t.csv"), self.p("a.csv")
        self.ok(["voronoi", self.inp, "--bounds", "-.5", "2", "-.25", "1", "--cell-table", t, "-q"])
        self.ok(["voronoi", self.inp, "--bounds", "-0.5", "2", "-0.25", "1", "--cell-table", a, "-q"])
        self.assertEqual(read_bytes(t), read_bytes(a))
        f = self.p("f.npy")
        self.ok(["fill", self.inp, "-o", f, "--bounds", "-.5", "2", "-.25", "1", "-q"])

    def test_threads_byte_identical(self):
        a, b = self.p("a.vtp"), self.p("b.vtp")
        self.ok(["voronoi", self.inp, "-o", a, "--threads", "1", "-q"])
        self.ok(["voronoi", self.inp, "-o", b, "--threads", "2", "-q"])
        self.assertTrue(read_bytes(a) == read_bytes(b))


class Interrupt(TempDirCase):
    def test_ctrl_c_writes_nothing(self):
        """SIGINT during the computation: exit 130, one error line, no output."""
        import pty
        import signal
        import time
        inp = self.save("p.npy", np.random.default_rng(4).random((300000, 3)))
        out = self.p("c.vtu")
        pid, fd = pty.fork()  # a terminal, as for an interactive user
        if pid == 0:
            os.execv(TESSERA, [TESSERA, "voronoi", inp, "-o", out])
        time.sleep(0.5)
        os.kill(pid, signal.SIGINT)
        text = b""
        while True:
            try:
                chunk = os.read(fd, 65536)
            except OSError:
                break
            if not chunk:
                break
            text += chunk
        os.close(fd)
        _, status = os.waitpid(pid, 0)
        code = os.waitstatus_to_exitcode(status)
        if code == 0:
            self.skipTest("the run finished before the signal")
        self.assertEqual(code, 130, text)
        self.assertIn(b"tessera: error: interrupted", text)
        self.assertEqual(sorted(os.listdir(self.dir)), ["p.npy"])

    def test_ignored_ctrl_c_stays_ignored(self):
        """Started with SIGINT ignored (a shell's background job, nohup), a
        Ctrl-C during the computation is ignored too: it was taken as an
        interruption there, and ignored while writing."""
        import signal
        import time
        inp = self.save("p.npy", np.random.default_rng(4).random((300000, 3)))
        out = self.p("c.vtu")
        proc = subprocess.Popen([TESSERA, "voronoi", inp, "-o", out, "-q"], stderr=subprocess.PIPE,
                                preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
        time.sleep(0.3)
        for _ in range(3):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
            time.sleep(0.1)
        err = proc.communicate(timeout=120)[1]
        self.assertEqual(proc.returncode, 0, err)
        self.assertTrue(os.path.exists(out))

    def kill_while_writing(self, sig, message):
        """Signal `sig` once the output's temporary exists: the run ends by that
        signal, prints one error line, and leaves neither the output nor its
        temporary (a killed run used to leave OUTPUT.tmp-XXXXXX behind)."""
        import time
        inp = self.save("p.npy", np.random.default_rng(5).random((200000, 3)))
        out = self.p("c.vtu")
        proc = subprocess.Popen([TESSERA, "voronoi", inp, "-o", out, "-q"], stderr=subprocess.PIPE)
        deadline = time.monotonic() + 120
        while proc.poll() is None and time.monotonic() < deadline:
            if any(".tmp-" in name for name in os.listdir(self.dir)):
                proc.send_signal(sig)
                break
            time.sleep(0.001)
        err = proc.communicate(timeout=120)[1]
        if proc.returncode == 0:
            self.skipTest("the write finished before the signal")
        self.assertEqual(proc.returncode, -sig, err)
        self.assertEqual(err.decode().strip().splitlines(), ["tessera: error: " + message + "; unfinished output removed"])
        self.assertEqual(sorted(os.listdir(self.dir)), ["p.npy"])

    def test_sigterm_while_writing_removes_the_temporary(self):
        import signal
        self.kill_while_writing(signal.SIGTERM, "terminated (SIGTERM)")

    def test_ctrl_c_while_writing_removes_the_temporary(self):
        import signal
        self.kill_while_writing(signal.SIGINT, "interrupted")


class Stdin(TempDirCase):
    """INPUT "-": standard input, spooled into a temporary in $TMPDIR named by
    the format its first bytes show, which is gone after the run however it
    ends; and Qhull's point format, which `rbox` writes."""
    N = 300

    def setUp(self):
        super().setUp()
        self.tmp = self.p("tmpdir")
        os.mkdir(self.tmp)
        self.pts = np.random.default_rng(11).random((self.N, 3))
        self.ref = self.p("ref.csv")
        self.ok(["voronoi", self.save("pts.npy", self.pts), "--cell-table", self.ref, "--bounds"] + BOX3)

    def piped(self, args, data):
        env = dict(os.environ, TMPDIR=self.tmp)
        env.pop("TESSERA_NUM_THREADS", None)
        r = subprocess.run([TESSERA] + args, input=data, capture_output=True, env=env, timeout=600)
        self.assertEqual(os.listdir(self.tmp), [], "the spool of standard input is removed")
        return r

    def qhull_text(self, pts, comment="rbox 300 D3"):
        lines = ["%d %s" % (pts.shape[1], comment), str(len(pts))]
        lines += [" ".join("%.17g" % v for v in row) for row in pts]
        return ("\n".join(lines) + "\n").encode()

    def test_every_format_through_stdin(self):
        import io
        buf = io.BytesIO()
        np.save(buf, self.pts)
        csv = "x,y,z\n" + "".join("%.17g,%.17g,%.17g\n" % tuple(r) for r in self.pts)
        ply = "ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\nproperty double z\nend_header\n" % self.N
        ply += "".join("%.17g %.17g %.17g\n" % tuple(r) for r in self.pts)
        inputs = {"npy": buf.getvalue(), "csv": csv.encode(), "ply": ply.encode(), "qhull": self.qhull_text(self.pts)}
        if vtk is not None:
            d = vtk.vtkPolyData()
            p = vtk.vtkPoints()
            p.SetData(numpy_to_vtk(self.pts, deep=1))
            d.SetPoints(p)
            w = vtk.vtkXMLPolyDataWriter()
            w.SetInputData(d)
            w.SetFileName(self.p("pts.vtp"))
            w.Write()
            with open(self.p("pts.vtp"), "rb") as f:
                inputs["vtp"] = f.read()
        with open(self.ref) as f:
            want = f.read()
        for kind, data in inputs.items():
            t = self.p("t_%s.csv" % kind)
            r = self.piped(["voronoi", "-", "--cell-table", t, "--bounds"] + BOX3, data)
            self.assertEqual(r.returncode, 0, (kind, r.stderr))
            self.assertIn(b"from stdin", r.stdout, kind)
            with open(t) as f:
                self.assertEqual(f.read(), want, kind)
        # The same Qhull text from a file; and rbox's own output, through a pipe.
        q = self.p("rbox.txt")
        with open(q, "wb") as f:
            f.write(inputs["qhull"])
        t = self.p("t_file.csv")
        self.ok(["voronoi", q, "--cell-table", t, "--bounds"] + BOX3)
        with open(t) as f:
            self.assertEqual(f.read(), want)
        if shutil.which("rbox"):
            data = subprocess.run(["rbox", "500", "D3"], capture_output=True, check=True).stdout
            r = self.piped(["voronoi", "-", "--neighbors", self.p("nb.npy"), "--validate"], data)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn(b"500 points (3D) from stdin", r.stdout)

    def test_outputs_to_stdout(self):
        # "-" as the table, the neighbours or the simplices: the file's bytes on
        # standard output alone, the summary on standard error.
        inp = self.save("pts.npy", self.pts)
        with open(self.ref, "rb") as f:
            want = f.read()
        r = run_bytes(["voronoi", inp, "--cell-table", "-", "--bounds"] + BOX3)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout, want)
        self.assertIn(b"tessera voronoi: 300 points (3D)", r.stderr)
        self.assertIn(b"wrote              stdout", r.stderr)
        nb = self.p("nb.npy")
        self.ok(["voronoi", inp, "--neighbors", nb, "--bounds"] + BOX3)
        r = run_bytes(["voronoi", "-", "--neighbors", "-", "-q", "--bounds"] + BOX3, self.qhull_text(self.pts))
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(nb, "rb") as f:
            self.assertEqual(r.stdout, f.read())
        sx = self.p("s.npy")
        self.ok(["delaunay", inp, "--simplices", sx])
        r = run_bytes(["delaunay", inp, "--simplices", "-", "--validate"])
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(sx, "rb") as f:
            self.assertEqual(r.stdout, f.read())
        self.assertIn(b"valid", r.stderr.lower())
        # The point tools write the binary .ply, which `voronoi -` reads back.
        jp = self.p("j.ply")
        self.ok(["joggle", inp, "-o", jp])
        r = run_bytes(["joggle", inp, "-o", "-"])
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(b"wrote stdout", r.stderr)
        with open(jp, "rb") as f:
            self.assertEqual(r.stdout, f.read())
        filled = run_bytes(["fill", inp, "-o", "-", "-q"]).stdout
        r = run_bytes(["voronoi", "-", "--labels", "label", "--cell-table", "-", "-q"], filled)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.count(b"\n"), self.N + 1, "the filled points own no cells")
        for args, words in ((["voronoi", inp, "--cell-table", "-", "--neighbors", "-"], "only one output"),
                            (["voronoi", inp, "-o", "-"], "not to standard output"),
                            (["delaunay", inp, "-o", "-"], "not to standard output")):
            r = run_bytes(args)
            self.assertEqual(r.returncode, 2, args)
            self.assertEqual(r.stdout, b"")
            self.assertIn(words, r.stderr.decode())

    def test_threshold_reads_stdin_twice(self):
        # threshold reads INPUT for the points, then again for its scalars.
        csv = "x,y,z,temp\n" + "".join("%.17g,%.17g,%.17g,%d\n" % (x, y, z, i % 3) for i, (x, y, z) in enumerate(self.pts))
        out = self.p("lab.npy")
        r = self.piped(["threshold", "-", "--scalars", "temp", "--interval", "1,2,7", "-o", out], csv.encode())
        self.assertEqual(r.returncode, 0, r.stderr)
        labels = np.load(self.p("lab_labels.npy"))
        self.assertEqual(int((labels == 7).sum()), len([i for i in range(self.N) if i % 3 == 1]))

    def test_errors_name_stdin(self):
        for data, words in ((b"", "stdin: no points"), (b"1,2,3\n4,x,6\n", "stdin: line 2"),
                            (self.qhull_text(self.pts[:5])[:-30], "stdin: Qhull point format"),
                            (b"<?xml version='1.0'?>\n<Other/>\n", "stdin: XML, but not a VTK")):
            r = self.piped(["voronoi", "-", "--cell-table", self.p("e.csv")], data)
            self.assertEqual(r.returncode, 2, data)
            lines = r.stderr.decode().splitlines()
            self.assertEqual(len(lines), 1, r.stderr)
            self.assertTrue(lines[0].startswith("tessera: error: " + words), lines[0])
            self.assertNotIn(self.tmp, lines[0])
            self.assertFalse(os.path.exists(self.p("e.csv")))

    def test_terminal_is_refused(self):
        import pty
        master, slave = pty.openpty()
        try:
            env = dict(os.environ, TMPDIR=self.tmp)
            r = subprocess.run([TESSERA, "voronoi", "-", "--cell-table", self.p("e.csv")], stdin=slave,
                               capture_output=True, env=env, timeout=60)
        finally:
            os.close(master)
            os.close(slave)
        self.assertEqual(r.returncode, 2)
        self.assertIn(b"standard input, which is a terminal", r.stderr)

    def test_sigterm_while_reading_removes_the_spool(self):
        import signal
        import time
        env = dict(os.environ, TMPDIR=self.tmp)
        proc = subprocess.Popen([TESSERA, "voronoi", "-", "--cell-table", self.p("e.csv")], stdin=subprocess.PIPE,
                                stderr=subprocess.PIPE, env=env)
        proc.stdin.write(b"x,y,z\n" + b"0.5,0.5,0.5\n" * 20000)  # past the first 64 KiB: the spool exists
        proc.stdin.flush()
        deadline = time.monotonic() + 60
        while not os.listdir(self.tmp) and time.monotonic() < deadline:
            time.sleep(0.005)
        self.assertTrue(os.listdir(self.tmp), "the spool appears while standard input is open")
        proc.send_signal(signal.SIGTERM)
        err = proc.communicate(timeout=60)[1]
        self.assertEqual(proc.returncode, -signal.SIGTERM, err)
        self.assertEqual(os.listdir(self.tmp), [])


class Bench(TempDirCase):
    KEYS = {"tool", "op", "n", "threads", "seconds", "simplices", "extra"}
    EXTRA = {"cpu_user_s", "cpu_sys_s", "minflt", "peak_rss_bytes", "neighbors", "exact_calls", "volume_sum"}

    def check_lines(self, out, op, n, count):
        lines = [l for l in out.splitlines() if l.strip()]
        self.assertEqual(len(lines), count, out)
        for line in lines:
            j = json.loads(line)
            self.assertTrue(self.KEYS <= set(j), j)
            self.assertTrue(self.EXTRA <= set(j["extra"]), j)
            self.assertEqual(j["tool"], "tessera")
            self.assertEqual(j["op"], op)
            self.assertEqual(j["n"], n)
            self.assertEqual(j["simplices"], n)
            self.assertGreaterEqual(j["threads"], 1)
            self.assertGreater(j["seconds"], 0)
            self.assertGreater(j["extra"]["neighbors"], 0)
            self.assertGreater(j["extra"]["peak_rss_bytes"], 0)
            self.assertAlmostEqual(j["extra"]["volume_sum"], 1.0, delta=1e-9)

    def test_bench_3d(self):
        inp = self.save("p.npy", np.random.default_rng(2).random((2000, 3)))
        r = self.ok(["bench", "voronoi", inp, "--repeat", "3", "--threads", "2", "--bounds"] + BOX3)
        self.check_lines(r.stdout, "voronoi3", 2000, 3)
        self.assertEqual(json.loads(r.stdout.splitlines()[0])["threads"], 2)

    def test_bench_2d(self):
        inp = self.save("p.npy", np.random.default_rng(2).random((2000, 2)))
        r = self.ok(["bench", "voronoi", inp, "--bounds"] + BOX2)
        self.check_lines(r.stdout, "voronoi2", 2000, 1)

    def test_bench_bad_input(self):
        r = run(["bench", "voronoi", self.p("missing.npy")])
        self.assertEqual(r.returncode, 2)
        self.assertTrue(r.stderr.startswith("tessera: error:"))


class RunDefault(TempDirCase):
    def test_small_run(self):
        d = self.p("out")  # created by the command
        r = self.ok(["run-default", "-o", d, "--points", "3000"])
        g = read_vtu(os.path.join(d, "cells.vtu"))
        self.assertEqual(g.GetNumberOfCells(), 3000)
        self.assertAlmostEqual(vtk_to_numpy(cell_array(g, "Volume")).sum(), 1.0, delta=1e-9)
        t = np.loadtxt(os.path.join(d, "cells.csv"), delimiter=",", skiprows=1)
        self.assertEqual(t.shape, (3000, 8))
        for word in ("cells", "faces", "neighbour", "volume sum", "compute", "thread"):
            self.assertIn(word, r.stdout)
        # fixed seed: the same points every time
        d2 = self.p("out2")
        self.ok(["run-default", "-o", d2, "--points", "3000", "-q"])
        self.assertTrue(read_bytes(os.path.join(d, "cells.vtu")) == read_bytes(os.path.join(d2, "cells.vtu")))


class Periodic(TempDirCase):
    """--periodic: cells among the points' images, neighbour shifts, validation."""

    def entries(self, nb, sh):
        n, off, ids = load_neighbors(nb)
        s = np.load(sh)
        self.assertEqual(s.dtype, np.int8)
        self.assertEqual(s.shape, (len(ids), 3 if s.ndim == 2 and s.shape[1] == 3 else 2))
        out = {}
        for c in range(n):
            for e in range(off[c], off[c + 1]):
                key = (c, int(ids[e]), tuple(int(x) for x in s[e]))
                out[key] = out.get(key, 0) + 1
        return out

    def test_tiles_the_box_with_shifts_that_pair_up(self):
        for dim, box, axes in ((3, ["-1", "1", "0", "1.5", "2", "3"], "xyz"), (3, BOX3, "xz"), (2, BOX2, "xy")):
            pts = np.random.default_rng(dim).random((3000, dim))
            lo = np.array([float(x) for x in box[0::2]])
            hi = np.array([float(x) for x in box[1::2]])
            pts = lo + pts * (hi - lo)
            inp = self.save("p%d.npy" % dim, pts)
            nb, sh, tab = self.p("n.npy"), self.p("s.npy"), self.p("t.csv")
            out = self.p("c.vtu" if dim == 3 else "c.vtp")
            r = self.ok(["voronoi", inp, "--bounds"] + box + ["--periodic", axes, "--neighbors", nb,
                                                                "--neighbor-shifts", sh, "--cell-table", tab, "-o", out,
                                                                "--validate"])
            self.assertIn("periodic           %s (" % axes, r.stdout)
            self.assertIn("validation: OK", r.stdout)
            vol = np.loadtxt(tab, delimiter=",", skiprows=1)[:, 2]
            self.assertAlmostEqual(vol.sum(), float(np.prod(hi - lo)), delta=1e-12 * float(np.prod(hi - lo)))
            e = self.entries(nb, sh)
            for (i, j, s), m in e.items():
                self.assertEqual(e.get((j, i, tuple(-x for x in s))), m, "entry %d %d %s has no twin" % (i, j, s))
                for a in range(dim):
                    if "xyz"[a] not in axes:
                        self.assertEqual(s[a], 0)
            g = read_vtu(out) if dim == 3 else read_vtp(out)
            self.assertEqual(g.GetNumberOfCells(), 3000)

    def test_wrapped_points_and_threads(self):
        pts = np.floor(np.random.default_rng(5).random((1000, 3)) * 2**30) / 2**30
        moved = pts.copy()
        moved[::3, 0] += 1.0
        moved[1::3, 2] -= 2.0
        tables = []
        for p, th in ((pts, 1), (moved, 2)):
            t = self.p("t%d.csv" % th)
            self.ok(["voronoi", self.save("w%d.npy" % th, p), "--bounds"] + BOX3 +
                    ["--periodic", "xyz", "--cell-table", t, "--threads", str(th), "-q"])
            tables.append(read_bytes(t))
        self.assertEqual(tables[0], tables[1])

    def test_triclinic_box(self):
        # --tilt: the sheared box tiles with paired shifts; a point moved by a
        # lattice vector is wrapped back (the same table); 2D takes one tilt.
        for dim, box, tilt in ((3, ["0", "2", "0", "1.5", "0", "1"], ["0.375", "-0.5", "0.25"]),
                               (2, ["0", "2", "0", "1"], ["-0.625"])):
            lo = np.array([float(x) for x in box[0::2]])
            hi = np.array([float(x) for x in box[1::2]])
            vec = np.diag(hi - lo)
            for k, (a, b) in enumerate([(0, 1), (0, 2), (1, 2)][:len(tilt)]):
                vec[b, a] = float(tilt[k])
            f = np.random.default_rng(dim + 10).random((2000, dim)) * (1 - 2e-6) + 1e-6
            pts = np.ldexp(np.floor(np.ldexp(lo + f @ vec, 30)), -30)
            moved = pts.copy()
            moved[::3] += vec[dim - 1]  # the last lattice vector: every axis moves
            tables = []
            for name, p in (("t.npy", pts), ("m.npy", moved)):
                nb, sh, tab = self.p("n" + name), self.p("s" + name), self.p(name + ".csv")
                r = self.ok(["voronoi", self.save(name, p), "--bounds"] + box + ["--periodic", "xyz"[:dim],
                             "--tilt"] + tilt + ["--neighbors", nb, "--neighbor-shifts", sh, "--cell-table", tab,
                                                 "--validate"])
                self.assertIn("tilt (triclinic)", r.stdout)
                self.assertIn("validation: OK", r.stdout)
                e = self.entries(nb, sh)
                for (i, j, s), m in e.items():
                    self.assertEqual(e.get((j, i, tuple(-x for x in s))), m, "entry %d %d %s has no twin" % (i, j, s))
                tables.append(read_bytes(tab))
            self.assertEqual(tables[0], tables[1])
            vol = np.loadtxt(self.p("t.npy.csv"), delimiter=",", skiprows=1)[:, 2]
            self.assertAlmostEqual(vol.sum(), float(np.prod(hi - lo)), delta=1e-12 * float(np.prod(hi - lo)))
            # The same lattice by b + 7 a and c + 7 b + 7 a: tilts reduced to
            # the ones above (the summary says so), the same table.
            t = [float(x) for x in tilt]
            more = [t[0] + 7 * vec[0, 0]]
            if dim == 3:
                more += [t[1] + 7 * t[0] + 7 * vec[0, 0], t[2] + 7 * vec[1, 1]]
            more = [repr(x) for x in more]
            r = self.ok(["voronoi", self.p("t.npy"), "--bounds"] + box + ["--periodic", "xyz"[:dim], "--tilt"] + more +
                        ["--cell-table", self.p("r.csv")])
            self.assertIn("the given tilts reduced by whole box lengths", r.stdout)
            self.assertEqual(read_bytes(self.p("r.csv")), tables[0])
            # The other commands' summaries give the tilts used too.
            r = self.ok(["delaunay", self.p("t.npy"), "--bounds"] + box + ["--periodic", "xyz"[:dim], "--tilt"] + more +
                        ["--simplices", self.p("ds.npy")])
            self.assertIn("tessera: tilts xy %.17g" % t[0], r.stderr)
            self.assertIn("the given tilts reduced", r.stderr)
            r = self.ok(["graph", self.p("t.npy"), "--bounds"] + box + ["--periodic", "xyz"[:dim], "--tilt"] + more +
                        ["--csr", self.p("g.npy")])
            self.assertIn("the given tilts reduced", r.stdout)

    def test_periodic_delaunay(self):
        # delaunay --periodic: every simplex once with its vertices' images,
        # validated; the .vtu holds the wrapped points and one point per
        # image used (PointId), and each tetrahedron's corners there are the
        # images the shifts name. 2D: a torus has twice as many triangles as
        # points.
        for dim, box, tilt in ((3, ["0", "1", "0", "1.5", "0", "1"], ["0.25", "0", "-0.125"]), (2, BOX2, ["0.375"])):
            lo = np.array([float(x) for x in box[0::2]])
            hi = np.array([float(x) for x in box[1::2]])
            vec = np.diag(hi - lo)
            for k, (a, b) in enumerate([(0, 1), (0, 2), (1, 2)][:len(tilt)]):
                vec[b, a] = float(tilt[k])
            f = np.random.default_rng(20 + dim).random((1500, dim)) * (1 - 2e-6) + 1e-6
            pts = np.ldexp(np.floor(np.ldexp(lo + f @ vec, 30)), -30)
            inp = self.save("d%d.npy" % dim, pts)
            out, simp, shifts = self.p("d.vtu"), self.p("s.npy"), self.p("sh.npy")
            r = self.ok(["delaunay", inp, "--bounds"] + box + ["--periodic", "xyz"[:dim], "--tilt"] + tilt +
                        ["-o", out, "--simplices", simp, "--simplex-shifts", shifts, "--validate"])
            self.assertIn("validation passed", r.stderr)
            s, sh = np.load(simp), np.load(shifts)
            self.assertEqual((sh.dtype, sh.shape), (np.int8, (len(s), dim + 1, dim)))
            if dim == 2:
                self.assertEqual(len(s), 2 * len(pts))
            g = read_vtu(out)
            self.assertEqual(g.GetNumberOfCells(), len(s))
            xyz = vtk_to_numpy(g.GetPoints().GetData())[:, :dim]
            pid = vtk_to_numpy(g.GetPointData().GetArray("PointId"))
            np.testing.assert_array_equal(xyz[:len(pts)], pts)
            conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(len(s), dim + 1)
            np.testing.assert_array_equal(pid[conn], s)
            np.testing.assert_allclose(xyz[conn], pts[s] + sh @ vec, rtol=0, atol=1e-14)

    def test_bench(self):
        inp = self.save("b.npy", np.random.default_rng(6).random((2000, 3)))
        r = self.ok(["bench", "voronoi", inp, "--bounds"] + BOX3 + ["--periodic", "xyz"])
        j = json.loads(r.stdout.splitlines()[0])
        self.assertEqual(j["simplices"], 2000)
        self.assertAlmostEqual(j["extra"]["volume_sum"], 1.0, delta=1e-12)
        # The periodic triangulation: as many simplices as delaunay writes.
        r = self.ok(["bench", "delaunay", inp, "--bounds"] + BOX3 + ["--periodic", "xyz", "--tilt", "0.25", "0", "0"])
        simp = self.p("s.npy")
        self.ok(["delaunay", inp, "--bounds"] + BOX3 + ["--periodic", "xyz", "--tilt", "0.25", "0", "0",
                                                       "--simplices", simp, "-q"])
        self.assertEqual(json.loads(r.stdout.splitlines()[0])["simplices"], len(np.load(simp)))


class FileBoxes(TempDirCase):
    """A LAMMPS dump or an extended XYZ as INPUT: its box and periodic axes
    are the domain unless the command line gives one; columns as labels and
    radii."""

    LO = np.array([-1.0, 0.5, 2.0])
    VEC = np.array([[4.0, 0, 0], [1.5, 5.0, 0], [-0.5, 0.75, 6.0]])  # a, b, c as rows

    def dump(self, name, frac, flags="pp pp pp", tilted=True, scaled=False, extra=""):
        vec = self.VEC if tilted else np.diag(np.diag(self.VEC))
        xy, xz, yz = vec[1, 0], vec[2, 0], vec[2, 1]
        lo, hi = self.LO, self.LO + np.diag(vec)
        pts = self.LO + frac @ vec
        with open(self.p(name), "w") as f:
            f.write("ITEM: TIMESTEP\n42\nITEM: NUMBER OF ATOMS\n%d\n" % len(frac))
            if tilted:
                f.write("ITEM: BOX BOUNDS xy xz yz %s\n" % flags)
                f.write("%r %r %r\n" % (lo[0] + min(0, xy, xz, xy + xz), hi[0] + max(0, xy, xz, xy + xz), xy))
                f.write("%r %r %r\n" % (lo[1] + min(0, yz), hi[1] + max(0, yz), xz))
                f.write("%r %r %r\n" % (lo[2], hi[2], yz))
            else:
                f.write("ITEM: BOX BOUNDS %s\n" % flags)
                for a in range(3):
                    f.write("%r %r\n" % (lo[a], hi[a]))
            cols = "xs ys zs" if scaled else "x y z"
            f.write("ITEM: ATOMS id type %s radius%s\n" % (cols, extra))
            for k in range(len(frac)):
                c = frac[k] if scaled else pts[k]
                f.write("%d %d %r %r %r %r\n" % (k + 1, 1 + k % 3, c[0], c[1], c[2], 0.1 + 0.05 * (k % 2)))
        return self.p(name), pts

    def test_box_from_the_header(self):
        # The triclinic periodic box of the header gives the same cells as
        # --bounds/--periodic/--tilt on the same points; scaled columns too.
        frac = np.random.default_rng(30).random((800, 3))
        for scaled in (False, True):
            inp, pts = self.dump("t.lammpstrj", frac, scaled=scaled)
            t1, nb1, sh1 = self.p("t1.csv"), self.p("n1.npy"), self.p("s1.npy")
            r = self.ok(["voronoi", inp, "--cell-table", t1, "--neighbors", nb1, "--neighbor-shifts", sh1,
                         "--labels", "type", "--validate"])
            self.assertIn("domain from        the box of %s (LAMMPS dump, timestep 42)" % inp, r.stdout)
            self.assertIn("periodic           xyz (", r.stdout)
            self.assertIn("tilt (triclinic)", r.stdout)
            self.assertIn("validation: OK", r.stdout)
            box = [repr(v) for a in range(3) for v in (self.LO[a], self.LO[a] + self.VEC[a, a])]
            tilt = [repr(self.VEC[1, 0]), repr(self.VEC[2, 0]), repr(self.VEC[2, 1])]
            t2, nb2, sh2 = self.p("t2.csv"), self.p("n2.npy"), self.p("s2.npy")
            self.ok(["voronoi", self.save("p.npy", pts), "--bounds"] + box + ["--periodic", "xyz", "--tilt"] + tilt +
                    ["--cell-table", t2, "--neighbors", nb2, "--neighbor-shifts", sh2, "--labels",
                     self.save("l.npy", (1 + np.arange(800) % 3).astype(np.int32)), "-q"])
            a, b = np.loadtxt(t1, delimiter=",", skiprows=1), np.loadtxt(t2, delimiter=",", skiprows=1)
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
            self.assertEqual(load_neighbors(nb1)[2].tolist(), load_neighbors(nb2)[2].tolist())
            np.testing.assert_array_equal(np.load(sh1), np.load(sh2))
            self.assertAlmostEqual(a[:, 2].sum(), abs(np.linalg.det(self.VEC)), delta=1e-9)

    def test_walls_radii_and_overrides(self):
        frac = np.random.default_rng(31).random((600, 3))
        inp, pts = self.dump("w.dump", frac, flags="pp ff pp", tilted=False)
        t = self.p("t.csv")
        r = self.ok(["voronoi", inp, "--radii", "radius", "--cell-table", t, "--validate"])
        self.assertIn("periodic           xz (", r.stdout)
        self.assertIn("power cells", r.stdout)
        self.assertIn("domain             [-1, 3] x [0.5, 5.5] x [2, 8]", r.stdout)
        # --bounds: the command line's domain alone.
        r = self.ok(["voronoi", inp, "--bounds", "-2", "4", "0", "6", "1", "9", "--cell-table", t])
        self.assertNotIn("domain from", r.stdout)
        self.assertNotIn("periodic", r.stdout)
        self.assertAlmostEqual(np.loadtxt(t, delimiter=",", skiprows=1)[:, 2].sum(), 6 * 6 * 8, delta=1e-9)
        # --periodic alone: the file's box along the option's axes, the same
        # cells as that box given in full.
        r = self.ok(["voronoi", inp, "--periodic", "xyz", "--cell-table", t])
        self.assertIn("periodic along --periodic's axes", r.stdout)
        self.assertIn("periodic           xyz (", r.stdout)
        t2 = self.p("t2.csv")
        self.ok(["voronoi", inp, "--bounds", "-1", "3", "0.5", "5.5", "2", "8", "--periodic", "xyz", "--cell-table",
                 t2, "-q"])
        self.assertEqual(read_bytes(t), read_bytes(t2))
        # Each frame of a series keeps the option's axes with its own box.
        with open(inp) as f:
            text = f.read()
        with open(self.p("two.dump"), "w") as f:
            f.write(text + text)
        self.ok(["voronoi", self.p("two.dump"), "--frame", "all", "--periodic", "xyz", "--cell-table",
                 self.p("s{frame}.csv"), "-q"])
        for k in range(2):
            self.assertEqual(read_bytes(self.p("s%d.csv" % k)), read_bytes(t2))
        # ... and the periodic triangulation of that box.
        r = self.ok(["delaunay", inp, "--periodic", "xyz", "--validate"])
        self.assertIn("validation passed", r.stderr)
        # A file's tilt along an axis --periodic makes a wall: refused, naming both.
        tilted, _ = self.dump("tw.dump", frac)
        r = run(["voronoi", tilted, "--periodic", "xy", "--cell-table", t])
        self.assertEqual(r.returncode, 2)
        self.assertIn("but z is a wall there (--periodic xy)", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)
        r = self.ok(["voronoi", tilted, "--periodic", "xy", "--tilt", "0.5", "0", "0", "--cell-table", t])
        self.assertIn("tilted by --tilt", r.stdout)
        # --tilt alone along an axis the file walls: the file's wall is named.
        r = run(["voronoi", inp, "--tilt", "0.5", "0", "0", "--cell-table", t])
        self.assertEqual(r.returncode, 2)
        self.assertIn("--tilt: xy needs y periodic, and the box of %s" % inp, r.stderr)
        # A triangulation needs every axis periodic: the dump's walls are named.
        r = run(["delaunay", inp, "--validate"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("is periodic along xz only", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1)
        r = self.ok(["delaunay", inp, "--bounds", "-1", "3", "0.5", "5.5", "2", "8", "--validate"])
        self.assertIn("validation passed", r.stderr)
        # Fully periodic: the periodic triangulation; standard input too.
        inp2, _ = self.dump("p.dump", frac)
        r = self.ok(["delaunay", inp2, "--validate"])
        self.assertIn("of the periodic box (triclinic)", r.stderr)
        with open(inp2, "rb") as f:
            # LAMMPS writes UNITS and TIME first with dump_modify units/time yes.
            r = run_bytes(["voronoi", "-", "--cell-table", "-", "-q"], b"ITEM: UNITS\nlj\nITEM: TIME\n0.5\n" + f.read())
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertAlmostEqual(np.loadtxt(io.StringIO(r.stdout.decode()), delimiter=",", skiprows=1)[:, 2].sum(),
                               abs(np.linalg.det(self.VEC)), delta=1e-9)
        # --dim 2 takes x, y of an orthogonal box.
        inp3, _ = self.dump("o.dump", frac, tilted=False)
        r = self.ok(["voronoi", inp3, "--dim", "2", "--cell-table", t])
        self.assertIn("periodic           xy (", r.stdout)
        self.assertAlmostEqual(np.loadtxt(t, delimiter=",", skiprows=1)[:, 2].sum(), 20.0, delta=1e-9)

    def test_extended_xyz(self):
        # An extended XYZ's Lattice, Origin and pbc are the domain as a
        # dump's box is (also from standard input); a plain XYZ has none.
        frac = np.random.default_rng(33).random((500, 3))
        vec = self.VEC.copy()
        vec[2, :2] = 0  # z is a wall: c may not tilt
        pts = self.LO + frac @ vec
        with open(self.p("e.xyz"), "w") as f:
            f.write("%d\nLattice=\"%s\" Origin=\"%s\" Properties=species:S:1:pos:R:3:tag:I:1 pbc=\"T T F\"\n" % (
                len(pts), " ".join(repr(v) for v in vec.ravel()), " ".join(repr(v) for v in self.LO)))
            for k, q in enumerate(pts):
                f.write("%s %r %r %r %d\n" % ("Cu" if k % 2 else "Ni", q[0], q[1], q[2], k % 2))
        t1, t2 = self.p("t1.csv"), self.p("t2.csv")
        r = self.ok(["voronoi", self.p("e.xyz"), "--labels", "tag", "--cell-table", t1, "--validate"])
        self.assertIn("(extended XYZ Lattice)", r.stdout)
        self.assertIn("periodic           xy (", r.stdout)
        self.assertIn("validation: OK", r.stdout)
        box = [repr(v) for a in range(3) for v in (self.LO[a], self.LO[a] + vec[a, a])]
        self.ok(["voronoi", self.save("p.npy", pts), "--bounds"] + box + ["--periodic", "xy", "--tilt",
                repr(vec[1, 0]), "0", "0", "--labels", self.save("l.npy", (np.arange(500) % 2).astype(np.int32)),
                "--cell-table", t2, "-q"])
        self.assertEqual(read_bytes(t1), read_bytes(t2))
        vol = np.loadtxt(t1, delimiter=",", skiprows=1)[:, 2]
        self.assertAlmostEqual(vol.sum(), abs(np.linalg.det(vec)), delta=1e-9)
        with open(self.p("e.xyz"), "rb") as f:
            r = run_bytes(["voronoi", "-", "--labels", "tag", "--cell-table", "-", "-q"], f.read())
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout, read_bytes(t1))
        with open(self.p("plain.xyz"), "w") as f:
            f.write("%d\nplain\n" % len(pts))
            for q in pts:
                f.write("C %r %r %r\n" % tuple(q))
        r = self.ok(["voronoi", self.p("plain.xyz"), "--cell-table", t1])
        self.assertNotIn("domain from", r.stdout)
        self.assertNotIn("periodic", r.stdout)

    def test_frames(self):
        # --frame reads any frame of a trajectory, by its index from either
        # end, with its own box, labels and radii: the same cells as that
        # frame alone in a file. Standard input too; every command.
        rng = np.random.default_rng(34)
        frames, texts = [], []
        for k in range(3):
            frac = rng.random((200 + 50 * k, 3))
            name = "f%d.dump" % k
            inp, _ = self.dump(name, frac, tilted=(k != 1))
            frames.append(inp)
            with open(inp) as f:
                texts.append(f.read().replace("TIMESTEP\n42\n", "TIMESTEP\n%d\n" % (1000 * k)))
        traj = self.p("run.lammpstrj")
        with open(traj, "w") as f:
            f.write("\n".join(texts))  # a blank line between frames
        common = ["--labels", "type", "--radii", "radius", "-q"]
        for k, index in ((0, "0"), (1, "1"), (2, "2"), (2, "-1"), (0, "-3")):
            t1, t2 = self.p("t1.csv"), self.p("t2.csv")
            r = self.ok(["voronoi", traj, "--frame", index, "--cell-table", t1, "--labels", "type", "--radii",
                         "radius"])
            self.assertIn("from %s, frame %d (from line " % (traj, k), r.stdout)
            self.assertIn("the box of frame %d of %s (LAMMPS dump, timestep %d)" % (k, traj, 1000 * k), r.stdout)
            self.ok(["voronoi", frames[k], "--cell-table", t2] + common)
            self.assertEqual(read_bytes(t1), read_bytes(t2), index)
        with open(traj, "rb") as f:
            r = run_bytes(["voronoi", "-", "--frame", "-2", "--cell-table", "-"] + common, f.read())
        self.assertEqual(r.returncode, 0, r.stderr)
        self.ok(["voronoi", frames[1], "--cell-table", self.p("t2.csv")] + common)
        self.assertEqual(r.stdout, read_bytes(self.p("t2.csv")))
        r = self.ok(["delaunay", traj, "--frame", "-1", "--validate"])
        self.assertIn("tessera: points from %s, frame 2 (from line " % traj, r.stderr)
        self.assertIn("validation passed", r.stderr)
        self.ok(["graph", traj, "--frame", "1", "--csr", self.p("g.npy"), "-q"])
        self.ok(["bench", "voronoi", traj, "--frame", "2"])
        # One frame by its index names its outputs as a series would: {frame}
        # is the index from the start (a loop over indices, or -1).
        self.ok(["voronoi", traj, "--frame", "-1", "--cell-table", self.p("k_{frame}.csv"), "-q"])
        self.ok(["voronoi", traj, "--frame", "2", "--cell-table", self.p("one.csv"), "-q"])
        self.assertEqual(read_bytes(self.p("k_2.csv")), read_bytes(self.p("one.csv")))
        # A .npy of labels serves every frame: its length is the frame's.
        self.ok(["voronoi", traj, "--frame", "1", "--labels", self.save("l.npy", np.ones(250, np.int32)),
                 "--cell-table", self.p("t1.csv"), "-q"])
        # Bad frames: one line, exit 2, nothing written.
        out = self.p("bad.csv")
        for args, fragment in (
                (["--frame", "3"], "--frame: %s: no frame 3: it has 3 frames (0 to 2, or -3 to -1 from the end)" % traj),
                (["--frame", "-4"], "no frame -4: it has 3 frames"),
                (["--frame", "1.5"], "--frame: '1.5' is not a frame's index or a series"),
                (["--frame", "99999999999999999999"], "is not a frame's index"),
                (["--frame", "5:"], "--frame: '5:' selects none of the 3 frames of %s" % traj),
                (["--frame", "::0"], "the step is 0"),
                (["--frame", "1:2:3:4"], "is not START:STOP or START:STOP:STEP"),
                (["--frame", "all"], "--frame all writes one file per frame: --cell-table's name must hold {frame}"),
                (["--frame", ""], "expected a frame's index"),
                (["--frame", "0", "--labels", self.p("l.npy")], "labels: 250 values for 200 points")):
            r = run(["voronoi", traj, "--cell-table", out] + args)
            self.assertEqual(r.returncode, 2, args)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
            self.assertIn(fragment, r.stderr, args)
            self.assertFalse(os.path.exists(out))
        # A series: every frame selected, in its order, each with its own
        # box, into outputs named by its index; the same files as one by one.
        for sel, ks in (("all", [0, 1, 2]), ("-2:", [1, 2]), ("::-2", [2, 0]), ("1:2", [1])):
            for f in os.listdir(self.dir):
                if f.startswith("s_"):
                    os.remove(self.p(f))
            r = self.ok(["voronoi", traj, "--frame=" + sel, "--cell-table", self.p("s_{frame}.csv"), "--neighbors",
                         self.p("s_{frame}.npy"), "--validate", "--labels", "type", "--radii", "radius"])
            self.assertEqual([int(l.split("frame ")[1].split(" ")[0]) for l in r.stdout.splitlines()
                              if l.startswith("tessera voronoi:")], ks)
            # The first frame's summary in full, then one line a frame (a
            # failed validation would still be reported).
            self.assertEqual(r.stdout.count("validation: OK"), 1)
            later = [l for l in r.stdout.splitlines() if l.startswith("tessera voronoi:")][1:]
            self.assertEqual(r.stdout.splitlines()[-len(later) or len(r.stdout):], later)
            for l in later:
                self.assertRegex(l, r": \d+ points, \d+ cells; [0-9.]+ s; wrote .*s_\d+\.csv, .*s_\d+\.npy$")
            self.assertEqual(sorted(f for f in os.listdir(self.dir) if f.startswith("s_")),
                             sorted("s_%d.%s" % (k, e) for k in ks for e in ("csv", "npy")))
            for k in ks:
                self.ok(["voronoi", traj, "--frame", str(k), "--cell-table", self.p("one.csv")] + common)
                self.assertEqual(read_bytes(self.p("s_%d.csv" % k)), read_bytes(self.p("one.csv")), (sel, k))
        # The other commands take series too, the benches one frame; standard
        # output takes no series. A series' error names its frame and keeps
        # the frames before it (each whole).
        r = self.ok(["delaunay", traj, "--frame", "1:", "--simplices", self.p("d_{frame}.npy"), "--validate"])
        self.assertEqual(r.stderr.count("validation passed"), 1)  # later frames: failures only
        self.assertRegex(r.stderr, r"tessera delaunay: .*, frame 2 \(from line \d+\): \d+ points, \d+ tetrahedra; ")
        for k in (1, 2):
            self.ok(["delaunay", traj, "--frame", str(k), "--simplices", self.p("one.npy"), "-q"])
            self.assertEqual(read_bytes(self.p("d_%d.npy" % k)), read_bytes(self.p("one.npy")))
        self.ok(["graph", traj, "--frame", "::2", "--csr", self.p("g_{frame}.npy"), "--spoke-measures",
                 self.p("m_{frame}.npy"), "-q"])
        self.ok(["faces", traj, "--frame", "all", "--kind", "boundary", "--labels", "type", "-o",
                 self.p("f_{frame}.vtp"), "-q"])
        self.ok(["surface-nets", traj, "--frame", "-1:", "--labels", "type", "-o", self.p("n_{frame}.vtp"), "-q"])
        self.ok(["flower", traj, "--frame", "0:2", "--point", "3", "-o", self.p("w_{frame}.vtp"), "-q"])
        made = sorted(f for f in os.listdir(self.dir) if f[:2] in ("g_", "m_", "f_", "n_", "w_"))
        self.assertEqual(made, ["f_0.vtp", "f_1.vtp", "f_2.vtp", "g_0.npy", "g_2.npy", "m_0.npy", "m_2.npy",
                                "n_2.vtp", "w_0.vtp", "w_1.vtp"])
        for f in made:
            os.remove(self.p(f))
        for cmd, fragment in ((["bench", "voronoi", traj, "--frame", "all"], "a bench runs on one frame"),
                              (["delaunay", traj, "--frame", "all", "--simplices", "-"],
                               "--simplices cannot go to standard output"),
                              (["graph", traj, "--frame", "all", "--csr", self.p("g.npy")],
                               "--csr's name must hold {frame}")):
            r = run(cmd)
            self.assertEqual(r.returncode, 2, cmd)
            self.assertIn(fragment, r.stderr)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        bad = texts[:2] + [texts[2].replace("\n1 1 ", "\n1 1 nan ", 1)]
        with open(self.p("nan.dump"), "w") as f:
            f.write("\n".join(bad))
        r = run(["voronoi", self.p("nan.dump"), "--frame", "all", "--cell-table", self.p("n_{frame}.csv"), "-q"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("frame 2: ", r.stderr)
        self.assertIn("; the frames before it were written", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertTrue(os.path.exists(self.p("n_1.csv")))
        self.assertFalse(os.path.exists(self.p("n_2.csv")))
        # Each frame of a series takes its own box, whichever frames have one
        # (an XYZ whose first frame is plain, its second with a Lattice).
        with open(self.p("mixed.xyz"), "w") as f:
            for comment in ("plain", 'Lattice="2 0 0 0 2 0 0 0 2" pbc="T T T"', "plain again"):
                f.write("3\n%s\nC 0.1 0.2 0.3\nC 0.5 0.6 0.7\nC 0.9 0.1 0.5\n" % comment)
        for sel in ("all", "::-1"):
            self.ok(["voronoi", self.p("mixed.xyz"), "--frame", sel, "--cell-table", self.p("x_{frame}.csv"), "-q"])
            for k in range(3):
                self.ok(["voronoi", self.p("mixed.xyz"), "--frame", str(k), "--cell-table", self.p("one.csv"), "-q"])
                self.assertEqual(read_bytes(self.p("x_%d.csv" % k)), read_bytes(self.p("one.csv")), (sel, k))
        self.assertAlmostEqual(np.loadtxt(self.p("x_1.csv"), delimiter=",", skiprows=1)[:, 2].sum(), 8.0, delta=1e-12)
        # A frame of no atoms (a dump of a group empty then) is skipped in a
        # series, with a note; asked for alone, or a series of only such
        # frames, it is an error.
        empty = texts[1].split("ITEM: NUMBER OF ATOMS\n")[0] + "ITEM: NUMBER OF ATOMS\n0\n" + \
            "ITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\nITEM: ATOMS id type x y z radius\n"
        with open(self.p("gap.dump"), "w") as f:
            f.write("\n".join([texts[0], empty, texts[2], empty]))
        r = self.ok(["voronoi", self.p("gap.dump"), "--frame", "all", "--cell-table", self.p("e_{frame}.csv"), "-q"])
        self.assertEqual(r.stderr.count("holds no atoms: skipped, no files for it"), 2, r.stderr)
        self.assertIn("frame 1 of %s (from line " % self.p("gap.dump"), r.stderr)
        self.assertEqual(sorted(f for f in os.listdir(self.dir) if f.startswith("e_")), ["e_0.csv", "e_2.csv"])
        self.ok(["voronoi", traj, "--frame", "2", "--cell-table", self.p("one.csv"), "-q"])
        self.assertEqual(read_bytes(self.p("e_2.csv")), read_bytes(self.p("one.csv")))
        for sel, fragment in (("1", "frame 1: %s: no points" % self.p("gap.dump")),
                              ("1::2", "--frame 1::2 selects only frames of no atoms; nothing was written")):
            r = run(["voronoi", self.p("gap.dump"), "--frame", sel, "--cell-table", self.p("g_{frame}.csv")])
            self.assertEqual(r.returncode, 2, sel)
            self.assertIn(fragment, r.stderr)
            self.assertFalse(os.path.exists(self.p("g_1.csv")))
        # Every frame's output folder is checked before the first frame is
        # computed ({frame} naming a folder): nothing is written when a later
        # frame's folder is missing.
        os.mkdir(self.p("d0"))
        r = run(["voronoi", traj, "--frame", "all", "--cell-table", self.p("d{frame}/c.csv"), "-q"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("d1' does not exist", r.stderr)
        self.assertEqual(os.listdir(self.p("d0")), [])
        # From standard input the note names stdin, not the spooled copy.
        with open(self.p("gap.dump"), "rb") as f:
            r = run_bytes(["voronoi", "-", "--frame", "all", "--cell-table", self.p("i_{frame}.csv"), "-q"], f.read())
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(b"frame 1 of stdin (from line ", r.stderr)
        # An XYZ trajectory whose first frames hold no atoms is still one (it was
        # "not a trajectory").
        with open(self.p("late.xyz"), "w") as f:
            f.write("0\nnothing yet\n0\nstill nothing\n3\nthree\nC 0.1 0.2 0.3\nC 0.5 0.6 0.7\nC 0.9 0.1 0.5\n")
        r = self.ok(["voronoi", self.p("late.xyz"), "--frame", "all", "--cell-table", self.p("late_{frame}.csv"), "-q"])
        self.assertEqual(r.stderr.count("holds no atoms"), 2)
        self.assertEqual(sorted(f for f in os.listdir(self.dir) if f.startswith("late_")), ["late_2.csv"])
        # A trajectory still being written: its last frame cut short. The
        # frames before it are read; the cut one is named, with its line.
        with open(traj) as f:
            whole = f.read()
        with open(self.p("cut.lammpstrj"), "w") as f:
            f.write(whole[: whole.rfind("\n5 ")])
        self.ok(["voronoi", self.p("cut.lammpstrj"), "--frame", "-2", "--cell-table", self.p("c1.csv"), "-q"])
        self.ok(["voronoi", traj, "--frame", "1", "--cell-table", self.p("one.csv"), "-q"])
        self.assertEqual(read_bytes(self.p("c1.csv")), read_bytes(self.p("one.csv")))
        r = run(["voronoi", self.p("cut.lammpstrj"), "--frame", "-1", "--cell-table", out])
        self.assertEqual(r.returncode, 2)
        self.assertIn("error: frame 2: %s: the file ends at line " % self.p("cut.lammpstrj"), r.stderr)
        self.assertIn(", after 4 of the frame's 300 atoms", r.stderr)
        self.assertFalse(os.path.exists(out))
        npy = self.save("p.npy", rng.random((20, 3)))
        r = run(["voronoi", npy, "--frame", "0", "--cell-table", out])
        self.assertEqual(r.returncode, 2)
        self.assertIn("not a trajectory", r.stderr)
        # A frame on the way one atom line short is named by its line.
        broken = texts[0].replace("\n2 2 ", "\nX", 1)
        broken = "\n".join(l for l in broken.split("\n") if not l.startswith("X"))
        with open(self.p("broken.dump"), "w") as f:
            f.write("\n".join([broken] + texts[1:]))
        r = run(["voronoi", self.p("broken.dump"), "--frame", "-1", "--cell-table", out])
        self.assertEqual(r.returncode, 2)
        self.assertIn("fewer atoms than NUMBER OF ATOMS", r.stderr)

    def test_bad_dumps(self):
        frac = np.random.default_rng(32).random((50, 3))
        inp, _ = self.dump("x.dump", frac, flags="ff pp pp")  # xy tilt, x a wall
        for cmd in (["voronoi", inp, "--validate"], ["graph", inp, "--csr", self.p("g.npy")]):
            r = run(cmd)
            self.assertEqual(r.returncode, 2)
            self.assertIn("the box tilts by xy = 1.5, but x is a wall there", r.stderr)
        inp, _ = self.dump("t.dump", frac)
        r = run(["voronoi", inp, "--dim", "2", "--validate"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("tilts along z", r.stderr)
        with open(inp) as g, open(self.p("cut.dump"), "w") as f:
            f.write(g.read()[:-40])
        out = self.p("c.vtu")
        r = run(["voronoi", self.p("cut.dump"), "-o", out])
        self.assertEqual(r.returncode, 2)
        self.assertIn("cut.dump: line", r.stderr)
        self.assertFalse(os.path.exists(out))
        # An atom outside a wall of the dump's box: the error shows the
        # coordinate and the box's range along that axis, in full.
        frac2 = frac.copy()
        frac2[7, 1] = 1.25
        for flags, tail in (("ff ff ff", " (use --ignore-outside"), ("pp ff pp", ", and y is not periodic")):
            inp, pts = self.dump("o.dump", frac2, flags=flags, tilted=False)
            r = run(["voronoi", inp, "-o", out])
            self.assertEqual(r.returncode, 2)
            self.assertIn("point 7 lies outside the bounds: y = %r is not in [0.5, 5.5]%s" % (pts[7, 1], tail), r.stderr)


class Power(TempDirCase):
    """--radii: power (radical) cells, some empty; the summary's power line."""

    N = 500

    def setUp(self):
        super().setUp()
        rng = np.random.default_rng(11)
        self.pts3 = rng.random((self.N, 3))
        self.r3 = rng.random(self.N) * 0.12
        self.pts2 = rng.random((self.N, 2))
        self.r2 = rng.random(self.N) * 0.045
        self.inp3, self.rad3 = self.save("p3.npy", self.pts3), self.save("r3.npy", self.r3)
        self.inp2, self.rad2 = self.save("p2.npy", self.pts2), self.save("r2.npy", self.r2)

    def power_line(self, out, n_empty):
        m = re.search(r"^  power cells +radii (\S+) to (\S+); empty cells (\d+)(?: \(points ([\d, .]+)\))?$",
                      out, re.M)
        self.assertIsNotNone(m, out)
        self.assertEqual(int(m.group(3)), n_empty, out)
        return float(m.group(1)), float(m.group(2)), m.group(4)

    def owning_their_position(self, pts, r):
        """Points whose power is strictly the least at their own position: their
        cells hold them, so they cannot be empty."""
        pw = ((pts[:, None, :] - pts[None, :, :]) ** 2).sum(axis=2) - r[None, :] ** 2
        own = np.diag(pw).copy()
        np.fill_diagonal(pw, np.inf)
        return np.flatnonzero(own < pw.min(axis=1))

    def test_periodic_box(self):
        # Every image has its point's radius; validate measures cells among the images.
        for extra in (["--periodic", "xyz"], ["--periodic", "xz"], ["--periodic", "xyz", "--tilt", "0.25", "0", "0.125"]):
            nb, sh = self.p("nb.npy"), self.p("sh.npy")
            r = self.ok(["voronoi", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 + extra +
                        ["--validate", "--neighbors", nb, "--neighbor-shifts", sh])
            self.assertIn("validation: OK", r.stdout)
            self.power_line(r.stdout, self.N - int(re.search(r"cells +(\d+)", r.stdout).group(1)))

    def test_vtu_read_back_and_validate(self):
        out, tab = self.p("power.vtu"), self.p("t.csv")
        r = self.ok(["voronoi", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 +
                    ["--validate", "-o", out, "--cell-table", tab])
        self.assertIn("validation: OK", r.stdout)
        g = read_vtu(out)
        n = g.GetNumberOfCells()
        self.assertLess(n, self.N, "radii this large leave some cells empty")
        lo, hi, listed = self.power_line(r.stdout, self.N - n)
        self.assertAlmostEqual(lo, self.r3.min(), delta=1e-9 * self.r3.max())
        self.assertAlmostEqual(hi, self.r3.max(), delta=1e-9 * self.r3.max())
        self.assertRegex(r.stdout, r"cells +%d\n" % n)
        gid = vtk_to_numpy(cell_array(g, "GeneratorId"))
        empty = np.setdiff1d(np.arange(self.N), gid)
        self.assertEqual(listed, ", ".join(str(i) for i in empty[:5]) + (", ..." if len(empty) > 5 else ""))
        self.assertFalse(np.isin(self.owning_their_position(self.pts3, self.r3), empty).any())
        vol = vtk_to_numpy(cell_array(g, "Volume"))
        self.assertTrue(np.all(vol > 0))
        self.assertAlmostEqual(vol.sum(), 1.0, delta=1e-12)
        geo_vol, nfaces = polyhedron_volumes(g)
        np.testing.assert_allclose(geo_vol, vol, rtol=1e-9, atol=1e-15)
        np.testing.assert_array_equal(nfaces, vtk_to_numpy(cell_array(g, "NumberOfFaces")))
        t = np.loadtxt(tab, delimiter=",", skiprows=1)
        np.testing.assert_array_equal(t[:, 0], gid)

    def test_2d_vtp_read_back_and_validate(self):
        out = self.p("power.vtp")
        r = self.ok(["voronoi", self.inp2, "--radii", self.rad2, "--bounds"] + BOX2 + ["--validate", "-o", out])
        self.assertIn("validation: OK", r.stdout)
        poly = read_vtp(out)
        n = poly.GetNumberOfCells()
        self.assertLess(n, self.N)
        self.power_line(r.stdout, self.N - n)
        area = vtk_to_numpy(cell_array(poly, "Area"))
        geo, _ = polygon_areas(poly)
        np.testing.assert_allclose(geo, area, rtol=1e-9, atol=1e-15)
        self.assertAlmostEqual(area.sum(), 1.0, delta=1e-12)
        empty = np.setdiff1d(np.arange(self.N), vtk_to_numpy(cell_array(poly, "GeneratorId")))
        self.assertFalse(np.isin(self.owning_their_position(self.pts2, self.r2), empty).any())

    def test_ply_property_and_csv_column(self):
        # The radii as a float32 .ply vertex property and as a .csv column: the
        # same cells as from an .npy of those values.
        header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
                  "property double z\nproperty float radius\nend_header\n" % self.N).encode()
        rec = np.zeros(self.N, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("radius", "<f4")])
        rec["x"], rec["y"], rec["z"] = self.pts3.T
        rec["radius"] = self.r3
        ply = self.p("s.ply")
        with open(ply, "wb") as f:
            f.write(header + rec.tobytes())
        csv_in = self.p("s.csv")
        with open(csv_in, "w") as f:
            f.write("x,y,z,r\n")
            for (x, y, z), ri in zip(self.pts3, self.r3):
                f.write("%.17g,%.17g,%.17g,%.17g\n" % (x, y, z, ri))
        r32 = self.save("r32.npy", rec["radius"].astype(np.float64))
        tables = {}
        for name, args in (("ply", [ply, "--radii", "radius"]), ("ply_ref", [self.inp3, "--radii", r32]),
                           ("csv", [csv_in, "--radii", "r"]), ("csv_ref", [self.inp3, "--radii", self.rad3])):
            t = self.p(name + ".csv")
            r = self.ok(["voronoi"] + args + ["--bounds"] + BOX3 + ["--cell-table", t, "--validate"])
            self.assertIn("power cells", r.stdout)
            self.assertIn("validation: OK", r.stdout)
            tables[name] = read_bytes(t)
        self.assertEqual(tables["ply"], tables["ply_ref"])
        self.assertEqual(tables["csv"], tables["csv_ref"])

    def test_equal_radii_are_the_ordinary_cells(self):
        plain, same = self.p("plain.vtu"), self.p("same.vtu")
        self.ok(["voronoi", self.inp3, "--bounds"] + BOX3 + ["-o", plain, "-q"])
        r = self.ok(["voronoi", self.inp3, "--radii", self.save("eq.npy", np.full(self.N, 0.25)), "--bounds"] +
                    BOX3 + ["-o", same])
        self.assertNotIn("power cells", r.stdout)
        self.assertEqual(read_bytes(plain), read_bytes(same))

    def test_threads_byte_identical(self):
        outs = []
        for th in ("1", "2"):
            out = self.p("t%s.vtu" % th)
            self.ok(["voronoi", self.inp3, "--radii", self.rad3, "-o", out, "--threads", th, "-q"])
            outs.append(read_bytes(out))
        self.assertEqual(outs[0], outs[1])

    def test_graph_and_faces(self):
        cells = self.p("c.vtu")
        self.ok(["voronoi", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 + ["-o", cells, "-q"])
        gid = vtk_to_numpy(cell_array(read_vtu(cells), "GeneratorId"))
        empty = np.setdiff1d(np.arange(self.N), gid)
        self.assertGreater(len(empty), 0)
        gv, csr = self.p("g.vtp"), self.p("w.npy")
        self.ok(["graph", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 + ["-o", gv, "--csr", csr, "-q"])
        g = read_vtp(gv)
        edges = np.concatenate(cells_of(g.GetLines())).reshape(-1, 2)
        self.assertFalse(np.isin(edges, empty).any(), "no edge to a point whose cell is empty")
        self.assertEqual(len(np.unique(edges)), len(gid))
        fv = self.p("f.vtp")
        r = self.ok(["faces", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 + ["--kind", "complex", "-o", fv])
        f = read_vtp(fv)
        sides = vtk_to_numpy(cell_array(f, "Sides")).reshape(-1, 2)
        self.assertFalse(np.isin(sides, empty).any())
        np.testing.assert_array_equal(np.unique(sides[sides >= 0]), gid)
        self.assertEqual(f.GetNumberOfCells(), len(edges) + int((sides[:, 1] < 0).sum()))
        # 2D too.
        self.ok(["faces", self.inp2, "--radii", self.rad2, "--bounds"] + BOX2 + ["--kind", "boundary", "-o",
                                                                                 self.p("f2.vtp"), "-q"])
        self.ok(["graph", self.inp2, "--radii", self.rad2, "--bounds"] + BOX2 + ["-o", self.p("g2.vtp"), "-q"])

    def test_bench(self):
        tab = self.p("t.csv")
        self.ok(["voronoi", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 + ["--cell-table", tab, "-q"])
        n_cells = len(np.loadtxt(tab, delimiter=",", skiprows=1))
        for extra in ([], ["--mesh", "--repeat", "2"]):
            r = self.ok(["bench", "voronoi", self.inp3, "--radii", self.rad3, "--bounds"] + BOX3 + extra)
            lines = r.stdout.splitlines()
            self.assertEqual(len(lines), 2 if extra else 1, r.stdout)
            for line in lines:
                j = json.loads(line)
                self.assertEqual(j["op"], "voronoi3_mesh" if extra else "voronoi3")
                self.assertEqual(j["n"], self.N)
                self.assertEqual(j["simplices"], n_cells)
                self.assertAlmostEqual(j["extra"]["volume_sum"], 1.0, delta=1e-12)
        r = self.ok(["bench", "voronoi", self.inp2, "--radii", self.rad2, "--bounds"] + BOX2)
        self.assertEqual(json.loads(r.stdout.splitlines()[0])["op"], "voronoi2")


class Regular(TempDirCase):
    """delaunay --radii: the regular triangulation, dual of the power cells."""

    N = 400

    def setUp(self):
        super().setUp()
        rng = np.random.default_rng(21)
        self.pts3, self.r3 = rng.random((self.N, 3)), rng.random(self.N) * 0.15
        self.pts2, self.r2 = rng.random((self.N, 2)), rng.random(self.N) * 0.06
        self.inp3, self.rad3 = self.save("p3.npy", self.pts3), self.save("r3.npy", self.r3)
        self.inp2, self.rad2 = self.save("p2.npy", self.pts2), self.save("r2.npy", self.r2)

    def hidden_line(self, err):
        m = re.search(r"^tessera: regular triangulation: radii \S+ to \S+; hidden points (\d+)", err, re.M)
        self.assertIsNotNone(m, err)
        return int(m.group(1))

    def check_regular(self, pts, r, simplices):
        """Brute force: no point's power at a simplex's orthocentre is below its vertices'."""
        d = pts.shape[1]
        p0 = pts[simplices[:, 0]]
        rows = pts[simplices[:, 1:]] - p0[:, None, :]
        w = r ** 2
        rhs = (rows ** 2).sum(axis=2) - (w[simplices[:, 1:]] - w[simplices[:, :1]])
        c = np.linalg.solve(2 * rows, rhs[..., None])[..., 0] + p0  # orthocentres
        own = ((p0 - c) ** 2).sum(axis=1) - w[simplices[:, 0]]
        power = ((pts[None, :, :] - c[:, None, :]) ** 2).sum(axis=2) - w[None, :]
        scale = 1e-9 * (1 + np.abs(own))
        self.assertTrue(np.all(power >= own[:, None] - scale[:, None]), "a point in conflict with a simplex")
        self.assertEqual(d + 1, simplices.shape[1])

    def test_3d_and_2d_with_validate(self):
        for pts, inp, rad, r, out in ((self.pts3, self.inp3, self.rad3, self.r3, "t.vtu"),
                                      (self.pts2, self.inp2, self.rad2, self.r2, "t.vtp")):
            sim, vtk = self.p("s.npy"), self.p(out)
            res = self.ok(["delaunay", inp, "--radii", rad, "--simplices", sim, "-o", vtk, "--validate"])
            self.assertIn("validation passed", res.stderr)
            self.assertIn("non-regular facets", res.stderr)
            s = np.load(sim)
            hidden = np.setdiff1d(np.arange(self.N), s)
            self.assertEqual(self.hidden_line(res.stderr), len(hidden))
            self.assertGreater(len(hidden), 0, "radii this large hide some points")
            self.check_regular(pts, r, s)
            g = read_vtu(vtk) if out.endswith(".vtu") else read_vtp(vtk)
            self.assertEqual(g.GetNumberOfCells(), len(s))
            np.testing.assert_array_equal(vtk_to_numpy(g.GetPointData().GetArray("Radius")), r)
            # Hidden points own no power cell.
            tab = self.p("c.csv")
            self.ok(["voronoi", inp, "--radii", rad, "--cell-table", tab, "-q"])
            owners = np.loadtxt(tab, delimiter=",", skiprows=1)[:, 0].astype(int)
            self.assertFalse(np.isin(hidden, owners).any())

    def test_periodic_boxes(self):
        # Every image has its point's radius; --validate checks local regularity
        # among the images and each hidden point under a translate of a simplex.
        for inp, extra in ((self.inp3, ["--periodic", "xyz", "--bounds"] + BOX3),
                           (self.inp3, ["--periodic", "xyz", "--bounds"] + BOX3 + ["--tilt", "0.25", "0", "-0.125"]),
                           (self.inp2, ["--periodic", "xy", "--bounds"] + BOX2 + ["--tilt", "0.5"])):
            rad = self.rad3 if inp == self.inp3 else self.rad2
            sim, sh, vtk = self.p("s.npy"), self.p("sh.npy"), self.p("t.vtu")
            res = self.ok(["delaunay", inp, "--radii", rad, "--simplices", sim, "--simplex-shifts", sh, "--validate",
                           "-o", vtk] + extra)
            # Every point, and every image a simplex uses, has its point's radius.
            g = read_vtu(vtk)
            pid = vtk_to_numpy(g.GetPointData().GetArray("PointId"))
            r = self.r3 if inp == self.inp3 else self.r2
            np.testing.assert_array_equal(vtk_to_numpy(g.GetPointData().GetArray("Radius")), r[pid])
            self.assertIn("validation passed", res.stderr)
            self.assertIn("of the periodic box", res.stderr)
            hidden = np.setdiff1d(np.arange(self.N), np.load(sim))
            self.assertEqual(self.hidden_line(res.stderr), len(hidden))
            self.assertGreater(len(hidden), 0)

    def test_threads_and_bench(self):
        outs = []
        for th in ("1", "2"):
            sim = self.p("s%s.npy" % th)
            self.ok(["delaunay", self.inp3, "--radii", self.rad3, "--simplices", sim, "--threads", th, "-q"])
            outs.append(read_bytes(sim))
        self.assertEqual(outs[0], outs[1])
        r = self.ok(["bench", "delaunay", self.inp3, "--radii", self.rad3, "--repeat", "2"])
        lines = [json.loads(x) for x in r.stdout.splitlines()]
        self.assertEqual(len(lines), 2)
        s = np.load(self.p("s1.npy"))
        for j in lines:
            self.assertEqual(j["op"], "delaunay3")
            self.assertEqual(j["simplices"], len(s))
            self.assertEqual(j["extra"]["hidden"], self.N - len(np.unique(s)))
        # Equal radii: the ordinary triangulation, and no regular line.
        eq, plain = self.p("eq.npy"), self.p("plain.npy")
        r = self.ok(["delaunay", self.inp3, "--radii", self.save("er.npy", np.full(self.N, 0.1)), "--simplices", eq])
        self.assertNotIn("regular triangulation", r.stderr)
        self.ok(["delaunay", self.inp3, "--simplices", plain, "-q"])
        self.assertEqual(read_bytes(eq), read_bytes(plain))


class Help(unittest.TestCase):
    def test_help_lists_everything(self):
        r = run(["voronoi", "--help"])
        self.assertEqual(r.returncode, 0)
        for opt in ("INPUT", "--output", "--dim", "--labels", "--bounds", "--padding", "--ignore-outside",
                    "--threads", "--bin-points", "--cell-table", "--neighbors", "--validate", "--quiet",
                    "--periodic", "--neighbor-shifts", "--radii"):
            self.assertIn(opt, r.stdout)
        for cmd in (["bench", "voronoi"], ["graph"], ["faces"], ["delaunay"], ["bench", "delaunay"]):
            self.assertIn("--radii", run(cmd + ["--help"]).stdout, cmd)
        r = run(["--help"])
        self.assertEqual(r.returncode, 0)
        for sub in ("voronoi", "bench", "run-default"):
            self.assertIn(sub, r.stdout)
        r = run(["bench", "voronoi", "--help"])
        self.assertEqual(r.returncode, 0)
        self.assertIn("--repeat", r.stdout)
        self.assertIn("run-default", run(["--help"]).stdout)


class BadInput(TempDirCase):
    """Every failure: exit 2, one stderr line "tessera: error: ...", no output files."""

    def setUp(self):
        super().setUp()
        self.good3 = self.save("good3.npy", np.random.default_rng(1).random((50, 3)))
        self.good2 = self.save("good2.npy", np.random.default_rng(1).random((50, 2)))

    def fails(self, args, fragment=None, code=2, outputs=None, env=None):
        before = set(os.listdir(self.dir))
        r = run(args, env=env)
        after = set(os.listdir(self.dir))
        cmd = "tessera " + " ".join(map(str, args))
        self.assertEqual(r.returncode, code, "%s: exit %d\nstdout: %s\nstderr: %s" %
                         (cmd, r.returncode, r.stdout, r.stderr))
        lines = r.stderr.splitlines()
        self.assertEqual(len(lines), 1, "%s: stderr must be one line, got %r" % (cmd, r.stderr))
        self.assertTrue(lines[0].startswith("tessera: error: "), "%s: %r" % (cmd, lines[0]))
        if fragment:
            self.assertIn(fragment, lines[0], cmd)
        self.assertEqual(after - before, set(), "%s left files behind" % cmd)
        for o in outputs or []:
            self.assertFalse(os.path.exists(o), "%s left %s" % (cmd, o))
        return lines[0]

    def out(self, name="cells.vtu"):
        return self.p(name)

    def test_missing_file(self):
        self.fails(["voronoi", self.p("nope.npy"), "-o", self.out()], "nope.npy")

    def test_error_line_is_utf8(self):
        # A corrupt file's bytes quoted in the message come out as '?' (run()
        # decodes stderr as UTF-8 and would raise on them); a file name's
        # UTF-8 stays.
        bad = self.p("b\u00e9d.vtp")
        with open(bad, "wb") as f:
            f.write(b'<VTKFile type="Poly\xd7Data"></VTKFile>')
        line = self.fails(["voronoi", bad, "-o", self.out()], "b\u00e9d.vtp")
        self.assertIn("'Poly?Data'", line)

    def test_unknown_input_extension(self):
        path = self.p("pts.foo")
        with open(path, "w") as f:
            f.write("0 0 0\n1 1 1\n")
        self.fails(["voronoi", path, "-o", self.out()])

    def test_wrong_dtypes(self):
        for name, arr in [("complex.npy", np.zeros((10, 3), complex)), ("str.npy", np.array([["a", "b", "c"]] * 10)),
                          ("obj.npy", None), ("bool.npy", np.eye(10, 3, dtype=bool))]:
            path = self.p(name)
            if arr is None:
                np.save(path, np.array([{"a": 1}] * 4, dtype=object), allow_pickle=True)
            else:
                np.save(path, arr)
            self.fails(["voronoi", path, "-o", self.out()], name)

    def test_wrong_shapes(self):
        for shape in [(20, 1), (20, 5), (20,), (4, 5, 3)]:
            path = self.save("s%d.npy" % len(shape), np.zeros(shape))
            self.fails(["voronoi", path, "-o", self.out()], "shape")
            os.remove(path)

    def test_empty_inputs(self):
        for name in ("empty.npy", "empty.csv", "empty.ply"):
            path = self.p(name)
            open(path, "w").close()
            self.fails(["voronoi", path, "-o", self.out()], name)
        self.fails(["voronoi", self.save("zero.npy", np.zeros((0, 3))), "-o", self.out()])

    def test_single_point(self):
        self.fails(["voronoi", self.save("one.npy", np.array([[0.5, 0.5, 0.5]])), "-o", self.out()], "--bounds")

    def test_no_cells_by_duplicates_of_outside_points(self):
        # The one point with a label >= 0 duplicates outside point 0, which
        # owns their place: no cells, and the message says why (it said no
        # point was inside with a label >= 0).
        pts = self.save("dp.npy", np.array([[0.2, 0.3], [0.7, 0.6], [0.2, 0.3]]))
        lab = self.save("dl.npy", np.array([-1, -1, 0], dtype=np.int32))
        self.fails(["voronoi", pts, "--labels", lab, "-o", self.out("c.vtp")], "all duplicate an outside point")

    def test_nan_inf(self):
        for name, bad in (("nan.npy", np.nan), ("inf.npy", np.inf)):
            pts = np.random.default_rng(1).random((20, 3))
            pts[7, 1] = bad
            self.fails(["voronoi", self.save(name, pts), "-o", self.out()])

    def test_labels_wrong_length(self):
        lab = self.save("lab.npy", np.zeros(49, dtype=np.int32))
        self.fails(["voronoi", self.good3, "--labels", lab, "-o", self.out()], "lab")

    def test_labels_not_integer(self):
        lab = self.save("labf.npy", np.zeros(50, dtype=np.float64) + 0.5)
        self.fails(["voronoi", self.good3, "--labels", lab, "-o", self.out()])

    def test_all_points_outside_bounds(self):
        args = ["voronoi", self.good3, "-o", self.out(), "--bounds", "5", "6", "5", "6", "5", "6"]
        self.fails(args)
        self.fails(args + ["--ignore-outside"])

    def test_some_points_outside_bounds_without_ignore(self):
        self.fails(["voronoi", self.good3, "-o", self.out(), "--bounds", "0", "0.5", "0", "1", "0", "1"])

    def test_bad_bounds(self):
        for b in (["0", "0", "0", "1", "0", "1"], ["1", "0", "0", "1", "0", "1"], ["0", "1", "0", "1", "0"],
                  ["0", "nan", "0", "1", "0", "1"], ["0", "1", "0", "1"]):
            self.fails(["voronoi", self.good3, "-o", self.out(), "--bounds"] + b)
        self.fails(["voronoi", self.good2, "-o", self.out("c.vtp"), "--bounds"] + BOX3)

    def test_bad_periodic(self):
        out = self.out()
        self.fails(["voronoi", self.good3, "-o", out, "--periodic", "xyz"], "--bounds")
        for axes in ("xx", "w", "x,y"):
            self.fails(["voronoi", self.good3, "-o", out, "--bounds"] + BOX3 + ["--periodic", axes], "--periodic")
        self.fails(["voronoi", self.good2, "-o", self.out("c.vtp"), "--bounds"] + BOX2 + ["--periodic", "xz"], "z")
        self.fails(["voronoi", self.good3, "--neighbor-shifts", self.p("s.npy"), "--bounds"] + BOX3, "--periodic")
        self.fails(["voronoi", self.good3, "--neighbor-shifts", self.p("s.csv"), "--bounds"] + BOX3 +
                   ["--periodic", "x"], ".npy")
        # --tilt: only with --periodic, as many values as the dimension asks,
        # both of a tilt's axes periodic, finite.
        tilted = ["voronoi", self.good3, "-o", out, "--bounds"] + BOX3
        self.fails(tilted + ["--tilt", "0.1", "0", "0"], "--periodic")
        self.fails(tilted + ["--periodic", "xyz", "--tilt", "0.1"], "three values")
        self.fails(["voronoi", self.good2, "-o", self.out("c.vtp"), "--bounds"] + BOX2 +
                   ["--periodic", "xy", "--tilt", "0.1", "0", "0"], "one value")
        self.fails(tilted + ["--periodic", "xz", "--tilt", "0.1", "0", "0"], "tilt xy needs x and y periodic")
        self.fails(tilted + ["--periodic", "xyz", "--tilt", "nan", "0", "0"], "tilt")
        # Outside a wall (y is not periodic) stays an error.
        pts = np.random.default_rng(2).random((50, 3))
        pts[3, 1] = 1.5
        self.fails(["voronoi", self.save("wall.npy", pts), "-o", out, "--bounds"] + BOX3 + ["--periodic", "xz"],
                   "not periodic")
        for cmd in (["faces", "--kind", "complex", "-o", self.p("f.vtp")], ["flower", "--point", "0", "-o", self.p("f.vtp")]):
            r = run([cmd[0], self.good3] + cmd[1:] + ["--bounds"] + BOX3 + ["--periodic", "xyz"])
            self.assertEqual(r.returncode, 0, r.stderr)  # served since stop 76 (test_dual_cli.py)
            self.fails([cmd[0], self.good3] + cmd[1:] + ["--periodic", "xyz"], "--bounds")
        self.fails(["graph", self.good3, "--spoke-shifts", self.p("s.npy"), "--bounds"] + BOX3, "--periodic")
        dl = ["delaunay", self.good3, "-o", self.p("d.vtu"), "--bounds"] + BOX3
        self.fails(dl + ["--simplex-shifts", self.p("s.npy")], "--periodic")
        self.fails(dl + ["--periodic", "xy"], "every axis periodic")
        self.fails(dl + ["--periodic", "xyz", "--no-hull-completion"], "no hull")
        self.fails(dl + ["--periodic", "xyz", "--simplex-shifts", self.p("s.csv")], ".npy")

    def test_bad_radii(self):
        out = self.out()
        vor = ["voronoi", self.good3, "-o", out, "--bounds"] + BOX3
        r = np.random.default_rng(2).random(50) * 0.1
        msg = self.fails(vor + ["--radii", self.save("short.npy", r[:-1])], "--radii", outputs=[out])
        self.assertIn("49 values for 50 points", msg)
        for value, shown in ((-0.5, "radius of point 7 is -0.5"), (np.nan, "radius of point 7 is NaN"),
                             (np.inf, "radius of point 7 is inf")):
            bad = r.copy()
            bad[7] = value
            self.fails(vor + ["--radii", self.save("bad.npy", bad)], shown, outputs=[out])
        rad = self.save("r.npy", r)
        self.fails(vor + ["--radii", self.p("missing.npy")], "missing.npy", outputs=[out])
        self.fails(vor + ["--radii", self.save("r2d.npy", np.stack([r, r], 1))], "1-D", outputs=[out])
        self.fails(vor + ["--radii", self.save("rs.npy", np.array(["a"] * 50))], outputs=[out])
        # Bools are a mask, not radii (as in Python); an (N, 1) column is N radii.
        self.fails(vor + ["--radii", self.save("rb.npy", np.ones(50, bool))], "found dtype bool", outputs=[out])
        self.assertEqual(run(vor + ["--radii", self.save("rc.npy", r[:, None]), "-q"]).returncode, 0)
        os.remove(out)
        # A name that the input has no column / property / field of.
        csv_in = self.p("s.csv")
        with open(csv_in, "w") as f:
            f.write("x,y,z,r\n")
            for p, ri in zip(np.load(self.good3), r):
                f.write("%.17g,%.17g,%.17g,%.17g\n" % (p[0], p[1], p[2], ri))
        self.fails(["voronoi", csv_in, "-o", out, "--bounds"] + BOX3 + ["--radii", "radius"], "'radius'",
                   outputs=[out])
        self.fails(vor + ["--radii", "radius"], "'radius'", outputs=[out])  # a plain .npy has no names
        # The other commands that take --radii check them alike; flower takes none.
        for args in (["graph", self.good3, "-o", self.p("g.vtp")],
                     ["faces", self.good3, "--kind", "complex", "-o", self.p("f.vtp")],
                     ["bench", "voronoi", self.good3]):
            args = args + ["--bounds"] + BOX3
            self.fails(args + ["--radii", self.p("short.npy")], "49 values for 50 points")
            self.fails(args + ["--radii", self.p("bad.npy")], "radius of point 7")
        self.fails(["flower", self.good3, "--point", "0", "-o", self.p("fl.vtp"), "--radii", rad], "--radii")
        # Every point that could own a cell has an empty power cell: said so, not "outside".
        few = self.save("few.npy", np.array([[0.5, 0.5, 0.5], [0.51, 0.5, 0.5], [0.2, 0.2, 0.2]]))
        few_r = self.save("few_r.npy", np.array([0.0, 0.5, 0.5]))
        few_l = self.save("few_l.npy", np.array([0, -1, -1], dtype=np.int32))
        self.fails(["voronoi", few, "--radii", few_r, "--labels", few_l, "--bounds"] + BOX3 + ["-o", out],
                   "has an empty power cell", outputs=[out])

    def test_bad_regular_radii(self):
        # delaunay --radii (the regular triangulation) checks them as voronoi does.
        out = self.p("t.vtu")
        r = np.random.default_rng(3).random(50) * 0.1
        base = ["delaunay", self.good3, "-o", out, "--radii"]
        rad = self.save("r.npy", r)
        bad = r.copy()
        bad[3] = -1
        self.fails(base + [self.save("bad.npy", bad)], "radius of point 3", outputs=[out])
        self.fails(base + [self.save("short.npy", r[:-1])], "49 values for 50 points", outputs=[out])
        self.fails(["bench", "delaunay", self.good3, "--radii", self.p("short.npy")], "49 values for 50 points")

    def test_coplanar_3d_suggests_dim2(self):
        pts = np.random.default_rng(1).random((50, 3))
        pts[:, 2] = 0.25
        msg = self.fails(["voronoi", self.save("flat.npy", pts), "-o", self.out()])
        self.assertIn("--dim 2", msg)

    def test_coincident_points(self):
        self.fails(["voronoi", self.save("same.npy", np.ones((10, 3))), "-o", self.out()])

    def test_output_dir_missing(self):
        self.fails(["voronoi", self.good3, "-o", self.p("no/such/dir/c.vtu")], "no/such/dir")
        self.fails(["voronoi", self.good3, "--cell-table", self.p("no/t.csv")])
        self.fails(["voronoi", self.good3, "-o", self.out(), "--neighbors", self.p("no/nb.npy")],
                   outputs=[self.out()])
        self.fails(["voronoi", self.good3, "-o", os.path.join(self.good3, "c.vtu")])  # parent is a file

    def test_output_dir_not_writable(self):
        if os.geteuid() == 0:
            self.skipTest("root can write anywhere")
        ro = self.p("ro")
        os.mkdir(ro)
        os.chmod(ro, 0o555)
        try:
            self.fails(["voronoi", self.good3, "-o", os.path.join(ro, "c.vtu")])
        finally:
            os.chmod(ro, 0o755)

    def test_output_is_directory(self):
        os.mkdir(self.p("d.vtu"))
        r = run(["voronoi", self.good3, "-o", self.p("d.vtu")])
        self.assertEqual(r.returncode, 2)
        self.assertTrue(r.stderr.startswith("tessera: error:"))

    def test_outputs_name_distinct_files(self):
        # Two options naming one file kept only the one written last (the
        # neighbours over the cell table), and the summary listed it twice.
        same = self.p("same.npy")
        self.fails(["voronoi", self.good3, "--cell-table", same, "--neighbors", same],
                   "--cell-table and --neighbors name the same file", outputs=[same])
        os.mkdir(self.p("sub"))
        self.fails(["voronoi", self.good3, "--neighbors", same, "--cell-table", self.p("sub/../same.npy")],
                   "--cell-table and --neighbors name the same file", outputs=[same])
        self.fails(["delaunay", self.good3, "--simplices", same, "--simplex-shifts", same, "--periodic", "xyz",
                    "--bounds", "0", "1", "0", "1", "0", "1"], "--simplices and --simplex-shifts", outputs=[same])
        self.fails(["graph", self.good3, "--csr", same, "--spoke-measures", same], "--csr and --spoke-measures",
                   outputs=[same])
        r = run(["voronoi", self.good3, "--cell-table", "-", "--neighbors", same])  # standard output is no file
        self.assertEqual(r.returncode, 0, r.stderr)
        # A bare name and ./name of a file not there yet (a fuzz found them
        # taken for two files; the neighbours replaced the table).
        r = subprocess.run([TESSERA, "voronoi", self.good3, "--cell-table", "new.npy", "--neighbors", "./new.npy"],
                           cwd=self.dir, capture_output=True, text=True)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("name the same file", r.stderr)
        self.assertFalse(os.path.exists(self.p("new.npy")))

    def test_outputs_may_not_replace_inputs(self):
        # An output naming a file the command reads replaced it, exit 0: the
        # points by the cell table, the labels by the neighbours, a threshold's
        # scalars by its points. Refused now, by any spelling, before any work,
        # and the input is left as it was.
        def intact(path, fn):
            with open(path, "rb") as f:
                before = f.read()
            line = fn()
            with open(path, "rb") as f:
                self.assertEqual(f.read(), before, "%s was changed" % path)
            return line
        pts = self.good3
        labels = self.save("lab.npy", np.arange(50, dtype=np.int32) % 3)
        scal = self.save("s.npy", np.linspace(0, 1, 50))
        os.mkdir(self.p("sub"))
        for args, fragment, path in (
                (["voronoi", pts, "--cell-table", pts], "it is the INPUT, which this run reads", pts),
                (["voronoi", pts, "--labels", labels, "--neighbors", self.p("sub/../lab.npy")], "it is --labels", labels),
                (["graph", pts, "--csr", pts], "the INPUT", pts),
                (["delaunay", pts, "--simplices", pts], "the INPUT", pts),
                (["joggle", pts, "-o", pts], "the INPUT", pts),
                (["threshold", pts, "--scalars", scal, "--interval", "0,0.5,1", "-o", scal], "--scalars", scal)):
            line = intact(path, lambda: self.fails(args))
            self.assertIn(fragment, line)
        os.symlink(pts, self.p("link.npy"))
        intact(pts, lambda: self.fails(["voronoi", self.p("link.npy"), "--cell-table", pts], "the INPUT"))
        # Standard input redirected from the file the output names.
        for args in (["joggle", "-", "-o", pts], ["voronoi", "-", "--cell-table", self.p("t.csv")]):
            target = args[-1]
            if not os.path.exists(target):
                shutil.copy(pts, target)
            def refused():
                with open(target, "rb") as f:
                    r = subprocess.run([TESSERA] + args, stdin=f, capture_output=True, text=True)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn("it is the INPUT, which this run reads", r.stderr)
            intact(target, refused)
        # An image header's data file (NRRD `data file:`), read beside the
        # header (named .npy here only so that -o, a points file, may name it).
        img = np.zeros((8, 9, 10), np.int32)
        img[2:6, 2:7, 3:8] = 1
        img.tofile(self.p("vol.npy"))
        with open(self.p("vol.nhdr"), "w") as f:
            f.write("NRRD0004\ntype: int32\ndimension: 3\nsizes: 10 9 8\nendian: little\nencoding: raw\n"
                    "data file: vol.npy\n")
        probe_pts = self.save("probe.npy", np.random.default_rng(0).random((20, 3)) * 7)
        line = intact(self.p("vol.npy"), lambda: self.fails(["probe", self.p("vol.nhdr"), probe_pts, "-o",
                                                            self.p("vol.npy")]))
        self.assertIn("it is the data file of", line)

    def test_empty_option_values_refused(self):
        # An empty value was taken as the option not given: `--cell-table ""
        # --neighbors nb.npy` wrote the neighbours alone, exit 0.
        for args, name in ((["--cell-table", "", "--neighbors", self.p("nb.npy")], "--cell-table"),
                           (["-o", "", "--validate"], "--output"),
                           (["--labels", "", "--validate"], "--labels")):
            self.fails(["voronoi", self.good3] + args, name + ": an empty value", outputs=[self.p("nb.npy")])
        self.fails(["voronoi", "", "--validate"], "INPUT: an empty value")
        self.fails(["voronoi", self.good3, "--radii=", "--validate"], "--radii: an empty value")
        self.fails(["delaunay", self.good3, "--simplices", "", "--validate"], "--simplices: an empty value")

    def test_output_extensions(self):
        self.fails(["voronoi", self.good3, "-o", self.out("c.vtp")], ".vtu")
        self.fails(["voronoi", self.good2, "-o", self.out("c.vtu")], ".vtp")
        self.fails(["voronoi", self.good3, "-o", self.out("c.vtk")])
        self.fails(["voronoi", self.good3, "--cell-table", self.out("t.txt")])
        self.fails(["voronoi", self.good3, "--neighbors", self.out("nb.csv")])

    def test_bad_command_lines(self):
        self.fails([])
        self.fails(["voronoi"])
        self.fails(["voronoi", self.good3])  # nothing to do
        self.fails(["voronoi", self.good3, "-o", self.out(), "--dim", "4"])
        self.fails(["voronoi", self.good3, "-o", self.out(), "--threads", "-1"])
        self.fails(["voronoi", self.good3, "-o", self.out(), "--threads", "5000"], "threads must be at most 4096")
        self.fails(["voronoi", self.good3, "-o", self.out()], "TESSERA_NUM_THREADS", env={"TESSERA_NUM_THREADS": "5000"})
        self.fails(["voronoi", self.good3, "-o", self.out(), "--padding", "-0.1"])
        # A padding that makes the domain overflow double (a segfault until
        # stop 17), in 3D and 2D, for cells and for surface nets.
        labels = self.save("lab50.npy", np.arange(50, dtype=np.int32) % 2)
        for good in (self.good3, self.good2):
            for pad in ("1e307", "1e308"):
                self.fails(["voronoi", good, "-o", self.out("p.vtu" if good == self.good3 else "p.vtp"),
                            "--padding", pad], "overflows double")
                self.fails(["surface-nets", good, "--labels", labels, "-o", self.out("s.vtp"), "--padding", pad],
                           "overflows double")
        self.fails(["voronoi", self.good3, "-o", self.out(), "--no-such-option"])
        self.fails(["bench", "voronoi", self.good3, "--repeat", "0"])
        self.fails(["frobnicate"])

    def test_numeric_option_words(self):
        """Every numeric option of every command, read from its --help, rejects
        words that are not its kind of number with a short message naming the
        option. CLI11 alone read '' as 0, wrapped '--seed -1' and took seeds
        past 2^64 (stop 17's fuzz); its range check printed DBL_MAX in full."""
        commands = [["voronoi"], ["delaunay"], ["graph"], ["faces"], ["flower"], ["surface-nets"],
                    ["joggle"], ["fill"], ["threshold"], ["lloyd"], ["sample-image"], ["probe"], ["run-default"],
                    ["bench", "voronoi"], ["bench", "delaunay"], ["bench", "surface-nets"]]
        option = re.compile(r"^\s+(?:-\w,)?(--[\w-]+) (INT|UINT|FLOAT)\b")
        seen = {"INT": 0, "UINT": 0, "FLOAT": 0}
        for cmd in commands:
            help_text = run(cmd + ["--help"]).stdout
            for line in help_text.splitlines():
                m = option.match(line)
                if not m:
                    continue
                name, kind = m.groups()
                seen[kind] += 1
                bad = ["", "abc", "1x", " 1", "--"]
                if kind != "FLOAT":
                    bad += ["1.5", "1e3", "0x10"]
                if kind == "UINT":
                    bad += ["-1", "18446744073709551616"]
                for word in bad:
                    args = cmd + ([] if cmd == ["run-default"] else [self.good3]) + [name + "=" + word]
                    msg = self.fails(args, name)
                    self.assertNotIn("179769313486231570814527423731704356798070567525844996598917476803157", msg)
                    self.assertLess(len(msg), 160, msg)
        # The sweep found the options (a change of --help's layout would
        # otherwise make it pass vacuously).
        self.assertGreater(seen["INT"], 20)
        self.assertGreater(seen["UINT"], 4)
        self.assertGreater(seen["FLOAT"], 15)


def main():
    return cli_main("test_cli.py", [(vtk is not None, "python3-vtk9 is required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
