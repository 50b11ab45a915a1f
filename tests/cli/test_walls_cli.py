#!/usr/bin/python3
"""End-to-end tests of --wall: cells in a convex domain (the box cut by half-spaces).

Usage: /usr/bin/python3 tests/cli/test_walls_cli.py PATH_TO_tessera [unittest args...]

Domains whose measures are known by hand: the unit square cut by x + y <= 1
(a triangle of area 1/2 and perimeter 2 + sqrt 2), the unit cube cut by
x + y + z <= 3/2 (volume 1/2, by the symmetry x -> 1 - x). Every file is read
back (VTK's readers, numpy); bad input: exit 2, one error line, nothing
written. Shares its helpers with test_cli.py.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import json
import math
import os
import sys
from fractions import Fraction

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli as base  # noqa: E402  (helpers only; its test classes are not collected here)
from test_cli import read_bytes, read_vtp, read_vtu, cell_array  # noqa: E402
from test_prep_cli import Case  # noqa: E402  (its fails(): exit 2, one error line, nothing written)

from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

run = base.run


def inside(points, normal, offset):
    """Exactly: normal . p <= offset for every row (fractions: no rounding)."""
    n = [Fraction(x) for x in normal]
    return all(sum(Fraction(float(x)) * a for x, a in zip(p, n)) <= Fraction(offset) for p in points)


class Walls(Case):
    def setUp(self):
        super().setUp()
        rng = np.random.default_rng(8)
        p2 = rng.random((3000, 2))
        self.p2 = p2[p2.sum(axis=1) <= 1]
        p3 = rng.random((4000, 3))
        self.p3 = p3[p3.sum(axis=1) <= 1.5]
        self.in2 = self.save("p2.npy", self.p2)
        self.in3 = self.save("p3.npy", self.p3)

    def test_triangle_2d(self):
        r = self.ok(["voronoi", self.in2, "--bounds", "0", "1", "0", "1", "--wall", "1,1,1", "-o", self.p("c.vtp"),
                     "--cell-table", self.p("t.csv"), "--neighbors", self.p("nb.npy"), "--validate"])
        self.assertIn("domain             [0, 1] x [0, 1], inside 1 wall\n", r.stdout)
        self.assertIn("validation: OK", r.stdout)
        n = len(self.p2)
        out = read_vtp(self.p("c.vtp"))
        self.assertEqual(out.GetNumberOfCells(), n)
        area = vtk_to_numpy(cell_array(out, "Area"))
        self.assertAlmostEqual(float(area.sum()), 0.5, delta=1e-12)
        t = np.loadtxt(self.p("t.csv"), delimiter=",", skiprows=1)
        self.assertEqual(len(t), n)
        self.assertTrue(np.array_equal(t[:, 2], area))
        # INPUT right after a 2D wall's three numbers (which CLI11 reads as a fourth) is INPUT.
        self.ok(["voronoi", "--bounds", "0", "1", "0", "1", "--wall", "1", "1", "1", self.in2,
                 "--cell-table", self.p("t2.csv"), "-q"])
        self.assertEqual(read_bytes(self.p("t2.csv")), read_bytes(self.p("t.csv")))
        nb = np.load(self.p("nb.npy"))
        ids = nb[2 + n:]
        self.assertTrue(np.all(ids >= 0))  # walls, as the box, are not neighbours
        # The boundary is the triangle's perimeter, every face of class 2.
        self.ok(["faces", self.in2, "--kind", "boundary", "--bounds", "0,1,0,1", "--wall", "1", "1", "1",
                 "-o", self.p("b.vtp"), "-q"])
        b = read_vtp(self.p("b.vtp"))
        pts = vtk_to_numpy(b.GetPoints().GetData())
        length = 0.0
        for c in range(b.GetNumberOfCells()):
            ids = b.GetCell(c).GetPointIds()
            length += float(np.linalg.norm(pts[ids.GetId(1)] - pts[ids.GetId(0)]))
        self.assertAlmostEqual(length, 2 + math.sqrt(2), delta=1e-12)
        self.assertTrue(np.all(vtk_to_numpy(cell_array(b, "SpokeClass")) == 2))

    def test_half_cube_3d(self):
        r = self.ok(["voronoi", self.in3, "--bounds", "0", "1", "0", "1", "0", "1", "--wall", "1", "1", "1", "1.5",
                     "-o", self.p("c.vtu"), "--validate"])
        self.assertIn("inside 1 wall", r.stdout)
        self.assertIn("validation: OK", r.stdout)
        out = read_vtu(self.p("c.vtu"))
        self.assertEqual(out.GetNumberOfCells(), len(self.p3))
        self.assertEqual({out.GetCellType(c) for c in range(out.GetNumberOfCells())}, {42})  # VTK_POLYHEDRON
        self.assertAlmostEqual(float(vtk_to_numpy(cell_array(out, "Volume")).sum()), 0.5, delta=1e-12)
        # The graph lists the wall as spoke -7, a domain boundary (class 2).
        self.ok(["graph", self.in3, "--bounds", "0,1,0,1,0,1", "--wall", "1,1,1,1.5", "--csr", self.p("g.npy"),
                 "--spoke-classes", self.p("k.npy"), "-q"])
        g = np.load(self.p("g.npy"))
        n = int(g[0])
        spokes = g[2 + n:]
        k = np.load(self.p("k.npy"))
        self.assertGreater(int(np.sum(spokes == -7)), 0)
        self.assertTrue(np.all(k[spokes == -7] == 2))
        # Surface nets close on the wall (capping): every face's vertices inside it.
        lab = self.save("lab.npy", (np.linalg.norm(self.p3 - 0.5, axis=1) < 0.3).astype(np.int32))
        self.ok(["surface-nets", self.in3, "--labels", lab, "--capping", "--bounds", "0,1,0,1,0,1",
                 "--wall", "1,1,1,1.5", "-o", self.p("sn.vtp"), "-q"])
        sn = vtk_to_numpy(read_vtp(self.p("sn.vtp")).GetPoints().GetData())
        self.assertLessEqual(float(sn.sum(axis=1).max()), 1.5 + 1e-12)
        self.assertGreater(int(np.sum(np.abs(sn.sum(axis=1) - 1.5) < 1e-12)), 10)
        # bench voronoi takes walls too.
        r = self.ok(["bench", "voronoi", self.in3, "--bounds", "0,1,0,1,0,1", "--wall", "1,1,1,1.5"])
        line = json.loads(r.stdout.splitlines()[0])
        self.assertEqual(line["n"], len(self.p3))

    def test_lloyd_keeps_points_inside(self):
        self.ok(["lloyd", self.in3, "--bounds", "0,1,0,1,0,1", "--wall", "1,1,1,1.5", "--wall", "-1,0,0,0",
                 "--iterations", "3", "-o", self.p("r.npy"), "-q"])
        q = np.load(self.p("r.npy"))
        self.assertEqual(q.shape, self.p3.shape)
        self.assertTrue(inside(q, (1, 1, 1), 1.5))
        self.assertFalse(np.array_equal(q, self.p3))

    def test_points_outside_and_bad_walls(self):
        out = self.p("c.vtp")
        box = ["--bounds", "0,1,0,1"]
        self.fails(["voronoi", self.in2, "--wall", "1,1,0.5", "-o", out] + box, "lies outside wall 0")
        self.fails(["voronoi", self.in2, "--wall", "1,1,1,1", "-o", out] + box, "expected three values")
        self.fails(["voronoi", self.in3, "--wall", "1,1,1", "-o", self.p("c.vtu")], "expected four values")
        self.fails(["voronoi", self.in2, "--wall", "0,0,1", "-o", out] + box, "wall 0: its normal is zero")
        self.fails(["voronoi", self.in2, "--wall", "1", "x", "1", "-o", out] + box, "--wall: 'x' is not a number")
        self.fails(["voronoi", self.in2, "--wall", "1,1,1", "--wall", "1,0,inf", "-o", out] + box,
                   "wall 1: its offset is not finite")
        self.fails(["voronoi", self.in2, "--wall", "1,1,1", "--periodic", "xy", "-o", out] + box, "periodic")
        self.fails(["delaunay", self.in2, "--wall", "1,1,1", "-o", out] + box)
        # Dropped instead, and listed.
        r = self.ok(["voronoi", self.in2, "--wall", "1,1,0.5", "--ignore-outside", "-o", out] + box)
        outside = int(np.sum(self.p2.sum(axis=1) > 0.5))
        self.assertIn("ignored (outside)  %d (points" % outside, r.stdout)
        self.assertEqual(read_vtp(out).GetNumberOfCells(), len(self.p2) - outside)


class HullWalls(Case):
    """--hull-walls: the points' convex hull as walls (tessera::hull_walls)."""

    def test_lattice_hull_and_dilation(self):
        g = np.stack(np.meshgrid(np.arange(8.0), np.arange(8.0), indexing="ij"), -1).reshape(-1, 2)
        lat = self.save("lat.npy", g)
        r = self.ok(["voronoi", lat, "--hull-walls", "--validate", "-o", self.p("c.vtp")])
        self.assertIn("inside 4 walls", r.stdout)  # the square's 28 hull edges, merged by line
        self.assertIn("validation: OK", r.stdout)
        area = vtk_to_numpy(cell_array(read_vtp(self.p("c.vtp")), "Area"))
        self.assertEqual(float(area.sum()), 49.0)  # exactly: the walls pass through the lattice's border
        # Dilated by 0.5: the square of side 8, the default box grown to hold it.
        r = self.ok(["voronoi", lat, "--hull-walls", "--hull-dilation", "0.5", "-o", self.p("d.vtp"), "-q"])
        area = vtk_to_numpy(cell_array(read_vtp(self.p("d.vtp")), "Area"))
        self.assertAlmostEqual(float(area.sum()), 64.0, delta=1e-12)
        # Points in a ball: many walls, every cell inside the hull, sum = the hull's volume.
        rng = np.random.default_rng(3)
        b = rng.normal(size=(3000, 3))
        b *= (rng.random((3000, 1)) ** (1 / 3)) / np.linalg.norm(b, axis=1)[:, None]
        ball = self.save("ball.npy", b)
        r = self.ok(["voronoi", ball, "--hull-walls", "--validate", "-o", self.p("b.vtu")])
        self.assertIn("validation: OK", r.stdout)
        self.assertRegex(r.stdout, r"inside \d{3,} walls")
        self.ok(["graph", ball, "--hull-walls", "-o", self.p("g.vtp"), "-q"])

    def test_refusals(self):
        flat = self.save("flat.npy", np.array([[0.0, 0, 0], [1, 0, 1], [0, 1, 1], [1, 1, 2], [0.5, 0.25, 0.75]]))
        self.fails(["voronoi", flat, "--hull-walls", "-o", self.p("c.vtu")], "--hull-walls: ")
        self.fails(["voronoi", self.save("p.npy", np.random.default_rng(1).random((20, 2))), "--hull-dilation",
                    "0.5", "-o", self.p("c.vtp")], "--hull-dilation requires --hull-walls")
        self.fails(["voronoi", self.save("q.npy", np.random.default_rng(1).random((20, 2))), "--hull-walls",
                    "--hull-dilation", "-1", "-o", self.p("c.vtp")])


