#!/usr/bin/python3
"""End-to-end tests of `tessera joggle`, `tessera fill`, `tessera threshold` and `tessera lloyd`.

Usage: /usr/bin/python3 tests/cli/test_prep_cli.py PATH_TO_tessera [unittest args...]

Every output is read back: .npy with numpy, .ply with a small numpy parser
here, .vtp through VTK's XML reader. Results are checked on hand-checkable
inputs; bad input: exit 2, one error line, nothing written. Shares its
helpers with test_cli.py.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli as base  # noqa: E402  (helpers only; its test classes are not collected here)
from test_cli import read_vtp, read_bytes, read_ply, run_bytes  # noqa: E402

from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

run = base.run


class Case(base.TempDirCase):
    def fails(self, args, fragment=None):
        before = set(os.listdir(self.dir))
        r = run(args)
        after = set(os.listdir(self.dir))
        cmd = "tessera " + " ".join(map(str, args))
        self.assertEqual(r.returncode, 2, "%s: exit %d\nstdout: %s\nstderr: %s" % (cmd, r.returncode, r.stdout, r.stderr))
        lines = r.stderr.splitlines()
        self.assertEqual(len(lines), 1, "%s: stderr must be one line, got %r" % (cmd, r.stderr))
        self.assertTrue(lines[0].startswith("tessera: error: "), "%s: %r" % (cmd, lines[0]))
        if fragment:
            self.assertIn(fragment, lines[0], cmd)
        self.assertEqual(after - before, set(), "%s left files behind" % cmd)
        self.assertEqual(r.stdout, "")
        return lines[0]


class Joggle(Case):
    def setUp(self):
        super().setUp()
        self.pts = np.random.default_rng(3).random((2000, 3))
        self.inp = self.save("pts.npy", self.pts)

    def test_within_radius_deterministic_and_labels_carried(self):
        labels = self.save("lab.npy", np.arange(2000, dtype=np.int32) % 3)
        r = self.ok(["joggle", self.inp, "--labels", labels, "--radius", "0.01", "--absolute", "--seed", "7",
                     "-o", self.p("j.npy")])
        self.assertEqual(len(r.stdout.splitlines()), 1, r.stdout)
        self.assertIn("tessera joggle: 2000 points (3D)", r.stdout)
        q = np.load(self.p("j.npy"))
        self.assertEqual(q.shape, (2000, 3))
        d = np.linalg.norm(q - self.pts, axis=1)
        self.assertTrue(np.all(d <= 0.01 * (1 + 1e-12)))
        self.assertGreater(d.min(), 0)
        self.assertTrue(np.array_equal(np.load(self.p("j_labels.npy")), np.load(labels)))
        self.ok(["joggle", self.inp, "--labels", labels, "--radius", "0.01", "--absolute", "--seed", "7",
                 "--threads", "1", "-o", self.p("k.npy"), "-q"])
        self.assertEqual(read_bytes(self.p("j.npy")), read_bytes(self.p("k.npy")))

    def test_relative_radius(self):
        self.ok(["joggle", self.inp, "-o", self.p("j.npy")])
        q = np.load(self.p("j.npy"))
        diag = np.linalg.norm(self.pts.max(0) - self.pts.min(0))
        self.assertTrue(np.all(np.linalg.norm(q - self.pts, axis=1) <= 1e-4 * diag * (1 + 1e-9)))

    def test_mask_and_plane_mode(self):
        mask = self.save("mask.npy", (np.arange(2000) % 2 == 0))
        self.ok(["joggle", self.inp, "--mask", mask, "--mode", "xy", "--radius", "0.1", "-o", self.p("j.ply")])
        v = read_ply(self.p("j.ply"))
        q = np.stack([v["x"], v["y"], v["z"]], axis=1)
        moved = np.any(q != self.pts, axis=1)
        self.assertTrue(np.array_equal(moved, np.arange(2000) % 2 == 0))
        self.assertTrue(np.array_equal(q[1::2], self.pts[1::2]))  # bit for bit
        self.assertTrue(np.array_equal(q[:, 2], self.pts[:, 2]))  # xy mode keeps z

    def test_bad_input(self):
        out = self.p("j.npy")
        self.fails(["joggle", self.p("nope.npy"), "-o", out], "nope.npy")
        self.fails(["joggle", self.inp, "-o", self.p("j.txt")], ".npy, .ply or .vtp")
        self.fails(["joggle", self.inp, "--radius", "-1", "-o", out])
        self.fails(["joggle", self.inp, "--mode", "zz", "-o", out])
        self.fails(["joggle", self.inp, "--mask", self.save("m.npy", np.ones(5, np.uint8)), "-o", out], "mask")
        self.fails(["joggle", self.inp, "--dim", "2", "--mode", "xz", "-o", out], "3D")
        self.fails(["joggle", self.inp])
        self.fails(["joggle", self.inp, "-o", self.p("missing/j.npy")], "missing")


class Fill(Case):
    def test_uniform_by_hand_2d(self):
        inp = self.save("p.npy", np.array([[0.1, 0.1], [0.9, 0.9]]))
        r = self.ok(["fill", inp, "--bin-points", "0.5", "--bounds", "0,1,0,1", "-o", self.p("f.npy")])
        self.assertIn("2 background points added", r.stdout)
        q = np.load(self.p("f.npy"))
        self.assertTrue(np.array_equal(q, [[0.1, 0.1], [0.9, 0.9], [0.75, 0.25], [0.25, 0.75]]))
        # --bounds as voronoi's: spaced words too, before or after INPUT.
        for args in (["fill", inp, "--bounds", "0", "1", "0", "1"], ["fill", "--bounds", "0", "1", "0", "1", inp]):
            self.ok(args + ["--bin-points", "0.5", "-o", self.p("g.npy")])
            self.assertTrue(np.array_equal(np.load(self.p("g.npy")), q))
        self.assertTrue(np.array_equal(np.load(self.p("f_labels.npy")), [0, 0, -1, -1]))

    def test_labels_vtp_and_concave_voronoi(self):
        # An L-shaped cloud: filling the notch with outside points makes the cells concave.
        g = np.linspace(0.025, 0.975, 20)
        xx, yy = np.meshgrid(g, g)
        pts = np.stack([xx.ravel(), yy.ravel()], axis=1)
        pts = pts[~((pts[:, 0] > 0.5) & (pts[:, 1] > 0.5))]
        inp = self.save("l.npy", pts)
        lab = self.save("l_lab.npy", np.full(len(pts), 3, np.int32))
        self.ok(["fill", inp, "--labels", lab, "--background-label", "-9", "--bin-points", "4",
                 "--bounds", "0,1,0,1", "-o", self.p("f.vtp")])
        pd = read_vtp(self.p("f.vtp"))
        n = pd.GetNumberOfPoints()
        self.assertGreater(n, len(pts))
        self.assertEqual(pd.GetNumberOfVerts(), n)
        xyz = vtk_to_numpy(pd.GetPoints().GetData())
        self.assertTrue(np.array_equal(xyz[:len(pts), :2], pts))
        self.assertTrue(np.all(xyz[:, 2] == 0))
        labels = vtk_to_numpy(pd.GetPointData().GetArray("label"))
        self.assertTrue(np.all(labels[:len(pts)] == 3) and np.all(labels[len(pts):] == -9))
        added = xyz[len(pts):, :2]
        self.assertTrue(np.all((added[:, 0] > 0.5) & (added[:, 1] > 0.5)))  # only in the empty notch
        # The filled cloud tessellates with the notch carved out.
        self.ok(["fill", inp, "--labels", lab, "--bin-points", "4", "--bounds", "0,1,0,1", "-o", self.p("f.npy")])
        self.ok(["voronoi", self.p("f.npy"), "--labels", self.p("f_labels.npy"), "--bounds", "0", "1", "0", "1",
                 "--cell-table", self.p("cells.csv")])
        table = np.genfromtxt(self.p("cells.csv"), delimiter=",", names=True)
        self.assertAlmostEqual(table["area"].sum(), 0.75, delta=0.05)

    def test_adaptive_3d_ply(self):
        rng = np.random.default_rng(4)
        pts = rng.normal(0.5, 0.05, (3000, 3)).clip(0.01, 0.99)
        inp = self.save("b.npy", pts)
        self.ok(["fill", inp, "--strategy", "adaptive", "--bounds", "0,1,0,1,0,1", "--bin-points", "0.5",
                 "--seed", "2", "-o", self.p("a.ply")])
        v = read_ply(self.p("a.ply"))
        self.assertTrue(np.array_equal(np.stack([v["x"], v["y"], v["z"]], 1)[:3000], pts))
        self.assertTrue(np.all(v["label"][:3000] == 0) and np.all(v["label"][3000:] == -1))
        self.assertGreater(len(v), 3000)
        self.ok(["fill", inp, "--strategy", "adaptive", "--bounds", "0,1,0,1,0,1", "--bin-points", "0.5",
                 "--seed", "2", "--threads", "1", "-o", self.p("b.ply"), "-q"])
        self.assertEqual(read_bytes(self.p("a.ply")), read_bytes(self.p("b.ply")))

    def test_bad_input(self):
        inp = self.save("p.npy", np.array([[0.1, 0.1], [0.9, 0.9]]))
        out = self.p("f.npy")
        self.fails(["fill", inp, "--background-label", "0", "-o", out], "background")
        self.fails(["fill", inp, "--bin-points", "0", "-o", out], "bin-points")
        self.fails(["fill", inp, "--joggle", "0.7", "-o", out], "joggle")
        self.fails(["fill", inp, "--bounds", "0,1,0", "-o", out], "bounds")
        self.fails(["fill", inp, "--bounds", "0,1,0,1,0,1", "-o", out], "2D")
        self.fails(["fill", inp, "--bounds", "0,0.5,0,1", "-o", out], "outside")
        self.fails(["fill", inp, "--bounds", "0,a,0,1", "-o", out], "'a'")
        self.fails(["fill", inp, "--strategy", "random", "-o", out])
        self.fails(["fill", "--bounds", "0", "1", "0", "1", "-o", out], "INPUT is required")
        self.fails(["fill", "--bounds", "0", "1", "0", "1", "0", inp, "-o", out], "got 5 numbers")
        self.fails(["fill", self.save("flat.npy", np.array([[0.0, 1.0], [1.0, 1.0]])), "-o", out], "y =")


class Threshold(Case):
    def test_npy_scalars_intervals(self):
        inp = self.save("p.npy", np.arange(12, dtype=float).reshape(6, 2))
        s = self.save("s.npy", np.array([-1.0, 0.0, 0.5, 1.0, np.nan, 2.0]))
        r = self.ok(["threshold", inp, "--scalars", s, "--interval", "1,2,20", "--interval", "0,1,10",
                     "-o", self.p("t.npy")])
        self.assertIn("background -1: 3", r.stdout)
        self.assertTrue(np.array_equal(np.load(self.p("t_labels.npy")), [-1, 10, 10, 20, -1, -1]))
        self.assertTrue(np.array_equal(np.load(self.p("t.npy")), np.load(inp)))
        self.assertEqual(sorted(os.listdir(self.dir)), ["p.npy", "s.npy", "t.npy", "t_labels.npy"])

    def test_ply_property_and_csv_column(self):
        # A .ply with a float32 scalar property, as other tools write them.
        xyz = np.random.default_rng(5).random((50, 3))
        val = np.linspace(-1, 1, 50)
        header = ("ply\nformat binary_little_endian 1.0\nelement vertex 50\nproperty double x\nproperty double y\n"
                  "property double z\nproperty float value\nend_header\n").encode()
        rec = np.zeros(50, dtype=[("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("value", "<f4")])
        rec["x"], rec["y"], rec["z"], rec["value"] = xyz[:, 0], xyz[:, 1], xyz[:, 2], val
        with open(self.p("v.ply"), "wb") as f:
            f.write(header + rec.tobytes())
        self.ok(["threshold", self.p("v.ply"), "--scalars", "value", "--interval", "-inf,0,1", "--interval", "0,inf,2",
                 "--background-label", "-3", "-o", self.p("t.vtp")])
        pd = read_vtp(self.p("t.vtp"))
        labels = vtk_to_numpy(pd.GetPointData().GetArray("label"))
        v32 = val.astype(np.float32).astype(float)
        self.assertTrue(np.array_equal(labels, np.where(v32 < 0, 1, 2)))
        self.assertTrue(np.array_equal(vtk_to_numpy(pd.GetPointData().GetArray("scalars")), v32))
        with open(self.p("c.csv"), "w") as f:
            f.write("x,y,t\n")
            for i in range(10):
                f.write("%d,%d,%g\n" % (i, i % 3, i / 10))
        self.ok(["threshold", self.p("c.csv"), "--dim", "2", "--scalars", "t", "--interval", "0.3,0.6,1",
                 "-o", self.p("c.ply")])
        v = read_ply(self.p("c.ply"))
        self.assertTrue(np.array_equal(v["label"], [-1, -1, -1, 1, 1, 1, -1, -1, -1, -1]))
        self.assertTrue(np.all(v["z"] == 0))

    def test_bad_input(self):
        inp = self.save("p.npy", np.arange(12, dtype=float).reshape(6, 2))
        s = self.save("s.npy", np.zeros(6))
        out = self.p("t.npy")
        self.fails(["threshold", inp, "--scalars", s, "--interval", "0,2,1", "--interval", "1,3,2", "-o", out],
                   "overlap")
        self.fails(["threshold", inp, "--scalars", s, "--interval", "2,1,1", "-o", out], "lo < hi")
        self.fails(["threshold", inp, "--scalars", s, "--interval", "0,1", "-o", out], "lo,hi,label")
        self.fails(["threshold", inp, "--scalars", s, "--interval", "0,1,x", "-o", out], "label")
        self.fails(["threshold", inp, "--scalars", s, "--interval", "nan,1,1", "-o", out])
        self.fails(["threshold", inp, "--scalars", self.save("s5.npy", np.zeros(5)), "--interval", "0,1,1",
                    "-o", out], "5 values for 6 points")
        self.fails(["threshold", inp, "--scalars", "value", "--interval", "0,1,1", "-o", out], "property")
        self.fails(["threshold", inp, "--interval", "0,1,1", "-o", out], "scalars")
        self.fails(["threshold", inp, "--scalars", s, "-o", out], "interval")


class NonFinite(Case):
    """An organized cloud (PCL's .pcd, NaN rows for missing returns) through
    the point tools with --keep-non-finite, then `voronoi --ignore-outside`:
    the missing points keep their ids and bits and take no part."""

    def setUp(self):
        super().setUp()
        rng = np.random.default_rng(8)
        self.pts = rng.random((1200, 3))
        self.intensity = rng.random(1200)
        self.missing = np.arange(5, 1200, 9)
        pts = self.pts.copy()
        pts[self.missing] = np.nan
        pts[self.missing[::4], 1] = 0.5  # some rows only partly missing
        self.pcd = self.p("organized.pcd")
        with open(self.pcd, "w") as f:
            f.write("VERSION .7\nFIELDS x y z intensity\nSIZE 8 8 8 8\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 40\n"
                    "HEIGHT 30\nPOINTS 1200\nDATA ascii\n")
            for p, s in zip(pts, self.intensity):
                f.write("%.17g %.17g %.17g %.17g\n" % (p[0], p[1], p[2], s))
        self.kept = np.setdiff1d(np.arange(1200), self.missing)

    def test_refused_without_the_flag(self):
        for cmd in (["joggle"], ["fill"], ["threshold", "--scalars", "intensity", "--interval", "0,1,1"]):
            self.fails(cmd + [self.pcd, "-o", self.p("o.npy")], "--keep-non-finite")
        img = self.save("img.npy", np.zeros((4, 4, 4)))
        self.fails(["probe", img, self.pcd, "-o", self.p("v.npy")], "--keep-non-finite")

    def test_joggle_fill_threshold_then_voronoi(self):
        n_missing = len(self.missing)
        r = self.ok(["joggle", self.pcd, "--keep-non-finite", "--radius", "1e-3", "-o", self.p("j.npy")])
        self.assertIn("%d moved" % (1200 - n_missing), r.stdout)
        self.assertIn("%d with a non-finite coordinate kept in place" % n_missing, r.stdout)
        j = np.load(self.p("j.npy"))
        raw = np.loadtxt(self.pcd, skiprows=9)[:, :3]
        lost = ~np.all(np.isfinite(raw), axis=1)
        self.assertTrue(np.array_equal(np.flatnonzero(lost), self.missing))
        self.assertTrue(np.array_equal(j[lost], raw[lost], equal_nan=True))  # copied through
        self.assertTrue(np.all(j[~lost] != raw[~lost]))

        # fill: the points first, then the finite points' background points.
        r = self.ok(["fill", self.p("j.npy"), "--keep-non-finite", "-o", self.p("f.npy")])
        self.assertIn("%d with a non-finite coordinate kept in place" % n_missing, r.stdout)
        f = np.load(self.p("f.npy"))
        self.ok(["fill", self.save("jk.npy", j[~lost]), "-o", self.p("fk.npy"), "-q"])
        fk = np.load(self.p("fk.npy"))
        self.assertTrue(np.array_equal(f[:1200], j, equal_nan=True))
        self.assertTrue(np.array_equal(f[1200:], fk[len(self.kept):]))

        # threshold: labels from the scalars, every row kept.
        self.ok(["threshold", self.pcd, "--keep-non-finite", "--scalars", "intensity", "--interval", "0,0.5,1",
                 "--interval", "0.5,1,2", "-o", self.p("t.npy"), "-q"])
        lab = np.load(self.p("t_labels.npy"))
        self.assertTrue(np.array_equal(lab, np.where(self.intensity < 0.5, 1, 2)))

        # voronoi of the filled cloud: the missing points set aside, the
        # cells those of the finite pipeline, under the input's ids.
        t = self.p("cells.csv")
        r = self.ok(["voronoi", self.p("f.npy"), "--labels", self.p("f_labels.npy"), "--ignore-outside",
                     "--cell-table", t])
        self.assertIn("ignored (outside)  %d" % n_missing, r.stdout)
        ref = self.p("ref.csv")
        self.ok(["voronoi", self.p("fk.npy"), "--labels", self.p("fk_labels.npy"), "--cell-table", ref, "-q"])
        a = np.loadtxt(t, delimiter=",", skiprows=1)
        b = np.loadtxt(ref, delimiter=",", skiprows=1)
        self.assertTrue(np.array_equal(a[:, 0], self.kept))
        self.assertTrue(np.array_equal(a[:, 1:], b[:, 1:]))

    def test_probe_counts_them_outside(self):
        img = self.save("img.npy", np.arange(64, dtype=float).reshape(4, 4, 4))
        r = self.ok(["probe", img, self.pcd, "--keep-non-finite", "--outside-value", "-1", "-o", self.p("v.npy")])
        self.assertIn("(%d inside, %d outside)" % (len(self.kept), len(self.missing)), r.stdout)
        v = np.load(self.p("v.npy"))
        self.assertTrue(np.all(v[self.missing] == -1))
        # The others lie in [0, 1]^3, inside the voxel-centre box [0, 3]^3.
        self.assertTrue(np.all(v[self.kept] >= 0))


class Lloyd(Case):
    def setUp(self):
        super().setUp()
        self.pts = np.random.default_rng(4).random((400, 3))
        self.inp = self.save("pts.npy", self.pts)

    def files(self):
        return sorted(os.listdir(self.dir))

    def test_one_iteration_is_the_cells_centroids(self):
        # The moved points are the centroids `voronoi --cell-table` reports,
        # bit for bit; the summary says what ran.
        box = ["--bounds", "0", "1", "0", "1", "0", "1"]
        r = self.ok(["lloyd", self.inp, "--iterations", "1", "-o", self.p("r.npy")] + box)
        self.assertIn("tessera lloyd: 400 points (3D) from", r.stdout)
        self.assertIn("iterations         1 of 1\n", r.stdout)
        self.assertIn("moved              400 in every iteration", r.stdout)
        self.assertIn("domain             [0, 1] x [0, 1] x [0, 1]", r.stdout)
        self.assertEqual(r.stderr, "")
        self.ok(["voronoi", self.inp, "--cell-table", self.p("t.npy"), "-q"] + box)
        t = np.load(self.p("t.npy"))
        q = np.load(self.p("r.npy"))
        self.assertTrue(np.array_equal(q[t[:, 0].astype(int)], t[:, 3:6]))
        # Nothing but the output was written (atomically: no temporaries left).
        self.assertEqual(self.files(), ["pts.npy", "r.npy", "t.npy"])

    def test_labels_radii_formats_and_the_fixed_domain(self):
        labels = np.where(np.arange(400) % 10 == 0, -1, 2).astype(np.int32)
        lab = self.save("lab.npy", labels)
        radii = self.save("rad.npy", np.random.default_rng(5).random(400) * 0.05)
        r = self.ok(["lloyd", self.inp, "--labels", lab, "--radii", radii, "--iterations", "4", "-o",
                     self.p("r.ply")])
        self.assertIn("moved              360 in every iteration", r.stdout)
        self.assertIn("power cells", r.stdout)
        v = read_ply(self.p("r.ply"))
        q = np.stack([v["x"], v["y"], v["z"]], axis=1)
        self.assertTrue(np.array_equal(v["label"], labels))
        self.assertTrue(np.array_equal(v["radius"], np.load(radii)))
        self.assertTrue(np.array_equal(q[labels < 0], self.pts[labels < 0]))  # outside points stay
        self.assertFalse(np.any(np.all(q[labels >= 0] == self.pts[labels >= 0], axis=1)))
        # The same iterations from the .npy, and as .vtp; the default domain
        # is the first iteration's, so giving it as --bounds changes nothing.
        dom = [w.strip("[],") for w in r.stdout.split("domain             ")[1].split("(")[0].split()
               if w != "x"]
        self.ok(["lloyd", self.inp, "--labels", lab, "--radii", radii, "--iterations", "4", "-q", "-o",
                 self.p("r.npy")])
        self.assertTrue(np.array_equal(np.load(self.p("r.npy")), q))
        self.assertTrue(np.array_equal(np.load(self.p("r_labels.npy")), labels))
        self.ok(["lloyd", self.inp, "--labels", lab, "--radii", radii, "--iterations", "4", "-q", "-o",
                 self.p("b.vtp"), "--bounds"] + dom)
        pd = read_vtp(self.p("b.vtp"))
        self.assertTrue(np.array_equal(vtk_to_numpy(pd.GetPoints().GetData()), q))
        self.assertTrue(np.array_equal(vtk_to_numpy(pd.GetPointData().GetArray("label")), labels))
        # 2D: z = 0 in the .ply, read back with --dim 2.
        two = self.save("p2.npy", self.pts[:, :2])
        self.ok(["lloyd", two, "--iterations", "2", "-q", "-o", self.p("r2.ply")])
        v2 = read_ply(self.p("r2.ply"))
        self.assertTrue(np.all(v2["z"] == 0))
        self.ok(["lloyd", self.p("r2.ply"), "--dim", "2", "--iterations", "0", "-q", "-o", self.p("same.npy")])
        self.assertTrue(np.array_equal(np.load(self.p("same.npy")), np.stack([v2["x"], v2["y"]], axis=1)))

    def test_tolerance_threads_periodic_and_stdout(self):
        r = self.ok(["lloyd", self.inp, "--iterations", "1000", "--tolerance", "0.03", "-o", self.p("a.npy")])
        done = int(r.stdout.split("iterations         ")[1].split()[0])
        self.assertGreater(done, 1)
        self.assertLess(done, 1000)
        self.assertIn("of 1000 (stopped: the largest displacement is within --tolerance 0.03", r.stdout)
        q = self.ok(["lloyd", self.inp, "--iterations", str(done), "--threads", "1", "-o", self.p("b.npy"), "-q"])
        self.assertEqual(q.stdout, "")
        self.assertEqual(read_bytes(self.p("a.npy")), read_bytes(self.p("b.npy")))
        # Periodic: points given periods away come back in the box.
        far = self.save("far.npy", self.pts + [3.0, -1.0, 0.0])
        r = self.ok(["lloyd", far, "--bounds", "0", "1", "0", "1", "0", "1", "--periodic", "xy", "--iterations", "3",
                     "-o", self.p("per.npy")])
        self.assertIn("periodic           xy", r.stdout)
        per = np.load(self.p("per.npy"))
        self.assertTrue(np.all((per >= 0) & (per <= 1)) and np.all(per[:, :2] < 1))
        # Standard output: the .ply, the summary on standard error.
        self.ok(["lloyd", self.inp, "--iterations", "2", "-o", self.p("s.ply"), "-q"])
        out = run_bytes(["lloyd", self.inp, "--iterations", "2", "-o", "-"])
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn(b"wrote              stdout", out.stderr)
        self.assertEqual(out.stdout, read_bytes(self.p("s.ply")))

    def test_help(self):
        r = self.ok(["lloyd", "--help"])
        for opt in ("INPUT", "--output", "--iterations", "--tolerance", "--dim", "--labels", "--bounds", "--padding",
                    "--ignore-outside", "--periodic", "--tilt", "--radii", "--method", "--threads", "--frame",
                    "--quiet", "Examples:", "tessera lloyd points.npy"):
            self.assertIn(opt, r.stdout)
        self.assertIn("lloyd", run(["--help"]).stdout)

    def test_bad_input(self):
        out = self.p("r.npy")
        self.fails(["lloyd", self.inp, "--iterations", "-1", "-o", out], "--iterations")
        self.fails(["lloyd", self.inp, "--iterations", "2.5", "-o", out], "--iterations")
        self.fails(["lloyd", self.inp, "--tolerance", "-1", "-o", out], "--tolerance")
        self.fails(["lloyd", self.inp, "--tolerance", "nan", "-o", out], "--tolerance")
        self.fails(["lloyd", self.inp, "-o", self.p("r.txt")], ".npy, .ply or .vtp")
        self.fails(["lloyd", self.inp])
        self.fails(["lloyd", self.p("nope.npy"), "-o", out], "nope.npy")
        self.fails(["lloyd", self.inp, "-o", self.p("missing/r.npy")], "missing")
        self.fails(["lloyd", self.inp, "--periodic", "xyz", "-o", out], "--bounds")
        self.fails(["lloyd", self.inp, "--bounds", "0", "0.5", "0", "1", "0", "1", "-o", out], "outside the bounds")
        self.fails(["lloyd", self.inp, "--radii", self.save("r5.npy", np.ones(5)), "-o", out], "--radii")
        self.fails(["lloyd", self.inp, "--labels", self.save("l5.npy", np.zeros(5, np.int32)), "-o", out])
        self.fails(["lloyd", self.inp, "-o", self.inp], "the INPUT")
        # No point owns a cell: every inside point duplicates an outside one.
        dup = self.save("dup.npy", np.vstack([self.pts[:20], self.pts[:20]]))
        lab = self.save("duplab.npy", np.r_[np.full(20, -1), np.zeros(20)].astype(np.int32))
        self.fails(["lloyd", dup, "--labels", lab, "-o", out], "no cells")


def main():
    return base.cli_main("test_prep_cli.py", [(base.vtk is not None, "python3-vtk9 is required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
