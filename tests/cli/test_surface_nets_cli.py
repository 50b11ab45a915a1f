#!/usr/bin/python3
"""End-to-end tests of `tessera surface-nets` and `tessera bench surface-nets`.

Usage: /usr/bin/python3 tests/cli/test_surface_nets_cli.py PATH_TO_tessera [unittest args...]

Every .vtp written is read back through VTK's XML reader: BoundaryLabels
(two int32 components, side 0 a selected label, interfaces (lower, higher)),
VertexKind, and watertightness of every label's surface (each edge in exactly
two of its faces, in opposite directions, once the faces with the label on
side 1 are reversed), enclosed volumes against the analytic ones. Inputs are
labelled points and label images (.npy with --image, and .vti / .mha written
by VTK's own writers). Bad input: exit 2, one error line, nothing written.
Shares its helpers with test_cli.py.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import json
import os
import re
import sys
from collections import Counter

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli as base  # noqa: E402  (helpers only; its test classes are not collected here)
from test_cli import read_bytes, read_vtp, cell_array, cells_of  # noqa: E402

from vtk.util.numpy_support import vtk_to_numpy, numpy_to_vtk  # noqa: E402

run = base.run


def load_net(path):
    pd = read_vtp(path)
    dim = 3 if pd.GetNumberOfPolys() or not pd.GetNumberOfLines() else 2
    faces = cells_of(pd.GetPolys() if dim == 3 else pd.GetLines())
    pts = vtk_to_numpy(pd.GetPoints().GetData())[:, :dim].astype(float)
    bl = cell_array(pd, "BoundaryLabels")
    labels = vtk_to_numpy(bl)
    kind = vtk_to_numpy(pd.GetPointData().GetArray("VertexKind"))
    return pd, dim, faces, pts, labels, kind, bl


def label_surface(faces, labels, label, pts, dim):
    """(boundary edges, non-manifold edges, enclosed volume) of one label's
    surface: its faces, reversed where it is side 1."""
    directed = Counter()
    vol = 0.0
    o = np.full(dim, 0.5)
    for f, (a, b) in zip(faces, labels):
        if label not in (a, b):
            continue
        l = [int(x) for x in f]
        if a != label:
            l = l[::-1]
        if dim == 2:
            directed[(l[0], l[1])] += 1
            p, q = pts[l[0]] - o, pts[l[1]] - o
            vol += 0.5 * (p[0] * q[1] - p[1] * q[0])
            continue
        for t in range(len(l)):
            directed[(l[t], l[(t + 1) % len(l)])] += 1
        p = pts[l] - o
        vol += np.dot(p[0], np.cross(p[1:-1], p[2:]).sum(axis=0)) / 6.0
    boundary = nonmanifold = 0
    if dim == 3:
        undirected = Counter()
        for (a, b), k in directed.items():
            undirected[(min(a, b), max(a, b))] += k
        for (a, b), k in undirected.items():
            if k == 1:
                boundary += 1
            elif k != 2 or directed.get((a, b), 0) != 1 or directed.get((b, a), 0) != 1:
                nonmanifold += 1
    else:
        inn, out = Counter(), Counter()
        for (a, b), k in directed.items():
            out[a] += k
            inn[b] += k
        for v in set(inn) | set(out):
            if inn[v] + out[v] == 1:
                boundary += 1
            elif inn[v] != 1 or out[v] != 1:
                nonmanifold += 1
    return boundary, nonmanifold, vol


def nested_points(n, dim, seed):
    p = np.random.default_rng(seed).random((n, dim))
    r = np.linalg.norm(p - 0.5, axis=1)
    return p, np.where(r < 0.2, 2, np.where(r < 0.35, 1, 0)).astype(np.int32)


def boxes_image(n=24):
    """Two boxes touching at x = n/2 (labels 1, 2) in a background of 0."""
    img = np.zeros((n, n, n), np.int32)
    q = n // 4
    img[q:3 * q, q:3 * q, q:n // 2] = 1   # (z, y, x) order: x is the last axis
    img[q:3 * q, q:3 * q, n // 2:3 * q] = 2
    return img


def to_vtk_image(img, spacing, origin):
    import vtk
    im = vtk.vtkImageData()
    im.SetDimensions(img.shape[2], img.shape[1], img.shape[0])
    im.SetSpacing(*spacing)
    im.SetOrigin(*origin)
    arr = numpy_to_vtk(img.ravel(order="C").copy(), deep=True)
    arr.SetName("labels")
    im.GetPointData().SetScalars(arr)
    return im


class SurfaceNetsCLI(base.TempDirCase):
    def net(self, args):
        out = self.p("net.vtp")
        r = self.ok(["surface-nets"] + [str(a) for a in args] + ["-o", out])
        return (r,) + load_net(out)

    def check_labels(self, labels, bl, selected):
        self.assertEqual(bl.GetNumberOfComponents(), 2)
        self.assertEqual(bl.GetDataTypeAsString(), "int")
        for a, b in labels:
            self.assertIn(a, selected, "side 0 must be a selected label")
            self.assertNotEqual(a, b)
            if b in selected:
                self.assertLess(a, b, "interfaces are (lower, higher)")

    def test_points_3d_capped_triangles_watertight(self):
        p, l = nested_points(4000, 3, 1)
        args = [self.save("p.npy", p), "--labels", self.save("l.npy", l), "--capping", "--triangles",
                "--bounds", *base.BOX3]
        r, pd, dim, faces, pts, labels, kind, bl = self.net(args)
        self.assertEqual(dim, 3)
        self.assertTrue(all(len(f) == 3 for f in faces))
        self.check_labels(labels, bl, {0, 1, 2})
        self.assertEqual({(int(a), int(b)) for a, b in labels}, {(0, -1), (0, 1), (1, 2)})
        self.assertTrue(set(np.unique(kind)) <= {0, 1, 2})
        self.assertIsNotNone(pd.GetCellData().GetArray("PolygonId"))
        want = {0: 1 - 4 / 3 * np.pi * 0.35 ** 3, 1: 4 / 3 * np.pi * (0.35 ** 3 - 0.2 ** 3), 2: 4 / 3 * np.pi * 0.2 ** 3}
        for label in (0, 1, 2):
            boundary, nonmanifold, vol = label_surface(faces, labels, label, pts, 3)
            self.assertEqual((boundary, nonmanifold), (0, 0), "label %d not watertight" % label)
            self.assertAlmostEqual(vol / want[label], 1.0, delta=0.25)
        self.assertIn("every selected label's surface is closed", r.stdout)

    def test_points_without_capping_and_unsmoothed(self):
        p, l = nested_points(3000, 3, 2)
        args = [self.save("p.npy", p), "--labels", self.save("l.npy", l), "--smooth", "0", "-q"]
        _, _, _, faces, pts, labels, kind, bl = self.net(args)
        self.assertTrue(any(len(f) > 3 for f in faces))  # polygons
        self.assertEqual({(int(a), int(b)) for a, b in labels}, {(0, 1), (1, 2)})
        for label in (1, 2):
            self.assertEqual(label_surface(faces, labels, label, pts, 3)[:2], (0, 0))
        # Only label 1, with capping: side 0 is always 1, even against the lower 0.
        args = [self.p("p.npy"), "--labels", self.p("l.npy"), "--select", "1", "--capping", "--background-label", "-7",
                "-q"]
        _, _, _, faces, pts, labels, kind, bl = self.net(args)
        self.assertEqual({(int(a), int(b)) for a, b in labels}, {(1, 0), (1, 2)})
        self.assertEqual(label_surface(faces, labels, 1, pts, 3)[:2], (0, 0))

    def test_empty_net_is_open_not_watertight(self):
        # One label, every neighbour unselected, no --capping: no face at all,
        # which the summary and the bench called closed and manifold.
        rng = np.random.default_rng(0)
        p = self.save("p.npy", rng.random((200, 3)))
        l = self.save("l.npy", rng.integers(0, 3, 200).astype(np.int32))
        r = self.ok(["surface-nets", p, "--labels", l, "--select", "1", "-o", self.p("net.vtp")])
        self.assertIn("0 polygons", r.stdout)
        self.assertIn("open: label 1 (no faces); they reach the domain box or unselected points (--capping closes them)",
                      r.stdout)
        r = self.ok(["bench", "surface-nets", p, "--labels", l, "--select", "1"])
        self.assertFalse(json.loads(r.stdout.splitlines()[0])["extra"]["watertight"])
        r = self.ok(["surface-nets", p, "--labels", l, "--select", "1", "--capping", "-o", self.p("net.vtp")])
        self.assertIn("every selected label's surface is closed and manifold", r.stdout)

    def test_untangling_of_strong_smoothing_keeps_it(self):
        # 60 iterations of relaxation 1, constraint 0.9 on a 24^3 map of 40
        # nearest-seed labels: the untangling's zone reruns (around what they
        # pin, the rest held) kept making crossings at the zones' borders for
        # 16 rounds, after which every vertex kept its start (largest move 0).
        # Once a round leaves no fewer crossings, the whole net runs again.
        n = 24
        seeds = np.random.default_rng(5).uniform(0, n, (40, 3))
        z, y, x = np.mgrid[0:n, 0:n, 0:n]
        d = (x[..., None] - seeds[:, 0]) ** 2 + (y[..., None] - seeds[:, 1]) ** 2 + (z[..., None] - seeds[:, 2]) ** 2
        image = self.save("grains.npy", (d.argmin(-1) + 1).astype(np.int32))
        r = self.ok(["surface-nets", image, "--image", "--triangles", "--smooth", "60", "--relax", "1",
                     "--constraint", "0.9", "-o", self.p("net.vtp")])
        move = float(re.search(r"largest move ([0-9.e+-]+)", r.stdout).group(1))
        self.assertGreater(move, 0.5, r.stdout)

    def test_points_2d(self):
        p, l = nested_points(3000, 2, 3)
        args = [self.save("p.npy", p), "--labels", self.save("l.npy", l), "--capping", "-q", "--bounds", *base.BOX2]
        _, pd, dim, faces, pts, labels, kind, bl = self.net(args)
        self.assertEqual(dim, 2)
        self.assertEqual(pd.GetNumberOfPolys(), 0)
        self.assertTrue(all(len(f) == 2 for f in faces))
        for label in (0, 1, 2):
            b, nm, area = label_surface(faces, labels, label, pts, 2)
            self.assertEqual((b, nm), (0, 0))
        self.assertAlmostEqual(label_surface(faces, labels, 2, pts, 2)[2] / (np.pi * 0.04), 1.0, delta=0.1)

    def test_image_npy(self):
        img = boxes_image(24)
        path = self.save("img.npy", img)
        r, pd, dim, faces, pts, labels, kind, bl = self.net(
            [path, "--image", "--spacing", "0.5,0.5,0.5", "--origin", "1,2,3", "--select", "1,2", "--capping",
             "--triangles", "--seed", "3"])
        self.assertIn("24x24x24 voxels", r.stdout)
        self.check_labels(labels, bl, {1, 2})
        self.assertEqual({(int(a), int(b)) for a, b in labels}, {(1, 0), (2, 0), (1, 2)})
        for label in (1, 2):
            self.assertEqual(label_surface(faces, labels, label, pts, 3)[:2], (0, 0))
        # Inside the image's voxels: centres at origin + i * 0.5, half a voxel beyond.
        lo, hi = np.array([1, 2, 3]) - 0.25, np.array([1, 2, 3]) + 23.5 * 0.5
        self.assertTrue(np.all(pts >= lo - 1e-12) and np.all(pts <= hi + 1e-12))
        # Each box holds 12 x 12 x 6 voxels of 0.125: the enclosed volumes are close.
        for label in (1, 2):
            vol = label_surface(faces, labels, label, pts, 3)[2]
            self.assertAlmostEqual(vol / (12 * 12 * 6 * 0.125), 1.0, delta=0.15)
        # Junctions: the boxes' common face meets the background in a square ring.
        self.assertGreater(int(np.sum(kind == 1)), 0)

    def test_periodic_image(self):
        # A periodic microstructure: a ball around the image's corner and a
        # slab across its x faces. With --periodic the image tiles space, so
        # each label's surface closes up across the box's faces (corners
        # identified modulo the box) with no capping; without it they reach
        # the box and stay open.
        n = 16
        i = np.indices((n, n, n))  # (z, y, x)
        wrapped = np.minimum(i, n - i)
        img = np.zeros((n, n, n), np.int32)
        img[np.isin(i[2], (14, 15, 0, 1))] = 2
        img[(wrapped ** 2).sum(axis=0) <= 25] = 1
        path = self.save("pimg.npy", img)
        for tilt, extra in ((False, ["--triangles"]), (False, ["--smooth", "0"]), (True, [])):
            # Joggled: at exact voxel centres several vertices share a corner,
            # and corners could not name them (the library tells copies by keys).
            args = [path, "--image", "--periodic", "xyz", "--joggle", "0.3", "--seed", "5"] + extra
            if tilt:  # a sheared tiling of the same voxels: the same labels' surfaces close up
                args += ["--tilt", "3", "0", "-2"]
            r, pd, dim, faces, pts, labels, kind, bl = self.net(args)
            self.assertIn("periodic", r.stdout)
            self.assertIn("every selected label's surface is closed", r.stdout)
            self.assertIsNotNone(pd.GetCellData().GetArray("SideShift"))
            # Copies of a corner lie lattice vectors apart (box [-0.5, 15.5]).
            lat = np.eye(3) * n
            if tilt:
                lat[1, 0], lat[2, 1] = 3, -2
            frac = (pts + 0.5) @ np.linalg.inv(lat)
            key = np.round(np.mod(frac, 1.0) * 1e7).astype(np.int64) % 10 ** 7
            _, canon = np.unique(key, axis=0, return_inverse=True)
            mapped = [canon.reshape(-1)[f] for f in faces]
            for label in (0, 1, 2):
                self.assertEqual(label_surface(mapped, labels, label, pts, 3)[:2], (0, 0), "label %d" % label)
        r, pd, dim, faces, pts, labels, kind, bl = self.net([path, "--image"])
        self.assertIn("open", r.stdout)

    def test_image_files_written_by_vtk(self):
        import vtk
        img = boxes_image(20)
        im = to_vtk_image(img, (1.0, 1.0, 1.0), (0.0, 0.0, 0.0))
        outs = []
        for ext, writer in ((".vti", vtk.vtkXMLImageDataWriter()), (".mha", vtk.vtkMetaImageWriter())):
            path = self.p("img" + ext)
            writer.SetFileName(path)
            writer.SetInputData(im)
            writer.Write()
            out = self.p("net%s.vtp" % ext[1:])
            self.ok(["surface-nets", path, "-o", out, "--select", "1,2", "--capping", "-q"])
            _, _, faces, pts, labels, kind, bl = load_net(out)
            for label in (1, 2):
                self.assertEqual(label_surface(faces, labels, label, pts, 3)[:2], (0, 0))
            outs.append(read_bytes(out))
        self.assertEqual(outs[0], outs[1], "same image, same result from .vti and .mha")

    def test_threads_byte_identical(self):
        p, l = nested_points(6000, 3, 4)
        inp, lab = self.save("p.npy", p), self.save("l.npy", l)
        outs = []
        for th in (1, 2):
            out = self.p("n%d.vtp" % th)
            self.ok(["surface-nets", inp, "--labels", lab, "-o", out, "--capping", "--triangles", "--threads", th, "-q"])
            outs.append(read_bytes(out))
        self.assertTrue(outs[0] == outs[1])

    def test_bench_json(self):
        path = self.save("img.npy", boxes_image(20))
        r = self.ok(["bench", "surface-nets", path, "--image", "--select", "1,2", "--capping", "--triangles",
                     "--repeat", "2"])
        lines = [json.loads(x) for x in r.stdout.splitlines()]
        self.assertEqual(len(lines), 2)
        for k, d in enumerate(lines):
            self.assertEqual((d["tool"], d["op"]), ("tessera", "surface-nets"))
            self.assertGreater(d["seconds"], 0)
            self.assertEqual(d["simplices"], d["extra"]["triangles"])
            self.assertTrue(d["extra"]["watertight"])
            self.assertEqual(d["extra"]["voxels"], 8000)
            self.assertEqual(d["extra"]["repeat"], k)
            for key in ("sample_s", "cells_s", "faces_s", "smoothing_s", "triangulation_s", "polygons"):
                self.assertIn(key, d["extra"])
        self.assertEqual(lines[0]["simplices"], lines[1]["simplices"])
        # Points input, no capping: labels reaching the box are open.
        p, l = nested_points(2000, 3, 5)
        l[p[:, 0] < 0.3] = 3  # label 3 reaches the box
        r = self.ok(["bench", "surface-nets", self.save("p.npy", p), "--labels", self.save("l.npy", l)])
        d = json.loads(r.stdout)
        self.assertFalse(d["extra"]["watertight"])
        self.assertGreater(d["extra"]["boundary_edges"], 0)


class SurfaceNetsBadInput(base.TempDirCase):
    def setUp(self):
        super().setUp()
        p, l = nested_points(300, 3, 6)
        self.pts, self.lab = self.save("p.npy", p), self.save("l.npy", l)
        self.img = self.save("img.npy", boxes_image(12))
        self.out = self.p("out.vtp")

    fails = base.BadInput.fails

    def sn(self, *extra):
        return ["surface-nets", self.pts, "--labels", self.lab, "-o", self.out] + [str(x) for x in extra]

    def test_errors(self):
        self.fails(self.sn("--select", "9"), "unknown label 9", outputs=[self.out])
        self.fails(self.sn("--select", "-1"), "negative", outputs=[self.out])
        self.fails(["surface-nets", self.pts, "-o", self.out], "labels", outputs=[self.out])
        neg = self.save("neg.npy", -np.ones(300, np.int32))
        self.fails(["surface-nets", self.pts, "--labels", neg, "-o", self.out], "empty selection", outputs=[self.out])
        self.fails(self.sn("--background-label", "0"), "--background-label", outputs=[self.out])
        self.fails(self.sn("--smooth", "-1"), "--smooth", outputs=[self.out])
        self.fails(self.sn("--relax", "0"), "--relax", outputs=[self.out])
        self.fails(self.sn("--relax", "1.5"), "--relax", outputs=[self.out])
        self.fails(self.sn("--constraint", "-1"), "--constraint", outputs=[self.out])
        self.fails(self.sn("--constraint", "nan"), None, outputs=[self.out])
        self.fails(["surface-nets", self.pts, "--labels", self.lab, "-o", self.p("out.vtu")], ".vtp")
        self.fails(["surface-nets", self.pts, "--labels", self.lab], "-o")
        self.fails(self.sn("--step", "4"), "image", outputs=[self.out])
        self.fails(["surface-nets", self.img, "-o", self.out], "--image", outputs=[self.out])
        self.fails(["surface-nets", self.img, "--image", "--labels", self.lab, "-o", self.out], "--labels",
                   outputs=[self.out])
        self.fails(["surface-nets", self.img, "--image", "--select", "5", "-o", self.out], "5", outputs=[self.out])
        csv = self.p("p.csv")
        with open(csv, "w") as f:
            f.write("0,0,0\n1,1,1\n")
        self.fails(["surface-nets", csv, "--image", "-o", self.out], "--image", outputs=[self.out])
        self.fails(["bench", "surface-nets", self.pts, "--labels", self.lab, "--repeat", "0"])


def main():
    return base.cli_main("test_surface_nets_cli.py", [(base.vtk is not None, "python3-vtk9 is required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
