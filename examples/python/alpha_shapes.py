#!/usr/bin/python3
"""Alpha shapes: a concave hull with holes (2D) and a surface from its samples (3D).

Left: points scattered over two letter-like blobs with holes; the alpha shape
at a radius of a few spacings keeps the triangles whose circumcircle is no
larger, and its boundary, chained into polygons (outer rings
counter-clockwise, holes clockwise, as GeoJSON and shapely want them), is the
concave hull. Right: the same at a larger alpha, which closes the small gaps.
Then samples of a torus's surface: little volume is kept at a small alpha,
and the alpha complex's singular triangles, with the kept tetrahedra's
boundary, are the reconstructed surface through (nearly) every sample. Random
samples leave it a few small holes and doubled slivers (about 80-90% of its
edges are in exactly two triangles): a clean manifold needs a further
extraction step, which this example does not do.

    /usr/bin/python3 examples/python/alpha_shapes.py --out docs/images

Writes OUT/alpha_shapes.png. --small uses fewer points (the ctest run).
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402
from PIL import Image  # noqa: E402

import tessera  # noqa: E402


def blobs(n, rng):
    """Uniform points in a ring (with its hole) beside a square with two square holes."""
    pts = []
    while sum(len(p) for p in pts) < n:
        q = rng.random((n, 2)) * [2.2, 1.0]
        ring = np.abs(np.linalg.norm(q - [0.5, 0.5], axis=1) - 0.33) < 0.14
        square = (np.abs(q - [1.65, 0.5]) < 0.45).all(axis=1)
        holes = (np.abs(q - [1.45, 0.5]) < [0.1, 0.25]).all(axis=1) | (np.abs(q - [1.85, 0.5]) < [0.1, 0.25]).all(axis=1)
        pts.append(q[ring | (square & ~holes)])
    return np.concatenate(pts)[:n]


def torus(n, rng, big=1.0, small=0.35):
    """Uniform samples of a torus's surface (by area)."""
    u = rng.uniform(0, 2 * np.pi, n)
    v = np.empty(0)
    while len(v) < n:
        c = rng.uniform(0, 2 * np.pi, 2 * n)
        v = np.concatenate([v, c[rng.uniform(0, 1 + small, 2 * n) < 1 + small * np.cos(c)]])
    v = v[:n]
    return np.c_[(big + small * np.cos(v)) * np.cos(u), (big + small * np.cos(v)) * np.sin(u), small * np.sin(v)]


def draw(ax, pts, dt, shape, title):
    ax.add_collection(PolyCollection(pts[shape.simplices], facecolors="#C6D5EA", edgecolors="#9AB0D0",
                                     linewidths=0.2))
    for rings in shape.polygons():
        for k, ring in enumerate(rings):
            closed = np.append(ring, ring[0])
            ax.plot(*pts[closed].T, color="#1F4E9A" if k == 0 else "#C44E52", lw=1.2)
    if len(shape.singular):
        ax.add_collection(LineCollection(pts[shape.singular], colors="#55A868", linewidths=0.8))
    ax.plot(*pts.T, ".", color="k", ms=1)
    ax.set_title(title, fontsize=10)
    ax.set_xlim(-0.05, 2.25)
    ax.set_ylim(-0.05, 1.05)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rng = np.random.default_rng(11)

    # 2D: the concave hull, as polygons.
    n = 1500 if args.small else 6000
    pts = blobs(n, rng)
    dt = tessera.delaunay(pts)
    spacing = np.sqrt(1.36 / n)  # about the blobs' area per point
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.4), constrained_layout=True)
    for ax, factor in zip(axes, (1.2, 2.5)):
        alpha = factor * spacing
        shape = dt.alpha_shape(alpha)
        polygons = shape.polygons()
        # The polygons' signed areas (outer rings positive, holes negative)
        # add up to the kept triangles' area.
        x, y = pts[:, 0], pts[:, 1]
        area = sum(0.5 * (x[r] * np.roll(y[r], -1) - np.roll(x[r], -1) * y[r]).sum() for rings in polygons for r in rings)
        assert abs(area - shape.volume) < 1e-9 * shape.volume
        holes = sum(len(rings) - 1 for rings in polygons)
        draw(ax, pts, dt, shape, f"alpha = {factor} spacings: {len(polygons)} polygons, {holes} holes, "
                                 f"{len(shape.singular)} singular segments (green)")
        print(f"2D alpha {alpha:.4f}: {len(shape.simplex_ids)} of {dt.nsimplex} triangles, {len(polygons)} polygons, "
              f"{holes} holes, area {shape.volume:.4f}")
    path = os.path.join(args.out, "alpha_shapes.png")
    fig.savefig(path, dpi=100, bbox_inches="tight", pad_inches=0.1)
    Image.open(path).convert("RGB").quantize(colors=64).save(path, optimize=True)  # a small PNG, the same look
    print(f"wrote {path}")

    # 3D: a surface from its samples. At a small alpha almost no tetrahedron
    # is kept; the surface is the singular triangles (and the boundary of the
    # few kept tetrahedra).
    m = 4000 if args.small else 40000
    p3 = torus(m, rng)
    dt3 = tessera.delaunay(p3)
    s = np.sqrt(4 * np.pi ** 2 * 0.35 / m)
    surface = dt3.alpha_shape(1.3 * s)
    tris = np.concatenate([surface.boundary, surface.singular])
    edges = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    verts = len(np.unique(tris))
    euler = verts - len(uniq) + len(tris)
    print(f"torus: {m} samples, {len(tris)} surface triangles ({len(surface.singular)} singular), "
          f"{verts} vertices, edges in 2 triangles: {np.mean(count == 2):.4f}, Euler characteristic {euler}")
    assert verts > 0.99 * m  # the surface passes through (nearly) every sample
    assert np.mean(count == 2) > 0.7


if __name__ == "__main__":
    main()
