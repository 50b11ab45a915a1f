#!/usr/bin/python3
"""Generate a labelled volume for the surface-nets benchmark.

Usage: gen_volume.py OUT.npy [--size 256] [--labels 12] [--seed 1]

Random overlapping ellipsoids (random centres, semi-axes and orientations),
each painted with its own label 1..L over a background of 0, later ones over
earlier ones, so labels touch, nest and cut each other (many label pairs and
junction curves). All ellipsoids stay at least 4 voxels inside the volume, so
every label's surface is closed. Written as int32 of shape (size, size, size)
in C order: (z, y, x), the layout `tessera surface-nets --image` reads.
"""
import argparse

import numpy as np


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--labels", type=int, default=12)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    n, rng = a.size, np.random.default_rng(a.seed)
    img = np.zeros((n, n, n), np.int32)
    ax = np.arange(n, dtype=np.float32)
    for label in range(1, a.labels + 1):
        semi = rng.uniform(0.08, 0.22, 3) * n
        r = semi.max() + 4
        c = rng.uniform(r, n - 1 - r, 3)
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))  # a random rotation
        lo = np.maximum(np.floor(c - r).astype(int), 0)
        hi = np.minimum(np.ceil(c + r).astype(int) + 1, n)
        z, y, x = np.meshgrid(ax[lo[2]:hi[2]], ax[lo[1]:hi[1]], ax[lo[0]:hi[0]], indexing="ij")
        d = np.stack([x - c[0], y - c[1], z - c[2]], axis=-1) @ q  # coordinates in the ellipsoid's frame
        inside = ((d / semi) ** 2).sum(axis=-1) < 1
        img[lo[2]:hi[2], lo[1]:hi[1], lo[0]:hi[0]][inside] = label
    np.save(a.out, img)
    counts = np.bincount(img.ravel(), minlength=a.labels + 1)
    print("%s: %d^3 voxels, labels 1..%d, voxels per label %s" % (a.out, n, a.labels, counts[1:].tolist()))


if __name__ == "__main__":
    main()
