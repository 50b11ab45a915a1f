#!/usr/bin/python3
"""End-to-end tests of `tessera delaunay` and `tessera bench delaunay`.

Usage: /usr/bin/python3 tests/cli/test_delaunay_cli.py PATH_TO_tessera [unittest args...]

Checks what the command writes by reading it back (VTK's XML readers, numpy)
and against scipy.spatial.Delaunay (Qhull) on general-position input, and that
bad input fails cleanly with nothing written. Prints "N passed, M failed" last.
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import vtk
from scipy.spatial import Delaunay as ScipyDelaunay
from vtk.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli  # noqa: E402  (the shared main() only)

TESSERA = None


def run(args):
    env = dict(os.environ)
    env.pop("TESSERA_NUM_THREADS", None)
    return subprocess.run([TESSERA] + [str(a) for a in args], capture_output=True, text=True, env=env, timeout=600)


def simplex_set(s):
    return set(map(tuple, np.sort(np.asarray(s), axis=1)))


class CommandCase(unittest.TestCase):
    """A temporary folder with p3.npy and p2.npy (self.p3, self.p2), and runs that must pass or fail cleanly."""

    def make_inputs(self, prefix, p3, p2):
        self.dir = tempfile.mkdtemp(prefix=prefix)
        self.p3, self.p2 = p3, p2
        np.save(self.path("p3.npy"), p3)
        np.save(self.path("p2.npy"), p2)

    def tearDown(self):
        shutil.rmtree(self.dir)

    def path(self, name):
        return os.path.join(self.dir, name)

    def ok(self, args):
        r = run(args)
        self.assertEqual(r.returncode, 0, r.stderr)
        return r

    def fails(self, args, outputs=()):
        """Exit 2 with one error line, none of `outputs` and no temporary file left; returns the line."""
        r = run(args)
        self.assertEqual(r.returncode, 2, r.stderr)
        lines = r.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith("tessera: error: "), r.stderr)
        for o in outputs:
            self.assertFalse(os.path.exists(o), o)
        self.assertEqual([f for f in os.listdir(self.dir) if f.startswith(".")], [])
        return lines[0]


class DelaunayCommand(CommandCase):
    def setUp(self):
        rng = np.random.default_rng(5)
        self.make_inputs("tessera-delaunay-", rng.random((3000, 3)), rng.random((3000, 2)))

    def test_3d_equals_scipy_and_reads_back(self):
        r = self.ok(["delaunay", self.path("p3.npy"), "-o", self.path("t.vtu"), "--simplices", self.path("t.npy"),
                     "--validate"])
        self.assertIn("validation passed", r.stderr)
        s = np.load(self.path("t.npy"))
        self.assertEqual(s.dtype, np.int64)
        self.assertEqual(s.shape[1], 4)
        self.assertEqual(simplex_set(s), simplex_set(ScipyDelaunay(self.p3).simplices))
        # Positively oriented: det[p1-p0, p2-p0, p3-p0] > 0.
        p = self.p3[s]
        det = np.linalg.det(np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]], axis=1))
        self.assertTrue((det > 0).all())
        rd = vtk.vtkXMLUnstructuredGridReader()
        rd.SetFileName(self.path("t.vtu"))
        rd.Update()
        g = rd.GetOutput()
        self.assertEqual(g.GetNumberOfCells(), len(s))
        self.assertEqual(g.GetNumberOfPoints(), len(self.p3))
        self.assertTrue(all(g.GetCellType(i) == vtk.VTK_TETRA for i in range(0, len(s), 97)))
        conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 4)
        np.testing.assert_array_equal(conn, s)
        np.testing.assert_allclose(vtk_to_numpy(g.GetPoints().GetData()), self.p3)

    def test_2d_vtp_and_vtu(self):
        self.ok(["delaunay", self.path("p2.npy"), "-o", self.path("t.vtp"), "--simplices", self.path("t.npy")])
        s = np.load(self.path("t.npy"))
        self.assertEqual(simplex_set(s), simplex_set(ScipyDelaunay(self.p2).simplices))
        p = self.p2[s]
        cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
        self.assertTrue((cross > 0).all(), "triangles are counter-clockwise")
        rd = vtk.vtkXMLPolyDataReader()
        rd.SetFileName(self.path("t.vtp"))
        rd.Update()
        self.assertEqual(rd.GetOutput().GetNumberOfPolys(), len(s))
        self.ok(["delaunay", self.path("p2.npy"), "-o", self.path("t.vtu")])
        rd = vtk.vtkXMLUnstructuredGridReader()
        rd.SetFileName(self.path("t.vtu"))
        rd.Update()
        self.assertEqual(rd.GetOutput().GetNumberOfCells(), len(s))
        self.assertEqual(rd.GetOutput().GetCellType(0), vtk.VTK_TRIANGLE)

    def test_threads_identical(self):
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("a.npy"), "--threads", "1"])
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("b.npy"), "--threads", "2"])
        with open(self.path("a.npy"), "rb") as a, open(self.path("b.npy"), "rb") as b:
            self.assertEqual(a.read(), b.read())

    def test_methods_give_the_same_file(self):
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("a.npy"), "--method", "cells"])
        r = self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("b.npy"), "--method", "insertion"])
        self.assertIn("by incremental insertion", r.stderr)
        with open(self.path("a.npy"), "rb") as a, open(self.path("b.npy"), "rb") as b:
            self.assertEqual(a.read(), b.read())
        r = self.ok(["bench", "delaunay", self.path("p3.npy"), "--method", "insertion"])
        j = json.loads(r.stdout)
        self.assertEqual(j["extra"]["from_insertion"], j["simplices"])

    def test_no_hull_completion_is_a_subset(self):
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("a.npy"), "--no-hull-completion"])
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("b.npy")])
        a, b = simplex_set(np.load(self.path("a.npy"))), simplex_set(np.load(self.path("b.npy")))
        self.assertLess(len(a), len(b))
        self.assertTrue(a <= b)

    def test_lattice_validates(self):
        g = np.stack(np.meshgrid(*[np.arange(6.0)] * 3, indexing="ij"), -1).reshape(-1, 3)
        np.save(self.path("g.npy"), g)
        r = self.ok(["delaunay", self.path("g.npy"), "--simplices", self.path("t.npy"), "--validate"])
        self.assertIn("validation passed", r.stderr)
        s = np.load(self.path("t.npy"))
        p = g[s]
        vol = np.linalg.det(np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]], axis=1)) / 6
        self.assertTrue((vol > 0).all())
        self.assertAlmostEqual(vol.sum(), 125.0, places=9)

    def test_labels(self):
        labels = np.where(np.linalg.norm(self.p3 - 0.5, axis=1) < 0.3, 1, -1).astype(np.int32)
        np.save(self.path("l.npy"), labels)
        self.ok(["delaunay", self.path("p3.npy"), "--labels", self.path("l.npy"), "--simplices", self.path("t.npy"),
                 "--validate"])
        s = np.load(self.path("t.npy"))
        self.assertTrue((labels[s] >= 0).all())
        # Inside points on the hull (x > 0.6): the whole triangulation's inside
        # simplices, hull slivers included; without completion, only those
        # whose circumcentres lie in the box.
        labels = np.where(self.p3[:, 0] > 0.6, 0, -1).astype(np.int32)
        np.save(self.path("l.npy"), labels)
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("whole.npy")])
        r = self.ok(["delaunay", self.path("p3.npy"), "--labels", self.path("l.npy"), "--simplices", self.path("t.npy")])
        whole = np.load(self.path("whole.npy"))
        inside = (labels[whole] >= 0).all(axis=1)
        self.assertTrue(np.array_equal(np.load(self.path("t.npy")), whole[inside]))
        self.assertIn("%d with an outside vertex left out" % (~inside).sum(), r.stderr)
        self.ok(["delaunay", self.path("p3.npy"), "--labels", self.path("l.npy"), "--simplices", self.path("b.npy"),
                 "--no-hull-completion"])
        boxed = {tuple(sorted(x)) for x in np.load(self.path("b.npy")).tolist()}
        full = {tuple(sorted(x)) for x in whole[inside].tolist()}
        self.assertTrue(boxed < full)

    def test_empty_results_say_why(self):
        # One tetrahedron whose circumcentre lies outside the box: without hull
        # completion none is found, which is not flat input; with an outside
        # vertex the one simplex is left out.
        p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.1, 0.1, 0.1]])
        np.save(self.path("tet.npy"), p)
        r = self.ok(["delaunay", self.path("tet.npy"), "--simplices", self.path("t.npy")])
        self.assertEqual(np.load(self.path("t.npy")).shape, (1, 4))
        r = self.ok(["delaunay", self.path("tet.npy"), "--simplices", self.path("t.npy"), "--no-hull-completion"])
        self.assertEqual(len(np.load(self.path("t.npy"))), 0)
        self.assertIn("none has its circumcentre in the domain box (hull completion is off)", r.stderr)
        np.save(self.path("l4.npy"), np.array([0, 0, 0, -1], np.int32))
        r = self.ok(["delaunay", self.path("tet.npy"), "--labels", self.path("l4.npy"), "--simplices", self.path("t.npy")])
        self.assertEqual(len(np.load(self.path("t.npy"))), 0)
        self.assertIn("each of the triangulation's 1 has an outside vertex", r.stderr)

    def test_bench_line(self):
        r = self.ok(["bench", "delaunay", self.path("p2.npy"), "--repeat", "2", "--threads", "1"])
        lines = [json.loads(x) for x in r.stdout.splitlines()]
        self.assertEqual(len(lines), 2)
        for j in lines:
            self.assertEqual(j["tool"], "tessera")
            self.assertEqual(j["op"], "delaunay2")
            self.assertEqual(j["n"], 3000)
            self.assertEqual(j["threads"], 1)
            self.assertEqual(j["simplices"], len(ScipyDelaunay(self.p2).simplices))

    def test_bad_input(self):
        out = self.path("t.vtu")
        self.fails(["delaunay", self.path("missing.npy"), "-o", out], [out])
        self.fails(["delaunay", self.path("p3.npy")], [])
        self.fails(["delaunay", self.path("p3.npy"), "-o", self.path("t.vtk")], [self.path("t.vtk")])
        self.fails(["delaunay", self.path("p3.npy"), "-o", self.path("t.vtp")], [self.path("t.vtp")])
        self.fails(["delaunay", self.path("p3.npy"), "--simplices", self.path("t.csv")], [self.path("t.csv")])
        bad = self.p3.copy()
        bad[7, 1] = np.nan
        np.save(self.path("nan.npy"), bad)
        self.fails(["delaunay", self.path("nan.npy"), "-o", out], [out])
        self.fails(["delaunay", self.path("p3.npy"), "-o", out, "--bounds", "0", "0.5", "0", "1", "0", "1"], [out])
        self.fails(["bench", "delaunay", self.path("p3.npy"), "--repeat", "0"])
        self.fails(["delaunay", self.path("p2.npy"), "-o", out, "--method", "insertion", "--no-hull-completion"], [out])
        self.fails(["delaunay", self.path("p3.npy"), "-o", out, "--method", "insertion", "--no-hull-completion"], [out])
        r = run(["delaunay", self.path("p3.npy"), "-o", out, "--method", "insertion", "--no-hull-completion"])
        self.assertIn("--no-hull-completion", r.stderr)  # the option the user gave, not the library's field
        self.fails(["delaunay", self.path("p3.npy"), "-o", out, "--method", "qhull"], [out])


def circumradii(points, simplices):
    """Circumradius of each simplex, in floats (numpy's solve)."""
    p = points[simplices]
    e = p[:, 1:] - p[:, :1]
    rhs = 0.5 * (e * e).sum(axis=2)
    c = np.linalg.solve(e, rhs[..., None])[..., 0]
    return np.sqrt((c * c).sum(axis=1))


def boundary_of(simplices):
    """Facets (sorted) in exactly one of the simplices."""
    d = simplices.shape[1] - 1
    facets = np.concatenate([np.delete(simplices, k, axis=1) for k in range(d + 1)])
    u, count = np.unique(np.sort(facets, axis=1), axis=0, return_counts=True)
    return set(map(tuple, u[count == 1]))


class AlphaShapeCommand(CommandCase):
    """delaunay --alpha / --boundary / --regularized."""

    def setUp(self):
        rng = np.random.default_rng(91)
        p3 = rng.random((3000, 3))
        a = rng.uniform(0, 2 * np.pi, 4000)
        r = np.sqrt(rng.uniform(0.25, 1, 4000))
        self.make_inputs("tessera-alpha-", p3, np.c_[r * np.cos(a), r * np.sin(a)])  # 2D: an annulus, with a hole

    def test_3d_kept_simplices_boundary_and_vtp(self):
        alpha = 0.1
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("all.npy")])
        r = self.ok(["delaunay", self.path("p3.npy"), "--alpha", alpha, "--simplices", self.path("k.npy"),
                     "--boundary", self.path("b.npy"), "-o", self.path("k.vtu")])
        full = np.load(self.path("all.npy"))
        radius = circumradii(self.p3, full)
        self.assertFalse((np.abs(radius - alpha) < 1e-9).any())  # no near ties: floats decide as exactly
        kept = np.load(self.path("k.npy"))
        self.assertEqual(simplex_set(kept), simplex_set(full[radius <= alpha]))
        self.assertGreater(len(kept), 0)
        self.assertLess(len(kept), len(full))
        # The boundary .npy: the kept simplices' boundary, then the singular facets.
        b = np.load(self.path("b.npy"))
        self.assertEqual(b.dtype, np.int64)
        regular = boundary_of(kept)
        self.assertEqual(set(map(tuple, np.sort(b[:len(regular)], axis=1))), regular)
        self.assertIn("%d singular triangles" % (len(b) - len(regular)), r.stderr)
        # -o holds the kept simplices only.
        rd = vtk.vtkXMLUnstructuredGridReader()
        rd.SetFileName(self.path("k.vtu"))
        rd.Update()
        self.assertEqual(rd.GetOutput().GetNumberOfCells(), len(kept))
        # .vtp: the same facets, oriented out of the simplex SimplexId names.
        self.ok(["delaunay", self.path("p3.npy"), "--alpha", alpha, "--boundary", self.path("b.vtp")])
        rd = vtk.vtkXMLPolyDataReader()
        rd.SetFileName(self.path("b.vtp"))
        rd.Update()
        out = rd.GetOutput()
        self.assertEqual(out.GetNumberOfCells(), len(b))
        ids = vtk_to_numpy(out.GetPointData().GetArray("PointId"))
        self.assertEqual(out.GetNumberOfPoints(), len(np.unique(b)))
        tri = vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        np.testing.assert_array_equal(ids[tri], b)
        simplex = vtk_to_numpy(out.GetCellData().GetArray("SimplexId"))
        singular = vtk_to_numpy(out.GetCellData().GetArray("Singular"))
        n_reg = len(regular)
        self.assertTrue((singular[:n_reg] == 0).all() and (singular[n_reg:] == 1).all())
        self.assertTrue((simplex[n_reg:] == -1).all())
        rows = kept[simplex[:n_reg]]
        facet = b[:n_reg]
        apex = np.array([list(set(r) - set(f))[0] for r, f in zip(rows, facet)])
        a0, a1, a2 = self.p3[facet[:, 0]], self.p3[facet[:, 1]], self.p3[facet[:, 2]]
        normal = np.cross(a1 - a0, a2 - a0)
        self.assertTrue(((normal * (self.p3[apex] - a0)).sum(axis=1) < 0).all())
        # --regularized: the boundary only.
        self.ok(["delaunay", self.path("p3.npy"), "--alpha", alpha, "--boundary", self.path("r.npy"), "--regularized"])
        np.testing.assert_array_equal(np.load(self.path("r.npy")), b[:n_reg])

    def test_2d_concave_hull_with_a_hole(self):
        r = self.ok(["delaunay", self.path("p2.npy"), "--alpha", 0.08, "--boundary", self.path("b.npy"),
                     "--simplices", self.path("k.npy"), "--regularized"])
        b = np.load(self.path("b.npy"))
        kept = np.load(self.path("k.npy"))
        self.assertEqual(set(map(tuple, np.sort(b, axis=1))), boundary_of(kept))
        # Shape on the left: the shoelace sum over the segments is the area.
        x, y = self.p2[:, 0], self.p2[:, 1]
        area = 0.5 * (x[b[:, 0]] * y[b[:, 1]] - x[b[:, 1]] * y[b[:, 0]]).sum()
        tri = self.p2[kept]
        kept_area = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).sum()
        self.assertAlmostEqual(area, kept_area, places=12)
        self.assertLess(kept_area, np.pi * 0.99)  # the hole (area pi/4) is left out
        self.assertGreater(kept_area, np.pi * 0.7)
        self.assertIn("1 piece", r.stderr)
        # GeoJSON: one polygon, the outer ring counter-clockwise and the hole
        # clockwise, closed; their areas add up to the shape's.
        self.ok(["delaunay", self.path("p2.npy"), "--alpha", 0.08, "--boundary", self.path("b.geojson")])
        with open(self.path("b.geojson")) as f:
            g = json.load(f)
        self.assertEqual(g["type"], "FeatureCollection")
        geom = g["features"][0]["geometry"]
        self.assertEqual(geom["type"], "MultiPolygon")
        self.assertEqual(len(geom["coordinates"]), 1)
        rings = [np.array(ring) for ring in geom["coordinates"][0]]
        self.assertEqual(len(rings), 2)

        def signed(ring):
            self.assertTrue((ring[0] == ring[-1]).all())
            return 0.5 * (ring[:-1, 0] * ring[1:, 1] - ring[1:, 0] * ring[:-1, 1]).sum()
        self.assertGreater(signed(rings[0]), 0)
        self.assertLess(signed(rings[1]), 0)
        self.assertAlmostEqual(signed(rings[0]) + signed(rings[1]), kept_area, places=12)
        self.assertEqual(sum(len(ring) - 1 for ring in rings), len(b))
        self.assertEqual(g["features"][0]["properties"]["pieces"], 1)

    def test_boundary_without_alpha_is_the_hull(self):
        from scipy.spatial import ConvexHull
        self.ok(["delaunay", self.path("p3.npy"), "--boundary", self.path("h.npy")])
        h = np.load(self.path("h.npy"))
        self.assertEqual(set(map(tuple, np.sort(h, axis=1))), simplex_set(ConvexHull(self.p3).simplices))
        r = self.ok(["delaunay", self.path("p3.npy"), "--alpha", "inf", "--boundary", self.path("i.npy")])
        np.testing.assert_array_equal(np.load(self.path("i.npy")), h)
        self.assertIn("0 singular triangles", r.stderr)

    def test_periodic(self):
        # The periodic triangulation's simplices of circumradius <= alpha, with their shifts.
        box = ["--bounds", "0", "1", "0", "1", "0", "1", "--periodic", "xyz"]
        self.ok(["delaunay", self.path("p3.npy"), "--simplices", self.path("all.npy"), "--simplex-shifts",
                 self.path("alls.npy")] + box)
        r = self.ok(["delaunay", self.path("p3.npy"), "--alpha", 0.07, "--simplices", self.path("k.npy"),
                     "--simplex-shifts", self.path("ks.npy"), "-o", self.path("k.vtu")] + box)
        rows, shifts = np.load(self.path("all.npy")), np.load(self.path("alls.npy"))
        images = self.p3[rows] + shifts  # the unit box: shifts are lattice vectors
        radius = circumradii(images.reshape(-1, 3), np.arange(4 * len(rows)).reshape(-1, 4))
        keep = radius <= 0.07
        self.assertFalse((np.abs(radius - 0.07) < 1e-9).any())
        np.testing.assert_array_equal(np.load(self.path("k.npy")), rows[keep])
        np.testing.assert_array_equal(np.load(self.path("ks.npy")), shifts[keep])
        self.assertIn("of %d tetrahedra kept" % len(rows), r.stderr)
        rd = vtk.vtkXMLUnstructuredGridReader()
        rd.SetFileName(self.path("k.vtu"))
        rd.Update()
        self.assertEqual(rd.GetOutput().GetNumberOfCells(), keep.sum())

    def test_threads_identical(self):
        for t in ("1", "2"):
            self.ok(["delaunay", self.path("p3.npy"), "--alpha", 0.08, "--boundary", self.path("b%s.vtp" % t),
                     "--threads", t, "-q"])
        with open(self.path("b1.vtp"), "rb") as f1, open(self.path("b2.vtp"), "rb") as f2:
            self.assertEqual(f1.read(), f2.read())

    def test_bad_arguments(self):
        b = self.path("b.npy")
        self.assertIn("--alpha -1", self.fails(["delaunay", self.path("p3.npy"), "--alpha", "-1", "--boundary", b], [b]))
        self.assertIn("--alpha nan", self.fails(["delaunay", self.path("p3.npy"), "--alpha", "nan", "--boundary", b], [b]))
        self.fails(["delaunay", self.path("p3.npy"), "--alpha", "x", "--boundary", b], [b])
        self.assertIn("unknown extension", self.fails(["delaunay", self.path("p3.npy"), "--boundary", self.path("b.txt")]))
        g = self.path("b.geojson")
        self.assertIn("2D", self.fails(["delaunay", self.path("p3.npy"), "--alpha", "0.1", "--boundary", g], [g]))
        self.assertIn("--regularized", self.fails(["delaunay", self.path("p3.npy"), "--boundary", b, "--regularized"], [b]))
        self.assertIn("--periodic", self.fails(["delaunay", self.path("p3.npy"), "--alpha", "0.1", "--boundary", b,
                                                "--bounds", "0", "1", "0", "1", "0", "1", "--periodic", "xyz"], [b]))
        self.fails(["delaunay", self.path("p3.npy"), "--boundary", b, "--simplices", b], [b])
        self.fails(["delaunay", self.path("p3.npy"), "--boundary", os.path.join(self.dir, "no", "b.npy")])


def main():
    def bind(path):
        global TESSERA
        TESSERA = path
    return test_cli.cli_main("test_delaunay_cli.py", bind=bind)


if __name__ == "__main__":
    sys.exit(main())
