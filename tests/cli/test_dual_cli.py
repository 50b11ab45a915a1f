#!/usr/bin/python3
"""End-to-end tests of `tessera graph`, `tessera faces` and `tessera flower`.

Usage: /usr/bin/python3 tests/cli/test_dual_cli.py PATH_TO_tessera [unittest args...]

Every file written is read back: .vtp through VTK's XML reader, .npy through
numpy. The graph is checked against scipy's Delaunay triangulation and the
`voronoi --neighbors` lists, face sets for completeness (counts from the graph),
closedness, orientation and enclosed volume, flowers against the cells. Bad
input: exit 2, one error line, nothing written. Shares its helpers with
test_cli.py.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import os
import sys
from collections import Counter

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli as base  # noqa: E402  (helpers only; its test classes are not collected here)
from test_cli import read_bytes, read_vtp, cell_array, cells_of  # noqa: E402

try:
    from scipy.spatial import Delaunay
except ImportError:  # pragma: no cover
    Delaunay = None

from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

run = base.run
BOX3 = base.BOX3
BOX2 = base.BOX2
SAME, REGION, DOMAIN, OUTSIDE = 0, 1, 2, 3


def load_csr(path):
    a = np.load(path)
    assert a.dtype == np.int64 and a.ndim == 1, (a.dtype, a.shape)
    n = int(a[0])
    return n, a[1:n + 2], a[n + 2:]


def surface(loops, pts, dim):
    """(unbalanced, nonmanifold, enclosed volume) of oriented faces: 3D polygons
    or 2D segments. Closed and consistently oriented iff unbalanced == 0."""
    directed = Counter()
    vol = 0.0
    o = pts.mean(axis=0)
    for l in loops:
        l = [int(x) for x in l]
        if dim == 2:
            directed[(l[0], l[1])] += 1
            a, b = pts[l[0]] - o, pts[l[1]] - o
            vol += 0.5 * (a[0] * b[1] - a[1] * b[0])
        else:
            for t in range(len(l)):
                directed[(l[t], l[(t + 1) % len(l)])] += 1
            p = pts[l] - o
            vol += np.dot(p[0], np.cross(p[1:-1], p[2:]).sum(axis=0)) / 6.0
    unbalanced = nonmanifold = 0
    if dim == 3:
        for (a, b), k in directed.items():
            if directed.get((b, a), 0) != k:
                unbalanced += 1
            if a < b and (k != 1 or directed.get((b, a), 0) != 1):
                nonmanifold += 1
    else:
        inn, out = Counter(), Counter()
        for (a, b), k in directed.items():
            out[a] += k
            inn[b] += k
        for v in set(inn) | set(out):
            unbalanced += inn[v] != out[v]
            nonmanifold += inn[v] != 1 or out[v] != 1
    return unbalanced, nonmanifold, vol


class Graph(base.TempDirCase):
    def graph(self, pts, extra=(), labels=None):
        inp = self.save("pts.npy", pts)
        out, csr, cls = self.p("g.vtp"), self.p("g.npy"), self.p("c.npy")
        args = ["graph", inp, "-o", out, "--csr", csr, "--spoke-classes", cls, "-q"] + list(extra)
        if labels is not None:
            args += ["--labels", self.save("labels.npy", labels)]
        self.ok(args)
        return read_vtp(out), load_csr(csr), np.load(cls)

    def check_graph(self, pts, pd, csr, cls, labels=None):
        n, off, ids = csr
        self.assertEqual(n, len(pts))
        self.assertEqual(cls.dtype, np.uint8)
        self.assertEqual(len(cls), len(ids))
        self.assertEqual(off[0], 0)
        self.assertEqual(off[-1], len(ids))
        # Points are the input points; lines are the undirected edges.
        np.testing.assert_array_equal(vtk_to_numpy(pd.GetPoints().GetData())[:, :pts.shape[1]], pts)
        spokes = {}
        for i in range(n):
            w = ids[off[i]:off[i + 1]]
            self.assertTrue(np.all(np.diff(w) > 0), "wheel must be ascending")
            for j, c in zip(w, cls[off[i]:off[i + 1]]):
                spokes[(i, int(j))] = int(c)
        edges = set()
        for (i, j), c in spokes.items():
            if j < 0:
                self.assertEqual(c, DOMAIN)
            elif c == OUTSIDE:
                self.assertTrue(labels is not None and labels[j] < 0)
                edges.add((i, j))
            else:
                self.assertEqual(spokes.get((j, i)), c, "spoke %d->%d has no twin of its class" % (i, j))
                self.assertEqual(c, SAME if labels is None or labels[i] == labels[j] else REGION)
                if i < j:
                    edges.add((i, j))
        lines = cells_of(pd.GetLines())
        self.assertEqual(len(lines), len(edges))
        got = {(int(l[0]), int(l[1])) for l in lines}
        self.assertEqual(got, edges)
        line_cls = vtk_to_numpy(cell_array(pd, "SpokeClass"))
        self.assertEqual([int(c) for c in line_cls], [spokes[(int(l[0]), int(l[1]))] for l in lines])
        name = "FaceArea" if pts.shape[1] == 3 else "FaceLength"
        self.assertTrue(np.all(vtk_to_numpy(cell_array(pd, name)) > 0))
        return spokes, edges

    def test_graph_3d_matches_neighbors_and_delaunay(self):
        pts = np.random.default_rng(21).random((800, 3))
        pd, csr, cls = self.graph(pts)
        spokes, edges = self.check_graph(pts, pd, csr, cls)
        # Same neighbours as `voronoi --neighbors` (which leaves out box faces).
        nb = self.p("nb.npy")
        self.ok(["voronoi", self.p("pts.npy"), "--neighbors", nb, "-q"])
        n, off, ids = base.load_neighbors(nb)
        want = {(i, int(j)) for i in range(n) for j in ids[off[i]:off[i + 1]]}
        self.assertEqual({k for k in spokes if k[1] >= 0}, want)
        # Every edge is a Delaunay edge (general position); nearly all Delaunay
        # edges are edges (the rest belong to thin hull simplices whose Voronoi
        # vertices lie outside the padded box).
        tri = Delaunay(pts)
        dt = set()
        for s in tri.simplices:
            for a in range(4):
                for b in range(a + 1, 4):
                    dt.add((min(s[a], s[b]), max(s[a], s[b])))
        self.assertTrue(edges <= dt, "graph edges that are not Delaunay edges: %s" % sorted(edges - dt)[:5])
        self.assertGreater(len(edges), 0.85 * len(dt))

    def test_graph_2d_with_labels(self):
        pts = np.random.default_rng(22).random((1000, 2))
        labels = np.random.default_rng(23).integers(-1, 3, len(pts)).astype(np.int32)
        pd, csr, cls = self.graph(pts, labels=labels)
        spokes, _ = self.check_graph(pts, pd, csr, cls, labels)
        self.assertEqual(set(spokes.values()), {SAME, REGION, DOMAIN, OUTSIDE})
        n, off, _ = csr
        self.assertTrue(np.all(np.diff(off)[labels < 0] == 0), "outside points have empty wheels")
        np.testing.assert_array_equal(vtk_to_numpy(pd.GetPointData().GetArray("Region")), labels)

    def test_prune_tolerance(self):
        pts = np.random.default_rng(24).random((800, 3))
        _, (_, off0, ids0), _ = self.graph(pts)
        pd, csr, cls = self.graph(pts, ["--prune-tolerance", "0.05"])
        self.check_graph(pts, pd, csr, cls)  # still symmetric
        self.assertLess(len(csr[2]), len(ids0))

    def test_spoke_measures_are_the_faces_areas(self):
        # Each cell's pyramids over its faces, apex at the generator, fill it:
        # sum of measure x distance to the face's plane / D = the cell's volume
        # (the table's). Both directions of a face carry one value.
        for dim, box in ((3, BOX3), (2, BOX2)):
            pts = np.random.default_rng(26 + dim).random((600, dim))
            inp = self.save("m%d.npy" % dim, pts)
            csr, meas, table = self.p("w.npy"), self.p("m.npy"), self.p("t.csv")
            self.ok(["graph", inp, "--csr", csr, "--spoke-measures", meas, "-q", "--bounds"] + box)
            self.ok(["voronoi", inp, "--cell-table", table, "-q", "--bounds"] + box)
            n, off, ids = load_csr(csr)
            m = np.load(meas)
            self.assertEqual((m.dtype, m.shape), (np.float64, ids.shape))
            self.assertTrue(np.all(m > 0))
            vol = np.loadtxt(table, delimiter=",", skiprows=1)[:, 2]
            at = {}
            for i in range(n):
                total = 0.0
                for j, a in zip(ids[off[i]:off[i + 1]], m[off[i]:off[i + 1]]):
                    if j >= 0:
                        h = 0.5 * np.linalg.norm(pts[j] - pts[i])
                        at[(i, int(j))] = a
                    else:  # box plane -1 - 2 axis (lower), -2 - 2 axis (upper)
                        axis, upper = (-1 - j) // 2, (-1 - j) % 2
                        h = 1.0 - pts[i][axis] if upper else pts[i][axis]
                    total += a * h / dim
                self.assertAlmostEqual(total, vol[i], delta=1e-12 * vol[i] + 1e-15, msg="%dD cell %d" % (dim, i))
            for (i, j), a in at.items():
                self.assertEqual(a, at[(j, i)])

    def test_periodic_graph(self):
        # A triclinic periodic box: spokes lead to images (--spoke-shifts);
        # every spoke i -> (j, s) has its twin j -> (i, -s) with the same
        # class and measure; each cell's pyramids over its faces, apex at its
        # point, fill it (height: half the distance to the image); the VTK
        # lines to images end at extra points there, tagged with PointId.
        for dim, box, tilt in ((3, ["0", "1", "0", "1", "0", "1"], ["0.25", "0", "-0.125"]),
                               (2, ["0", "1", "0", "1"], ["0.375"])):
            vec = np.eye(dim)
            for k, (a, b) in enumerate([(0, 1), (0, 2), (1, 2)][:len(tilt)]):
                vec[b, a] = float(tilt[k])
            f = np.random.default_rng(40 + dim).random((800, dim)) * (1 - 2e-6) + 1e-6
            pts = np.ldexp(np.floor(np.ldexp(f @ vec, 30)), -30)
            inp = self.save("p%d.npy" % dim, pts)
            files = [self.p(x) for x in ("pc.npy", "ps.npy", "pm.npy", "pk.npy", "pg.vtp", "pt.csv")]
            per = ["--bounds"] + box + ["--periodic", "xyz"[:dim], "--tilt"] + tilt
            r = self.ok(["graph", inp, "--csr", files[0], "--spoke-shifts", files[1], "--spoke-measures", files[2],
                         "--spoke-classes", files[3], "-o", files[4]] + per)
            self.assertIn("triclinic", r.stdout)
            self.ok(["voronoi", inp, "--cell-table", files[5], "-q"] + per)
            n, off, ids = load_csr(files[0])
            sh, m, cls = np.load(files[1]), np.load(files[2]), np.load(files[3])
            self.assertEqual((sh.dtype, sh.shape), (np.int8, (len(ids), dim)))
            self.assertTrue(np.all(ids >= 0) and np.all(cls == SAME), "no walls, one region")
            vol = np.loadtxt(files[5], delimiter=",", skiprows=1)[:, 2]
            spoke = {}
            for i in range(n):
                total = 0.0
                for e in range(off[i], off[i + 1]):
                    j, s = int(ids[e]), tuple(int(x) for x in sh[e])
                    self.assertNotIn((i, j, s), spoke)
                    spoke[(i, j, s)] = (m[e], cls[e])
                    total += m[e] * 0.5 * np.linalg.norm(pts[j] + np.array(s) @ vec - pts[i]) / dim
                self.assertAlmostEqual(total, vol[i], delta=1e-12 * vol[i], msg="%dD cell %d" % (dim, i))
            for (i, j, s), v in spoke.items():
                self.assertEqual(spoke[(j, i, tuple(-x for x in s))], v)
            pd = read_vtp(files[4])
            xyz = vtk_to_numpy(pd.GetPoints().GetData())[:, :dim]
            pid = vtk_to_numpy(pd.GetPointData().GetArray("PointId"))
            np.testing.assert_array_equal(pid[:n], np.arange(n))
            np.testing.assert_array_equal(xyz[:n], pts)
            lines = cells_of(pd.GetLines())
            self.assertEqual(len(lines), len(spoke) // 2)
            for a, b in lines:
                self.assertTrue(a < n)
                # the line's length is the distance to the neighbour's image
                d = np.linalg.norm(xyz[b] - xyz[a])
                self.assertTrue(any(abs(d - np.linalg.norm(pts[pid[b]] + np.array(s) @ vec - pts[a])) < 1e-12
                                    for (i, j, s) in spoke if i == a and j == pid[b]))

    def test_periodic_faces(self):
        # Faces of periodic cells (x-z periodic, y walls, so both kinds of
        # side): SideShift names side 1's image; every corner of a face lies
        # on the bisector of side 0's point and that image (a wall's face on
        # its plane); the capped surface net of each region closes up when
        # copies of a vertex (the same cell corner seen from several frames)
        # are identified: each polygon edge, as a pair of corners a lattice
        # translation apart, has its reverse.
        pts = np.ldexp(np.floor(np.ldexp(np.random.default_rng(44).random((600, 3)) * (1 - 2e-6) + 1e-6, 30)), -30)
        lab = (pts[:, 0] + pts[:, 2] > 1).astype(np.int32)
        inp, labf, out = self.save("pf.npy", pts), self.save("pfl.npy", lab), self.p("pf.vtp")
        per = ["--bounds", "0", "1", "0", "1", "0", "1", "--periodic", "xz", "--labels", labf]
        for kind in ("complex", "surface-net"):
            self.ok(["faces", inp, "--kind", kind, "-o", out, "-q"] + per + (["--capping"] if kind != "complex" else []))
            pd = read_vtp(out)
            xyz = vtk_to_numpy(pd.GetPoints().GetData())
            sides = vtk_to_numpy(pd.GetCellData().GetArray("Sides")).reshape(-1, 2)
            shift = vtk_to_numpy(pd.GetCellData().GetArray("SideShift")).reshape(-1, 3)
            self.assertTrue(np.all(shift[:, 1] == 0) and np.any(shift != 0))
            polys = cells_of(pd.GetPolys())
            for f, loop in enumerate(polys):
                i, j = sides[f]
                x = xyz[loop]
                if j < 0:  # a wall: y = 0 (-3) or y = 1 (-4)
                    self.assertIn(j, (-3, -4))
                    np.testing.assert_allclose(x[:, 1], 0.0 if j == -3 else 1.0, atol=1e-15)
                    continue
                image = pts[j] + shift[f]
                np.testing.assert_allclose(np.linalg.norm(x - pts[i], axis=1), np.linalg.norm(x - image, axis=1),
                                           atol=1e-12)
            if kind == "surface-net":
                labels = vtk_to_numpy(pd.GetCellData().GetArray("BoundaryLabels")).reshape(-1, 2)
                # A corner is identified across frames by rounding it back into the box.
                key = [tuple(np.round(np.mod(p, 1.0) * 1e9).astype(np.int64) % 10**9) for p in xyz]
                for region in (0, 1):
                    edges = {}
                    for f, loop in enumerate(polys):
                        if region not in labels[f]:
                            continue
                        loop = list(loop) if labels[f][0] == region else list(reversed(loop))
                        for a, b in zip(loop, loop[1:] + loop[:1]):
                            d = tuple(np.round(xyz[b] - xyz[a], 6))
                            edges[(key[a], key[b], d)] = edges.get((key[a], key[b], d), 0) + 1
                    for (a, b, d), m in edges.items():
                        self.assertEqual(edges.get((b, a, tuple(-x + 0.0 for x in d))), m, "region %d" % region)

        # An empty periodic face set (no labels: no boundary) has the
        # SideShift array too, with no tuples (a fuzz found it missing).
        self.ok(["faces", inp, "--kind", "boundary", "-o", out, "-q", "--bounds", "0", "1", "0", "1", "0", "1",
                 "--periodic", "xyz"])
        pd = read_vtp(out)
        self.assertEqual(pd.GetNumberOfCells(), 0)
        self.assertIsNotNone(pd.GetCellData().GetArray("SideShift"))
        self.assertEqual(pd.GetCellData().GetArray("SideShift").GetNumberOfComponents(), 3)

    def test_threads_byte_identical(self):
        inp = self.save("big.npy", np.random.default_rng(25).random((5000, 3)))
        outs = []
        for th in (1, 2):
            files = [self.p("g%d.vtp" % th), self.p("g%d.npy" % th), self.p("c%d.npy" % th), self.p("m%d.npy" % th)]
            self.ok(["graph", inp, "-o", files[0], "--csr", files[1], "--spoke-classes", files[2],
                     "--spoke-measures", files[3], "--threads", th, "-q"])
            outs.append([read_bytes(f) for f in files])
        self.assertTrue(outs[0] == outs[1])


class Faces(base.TempDirCase):
    def faces(self, inp, kind, extra=()):
        out = self.p("f-%s.vtp" % kind)
        self.ok(["faces", inp, "-o", out, "--kind", kind, "-q"] + list(extra))
        pd = read_vtp(out)
        dim = 3 if pd.GetNumberOfPolys() or not pd.GetNumberOfLines() else 2
        loops = cells_of(pd.GetPolys() if dim == 3 else pd.GetLines())
        pts = vtk_to_numpy(pd.GetPoints().GetData())[:, :dim]
        labels = vtk_to_numpy(cell_array(pd, "BoundaryLabels"))
        sides = vtk_to_numpy(cell_array(pd, "Sides"))
        cls = vtk_to_numpy(cell_array(pd, "SpokeClass"))
        self.assertEqual(labels.shape, (len(loops), 2))
        self.assertEqual(sides.shape, (len(loops), 2))
        self.assertEqual(len(np.unique(pts, axis=0)), len(pts), "vertices are merged")
        used = np.zeros(len(pts), bool)
        for l in loops:
            used[l] = True
        self.assertTrue(used.all(), "every vertex is used")
        return loops, pts, labels, sides, cls

    def graph_counts(self, inp, extra=()):
        csr, cls = self.p("g.npy"), self.p("c.npy")
        self.ok(["graph", inp, "--csr", csr, "--spoke-classes", cls, "-q"] + list(extra))
        c = np.load(cls)
        return {k: int(np.sum(c == k)) for k in (SAME, REGION, DOMAIN, OUTSIDE)}

    def test_boundary_is_closed_outward_box(self):
        for dim, box in ((3, BOX3), (2, BOX2)):
            inp = self.save("p%d.npy" % dim, np.random.default_rng(30 + dim).random((700, dim)))
            loops, pts, labels, sides, cls = self.faces(inp, "boundary", ["--bounds"] + box)
            unbalanced, nonmanifold, vol = surface(loops, pts, dim)
            self.assertEqual((unbalanced, nonmanifold), (0, 0), "%dD boundary must be a closed manifold" % dim)
            self.assertAlmostEqual(vol, 1.0, delta=1e-9, msg="outward: enclosed volume = the box")
            np.testing.assert_array_equal(labels[:, 1], -1)  # background label of the box side
            self.assertTrue(np.all(sides[:, 1] < 0))
            self.assertTrue(np.all(cls == DOMAIN))

    def test_complex_has_every_face_once(self):
        pts = np.random.default_rng(33).random((700, 3))
        labels = np.random.default_rng(34).integers(-1, 3, len(pts)).astype(np.int32)
        inp, lab = self.save("p.npy", pts), self.save("l.npy", labels)
        k = self.graph_counts(inp, ["--labels", lab])
        loops, _, blabels, sides, cls = self.faces(inp, "complex", ["--labels", lab])
        self.assertEqual(len(loops), (k[SAME] + k[REGION]) // 2 + k[DOMAIN] + k[OUTSIDE])
        pairs = {(min(a, b), max(a, b)) for a, b in sides if b >= 0}
        self.assertEqual(len(pairs), int(np.sum(sides[:, 1] >= 0)), "no face twice")
        # BoundaryLabels: side 0 is a cell; between cells the lower (label, id) first.
        self.assertTrue(np.all(blabels[:, 0] >= 0))
        inner = (cls == SAME) | (cls == REGION)
        self.assertTrue(np.all((blabels[inner, 0] < blabels[inner, 1]) |
                               ((blabels[inner, 0] == blabels[inner, 1]) & (sides[inner, 0] < sides[inner, 1]))))
        np.testing.assert_array_equal(blabels[cls == OUTSIDE, 1], labels[sides[cls == OUTSIDE, 1]])
        np.testing.assert_array_equal(blabels[cls == DOMAIN, 1], -1)

    def test_surface_net_regions_closed_with_capping(self):
        for dim in (3, 2):
            pts = np.random.default_rng(35 + dim).random((1500, dim))
            labels = np.where(pts[:, 0] < 0.5, 2, 5).astype(np.int32)
            labels[(pts[:, 0] > 0.8) & (pts[:, 1] > 0.8)] = -1
            inp, lab = self.save("p.npy", pts), self.save("l.npy", labels)
            box = BOX3 if dim == 3 else BOX2
            k = self.graph_counts(inp, ["--labels", lab, "--bounds"] + box)
            loops, _, blabels, _, cls = self.faces(inp, "surface-net", ["--labels", lab, "--bounds"] + box)
            self.assertEqual(len(loops), k[REGION] // 2)
            self.assertTrue(np.all(blabels == [2, 5]), "interfaces run from the lower label to the higher")
            loops, pts_f, blabels, _, cls = self.faces(inp, "surface-net",
                                                       ["--labels", lab, "--capping", "--bounds"] + box)
            self.assertEqual(len(loops), k[REGION] // 2 + k[DOMAIN] + k[OUTSIDE])
            table = self.p("t.csv")
            self.ok(["voronoi", inp, "--labels", lab, "--cell-table", table, "--bounds"] + box + ["-q"])
            t = np.loadtxt(table, delimiter=",", skiprows=1)
            for region in (2, 5):
                mine = [l if blabels[f, 0] == region else l[::-1]
                        for f, l in enumerate(loops) if region in blabels[f]]
                unbalanced, _, vol = surface(mine, pts_f, dim)
                self.assertEqual(unbalanced, 0, "%dD region %d must be enclosed" % (dim, region))
                self.assertAlmostEqual(vol, t[t[:, 1] == region, 2].sum(), delta=1e-9)

    def test_threads_byte_identical(self):
        inp = self.save("big.npy", np.random.default_rng(38).random((5000, 3)))
        outs = []
        for th in (1, 2):
            out = self.p("f%d.vtp" % th)
            self.ok(["faces", inp, "-o", out, "--kind", "complex", "--threads", th, "-q"])
            outs.append(read_bytes(out))
        self.assertTrue(outs[0] == outs[1])


class Flower(base.TempDirCase):
    def test_flower_3d_and_2d(self):
        for dim in (3, 2):
            pts = np.random.default_rng(40 + dim).random((400, dim))
            inp = self.save("p%d.npy" % dim, pts)
            nb = self.p("nb.npy")
            self.ok(["voronoi", inp, "--neighbors", nb, "-q"])
            n, off, ids = base.load_neighbors(nb)
            for glyphs in (False, True):
                out = self.p("fl.vtp")
                self.ok(["flower", inp, "--point", "5", "--point", "17,33", "-o", out, "-q"] +
                        (["--glyphs"] if glyphs else []))
                pd = read_vtp(out)
                P = vtk_to_numpy(pd.GetPoints().GetData())[:, :dim]
                radius = vtk_to_numpy(pd.GetPointData().GetArray("Radius"))
                role = vtk_to_numpy(pd.GetPointData().GetArray("Role"))
                gen = vtk_to_numpy(pd.GetPointData().GetArray("GeneratorId"))
                pid = vtk_to_numpy(pd.GetPointData().GetArray("PointId"))
                cell_role = vtk_to_numpy(cell_array(pd, "Role"))
                for g in (5, 17, 33):
                    site = np.flatnonzero((role == 0) & (gen == g))
                    self.assertEqual(len(site), 1)
                    np.testing.assert_array_equal(P[site[0]], pts[g])
                    petals = np.flatnonzero((role == 1) & (gen == g))
                    d = np.linalg.norm(P[petals] - pts[g], axis=1)
                    np.testing.assert_allclose(radius[petals], d, rtol=1e-12)
                    self.assertAlmostEqual(radius[site[0]], 2 * d.max(), delta=1e-12, msg="circumflower")
                    # Petals are empty: no input point strictly inside any.
                    for c, r in zip(P[petals], radius[petals]):
                        self.assertGreaterEqual(np.linalg.norm(pts - c, axis=1).min(), r * (1 - 1e-9))
                    neigh = pid[(role == 2) & (gen == g)]
                    np.testing.assert_array_equal(neigh, ids[off[g]:off[g + 1]])
                self.assertEqual(set(cell_role) >= {5, 6}, glyphs)
                self.assertEqual(int(np.sum(cell_role == 3)), int(np.sum(role == 2)), "one spoke line per neighbour")

    def test_periodic_flower(self):
        # A periodic box: the cell of a point near a corner reaches across the
        # box's faces; its site is the point as wrapped, its neighbours are
        # drawn at the images across its faces (each at the petal-empty
        # distance: within the circumflower, none strictly inside a petal).
        pts = np.ldexp(np.floor(np.ldexp(np.random.default_rng(45).random((300, 3)) * (1 - 2e-6) + 1e-6, 30)), -30)
        pts[0] = [1 / 128, 1 / 64, 1 - 1 / 128]  # on the box's grid: kept as is
        out = self.p("pfl.vtp")
        self.ok(["flower", self.save("pfl.npy", pts), "--point", "0", "--bounds", *base.BOX3, "--periodic", "xyz",
                 "-o", out, "-q"])
        pd = read_vtp(out)
        P = vtk_to_numpy(pd.GetPoints().GetData())
        radius = vtk_to_numpy(pd.GetPointData().GetArray("Radius"))
        role = vtk_to_numpy(pd.GetPointData().GetArray("Role"))
        pid = vtk_to_numpy(pd.GetPointData().GetArray("PointId"))
        np.testing.assert_array_equal(P[role == 0][0], pts[0])
        petals = role == 1
        self.assertTrue(np.any(P[petals] < 0) and np.any(P[petals] > 1), "the cell crosses the box's faces")
        neigh = np.flatnonzero(role == 2)
        self.assertTrue(np.any((P[neigh] < 0) | (P[neigh] > 1)), "some neighbours are images")
        d = np.linalg.norm(P[neigh] - pts[0], axis=1)
        self.assertTrue(np.all(d <= radius[role == 0][0]))
        for k in neigh:  # an image of its point: the point moved by whole periods
            np.testing.assert_allclose(np.mod(P[k] - pts[pid[k]] + 0.5, 1.0), 0.5, atol=1e-12)
        for c, r in zip(P[petals], radius[petals]):
            self.assertGreaterEqual(np.linalg.norm(P[neigh] - c, axis=1).min(), r * (1 - 1e-9))


def python_module():
    """The tessera module built beside the binary (build/python), or None."""
    path = os.path.join(os.path.dirname(base.TESSERA), "python")
    if path not in sys.path:
        sys.path.insert(0, path)
    try:
        import tessera
    except ImportError:
        return None
    return tessera


def saved_case(case, name, pts, args=(), labels=None, radii=None):
    """For a comparison with the Python module's result of all cells: the
    module (the test skipped where it is not built), the points saved as
    NAME.npy, and the command's arguments: `args`, then --labels and --radii
    files where given."""
    tessera = python_module()
    if tessera is None:
        case.skipTest("the tessera Python module is not built")
    inp = case.save(name + ".npy", pts)
    extra = list(args)
    if labels is not None:
        extra += ["--labels", case.save(name + "_labels.npy", labels.astype(np.int32))]
    if radii is not None:
        extra += ["--radii", case.save(name + "_radii.npy", radii)]
    return tessera, inp, extra


class FlowerOfAFewCells(base.TempDirCase):
    """`flower` builds the cells asked for and their neighbours' only, not all N
    (VoronoiOptions::only): its .vtp equals byte for byte the one written from
    all cells (Python's flower of a computed Voronoi, which reads the whole
    mesh), and its summary names all cells."""

    def check(self, name, pts, ids, args=(), labels=None, **kw):
        tessera, inp, extra = saved_case(self, name, pts, args, labels)
        out, ref = self.p(name + ".vtp"), self.p(name + "_all.vtp")
        point_args = [a for i in ids for a in ("--point", str(i))]
        r = self.ok(["flower", inp, "-o", out, "--threads", "2"] + point_args + extra)
        vor = tessera.voronoi(pts, labels=labels, merge=True, threads=2, **kw)
        fl = tessera.flower(vor, ids)
        fl.save(ref)
        self.assertTrue(read_bytes(out) == read_bytes(ref), name + ": the flowers differ from all cells'")
        lines = r.stdout.splitlines()
        self.assertIn("  %-18s %d" % ("cells", vor.n_cells), lines, name)
        for f in fl:
            self.assertIn("  point %-12d %d petals, circumflower radius %.6g, %d clipping neighbours"
                          % (f.generator, f.n_petals, f.circumflower_radius, len(f.neighbors)), lines, name)
        # Python's flower of points builds a few cells too: the same flowers.
        few = tessera.flower(pts, ids, labels=labels, threads=2, **kw)
        self.assertLess(few.voronoi.n_cells, vor.n_cells, name)
        few.save(self.p(name + "_py.vtp"))
        self.assertTrue(read_bytes(self.p(name + "_py.vtp")) == read_bytes(ref), name + ": Python's flowers differ")
        return vor

    def test_uniform_and_lattice(self):
        rng = np.random.default_rng(861)
        self.check("u3", rng.random((3000, 3)), [5, 0, 2999])
        self.check("u2", rng.random((4000, 2)), [5, 1234, 3999])
        g = np.arange(9) * 0.125
        self.check("lat3", np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T.copy(), [0, 364, 100])
        self.check("lat2", np.array(np.meshgrid(g, g, indexing="ij")).reshape(2, -1).T.copy(), [0, 40, 80])

    def test_duplicates_and_labels(self):
        rng = np.random.default_rng(862)
        for dim in (3, 2):
            pts = rng.random((2000, dim))
            pts[9] = pts[4]  # 9 duplicates 4: 4 owns the cell
            self.check("dup%d" % dim, pts, [4])
            r = run(["flower", self.save("dup.npy", pts), "--point", "9", "-o", self.p("d.vtp")])
            self.assertEqual(r.returncode, 2)
            self.assertIn("owns no cell: it duplicates point 4", r.stderr)
            labels = rng.integers(-1, 3, 2000)
            labels[[11, 12]] = [2, 0]
            labels[10] = -1
            self.check("lab%d" % dim, pts, [11, 12], labels=labels)
            r = run(["flower", self.save("l.npy", pts), "--labels", self.save("ll.npy", labels.astype(np.int32)),
                     "--point", "11", "--point", "10", "-o", self.p("l.vtp")])
            self.assertEqual(r.returncode, 2)
            self.assertIn("point 10 owns no cell: it is an outside point (label < 0)", r.stderr)

    def test_bounds_and_boxes(self):
        rng = np.random.default_rng(863)
        pts = rng.random((3000, 3))
        pts[0] = [2, 0.5, 0.5]  # set aside
        self.check("ign", pts, [1, 2], ["--bounds", *BOX3, "--ignore-outside"], bounds=(0, 1, 0, 1, 0, 1),
                   ignore_outside=True)
        pts = rng.random((3000, 3))
        pts[0] = [0.001, 0.002, 0.999]  # near a corner: its neighbours are images
        self.check("per3", pts, [0, 77], ["--bounds", *BOX3, "--periodic", "xyz"], bounds=(0, 1, 0, 1, 0, 1),
                   periodic=True)
        self.check("tilt3", pts, [0, 77], ["--bounds", *BOX3, "--periodic", "xyz", "--tilt", "0.25", "-0.125", "0.5"],
                   bounds=(0, 1, 0, 1, 0, 1), periodic=True, tilt=(0.25, -0.125, 0.5))
        p2 = rng.random((3000, 2))
        self.check("per2", p2, [0, 5], ["--bounds", *BOX2, "--periodic", "x"], bounds=(0, 1, 0, 1), periodic="x")

    def test_insertion_path(self):
        # Points on a sphere: the automatic method takes the insertion.
        v = np.random.default_rng(864).normal(size=(5000, 3))
        vor = self.check("sphere", v / np.linalg.norm(v, axis=1)[:, None], [1, 4999])
        self.assertTrue(vor.from_insertion)


class FacesOfSomeCells(base.TempDirCase):
    """`faces --kind boundary|surface-net` builds the cells with a face of the
    set only (VoronoiOptions::only_with_faces), after a pass over all cells
    without the mesh: its .vtp equals byte for byte the one written from all
    cells (Python's faces of a computed Voronoi, which reads the whole mesh),
    and its summary counts all cells."""

    def check(self, name, pts, args=(), labels=None, radii=None, **kw):
        tessera, inp, extra = saved_case(self, name, pts, args, labels, radii)
        vor = tessera.voronoi(pts, labels=labels, merge=True, threads=2, radii=radii, **kw)
        for kind, capping in (("boundary", False), ("surface-net", False), ("surface-net", True)):
            what = "%s, %s%s" % (name, kind, " capped" if capping else "")
            out, ref = self.p(name + ".vtp"), self.p(name + "_all.vtp")
            r = self.ok(["faces", inp, "-o", out, "--kind", kind, "--threads", "2"] +
                        (["--capping"] if capping else []) + extra)
            tessera.faces(vor, kind=kind, capping=capping).save(ref)
            self.assertTrue(read_bytes(out) == read_bytes(ref), what + ": the faces differ from all cells'")
            self.assertIn("  %-18s %d" % ("cells", vor.n_cells), r.stdout.splitlines(), what)
        return vor

    def test_uniform_labels_and_outside_points(self):
        rng = np.random.default_rng(1301)
        for dim in (3, 2):
            pts = rng.random((3000, dim))
            self.check("u%d" % dim, pts)
            labels = (pts[:, 0] > 0.4).astype(np.int32) + 2 * (pts[:, 1] > 0.6)
            labels[np.linalg.norm(pts - 0.5, axis=1) < 0.15] = -1
            self.check("l%d" % dim, pts, labels=labels)
            self.check("b%d" % dim, pts, ["--bounds"] + (BOX3 if dim == 3 else BOX2), labels=labels,
                       bounds=(0, 1) * dim)

    def test_lattice_and_power_cells(self):
        g = np.arange(8) * 0.125
        lat = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T.copy()
        self.check("lat", lat, labels=(lat[:, 2] < 0.4).astype(np.int32))
        pts = np.random.default_rng(1302).random((2000, 3))
        radii = np.random.default_rng(1303).random(2000) * 0.06
        self.check("pow", pts, ["--bounds"] + BOX3, labels=(pts[:, 0] > 0.5).astype(np.int32), radii=radii,
                   bounds=(0, 1) * 3)


class HelpAndSummary(base.TempDirCase):
    def test_help(self):
        top = run(["--help"]).stdout
        for sub in ("graph", "faces", "flower"):
            self.assertIn(sub, top)
        options = {"graph": ("--csr", "--spoke-classes", "--spoke-measures", "--spoke-shifts", "--periodic",
                             "--tilt", "--prune-tolerance"),
                   "faces": ("--kind", "--capping", "--periodic", "--tilt"),
                   "flower": ("--point", "--glyphs", "--periodic", "--tilt")}
        for sub, own in options.items():
            r = run([sub, "--help"])
            self.assertEqual(r.returncode, 0)
            for opt in ("INPUT", "--output", "--dim", "--labels", "--bounds", "--padding", "--ignore-outside",
                        "--threads", "--quiet") + own:
                self.assertIn(opt, r.stdout, "%s --help lacks %s" % (sub, opt))

    def test_summaries_on_stdout(self):
        inp = self.save("p.npy", np.random.default_rng(50).random((300, 3)))
        for args, words in ((["graph", inp, "-o", self.p("g.vtp")], ("spokes", "edges", "wrote")),
                            (["faces", inp, "-o", self.p("f.vtp"), "--kind", "boundary"], ("faces", "vertices")),
                            (["flower", inp, "--point", "4", "-o", self.p("w.vtp")], ("petals", "circumflower"))):
            r = self.ok(args)
            self.assertEqual(r.stderr, "", "no progress bar when stderr is not a terminal")
            for w in words:
                self.assertIn(w, r.stdout)
            self.assertEqual(self.ok(args + ["-q"]).stdout, "")


class BadDualInput(base.TempDirCase):
    """Every failure: exit 2, one line "tessera: error: ...", no files left."""

    fails = base.BadInput.fails

    def setUp(self):
        super().setUp()
        self.good3 = self.save("good3.npy", np.random.default_rng(1).random((50, 3)))
        self.good2 = self.save("good2.npy", np.random.default_rng(1).random((50, 2)))
        labels = np.zeros(50, np.int32)
        labels[7] = -1
        self.labels = self.save("lab.npy", labels)

    def test_graph(self):
        out = self.p("g.vtp")
        self.fails(["graph", self.p("nope.npy"), "-o", out], "nope.npy")
        self.fails(["graph", self.good3], "nothing to do")
        self.fails(["graph", self.good3, "-o", self.p("g.vtu")], ".vtp")
        self.fails(["graph", self.good3, "--csr", self.p("g.csv")], ".npy")
        self.fails(["graph", self.good3, "--spoke-classes", self.p("c.txt")], ".npy")
        self.fails(["graph", self.good3, "--spoke-measures", self.p("m.csv")], ".npy")
        self.fails(["graph", self.good3, "-o", out, "--prune-tolerance", "-1"])
        self.fails(["graph", self.good3, "-o", out, "--prune-tolerance", "nan"])
        self.fails(["graph", self.good3, "-o", out, "--csr", self.p("no/dir/g.npy")], "no/dir")
        self.fails(["graph", self.good3, "-o", out, "--bounds", "0", "0.5", "0", "1", "0", "1"], "outside the bounds")
        self.fails(["graph", self.good3, "-o", out, "--labels", self.save("short.npy", np.zeros(3, np.int32))])

    def test_faces(self):
        out = self.p("f.vtp")
        self.fails(["faces", self.good3, "-o", out], "--kind")
        self.fails(["faces", self.good3, "-o", out, "--kind", "surface"], "surface-net")
        self.fails(["faces", self.good3, "-o", out, "--kind", "complex", "--capping"], "--capping")
        self.fails(["faces", self.good3, "--kind", "complex"], "nothing to do")
        self.fails(["faces", self.good3, "-o", self.p("f.vtu"), "--kind", "boundary"], ".vtp")
        self.fails(["faces", self.good2, "-o", out, "--kind", "boundary", "--bounds"] + BOX3)
        self.fails(["faces", self.save("flat.npy", np.c_[np.random.default_rng(2).random((20, 2)), np.zeros(20)]),
                    "-o", out, "--kind", "boundary"], "--dim 2")

    def test_flower(self):
        out = self.p("fl.vtp")
        self.fails(["flower", self.good3, "-o", out])
        self.fails(["flower", self.good3, "--point", "50", "-o", out], "50")
        self.fails(["flower", self.good3, "--point", "-3", "-o", out])
        self.fails(["flower", self.good3, "--point", "x", "-o", out])
        self.fails(["flower", self.good3, "--point", "7", "-o", out, "--labels", self.labels], "outside point")
        self.fails(["flower", self.good3, "--point", "3"], "nothing to do")
        self.fails(["flower", self.good3, "--point", "3", "-o", self.p("fl.vtu")], ".vtp")
        dup = np.random.default_rng(3).random((20, 3))
        dup[9] = dup[4]
        self.fails(["flower", self.save("dup.npy", dup), "--point", "9", "-o", out], "duplicates point 4")

    def test_point_before_input(self):
        # --point takes one value per occurrence, so INPUT may follow it.
        self.ok(["flower", "--point", "3", self.good3, "-o", self.p("fl.vtp"), "-q"])


def main():
    return base.cli_main("test_dual_cli.py", [(base.vtk is not None and Delaunay is not None,
                                               "python3-vtk9 and python3-scipy are required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
