#!/usr/bin/python3
"""Hostile inputs, generated at random from a seed, through every product's
own validation: `voronoi --validate`, `delaunay --validate`, and graph, faces
and flower (which must succeed); also the cells by `--method search` and by
`--method insertion`, whose neighbours must be equal (2D too since stop 52).

Usage: /usr/bin/python3 tests/cli/test_hostile_cli.py PATH_TO_tessera [unittest args...]
  env: TESSERA_HOSTILE_CASES (default 150), TESSERA_HOSTILE_SEED (default 1),
       TESSERA_HOSTILE_SCALE (default 1: 5 to 400 points; 10: up to 4000)

The default run is the regression test (about fifteen seconds); raise the
cases, change the seed or the scale to fuzz. A failing input is kept in a
folder named in the failure message, with the command that failed.

Each kind reproduces an input that once broke Tessera or could: rotated
lattices (coplanar hull faces up to rounding), near-duplicates, powers of ten
from 1e-200 to 1e200 (float sort keys overflowed past 1e19; volumes
underflow), axes scaled up to 1e9 apart, points on a few parallel planes,
a small integer grid offset by 2^50, concentric spheres, clouds far from the origin (few significant bits), a tiny
cluster in a huge cloud, nearly collinear and nearly coplanar points, points
on a sphere with its centre, small integer grids, a bulk with a few far
outliers (up to 1e30 away, and 1e160 to 1e300), magnitudes spread
log-uniformly over 1e-300..1e300, fcc, bcc and hexagonal packings, every point
with a near twin, with random labels on a third of the cases. A quarter of
the cases run again as spheres (power cells and the regular triangulation,
each by both methods): radii at the points' spacing, half zero, two tied
sizes, one sphere far beyond the box (radii up to 1e200 box lengths, whose
squares overflow), all beyond it, and radii near 1e-300. Another quarter
run in a periodic box a little larger than the points (some axes or all,
sheared a third of the time where x and y are periodic): the cells by both
methods, the periodic triangulation, graph and faces; a third of the
orthogonal ones again with the box declared by the file itself (a LAMMPS
dump or an extended XYZ), which must give the same cells. Labelled cases also
build their surface net; one in eight runs fill -> joggle -> voronoi, one in
eight cuts --bounds through the points (--ignore-outside), and one in eight
cuts the box by walls through the points (--wall, --ignore-outside), or by the
points' convex hull (--hull-walls).
The only accepted failures are input errors: a zero extent (all points on
an axis plane, or one point); with radii, input no frame fits and labelled
input whose inside points all have empty power cells; a periodic box's own
(coordinates too coarse for the box, images past double's range or too
many, cells longer than 127 periods); and fill's bins too narrow for the
coordinates' doubles.

Prints "N passed, M failed" last; exits 1 if anything failed.
"""
import os
import shutil
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import test_cli as base  # noqa: E402  (helpers only; its test classes are not collected here)

run = base.run


def lattice(m, d):
    return np.stack(np.meshgrid(*[np.arange(m)] * d), -1).reshape(-1, d).astype(float)


def rotation(rng, d):
    q, _ = np.linalg.qr(rng.normal(size=(d, d)))
    return q


KINDS = ["uniform", "lattice", "rotated_lattice", "rotated_lattice_scaled", "duplicates", "near_duplicates",
         "power_of_ten", "far_from_origin", "cluster_in_cloud", "nearly_collinear", "nearly_flat",
         "sphere_and_centre", "grid_jitter", "small_integers", "far_outliers", "log_uniform",
         "outliers_beyond_frame", "anisotropic", "layers", "big_integers", "concentric_spheres", "piles",
         "packed_lattice", "twins", "rectilinear"]


