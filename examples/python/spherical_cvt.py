#!/usr/bin/python3
"""A spherical centroidal Voronoi tessellation (the meshes of MPAS-style climate models).

Random points on the unit sphere have cells of very uneven areas. Lloyd's
iteration moves every point to its cell's centroid (SphericalVoronoi.centroids,
on the sphere) and recomputes the cells: after a few dozen iterations the cells
are near-regular hexagons (and twelve pentagons' worth of defects) of nearly
equal areas. The picture shows the front hemisphere (orthographic view) before
and after, cells coloured by their area over the mean; the printout follows the
areas' spread and the fraction of hexagons.

    /usr/bin/python3 examples/python/spherical_cvt.py --out docs/images

Writes OUT/spherical_cvt.png. --small uses fewer points and iterations (the ctest run).
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from PIL import Image  # noqa: E402

import tessera  # noqa: E402


def spread(sv):
    """(largest / smallest area, share of six-sided cells)."""
    a = sv.areas
    sides = np.diff(sv.region_offsets)
    return a.max() / a.min(), np.mean(sides == 6)


def draw(ax, sv, title):
    """The cells whose point faces the viewer (z > 0), seen from +z."""
    verts = sv.vertices
    polys, colours = [], []
    mean = 4 * np.pi / len(sv.points)
    for i, region in enumerate(sv.regions):
        if sv.points[i, 2] <= 0.05 or len(region) < 3:
            continue
        polys.append(verts[region][:, :2])
        colours.append(sv.areas[i] / mean)
    pc = PolyCollection(polys, array=np.array(colours), cmap="coolwarm", edgecolors="k", linewidths=0.2)
    pc.set_clim(0.5, 1.5)
    ax.add_collection(pc)
    ax.set_xlim(-1.02, 1.02)
    ax.set_ylim(-1.02, 1.02)
    ax.set_aspect("equal")
    ax.set_axis_off()
    ax.set_title(title, fontsize=10)
    return pc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points and iterations (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    n, iterations = (600, 15) if args.small else (2500, 60)
    v = np.random.default_rng(3).normal(size=(n, 3))
    pts = v / np.linalg.norm(v, axis=1)[:, None]

    sv = tessera.spherical_voronoi(pts)
    first = sv
    ratio, hexagons = spread(sv)
    print(f"random: area max/min {ratio:.1f}, hexagons {hexagons:.0%}")
    for it in range(iterations):
        moved = np.linalg.norm(sv.centroids - sv.points, axis=1).max()
        sv = tessera.spherical_voronoi(sv.centroids, radius=1.0)
        assert abs(sv.area_sum / (4 * np.pi) - 1) < 1e-12
        if it % 10 == 9 or it == iterations - 1:
            ratio, hexagons = spread(sv)
            print(f"iteration {it + 1}: largest move {moved:.2e}, area max/min {ratio:.2f}, hexagons {hexagons:.0%}")
    # Lloyd's iteration evens the areas out.
    assert spread(sv)[0] < spread(first)[0] / 2

    fig, axes = plt.subplots(1, 2, figsize=(10, 5.2), constrained_layout=True)
    draw(axes[0], first, f"{n} random points: area max/min {spread(first)[0]:.1f}")
    pc = draw(axes[1], sv, f"after {iterations} Lloyd iterations: max/min {spread(sv)[0]:.2f}, "
                           f"{spread(sv)[1]:.0%} hexagons")
    fig.colorbar(pc, ax=axes, shrink=0.7, label="cell area / mean")
    path = os.path.join(args.out, "spherical_cvt.png")
    fig.savefig(path, dpi=90, bbox_inches="tight", pad_inches=0.1)
    Image.open(path).convert("RGB").quantize(colors=64).save(path, optimize=True)  # a small PNG, the same look
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