class WallsFile(Case):
    """--walls FILE: many walls from a .npy array or a text file, as --wall gives them."""

    def setUp(self):
        super().setUp()
        rng = np.random.default_rng(6)
        p = rng.random((500, 2))
        self.in2 = self.save("p2.npy", p[p.sum(axis=1) <= 1])

    def test_npy_and_text(self):
        # 64 planes tangent to a ball (bench/walls' polyhedron): the same cells
        # from the array as from 64 --wall options.
        k = np.arange(64) + 0.5
        z = 1 - 2 * k / 64
        a = k * np.pi * (3 - np.sqrt(5))
        n = np.stack([np.sqrt(1 - z * z) * np.cos(a), np.sqrt(1 - z * z) * np.sin(a), z], axis=1)
        walls = np.hstack([n, (0.45 + n @ np.array([0.5, 0.5, 0.5]))[:, None]])
        rng = np.random.default_rng(7)
        p = rng.random((6000, 3))
        p = p[np.all(p @ walls[:, :3].T <= walls[:, 3] - 1e-12, axis=1)]
        pts = self.save("p3.npy", p)
        box = ["--bounds", "0,1,0,1,0,1"]
        args = [w for row in walls for w in ("--wall", ",".join(repr(float(x)) for x in row))]
        self.ok(["voronoi", pts, "--cell-table", self.p("a.csv"), "-q"] + box + args)
        r = self.ok(["voronoi", pts, "--walls", self.save("w.npy", walls), "--cell-table", self.p("b.csv"),
                     "--validate"] + box)
        self.assertIn("inside 64 walls", r.stdout)
        self.assertIn("validation: OK", r.stdout)
        self.assertEqual(read_bytes(self.p("a.csv")), read_bytes(self.p("b.csv")))
        # One wall as a 1-D array.
        r = self.ok(["voronoi", pts, "--walls", self.save("one.npy", np.array([1.0, 1, 1, 3])), "-o",
                     self.p("c.vtu")] + box)
        self.assertIn("inside 1 wall\n", r.stdout)
        # Text: comments, blank lines, commas and spaces, with --wall beside it.
        with open(self.p("w.txt"), "w") as f:
            f.write("# nx ny d\n\n1, 1, 1\n\t-1 0 0\n")
        r = self.ok(["voronoi", self.in2, "--bounds", "0,1,0,1", "--walls", self.p("w.txt"), "--wall", "0,-1,0",
                     "--cell-table", self.p("t.csv")])
        self.assertIn("inside 3 walls", r.stdout)
        area = np.loadtxt(self.p("t.csv"), delimiter=",", skiprows=1)[:, 2]
        self.assertAlmostEqual(float(area.sum()), 0.5, delta=1e-12)
        self.ok(["graph", self.in2, "--bounds", "0,1,0,1", "--walls", self.p("w.txt"), "-o", self.p("g.vtp"), "-q"])

    def test_refusals(self):
        pts = self.in2
        out = self.p("c.vtp")
        self.fails(["voronoi", pts, "--walls", self.p("none.npy"), "-o", out], "--walls: ")
        self.fails(["voronoi", pts, "--walls", self.p("none.txt"), "-o", out], "cannot open")
        self.fails(["voronoi", pts, "--walls", self.save("w5.npy", np.ones((3, 5))), "-o", out],
                   "expected an array of shape (k, 3) or (k, 4)")
        self.fails(["voronoi", pts, "--walls", self.save("w4.npy", np.ones((3, 4))), "-o", out],
                   "expected three values, NX NY D, for 2D points")
        for name, text, says in [("e.txt", "# nothing\n", "no walls in the file"),
                                 ("b.txt", "1 1 1\n1 x 1\n", "line 2: 'x' is not a finite number"),
                                 ("c.txt", "1 1 1 # a comment after a wall\n", "line 1: '#' is not a finite number"),
                                 ("n.txt", "1 1 1\n1 1\n", "line 2: 2 values"),
                                 ("i.txt", "1 1 1e999\n", "beyond double's range"),
                                 ("z.txt", "0 0 1\n", "its normal is zero")]:
            with open(self.p(name), "w") as f:
                f.write(text)
            self.fails(["voronoi", pts, "--walls", self.p(name), "-o", out], says)
        with open(self.p("w.csv"), "w") as f:
            f.write("1 1 1\n")
        self.fails(["voronoi", pts, "--walls", self.p("w.csv"), "--cell-table", self.p("w.csv")], "--walls")


def main():
    return base.cli_main("test_walls_cli.py", [(base.vtk is not None, "python3-vtk9 is required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
