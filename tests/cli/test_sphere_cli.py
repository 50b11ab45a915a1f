#!/usr/bin/python3
"""End-to-end tests of `tessera sphere` and `tessera bench sphere`.

Usage: /usr/bin/python3 tests/cli/test_sphere_cli.py PATH_TO_tessera [unittest args...]

Checks what the command writes by reading it back (VTK's XML reader, numpy)
against scipy.spatial.SphericalVoronoi (Qhull's hull) and scipy's ConvexHull,
that lon/lat input and a centre and radius are honoured, that 1 and 2 threads
write the same bytes, and that bad input fails cleanly with nothing written.
Prints "N passed, M failed" last.
"""
import json
import os
import subprocess
import sys

import numpy as np
import vtk
from scipy.spatial import ConvexHull, SphericalVoronoi
from vtk.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli  # noqa: E402  (the shared main() only)
import test_delaunay_cli  # noqa: E402  (CommandCase)


def on_sphere(n, seed, radius=1.0, center=(0.0, 0.0, 0.0)):
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return np.asarray(center) + radius * v / np.linalg.norm(v, axis=1)[:, None]


def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


def canonical(t):
    t = list(t)
    k = t.index(min(t))
    return tuple(t[k:] + t[:k])


class SphereCommand(test_delaunay_cli.CommandCase):
    def setUp(self):
        self.make_inputs("tessera-sphere-", on_sphere(3000, 4, 2.0, (1.0, 2.0, -1.0)), np.zeros((4, 2)))

    def test_cells_equal_scipys_and_read_back(self):
        cells, tri, table, nb = (self.path(x) for x in ("c.vtp", "t.vtp", "c.csv", "nb.npy"))
        r = self.ok(["sphere", self.path("p3.npy"), "--center", "1", "2", "-1", "-o", cells, "--triangles", tri,
                     "--cell-table", table, "--neighbors", nb, "--validate"])
        self.assertIn("cells          3000", r.stdout)
        self.assertIn("validation     passed", r.stdout)
        ref = SphericalVoronoi(self.p3, radius=2.0, center=np.array([1.0, 2.0, -1.0]))
        ref.sort_vertices_of_regions()
        areas = ref.calculate_areas()
        t = np.genfromtxt(table, delimiter=",", names=True)
        self.assertEqual(t.dtype.names, ("id", "area", "cx", "cy", "cz", "edges", "neighbors"))
        np.testing.assert_array_equal(t["id"], np.arange(3000))
        np.testing.assert_allclose(t["area"], areas, rtol=1e-9)
        self.assertAlmostEqual(t["area"].sum(), 16 * np.pi, places=9)
        # The polygons: one per cell, vertices on the sphere, the same as scipy's per cell.
        pd = read_vtp(cells)
        self.assertEqual(pd.GetNumberOfCells(), 3000)
        pts = vtk_to_numpy(pd.GetPoints().GetData())
        np.testing.assert_allclose(np.linalg.norm(pts - [1, 2, -1], axis=1), 2.0, rtol=1e-12)
        gid = vtk_to_numpy(pd.GetCellData().GetArray("GeneratorId"))
        np.testing.assert_array_equal(gid, np.arange(3000))
        np.testing.assert_allclose(vtk_to_numpy(pd.GetCellData().GetArray("Area")), areas, rtol=1e-9)
        for c in range(0, 3000, 37):
            ids = vtk.vtkIdList()
            pd.GetCellPoints(c, ids)
            ours = pts[[ids.GetId(k) for k in range(ids.GetNumberOfIds())]]
            theirs = ref.vertices[ref.regions[c]]
            self.assertEqual(len(ours), len(theirs))
            # Ours counter-clockwise seen from outside, every one; scipy's
            # sorted regions go either way (scipy issue 7046): the same
            # cycle, in one direction or the other.
            g = self.p3[c] - [1, 2, -1]
            turn = sum(np.dot(np.cross(ours[k] - self.p3[c], ours[(k + 1) % len(ours)] - self.p3[c]), g)
                       for k in range(len(ours)))
            self.assertGreater(turn, 0)
            k = int(np.argmin(np.linalg.norm(theirs - ours[0], axis=1)))
            theirs = np.roll(theirs, -k, axis=0)
            if not np.allclose(theirs, ours, atol=1e-9):
                theirs = np.roll(theirs[::-1], 1, axis=0)
            np.testing.assert_allclose(theirs, ours, atol=1e-9)
        # The triangles: the convex hull's facets, outward.
        tp = read_vtp(tri)
        self.assertEqual(tp.GetNumberOfPoints(), 3000)
        conn = vtk_to_numpy(tp.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        expected = set()
        for s in ConvexHull(self.p3).simplices:
            a, b, c = self.p3[s]
            outward = np.dot(np.cross(b - a, c - a), a - [1, 2, -1]) > 0
            expected.add(canonical(s if outward else s[::-1]))
        self.assertEqual({canonical(x) for x in conn}, expected)
        # Neighbours: CSR of every point, symmetric, the table's counts.
        a = np.load(nb)
        n = a[0]
        off = a[1:n + 2]
        ids = a[n + 2:]
        self.assertEqual(n, 3000)
        np.testing.assert_array_equal(np.diff(off), t["neighbors"])
        pairs = {(i, j) for i in range(n) for j in ids[off[i]:off[i + 1]]}
        self.assertEqual(pairs, {(j, i) for i, j in pairs})

    def test_lonlat_and_threads(self):
        rng = np.random.default_rng(9)
        ll = np.column_stack([rng.uniform(-180, 180, 2000), np.degrees(np.arcsin(rng.uniform(-1, 1, 2000)))])
        np.savetxt(self.path("ll.csv"), ll, delimiter=",", header="lon,lat", comments="")
        outs = []
        for threads in ("1", "2"):
            o = self.path(f"c{threads}.csv")
            v = self.path(f"c{threads}.vtp")
            r = self.ok(["sphere", self.path("ll.csv"), "--lonlat", "--radius", "6371", "--cell-table", o, "-o", v,
                         "--threads", threads])
            outs.append((open(o, "rb").read(), open(v, "rb").read()))
        self.assertEqual(outs[0], outs[1])
        t = np.genfromtxt(self.path("c1.csv"), delimiter=",", names=True)
        self.assertAlmostEqual(t["area"].sum() / (4 * np.pi * 6371**2), 1.0, places=12)
        lon, lat = np.radians(ll[:, 0]), np.radians(ll[:, 1])
        xyz = 6371 * np.column_stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
        ref = SphericalVoronoi(xyz, radius=6371)
        np.testing.assert_allclose(t["area"], ref.calculate_areas(), rtol=1e-8)

    def test_duplicates_and_a_grid(self):
        # A lon/lat grid with its poles once per longitude, and a repeated point.
        ll = np.array([(lon, lat) for lat in range(-90, 91, 15) for lon in range(-180, 180, 20)], dtype=float)
        ll = np.vstack([ll, ll[40]])
        np.save(self.path("grid.npy"), ll)
        r = self.ok(["sphere", self.path("grid.npy"), "--lonlat", "--cell-table", self.path("g.npy")])
        self.assertIn("duplicates", r.stdout)
        t = np.load(self.path("g.npy"))
        self.assertNotIn(len(ll) - 1, t[:, 0])
        self.assertAlmostEqual(t[:, 1].sum(), 4 * np.pi, places=11)
        # The same from standard input.
        with open(self.path("grid.npy"), "rb") as f:
            r = subprocess.run([test_delaunay_cli.TESSERA, "sphere", "-", "--lonlat", "--cell-table",
                                self.path("g2.npy")], stdin=f, capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("from stdin", r.stdout)
        np.testing.assert_array_equal(np.load(self.path("g2.npy")), t)
        # And the table to standard output (the summary on standard error).
        r = self.ok(["sphere", self.path("grid.npy"), "--lonlat", "--cell-table", "-"])
        self.assertIn("tessera sphere:", r.stderr)
        rows = np.loadtxt(r.stdout.splitlines(), delimiter=",", skiprows=1)
        np.testing.assert_allclose(rows, t, rtol=0, atol=0)

    def test_bench_prints_json(self):
        r = self.ok(["bench", "sphere", self.path("p3.npy"), "--center", "1", "2", "-1", "--repeat", "2",
                     "--threads", "2"])
        lines = [json.loads(x) for x in r.stdout.strip().splitlines()]
        self.assertEqual(len(lines), 2)
        self.assertEqual(lines[0]["op"], "sphere")
        self.assertEqual(lines[0]["n"], 3000)
        self.assertEqual(lines[0]["simplices"], 2 * 3000 - 4)
        self.assertLess(abs(lines[0]["extra"]["area_error"]), 1e-12)

    def test_bad_input(self):
        out = self.path("c.vtp")
        self.assertIn("off the sphere", self.fails(["sphere", self.path("p3.npy"), "-o", out], [out]))
        self.assertIn("2D points", self.fails(["sphere", self.path("p2.npy"), "-o", out], [out]))
        self.assertIn("unknown extension", self.fails(["sphere", self.path("p3.npy"), "-o", self.path("c.vtu")]))
        self.assertIn("--triangles", self.fails(["sphere", self.path("p3.npy"), "--triangles", self.path("t.ply")]))
        self.fails(["sphere", self.path("p3.npy"), "--center", "1", "2", "-1", "-o", out, "--triangles", out], [out])
        self.fails(["sphere", self.path("p3.npy"), "--center", "1", "2", "-1", "--radius", "-1", "-o", out], [out])
        self.fails(["sphere", self.path("missing.npy"), "-o", out], [out])
        self.fails(["sphere", self.path("p3.npy"), "--center", "1", "2", "-1",
                    "-o", os.path.join(self.dir, "no", "c.vtp")])
        np.save(self.path("bad_lat.npy"), np.array([[0.0, 95.0], [10.0, 0.0]]))
        self.assertIn("latitude", self.fails(["sphere", self.path("bad_lat.npy"), "--lonlat", "-o", out], [out]))
        nan = self.p3.copy()
        nan[5, 1] = np.nan
        np.save(self.path("nan.npy"), nan)
        self.fails(["sphere", self.path("nan.npy"), "--center", "1", "2", "-1", "-o", out], [out])
        # A looser tolerance takes points a little off the sphere.
        off = self.p3.copy()
        off[7] = [1, 2, -1] + (off[7] - [1, 2, -1]) * 1.001
        np.save(self.path("off.npy"), off)
        self.fails(["sphere", self.path("off.npy"), "--center", "1", "2", "-1", "-o", out], [out])
        self.ok(["sphere", self.path("off.npy"), "--center", "1", "2", "-1", "--tolerance", "1e-2", "-o", out])


def main():
    def bind(path):
        test_delaunay_cli.TESSERA = path
    return test_cli.cli_main("test_sphere_cli.py", bind=bind)


if __name__ == "__main__":
    sys.exit(main())
