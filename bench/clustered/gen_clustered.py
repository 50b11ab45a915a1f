#!/usr/bin/python3
"""Strongly clustered 3D point sets, harder than gen_points.py's clustered3,
and points sampled on surfaces (scans, terrain, mesh vertices).

Usage: gen_clustered.py KIND N OUT.npy [--seed S]

Kinds (float64, shape (N, 3); about the unit cube, a few blob and hierarchy
points a little outside it):
  blobs  90% of the points in sqrt(N)/4 Gaussian blobs of sigma 1e-3..5e-3,
         10% uniform background (cosmology-like halos in a void).
  sheet  80% in a thin sheet z = 0.5 + N(0, 1e-3), 20% uniform background
         (a wall or a fracture surface).
  hier   a Soneira-Peebles hierarchy: 6 levels, 6 children per point, each
         level's radius 1/1.9 of the one above (fractal clustering; the
         surplus points are dropped, a shortfall filled uniformly).

Surface samples (no background; every cell is a needle reaching through
the object or to the domain box):
  terrain    a height field z = 0.1 sin(6x) cos(4y) over the unit square.
  ellipsoid  uniform in the parameters of an ellipsoid of semi-axes 1, 0.7, 0.4.
  torus      a torus of radii 1 and 0.35 (a tube: its inner cells' petals
             touch the surface along whole circles, the hardest case).

Near-degenerate sets (ties to within rounding everywhere; docs/design.md,
"Stalls, ties and the automatic method"): N is rounded to a cube k^3.
  latrot     the k^3 integer lattice rotated by 0.3 rad about z, then 0.7 rad
             about x (a crystal in lab coordinates: every hull face and every
             cube of neighbours coplanar or cospherical to within rounding).
  latjit     the k^3 integer lattice, each coordinate moved by up to 1e-9
             (a lattice with float noise).
  sphere     N points uniform on the unit sphere (every point on the hull,
             all nearly cospherical with the centre).
  lat01      the k^3 lattice of spacing 0.1 (0.1 * i in doubles): every cube
             corner an exact tie, every coordinate a full mantissa, so no
             small integer grid holds them.
  voxels     voxel centres of a scan: origin (-20.5, -18.25, -30.1), spacing
             (0.7, 0.7, 1.2) mm, k^3 of them (exact ties off any small grid,
             as lat01, on an anisotropic lattice).

2D (shape (N, 2); run.sh times them against CGAL's and scipy's 2D peers):
  circle2    N points uniform on the unit circle (every cell a needle
             reaching the centre, where all points are nearly co-circular).
  curves2    N points on 12 circles of radii 0.05-0.27 in a 4 x 3 grid,
             moved by N(0, 1e-4) (contour lines, particle tracks).
  blobs2     as blobs, in the unit square.
"""
import argparse

import numpy as np


def blobs(rng, n, dim=3):
    c = max(1, int(np.sqrt(n) / 4))
    centres = rng.random((c, dim))
    sigma = rng.uniform(1e-3, 5e-3, c)
    m = int(0.9 * n)
    lab = rng.integers(0, c, m)
    return np.vstack([centres[lab] + rng.normal(size=(m, dim)) * sigma[lab, None], rng.random((n - m, dim))])


def sheet(rng, n):
    m = int(0.8 * n)
    q = rng.random((m, 3))
    q[:, 2] = 0.5 + rng.normal(size=m) * 1e-3
    return np.vstack([q, rng.random((n - m, 3))])


def hier(rng, n, levels=6, children=6, ratio=1.9):
    pts = np.array([[0.5, 0.5, 0.5]])
    r = 0.5
    for _ in range(levels):
        r /= ratio
        d = rng.normal(size=(len(pts) * children, 3))
        d /= np.linalg.norm(d, axis=1)[:, None]
        d *= (rng.random(len(d)) ** (1 / 3) * r)[:, None]
        pts = np.repeat(pts, children, axis=0) + d
    pts = pts[rng.permutation(len(pts))][:n]
    return np.vstack([pts, rng.random((max(0, n - len(pts)), 3))])


def terrain(rng, n):
    x, y = rng.random(n), rng.random(n)
    return np.column_stack([x, y, 0.1 * np.sin(6 * x) * np.cos(4 * y)])


def ellipsoid(rng, n):
    z, t = 2 * rng.random(n) - 1, 2 * np.pi * rng.random(n)
    r = np.sqrt(1 - z * z)
    return np.column_stack([r * np.cos(t), 0.7 * r * np.sin(t), 0.4 * z])


def torus(rng, n):
    a, b = 2 * np.pi * rng.random(n), 2 * np.pi * rng.random(n)
    ring = 1 + 0.35 * np.cos(b)
    return np.column_stack([ring * np.cos(a), ring * np.sin(a), 0.35 * np.sin(b)])


def _lattice(n):
    k = max(2, round(n ** (1 / 3)))
    return np.stack(np.meshgrid(*[np.arange(k, dtype=float)] * 3, indexing="ij"), -1).reshape(-1, 3)


def latrot(rng, n):
    a, b = 0.3, 0.7
    rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(b), -np.sin(b)], [0, np.sin(b), np.cos(b)]])
    return _lattice(n) @ (rz @ rx).T


def latjit(rng, n):
    g = _lattice(n)
    return g + rng.uniform(-1e-9, 1e-9, g.shape)


def lat01(rng, n):
    return 0.1 * _lattice(n)


def voxels(rng, n):
    return np.array([-20.5, -18.25, -30.1]) + np.array([0.7, 0.7, 1.2]) * _lattice(n)


def sphere(rng, n):
    p = rng.normal(size=(n, 3))
    return p / np.linalg.norm(p, axis=1)[:, None]


def circle2(rng, n):
    t = rng.random(n) * 2 * np.pi
    return np.c_[np.cos(t), np.sin(t)]


def curves2(rng, n):
    c = np.arange(n) % 12
    t = rng.random(n) * 2 * np.pi
    r = 0.05 + 0.02 * c
    return np.c_[0.3 * (c % 4) + r * np.cos(t), 0.4 * (c // 4) + r * np.sin(t)] + rng.normal(size=(n, 2)) * 1e-4


def blobs2(rng, n):
    return blobs(rng, n, dim=2)


KINDS = {"blobs": blobs, "sheet": sheet, "hier": hier, "terrain": terrain, "ellipsoid": ellipsoid, "torus": torus,
         "latrot": latrot, "latjit": latjit, "sphere": sphere, "lat01": lat01, "voxels": voxels,
         "circle2": circle2, "curves2": curves2, "blobs2": blobs2}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("kind", choices=list(KINDS))
    ap.add_argument("n", type=float)
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=7)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    n = int(a.n)
    p = KINDS[a.kind](rng, n)
    np.save(a.out, np.ascontiguousarray(p, dtype="<f8"))


if __name__ == "__main__":
    main()