def generate(kind, rng, n, d):
    """n (about) points of the given kind in d dimensions."""
    if kind == "uniform":
        return rng.random((n, d))
    if kind == "lattice":
        return lattice(int(rng.integers(2, 8)), d)
    if kind == "rotated_lattice":
        return lattice(int(rng.integers(2, 7)), d) @ rotation(rng, d).T
    if kind == "rotated_lattice_scaled":
        return lattice(int(rng.integers(2, 10)), d) @ rotation(rng, d).T * 10.0 ** int(rng.integers(-3, 4))
    if kind == "duplicates":
        p = rng.random((n, d))
        return np.vstack([p, p[rng.integers(0, n, n // 3)]])
    if kind == "near_duplicates":
        p = rng.random((n, d))
        q = p[rng.integers(0, n, n // 3)]
        return np.vstack([p, q + rng.normal(size=q.shape) * 1e-13])
    if kind == "power_of_ten":
        s = 10.0 ** int(rng.integers(-200, 200))
        return (rng.random((n, d)) + 10.0 ** int(rng.integers(-5, 12)) * rng.normal(size=d)) * s
    if kind == "far_from_origin":
        off = 10.0 ** int(rng.integers(3, 15))
        return off + rng.random((n, d)) * off * 1e-9 * 10.0 ** int(rng.integers(-6, 0))
    if kind == "cluster_in_cloud":
        return np.vstack([rng.random((n, d)) * 1e6, 0.5e6 + rng.random((n // 2, d)) * 1e-6])
    if kind == "nearly_collinear":
        p = np.outer(rng.random(n), rng.normal(size=d)) + rng.normal(size=(n, d)) * 1e-12
        p[:4] += rng.random((4, d))
        return p
    if kind == "nearly_flat":
        p = rng.random((n, d))
        p[:, -1] *= 1e-9
        return p
    if kind == "sphere_and_centre":
        v = rng.normal(size=(min(n, 120), d))
        return np.vstack([v / np.linalg.norm(v, axis=1)[:, None], np.zeros((1, d))])
    if kind == "grid_jitter":
        g = lattice(int(rng.integers(2, 7)), d)
        return g + rng.normal(size=g.shape) * 1e-15
    if kind == "far_outliers":
        # A bulk large enough for the locator to tell it from its outliers
        # (grid_box samples 256 points or more), and one to three points
        # 10 to 1e30 bulk widths away in random directions.
        p = rng.random((max(n, 300), d))
        k = int(rng.integers(1, 4))
        far = rng.normal(size=(k, d)) * 10.0 ** rng.integers(1, 31, size=(k, 1))
        return np.vstack([p, far])
    if kind == "log_uniform":
        # Magnitudes spread over 600 decades in random directions: no
        # power-of-two frame fits (the insertion failed here, stop 52).
        return 10.0 ** rng.uniform(-300, 300, size=(n, 1)) * rng.normal(size=(n, d))
    if kind == "outliers_beyond_frame":
        # A unit bulk beside points 1e160 to 1e300 away: no frame fits either.
        p = rng.random((max(n, 300), d))
        k = int(rng.integers(1, 4))
        return np.vstack([p, rng.normal(size=(k, d)) * 10.0 ** rng.uniform(160, 300, size=(k, 1))])
    if kind == "small_integers":
        return rng.integers(0, 4, size=(n, d)).astype(float)
    if kind == "anisotropic":
        # Each axis scaled by its own power of ten, up to 1e9 apart (a core
        # sample, a wire, a slab of voxels 1e-8 thick).
        return rng.random((n, d)) * 10.0 ** rng.integers(-9, 10, size=d)
    if kind == "layers":
        # Points on a few parallel lines or planes (CT slices, scan lines,
        # stacked contours): the last coordinate takes one of a few exact
        # values, the others are random.
        p = rng.random((n, d))
        p[:, -1] = rng.integers(0, int(rng.integers(2, 6)), n) * 0.1
        return p
    if kind == "big_integers":
        # A small integer grid offset by 2^50 (cell ties where a double has
        # two fractional bits left).
        return rng.integers(0, 5, size=(n, d)).astype(float) + 2.0 ** 50
    if kind == "concentric_spheres":
        # Points on two to four spheres about one centre (shells of a
        # simulation): every sphere cospherical up to rounding.
        v = rng.normal(size=(min(n, 200), d))
        v /= np.linalg.norm(v, axis=1)[:, None]
        return v * rng.integers(1, 5, size=(len(v), 1))
    if kind == "piles":
        # One to three points each repeated ten times n, shuffled among the
        # rest (a sensor stuck on one reading, a padded array): a pile of
        # 60,000 copies took 97 s, 70,000 beside distinct points broke the
        # face limit, before the pass left duplicates out of the locator.
        p = rng.random((n, d))
        piles = np.repeat(p[rng.integers(0, n, int(rng.integers(1, 4)))], 10 * n, axis=0)
        return rng.permutation(np.vstack([p, piles]))
    if kind == "packed_lattice":
        # Crystal packings (granular and materials inputs): fcc or bcc in
        # 3D, hexagonal in 2D, whose cells meet in many cospherical
        # (cocircular) sets at once; rotated half the time, so the ties hold
        # only up to rounding.
        m = int(rng.integers(2, 6)) if d == 3 else int(rng.integers(3, 16))
        b = lattice(m, d)
        if d == 3:
            shifts = [[0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]] if rng.integers(0, 2) else [[0.5, 0.5, 0.5]]
            p = np.vstack([b] + [b + s for s in shifts])
        else:
            p = np.column_stack([b[:, 0] + 0.5 * (b[:, 1] % 2), b[:, 1] * np.sqrt(3) / 2])
        return p @ rotation(rng, d).T if rng.integers(0, 2) else p
    if kind == "twins":
        # Every point with a twin 1e-15 to 1e-9 away (a merged pair of
        # scans, a particle output written twice with noise).
        p = rng.random((n, d))
        return np.vstack([p, p + rng.normal(size=p.shape) * 10.0 ** int(rng.integers(-15, -8))])
    if kind == "rectilinear":
        # Voxel centres and rectilinear grids: each axis's coordinates from a
        # list of its own, with uneven full-mantissa steps (a scan at 0.7 x
        # 0.7 x 1.2 mm, a stretched CFD grid), at a random scale and offset,
        # some points dropped (a sampled label image). Every cell corner is a
        # tie at the corners of an axis-aligned box.
        m = int(rng.integers(2, 7)) if d == 3 else int(rng.integers(3, 20))
        s = 10.0 ** int(rng.integers(-6, 7))
        axes = [s * (rng.normal() * 1e3 + np.cumsum(rng.uniform(0.3, 1.7, m))) for _ in range(d)]
        p = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, d)
        keep = rng.random(len(p)) < rng.uniform(0.5, 1.0)
        return rng.permutation(p[keep] if keep.sum() > d + 1 else p)
    raise ValueError(kind)


# A periodic box's own input errors: coordinates too coarse for the box's
# doubles (a box 1e-9 wide at 1e6), images past double's range, more images
# than 32-bit ids or memory allow (heights tiny next to the cells), and
# cells reaching past the 127 box lengths an int8 shift can name.
PERIODIC_REFUSALS = ("too thin for its coordinates", "images overflow double", "with their periodic images",
                     "images of its", "reaches past 127 box lengths")

RADII_KINDS = ["spacing", "zeros", "tied", "one_huge", "all_huge", "tiny"]


def hostile_radii(kind, rng, pts):
    """Radii for power cells and regular triangulations, relative to the
    points' extent and spacing (the point kinds span 1e-200..1e200)."""
    n, d = pts.shape
    extent = float(np.max(np.ptp(pts, axis=0))) if n > 1 else 1.0
    extent = extent if np.isfinite(extent) and extent > 0 else 1.0
    s = extent * n ** (-1.0 / d)
    if kind == "spacing":  # polydisperse spheres, up to overlapping ones
        return rng.random(n) * s * float(rng.choice([0.1, 0.5, 2.0]))
    if kind == "zeros":  # ordinary points among spheres: ties between zero radii
        r = rng.random(n) * s
        r[rng.random(n) < 0.6] = 0.0
        return r
    if kind == "tied":  # two sizes (a binary packing): power ties on lattices
        return rng.choice([0.2, 0.35], n) * s
    if kind == "one_huge":  # one sphere owns the box (or everything): up to radii whose squares overflow
        r = rng.random(n) * s * 0.3
        r[int(rng.integers(0, n))] = extent * 10.0 ** int(rng.integers(0, 200))
        return r
    if kind == "all_huge":  # weights far beyond the box, differing in their last bits relative to it
        return extent * 10.0 ** int(rng.integers(1, 100)) * (1 + rng.random(n) * 1e-9)
    if kind == "tiny":  # radii at the bottom of double's range
        return rng.random(n) * 1e-300
    raise ValueError(kind)


# Power cells need a power-of-two frame for their exact weights: inputs that
# span more than ~1e-150..1e150 are refused for radii (an input error); and
# where one outside point's sphere takes the whole box, no inside point has
# a cell (an input error too).
RADII_REFUSALS = ("need coordinates within", "has an empty power cell")
# --bounds cut through the points: none left inside, or none with a label >= 0.
CUT_REFUSALS = ("all points lie outside", "none inside", "none of the")
ZERO_EXTENT = ("zero extent", "coplanar", "collinear", "--dim 2", "single point", "one point")


class Hostile(base.TempDirCase):
    def both_methods(self, args, tag, inp, labels, what, d, case, extra_out=(), **check_kw):
        """voronoi ARGS by --method search and by insertion, validated, each
        writing --neighbors (and every option of extra_out, such as
        --neighbor-shifts) to files of its own: they must agree. Returns the
        search run's files by option, or None where the input was refused."""
        out = {}
        for method in ("search", "insertion"):
            files = {o: self.p("%s%s_%s.npy" % (tag, o.strip("-").replace("-", "_"), method))
                     for o in ("--neighbors",) + tuple(extra_out)}
            run_args = ["voronoi"] + args + ["--method", method, "--validate"]
            for o, f in files.items():
                run_args += [o, f]
            if not self.check(run_args, inp, labels, what, d, case, **check_kw):
                return None
            out[method] = files
        for o in out["search"]:
            self.assertTrue(np.array_equal(np.load(out["search"][o]), np.load(out["insertion"][o])),
                            "case %d (%s): %s by search and by insertion differ" % (case, what, o))
        return out["search"]

    def check(self, args, inp, labels, kind, d, case, radii=None, periodic=False, accept=()):
        r = run(args)
        if r.returncode == 2 and any(w in r.stderr for w in ZERO_EXTENT + tuple(accept)):
            return False
        if periodic and r.returncode == 2 and any(w in r.stderr for w in PERIODIC_REFUSALS):
            return False
        if radii is not None and r.returncode == 2 and any(w in r.stderr for w in RADII_REFUSALS):
            return False
        if r.returncode != 0:
            keep = tempfile.mkdtemp(prefix="tessera-hostile-")
            shutil.copy(inp, keep)
            for extra in (labels, radii):
                if extra:
                    shutil.copy(extra, keep)
            self.fail("case %d (%s, %dD): tessera %s -> exit %d\n%s%s\ninput kept in %s" % (
                case, kind, d, " ".join(map(str, args)), r.returncode, r.stdout[-2000:], r.stderr[-2000:], keep))
        return True

    def test_hostile_inputs(self):
        cases = int(os.environ.get("TESSERA_HOSTILE_CASES", "150"))
        rng = np.random.default_rng(int(os.environ.get("TESSERA_HOSTILE_SEED", "1")))
        scale = int(os.environ.get("TESSERA_HOSTILE_SCALE", "1"))
        names = sorted(KINDS)
        for case in range(cases):
            kind = names[case % len(names)]
            d = 2 + int(rng.integers(0, 2))
            n = int(rng.integers(5, 400)) * scale
            pts = np.ascontiguousarray(generate(kind, rng, n, d), dtype="<f8")
            inp = self.save("case%d.npy" % case, pts)
            args_labels = []
            labels = None
            # A third of the cases, rotating through the kinds round by round
            # (case % 3 alone labelled only the 7 kinds at 2 mod 3 of the 21).
            if (case + case // len(names)) % 3 == 2:
                lab = rng.integers(-1, 3, len(pts)).astype(np.int32)
                lab[0] = 0
                labels = self.save("case%d_labels.npy" % case, lab)
                args_labels = ["--labels", labels]
            threads = str(int(rng.integers(1, 3)))
            common = [inp, "--threads", threads, "--quiet"] + args_labels
            out = self.p("c.vtu" if d == 3 else "c.vtp")
            if not self.check(["voronoi"] + common + ["-o", out, "--validate"], inp, labels, kind, d, case):
                continue  # a zero extent: every product refuses it alike
            tri = self.p("t.npy")
            made = self.check(["delaunay"] + common + ["-o", self.p("t.vtu"), "--simplices", tri, "--validate"],
                              inp, labels, kind, d, case)
            if made and case % 3 == 0:
                self.check_alpha(case, kind, d, pts, inp, labels, common, tri, rng)
            if made and labels:
                # Labelled: the whole triangulation's inside rows, whichever way it came.
                whole = self.p("whole.npy")
                unlabelled = [inp, "--threads", threads, "--quiet"]
                if self.check(["delaunay"] + unlabelled + ["--simplices", whole], inp, None, kind, d, case):
                    w = np.load(whole)
                    inside = (lab[w] >= 0).all(axis=1) if len(w) else np.zeros(0, bool)
                    self.assertTrue(np.array_equal(np.load(tri), w[inside]),
                                    "case %d (%s): labelled simplices are not the whole triangulation's inside ones"
                                    % (case, kind))
            # The cells from the Delaunay triangulation are the searched ones.
            self.both_methods(common, "", inp, labels, kind, d, case)
            if case % 4 == 0:
                self.check(["graph"] + common + ["-o", self.p("g.vtp")], inp, labels, kind, d, case)
                for k in ("complex", "boundary", "surface-net"):
                    self.check(["faces"] + common + ["-o", self.p("f.vtp"), "--kind", k], inp, labels, kind, d, case)
                self.check(["flower"] + common + ["--point", "0", "-o", self.p("fl.vtp")], inp, labels, kind, d, case)
            # A quarter of the cases, rotating through the kinds: the same
            # points as spheres (power cells, the regular triangulation).
            if (case + case // len(names)) % 4 == 1:
                self.check_power(case, kind, d, pts, inp, labels, common, rng)
            # Another quarter: the points in a periodic box around them.
            if (case + case // len(names)) % 4 == 3:
                self.check_periodic(case, kind, d, pts, inp, labels, threads, rng)
            # Labelled cases: the surface net (capped half the time); one
            # case in eight runs the pipeline fill -> joggle -> cells.
            if labels and case % 2 == 0:
                net = ["surface-nets"] + common + ["-o", self.p("sn.vtp")]
                net += ["--capping"] if rng.random() < 0.5 else []
                net += ["--triangles"] if d == 3 and rng.random() < 0.5 else []
                self.check(net, inp, labels, kind, d, case)
            if case % 8 == 6:
                self.check_pipeline(case, kind, d, inp, labels, threads)
            if case % 8 == 2:
                self.check_cut_bounds(case, kind, d, pts, inp, labels, common, rng)
            if case % 8 == 4:
                self.check_walls(case, kind, d, pts, inp, labels, common, rng)
            if case % 4 == 2:
                self.check_sphere(case, kind, d, pts, threads)

    def check_sphere(self, case, kind, d, pts, threads):
        """The points pushed onto a sphere around their mean (3D), or read as
        longitudes and latitudes (2D, scaled into range): the cells tile the
        sphere (areas add to 4 pi R^2), the hull is simplicial (2 cells - 4
        triangles), the adjacency is symmetric."""
        if d == 3:
            c = pts.mean(axis=0)
            v = pts - c
            norm = np.linalg.norm(v, axis=1)
            if not np.isfinite(norm).all() or not (norm > 0).all():
                return
            sp = c + v / norm[:, None]
            args = ["--center"] + [repr(float(x)) for x in c] + ["--radius", "1", "--tolerance", "inf"]
        else:
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            span = np.where(hi > lo, hi - lo, 1.0)
            sp = (pts - lo) / span * [360.0, 180.0] - [180.0, 90.0]
            sp = np.clip(sp, [-180.0, -90.0], [180.0, 90.0])
            args = ["--lonlat"]
        if not np.isfinite(sp).all():
            return
        inp = self.save("case%d_sphere.npy" % case, np.ascontiguousarray(sp, dtype="<f8"))
        table, nb, tri = self.p("st.npy"), self.p("snb.npy"), self.p("stri.npy")
        if not self.check(["sphere", inp, "--threads", threads, "--quiet", "--cell-table", table, "--neighbors", nb,
                           "--triangles", tri] + args, inp, None, kind, d, case, accept=("at the centre",)):
            return
        t = np.load(table)
        what = "case %d (%s, %dD): sphere" % (case, kind, d)
        self.assertAlmostEqual(t[:, 1].sum() / (4 * np.pi), 1.0, places=9, msg=what)
        a = np.load(nb)
        n = int(a[0])
        off, ids = a[1:n + 2], a[n + 2:]
        pairs = {(i, int(j)) for i in range(n) for j in ids[off[i]:off[i + 1]]}
        self.assertEqual(pairs, {(j, i) for i, j in pairs}, what)
        if len(t) >= 3:
            self.assertEqual(len(np.load(tri)), 2 * len(t) - 4, what)

    def check_alpha(self, case, kind, d, pts, inp, labels, common, tri, rng):
        """The alpha shape at a radius among the simplices' (a quantile of
        their float circumradii): kept simplices are rows of the
        triangulation, the boundary is the facets one kept simplex has, each
        directed edge (2D: each vertex) as often entered as left; with the
        singular facets after it, none of them a kept simplex's facet."""
        rows = np.load(tri)
        if len(rows) == 0:
            return
        q = pts[rows]
        e = q[:, 1:] - q[:, :1]
        with np.errstate(all="ignore"):
            try:
                c = np.linalg.solve(e, 0.5 * (e * e).sum(axis=2)[..., None])[..., 0]
                r = np.sqrt((c * c).sum(axis=1))
            except np.linalg.LinAlgError:
                r = np.full(len(rows), np.nan)
        r = r[np.isfinite(r)]
        alpha = float(np.quantile(r, rng.uniform(0.2, 0.9))) if len(r) else 1.0
        k, b, bs = self.p("ak.npy"), self.p("ab.npy"), self.p("abs.npy")
        if not self.check(["delaunay"] + common + ["--alpha", repr(alpha), "--simplices", k, "--boundary", b,
                                                   "--regularized"], inp, labels, kind, d, case):
            return
        self.check(["delaunay"] + common + ["--alpha", repr(alpha), "--boundary", bs], inp, labels, kind, d, case)
        kept, bnd, both = np.load(k), np.load(b), np.load(bs)
        what = "case %d (%s, %dD, alpha %r)" % (case, kind, d, alpha)
        all_rows = set(map(tuple, np.sort(rows, axis=1)))
        self.assertTrue(set(map(tuple, np.sort(kept, axis=1))) <= all_rows, what + ": kept rows not in the triangulation")
        facets = np.concatenate([np.delete(kept, j, axis=1) for j in range(d + 1)]) if len(kept) else np.zeros((0, d), int)
        u, count = np.unique(np.sort(facets, axis=1), axis=0, return_counts=True)
        self.assertEqual(set(map(tuple, np.sort(bnd, axis=1))), set(map(tuple, u[count == 1])), what + ": boundary")
        if d == 3:
            directed = np.concatenate([bnd[:, [0, 1]], bnd[:, [1, 2]], bnd[:, [2, 0]]])
            fwd = sorted(map(tuple, directed))
            rev = sorted(map(tuple, directed[:, ::-1]))
            self.assertEqual(fwd, rev, what + ": boundary not closed and oriented")
        else:
            self.assertEqual(sorted(bnd[:, 0].tolist()), sorted(bnd[:, 1].tolist()), what + ": rings not closed")
        np.testing.assert_array_equal(both[:len(bnd)], bnd)
        singular = set(map(tuple, np.sort(both[len(bnd):], axis=1)))
        self.assertFalse(singular & set(map(tuple, u)), what + ": a singular facet belongs to a kept simplex")

    def check_walls(self, case, kind, d, pts, inp, labels, common, rng):
        """One to four walls through the point cloud (random normals, each
        offset at a quantile of the points along it; half the time a wall
        through a point, whose offset is then exact only where its products
        are) with --ignore-outside: the cells by both methods, validated
        (the volumes against the polytope's, sampled cells exactly), the
        same neighbours; the graph and the boundary. Two cases in five take
        the points' convex hull as walls instead (--hull-walls, dilated half
        the time: thousands of walls go through the wall index); half the
        others give their walls in a file (--walls, .npy or text)."""
        walls = []
        if rng.random() < 0.4:
            walls = ["--hull-walls"]
            finite = pts[np.all(np.isfinite(pts), axis=1)]
            extent = float(np.max(np.ptp(finite, axis=0))) if len(finite) else 0.0
            if rng.random() < 0.5 and np.isfinite(extent) and extent > 0:
                walls += ["--hull-dilation", repr(float(rng.uniform(0, 0.05)) * extent)]
        for _ in range(0 if walls else int(rng.integers(1, 5))):
            n = rng.normal(size=d)
            if rng.random() < 0.3:
                n[int(rng.integers(0, d))] = 0.0  # parallel to an axis
            if not np.any(n):
                n[0] = 1.0
            along = pts @ n
            finite = along[np.isfinite(along)]
            if len(finite) == 0:
                return
            if rng.random() < 0.5:
                off = float(np.quantile(finite, rng.uniform(0.3, 1.0)))
            else:
                off = float(finite[int(rng.integers(0, len(finite)))])
            walls += ["--wall", ",".join(repr(float(x)) for x in list(n) + [off])]
        if walls and walls[0] == "--wall" and rng.random() < 0.5:  # the same walls from a file (--walls)
            rows = np.array([[float(x) for x in w.split(",")] for w in walls[1::2]])
            if rng.random() < 0.5:
                np.save(self.p("walls.npy"), rows)
                walls = ["--walls", self.p("walls.npy")]
            else:
                with open(self.p("walls.txt"), "w") as f:
                    f.write("# nx ny [nz] d\n" + "".join(" ".join(repr(x) for x in r) + "\n" for r in rows))
                walls = ["--walls", self.p("walls.txt")]
        wc = common + walls + ["--ignore-outside"]
        accept = CUT_REFUSALS + ("its offset", "its normal's components", "--hull-walls: the points span no",
                                 "--hull-walls: a hull facet's normal", "--hull-walls: a wall's offset")
        if self.both_methods(wc, "w", inp, labels, "%s, walls %s" % (kind, walls), d, case, accept=accept) is None:
            return
        self.check(["graph"] + wc + ["-o", self.p("wg.vtp")], inp, labels, kind, d, case, accept=accept)
        self.check(["faces"] + wc + ["-o", self.p("wf.vtp"), "--kind", "boundary"], inp, labels, kind, d, case,
                   accept=accept)

    def check_cut_bounds(self, case, kind, d, pts, inp, labels, common, rng):
        """--bounds through the point cloud with --ignore-outside: the
        points outside are dropped and listed, the rest give cells by both
        methods (validated, the same neighbours) and a triangulation."""
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        ext = hi - lo
        if not (np.all(np.isfinite(ext)) and np.all(ext > 0)):
            return
        cut = rng.uniform(0.05, 0.4, size=(2, d)) * ext
        bounds = [str(float(x)) for a in range(d) for x in (lo[a] + cut[0][a], hi[a] - cut[1][a])]
        bc = common + ["--bounds"] + bounds + ["--ignore-outside"]
        # All points outside the cut box (a cluster at one end), or all that
        # the cut keeps labelled outside, is an input error.
        if self.both_methods(bc, "b", inp, labels, kind + ", cut bounds", d, case, accept=CUT_REFUSALS) is None:
            return
        self.check(["delaunay"] + bc + ["--simplices", self.p("bt.npy"), "--validate"], inp, labels, kind, d, case,
                   accept=CUT_REFUSALS)

    def check_pipeline(self, case, kind, d, inp, labels, threads):
        """fill (background points in the empty bins) -> joggle -> voronoi
        --validate, as a user carving a concave shape does."""
        filled = self.p("filled.npy")
        lab = ["--labels", labels] if labels else []
        # fill's own refusal: bins too narrow for the coordinates' doubles
        # (points far from the origin), where a bin centre could round onto a point.
        if not self.check(["fill", inp, "-o", filled, "--quiet", "--threads", threads] + lab, inp, labels, kind, d, case,
                          accept=("of double's resolution",)):
            return
        joggled = self.p("joggled.npy")
        if not self.check(["joggle", filled, "-o", joggled, "--quiet", "--labels", self.p("filled_labels.npy")],
                          inp, labels, kind, d, case):
            return
        self.check(["voronoi", joggled, "--labels", self.p("joggled_labels.npy"), "--threads", threads, "--quiet",
                    "--neighbors", self.p("jn.npy"), "--validate"], inp, labels, kind, d, case)

    def check_periodic(self, case, kind, d, pts, inp, labels, threads, rng):
        """The cells in a periodic box a little larger than the points'
        (some axes, or all; sheared where x and y are periodic): by both
        methods (validated, the same neighbours and shifts), the periodic
        triangulation where every axis is periodic, graph and faces."""
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        ext = hi - lo
        if not (np.all(np.isfinite(ext)) and np.all(ext > 0)):
            return  # a zero extent along some axis: the plain runs refused it
        pad = ext * float(rng.choice([0.01, 0.1, 0.5]))
        bounds = [str(float(x)) for a in range(d) for x in (lo[a] - pad[a], hi[a] + pad[a])]
        axes = "xyz"[:d] if rng.random() < 0.5 else "".join(a for a in "xyz"[:d] if rng.random() < 0.6) or "x"
        pc = [inp, "--threads", threads, "--quiet", "--bounds"] + bounds + ["--periodic", axes]
        if "x" in axes and "y" in axes and rng.random() < 0.3:
            lx, ly = ext[0] + 2 * pad[0], ext[1] + 2 * pad[1]
            pc += ["--tilt", str(0.3 * lx)] + ([] if d == 2 else
                                                [str(0.2 * lx) if "z" in axes else "0", str(-0.25 * ly) if "z" in axes else "0"])
        lab = ["--labels", labels] if labels else []
        what = "%s, periodic %s" % (kind, " ".join(pc[pc.index("--periodic") + 1:]))
        files = self.both_methods(pc + lab, "q", inp, labels, what, d, case, extra_out=("--neighbor-shifts",),
                                  periodic=True)
        if files is None:
            return
        if "--tilt" not in pc and case % 3 == 0 and np.all(np.isfinite(pts)):
            self.check_file_box(case, d, pts, labels, bounds, axes, threads, files["--neighbors"],
                                files["--neighbor-shifts"], what)
        if len(axes) == d and (labels is None or (np.load(labels) >= 0).all()):
            if self.check(["delaunay"] + pc + ["--simplices", self.p("qt.npy"), "--simplex-shifts", self.p("qs.npy"),
                                               "--validate"], inp, labels, what, d, case, periodic=True):
                # Its alpha shape at a size among the box's: the kept rows
                # (with their shifts) are rows of the triangulation.
                extent = float(np.min(np.asarray(bounds[1::2], float) - np.asarray(bounds[0::2], float)))
                alpha = extent * float(rng.uniform(0.01, 0.3))
                if self.check(["delaunay"] + pc + ["--alpha", repr(alpha), "--simplices", self.p("qk.npy"),
                                                   "--simplex-shifts", self.p("qks.npy")],
                              inp, labels, what, d, case, periodic=True):
                    rows = {tuple(r) + tuple(s.ravel()) for r, s in zip(np.load(self.p("qt.npy")), np.load(self.p("qs.npy")))}
                    kept = [tuple(r) + tuple(s.ravel()) for r, s in zip(np.load(self.p("qk.npy")), np.load(self.p("qks.npy")))]
                    self.assertTrue(set(kept) <= rows, "case %d (%s): periodic alpha rows not the triangulation's" % (case, what))
        if case % 2 == 1:
            self.check(["graph"] + pc + lab + ["-o", self.p("qg.vtp")], inp, labels, what, d, case, periodic=True)
            self.check(["faces"] + pc + lab + ["-o", self.p("qf.vtp"), "--kind", "complex"],
                       inp, labels, what, d, case, periodic=True)

    def check_file_box(self, case, d, pts, labels, bounds, axes, threads, nb, sh, what):
        """The same periodic box declared by the input file itself, a LAMMPS
        dump (even cases) or an extended XYZ (odd), its coordinates written
        to round-trip: the cells' neighbours and shifts are the explicit
        run's, with no --bounds/--periodic given."""
        lo = [float(bounds[2 * a]) for a in range(d)] + ([] if d == 3 else [-0.5])
        hi = [float(bounds[2 * a + 1]) for a in range(d)] + ([] if d == 3 else [0.5])
        # The lengths hi - lo are what the file can say: where they round,
        # the box is another one (an input this check cannot compare).
        if any(lo[a] + (hi[a] - lo[a]) != hi[a] for a in range(3)):
            return
        per = [("xyz"[a] in axes) for a in range(3)]
        xyz = np.c_[pts, np.zeros(len(pts))] if d == 2 else pts
        lab = np.load(labels) if labels else np.zeros(len(pts), dtype=np.int64)
        if case % 2 == 0:
            path = self.p("box%d.dump" % case)
            with open(path, "w") as f:
                f.write("ITEM: TIMESTEP\n%d\nITEM: NUMBER OF ATOMS\n%d\nITEM: BOX BOUNDS %s\n" % (
                    case, len(pts), " ".join("pp" if q else "ff" for q in per)))
                for a in range(3):
                    f.write("%r %r\n" % (lo[a], hi[a]))
                f.write("ITEM: ATOMS id type x y z\n")
                for k in range(len(pts)):
                    f.write("%d %d %r %r %r\n" % (k + 1, lab[k], xyz[k, 0], xyz[k, 1], xyz[k, 2]))
        else:
            path = self.p("box%d.xyz" % case)
            with open(path, "w") as f:
                f.write("%d\nLattice=\"%r 0 0 0 %r 0 0 0 %r\" Origin=\"%r %r %r\" pbc=\"%s\" "
                        "Properties=species:S:1:pos:R:3:type:I:1\n" % (
                            len(pts), hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], lo[0], lo[1], lo[2],
                            " ".join("T" if q else "F" for q in per)))
                for k in range(len(pts)):
                    f.write("Ar %r %r %r %d\n" % (xyz[k, 0], xyz[k, 1], xyz[k, 2], lab[k]))
        fnb, fsh = self.p("fnb.npy"), self.p("fsh.npy")
        args = ["voronoi", path, "--threads", threads, "--quiet", "--neighbors", fnb, "--neighbor-shifts", fsh,
                "--validate"] + (["--dim", "2"] if d == 2 else []) + (["--labels", "type"] if labels else [])
        if not self.check(args, path, None, what + ", box from the file", d, case, periodic=True):
            return
        self.assertTrue(np.array_equal(np.load(fnb), np.load(nb)) and np.array_equal(np.load(fsh), np.load(sh)),
                        "case %d (%s): the file's own box gave other cells than the options" % (case, what))

    def check_power(self, case, kind, d, pts, inp, labels, common, rng):
        """Power cells by both methods (validated, the same neighbours), the
        regular triangulation by both methods (validated, the same rows), and
        the graph and faces of the power cells."""
        rkind = RADII_KINDS[(case // 4) % len(RADII_KINDS)]
        radii = self.save("case%d_radii.npy" % case, np.ascontiguousarray(hostile_radii(rkind, rng, pts), dtype="<f8"))
        what = "%s, radii %s" % (kind, rkind)
        pc = common + ["--radii", radii]
        if self.both_methods(pc, "p", inp, labels, what, d, case, radii=radii) is None:
            return  # refused (no frame, or a zero extent): every product refuses it alike
        rows = {}
        for method in ("cells", "insertion"):
            rows[method] = self.p("prt_%s.npy" % method)
            if not self.check(["delaunay"] + pc + ["--method", method, "--simplices", rows[method], "--validate"],
                              inp, labels, what, d, case, radii):
                return
        self.assertTrue(np.array_equal(np.load(rows["cells"]), np.load(rows["insertion"])),
                        "case %d (%s): regular triangulations by the cells and by insertion differ" % (case, what))
        if case % 2 == 0:
            self.check(["graph"] + pc + ["-o", self.p("pg.vtp")], inp, labels, what, d, case, radii)
            for k in ("complex", "boundary"):
                self.check(["faces"] + pc + ["-o", self.p("pf.vtp"), "--kind", k], inp, labels, what, d, case, radii)


def main():
    return base.cli_main("test_hostile_cli.py", [(base.vtk is not None, "python3-vtk9 is required (run with /usr/bin/python3)")])


if __name__ == "__main__":
    sys.exit(main())
