#!/usr/bin/python3
"""End-to-end tests of `tessera sample-image` and `tessera probe`.

Usage: /usr/bin/python3 tests/cli/test_image_cli.py PATH_TO_tessera [unittest args...]

Label volumes are written as .vti (vtkXMLImageDataWriter), .mha (vtkMetaImageWriter),
.nrrd (hand-made header, gzip) and .npy; the sampled points must be the same from
every format and equal a reference computed here: boundary voxels by definition,
scipy's exact taxicab distance transform, the power-of-N schedule. Outputs are
read back through numpy, VTK's XML reader and a small PLY parser. probe is
checked on a linear field. Bad input: exit 2, one error line, nothing written.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import gzip
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli as base  # noqa: E402  (helpers only)
from test_cli import read_bytes, read_vtp, read_ply  # noqa: E402

try:
    from scipy.ndimage import distance_transform_cdt
except ImportError:  # pragma: no cover
    distance_transform_cdt = None

import vtk  # noqa: E402
from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy  # noqa: E402

run = base.run
SPACING = (0.5, 0.25, 2.0)
ORIGIN = (1.0, -2.0, 3.0)


def label_volume(nx=22, ny=19, nz=15, seed=0):
    """Two overlapping balls (labels 1, 2), a negative-label ball (-1), in 0."""
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    lab = np.zeros((nz, ny, nx), dtype=np.int16)
    lab[(i - 7) ** 2 + (j - 8) ** 2 + (k - 7) ** 2 < 30] = 1
    lab[(i - 13) ** 2 + (j - 10) ** 2 + (k - 8) ** 2 < 25] = 2
    lab[(i - 18) ** 2 + (j - 3) ** 2 + (k - 2) ** 2 < 6] = -1
    return lab


def reference(lab, select=None, step=2, schedule="exponential"):
    """Voxel flags (C order) the sampler keeps without randomisation, and the distance."""
    sel = (lab >= 0) if not select else np.isin(lab, select)
    b = np.zeros(lab.shape, dtype=bool)
    for ax in range(lab.ndim):
        a = [slice(None)] * lab.ndim
        c = [slice(None)] * lab.ndim
        a[ax] = slice(1, None)
        c[ax] = slice(None, -1)
        edge = (lab[tuple(a)] != lab[tuple(c)]) & (sel[tuple(a)] | sel[tuple(c)])
        b[tuple(a)] |= edge
        b[tuple(c)] |= edge
    d = distance_transform_cdt(~b, metric="taxicab").astype(np.int64) + 1
    if schedule == "exponential":
        keep = np.zeros(d.shape, dtype=bool)
        p = 1
        while p <= d.max():
            keep |= d == p
            p *= step
    else:
        keep = (d == 1) | (d % step == 0)
    return keep, d


def centres(shape, keep, spacing=SPACING, origin=ORIGIN):
    idx = np.argwhere(keep)[:, ::-1]  # (k, j, i) -> (i, j, k), C order = x fastest
    dim = idx.shape[1]
    return np.asarray(origin[:dim]) + idx * np.asarray(spacing[:dim])


def vtk_image(arr, spacing=SPACING, origin=ORIGIN, name="labels"):
    nz, ny, nx = arr.shape
    img = vtk.vtkImageData()
    img.SetDimensions(nx, ny, nz)
    img.SetSpacing(*spacing)
    img.SetOrigin(*origin)
    a = numpy_to_vtk(np.ascontiguousarray(arr).ravel(), deep=1)
    a.SetName(name)
    img.GetPointData().SetScalars(a)
    return img


def write_vti(path, arr, **kw):
    w = vtk.vtkXMLImageDataWriter()
    w.SetInputData(vtk_image(arr, **kw))
    w.SetFileName(path)
    w.SetCompressorTypeToZLib()
    w.SetDataModeToAppended()
    assert w.Write() == 1


def write_mha(path, arr):
    w = vtk.vtkMetaImageWriter()
    w.SetInputData(vtk_image(arr))
    w.SetFileName(path)
    w.SetCompression(True)
    w.Write()


def write_nrrd(path, arr):
    nz, ny, nx = arr.shape
    head = ("NRRD0004\ntype: short\ndimension: 3\nsizes: %d %d %d\nspace dimension: 3\n"
            "space directions: (%r,0,0) (0,%r,0) (0,0,%r)\nspace origin: (%r,%r,%r)\nencoding: gzip\n"
            "endian: little\n\n" % ((nx, ny, nz) + SPACING + ORIGIN))
    with open(path, "wb") as f:
        f.write(head.encode() + gzip.compress(arr.astype("<i2").tobytes()))


class SampleImage(base.TempDirCase):
    def setUp(self):
        super().setUp()
        self.lab = label_volume()
        self.vti = self.p("lab.vti")
        write_vti(self.vti, self.lab)

    def sample(self, image, out, *extra):
        r = self.ok(["sample-image", image, "-o", out] + list(extra))
        self.assertEqual(r.stderr, "")
        self.assertEqual(len(r.stdout.strip().splitlines()), 1, r.stdout)  # one-line summary
        self.assertIn("points", r.stdout)
        return r

    def test_every_format_gives_the_reference_points(self):
        keep, _ = reference(self.lab)
        want = centres(self.lab.shape, keep)
        want_labels = self.lab[keep]
        mha, nrrd, npy = self.p("lab.mha"), self.p("lab.nrrd"), self.p("lab_in.npy")
        write_mha(mha, self.lab)
        write_nrrd(nrrd, self.lab)
        np.save(npy, self.lab.astype(np.int32))
        outs = []
        for i, (image, extra) in enumerate([(self.vti, []), (mha, []), (nrrd, []),
                                            (npy, ["--spacing", "0.5,0.25,2", "--origin", "1,-2,3"])]):
            out = self.p("pts%d.npy" % i)
            self.sample(image, out, "--no-randomize", *extra)
            pts, labels = np.load(out), np.load(self.p("pts%d_labels.npy" % i))
            self.assertEqual(pts.dtype, np.float64)
            np.testing.assert_array_equal(pts, want, err_msg=image)
            np.testing.assert_array_equal(labels, want_labels, err_msg=image)
            outs.append(read_bytes(out))
        self.assertTrue(all(o == outs[0] for o in outs))

    def test_schedules_and_selection(self):
        for extra, kw in [(["--step", "3"], dict(step=3)),
                          (["--schedule", "linear", "--step", "4"], dict(schedule="linear", step=4)),
                          (["--select", "2"], dict(select=[2])),
                          (["--select", "1,2", "--step", "5"], dict(select=[1, 2], step=5))]:
            out = self.p("s.npy")
            self.sample(self.vti, out, "--no-randomize", *extra)
            keep, _ = reference(self.lab, **kw)
            np.testing.assert_array_equal(np.load(out), centres(self.lab.shape, keep), err_msg=str(extra))

    def test_ply_and_vtp_outputs(self):
        npy, ply, vtp = self.p("a.npy"), self.p("a.ply"), self.p("a.vtp")
        for out in (npy, ply, vtp):
            self.sample(self.vti, out, "--seed", "3")
        pts, labels = np.load(npy), np.load(self.p("a_labels.npy"))
        props = read_ply(ply)
        ppts = np.stack([props["x"], props["y"], props["z"]], axis=1)
        np.testing.assert_array_equal(ppts, pts)
        np.testing.assert_array_equal(props["label"], labels)
        poly = read_vtp(vtp)
        np.testing.assert_array_equal(vtk_to_numpy(poly.GetPoints().GetData()), pts)
        np.testing.assert_array_equal(vtk_to_numpy(poly.GetPointData().GetArray("label")), labels)
        self.assertEqual(poly.GetNumberOfVerts() > 0, True)

    def test_randomized_is_a_deterministic_subset(self):
        full, a, b, c = self.p("full.npy"), self.p("a.npy"), self.p("b.npy"), self.p("c.npy")
        self.sample(self.vti, full, "--no-randomize")
        self.sample(self.vti, a, "--seed", "7", "--threads", "1")
        self.sample(self.vti, b, "--seed", "7", "--threads", "2")
        self.sample(self.vti, c, "--seed", "8", "--threads", "2")
        self.assertEqual(read_bytes(a), read_bytes(b))
        self.assertNotEqual(read_bytes(a), read_bytes(c))
        sub, allp = np.load(a), np.load(full)
        self.assertLess(len(sub), len(allp))
        self.assertEqual(len({tuple(p) for p in sub} - {tuple(p) for p in allp}), 0)
        # Joggled: the same voxels, each point within its voxel.
        j = self.p("j.npy")
        self.sample(self.vti, j, "--seed", "7", "--joggle", "0.4")
        moved = np.load(j)
        self.assertEqual(moved.shape, sub.shape)
        off = np.linalg.norm(moved - sub, axis=1)
        self.assertTrue(np.all(off < 0.4 * min(SPACING) + 1e-12))
        self.assertTrue(np.any(off > 0))

    def test_output_modes_and_background_label(self):
        outs = {}
        for mode in ("all", "labelled", "background"):
            out = self.p(mode + ".npy")
            self.sample(self.vti, out, "--no-randomize", "--select", "1", "--background-label", "-9",
                        "--output-type", mode)
            outs[mode] = (np.load(out), np.load(self.p(mode + "_labels.npy")))
        self.assertTrue(np.all(outs["labelled"][1] == 1))
        self.assertTrue(np.all(outs["background"][1] == -9))
        self.assertEqual(len(outs["all"][0]), len(outs["labelled"][0]) + len(outs["background"][0]))
        keep, _ = reference(self.lab, select=[1])
        np.testing.assert_array_equal(outs["all"][0], centres(self.lab.shape, keep))
        np.testing.assert_array_equal(outs["all"][1], np.where(self.lab[keep] == 1, 1, -9))

    def test_2d_image(self):
        lab2 = label_volume()[7]
        path = self.save("two.npy", lab2.astype(np.uint8 if lab2.min() >= 0 else np.int8))
        out = self.p("two_pts.npy")
        self.sample(path, out, "--no-randomize", "--spacing", "0.5,0.25")
        keep, _ = reference(lab2)
        np.testing.assert_array_equal(np.load(out), centres(lab2.shape, keep, origin=(0, 0)))


class Probe(base.TempDirCase):
    C = (0.25, 1.5, -2.0, 0.75)

    def setUp(self):
        super().setUp()
        nz, ny, nx = 6, 7, 9
        k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
        x, y, z = (ORIGIN[0] + i * SPACING[0], ORIGIN[1] + j * SPACING[1], ORIGIN[2] + k * SPACING[2])
        c = self.C
        self.field = c[0] + c[1] * x + c[2] * y + c[3] * z
        self.vti = self.p("field.vti")
        write_vti(self.vti, self.field, name="f")
        self.hi = np.array(ORIGIN) + (np.array([nx, ny, nz]) - 1) * np.array(SPACING)
        rng = np.random.default_rng(5)
        inside = np.array(ORIGIN) + rng.random((300, 3)) * (self.hi - np.array(ORIGIN))
        self.pts = np.vstack([inside, [[-10, 0, 0], self.hi + 1, self.hi]])
        self.inp = self.save("pts.npy", self.pts)

    def expected(self):
        c, p = self.C, self.pts
        return c[0] + c[1] * p[:, 0] + c[2] * p[:, 1] + c[3] * p[:, 2]

    def test_linear_field_npy_and_vtp(self):
        out = self.p("v.npy")
        r = self.ok(["probe", self.vti, self.inp, "-o", out, "--outside-value", "-1"])
        self.assertIn("2 outside", r.stdout)
        # An overflowing value was taken as inf; "inf" itself is a value.
        r = run(["probe", self.vti, self.inp, "-o", self.p("o.npy"), "--outside-value", "1e400"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("--outside-value: '1e400' is beyond double's range", r.stderr)
        self.assertFalse(os.path.exists(self.p("o.npy")))
        self.ok(["probe", self.vti, self.inp, "-o", self.p("o.npy"), "--outside-value", "-inf"])
        v = np.load(out)
        self.assertEqual(v.shape, (len(self.pts),))
        e = self.expected()
        np.testing.assert_allclose(v[:300], e[:300], rtol=0, atol=1e-12)
        self.assertEqual(list(v[300:302]), [-1.0, -1.0])
        self.assertAlmostEqual(v[302], e[302], delta=1e-12)  # the far corner is inside
        labels = self.save("labels.npy", np.arange(len(self.pts), dtype=np.int32))
        vtp = self.p("v.vtp")
        self.ok(["probe", self.vti, self.inp, "-o", vtp, "--labels", labels, "-q"])
        poly = read_vtp(vtp)
        s = vtk_to_numpy(poly.GetPointData().GetArray("scalars"))
        np.testing.assert_array_equal(s[:300], v[:300])
        self.assertTrue(np.all(np.isnan(s[300:302])))  # default outside value: NaN
        np.testing.assert_array_equal(vtk_to_numpy(poly.GetPointData().GetArray("label")), np.arange(len(self.pts)))


class BadImageInput(base.TempDirCase):
    """Every failure: exit 2, one stderr line "tessera: error: ...", no output files."""
    fails = base.BadInput.fails

    def setUp(self):
        super().setUp()
        self.good3 = self.save("good3.npy", np.random.default_rng(1).random((50, 3)))
        self.lab = label_volume(8, 7, 6)
        self.vti = self.p("lab.vti")
        write_vti(self.vti, self.lab)

    def test_bad_selection_and_options(self):
        out = self.p("o.npy")
        self.fails(["sample-image", self.vti, "-o", out, "--select", "1,42"], "unknown label 42", outputs=[out])
        neg = self.save("neg.npy", -np.ones((4, 5), dtype=np.int32))
        self.fails(["sample-image", neg, "-o", out], "empty selection", outputs=[out])
        self.fails(["sample-image", self.vti, "-o", out, "--background-label", "2"], "--background-label")
        self.fails(["sample-image", self.vti, "-o", out, "--step", "1"], "--step")
        self.fails(["sample-image", self.vti, "-o", out, "--probability", "0.8,0.2"], "--probability")
        self.fails(["sample-image", self.vti, "-o", self.p("o.txt")], ".txt")
        self.fails(["sample-image", self.vti, "-o", out, "--output-type", "nope"], "--output-type")
        # --output is the file, as in every command; the selection's old
        # spelling is pointed to its option.
        self.fails(["sample-image", self.vti, "--output", "labelled"], "--output-type labelled")
        self.fails(["sample-image", self.vti, "-o", out, "--output", "background"], "--output-type background")
        self.fails(["sample-image", self.vti, "--output=all", "-o", out], "--output-type all")
        self.ok(["sample-image", self.vti, "--output", self.p("long.ply"), "-q"])
        self.assertTrue(os.path.getsize(self.p("long.ply")) > 0)
        lab = self.save("lab_in.npy", self.lab.astype(np.int32))
        self.fails(["sample-image", lab, "-o", out, "--spacing", "1,2"], "3 values")
        # --spacing / --origin take one comma-separated word: two values no
        # longer swallow the next positional (stop 17), and a wrong count or
        # word is a one-line error.
        im2 = self.save("im2.npy", np.array([[0, 1], [1, 1]], dtype=np.int32))
        pts2 = self.save("p2.npy", np.array([[0.5, 0.5]]))
        self.ok(["sample-image", "--spacing", "1,1", im2, "-o", self.p("ok.npy"), "-q"])
        self.ok(["probe", im2, "--origin", "0,0", pts2, "-o", self.p("pr.npy"), "-q"])
        for bad, what in (("1", "2 or 3"), ("1,2,3,4", "2 or 3"), ("1,x", "'x'"), ("1,nan", "'nan'")):
            self.fails(["sample-image", "--spacing", bad, im2, "-o", out], what, outputs=[out])
        self.fails(["sample-image", im2, "--origin", "1,1,1", "-o", out], "2D image takes 2 values", outputs=[out])
        # Voxel centres past double's range (they were written as inf, exit 0).
        for cmd in (["sample-image", im2, "-o", out], ["surface-nets", "--image", im2, "-o", self.p("s.vtp")]):
            self.fails(cmd + ["--spacing", "1e308,1", "--origin", "1e308,0"], "pass double's range", outputs=[out])
        fl = self.save("float.npy", np.zeros((3, 4, 5)))
        self.fails(["sample-image", fl, "-o", out], "float")

    def test_malformed_and_truncated_images(self):
        out = self.p("o.npy")
        nrrd = self.p("bad.nrrd")
        with open(nrrd, "wb") as f:
            f.write(b"NRRD0004\ntype: short\ndimension: 3\nsizes: 8 7\nencoding: raw\nendian: little\n\n" +
                    bytes(8 * 7 * 6 * 2))
        self.fails(["sample-image", nrrd, "-o", out], "sizes")
        short = self.p("short.nrrd")
        with open(short, "wb") as f:
            f.write(b"NRRD0004\ntype: short\ndimension: 3\nsizes: 8 7 6\nencoding: raw\nendian: little\n\n" +
                    bytes(100))
        self.fails(["sample-image", short, "-o", out], "shorter")
        data = read_bytes(self.vti)
        cut = self.p("cut.vti")
        with open(cut, "wb") as f:
            f.write(data[:len(data) - 60])  # the tail tags and ~30 characters of data
        self.fails(["sample-image", cut, "-o", out], "cut.vti")
        mha = self.p("m.mha")
        with open(mha, "w") as f:
            f.write("ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nTransformMatrix = 0 1 0 1 0 0 0 0 1\n"
                    "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n01234567")
        self.fails(["sample-image", mha, "-o", out], "rotated")
        self.fails(["probe", mha, self.good3, "-o", out], "rotated")
        self.fails(["sample-image", self.p("missing.vti"), "-o", out], "missing.vti")
        # A control character quoted from a header stays on the one error
        # line (a form feed used to break it, stop 17's fuzz), shown as '?'
        # (every InputError's message is printable, since stop 80).
        ff = self.p("ff.vti")
        with open(ff, "wb") as f:
            f.write(data.replace(b'compressor="vtkZLibDataCompressor"', b'compressor="vtk\fZ\x1bLib"', 1))
        self.assertIn(b"vtk\fZ", read_bytes(ff))
        self.fails(["sample-image", ff, "-o", out], "unsupported compressor 'vtk?Z?Lib'")


def main():
    return base.cli_main("test_image_cli.py", [(base.vtk is not None and distance_transform_cdt is not None,
                                                "python3-vtk9 and python3-scipy are required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
