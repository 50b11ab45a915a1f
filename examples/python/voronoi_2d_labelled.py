#!/usr/bin/python3
"""A labelled 2D Voronoi tessellation and its Delaunay triangulation, drawn with matplotlib.

Points in the unit square carry region labels (three bands bent by a wave);
the points inside a disc are outside points (label -1): they clip their
neighbours but own no cell, so the cells leave a hole. Left: the cells coloured
by region. Right: the Delaunay triangles between inside points, coloured by
region where all three corners agree. With labels the triangulation is the
whole one's triangles whose three corners are inside points, so the disc of
outside points leaves a hole in it too.

    /usr/bin/python3 examples/python/voronoi_2d_labelled.py --out docs/images

Writes OUT/voronoi_2d_labelled.png. --small uses fewer points (the ctest run).
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from PIL import Image  # noqa: E402

import tessera  # noqa: E402

COLOURS = np.array(["#4C72B0", "#DD8452", "#55A868"])


def labelled_points(n, seed=7):
    rng = np.random.default_rng(seed)
    pts = rng.random((n, 2))
    wave = 0.08 * np.sin(2 * np.pi * 2 * pts[:, 0])
    labels = np.digitize(pts[:, 1] + wave, [0.36, 0.66])  # bands 0, 1, 2
    hole = np.linalg.norm(pts - [0.62, 0.5], axis=1) < 0.17
    labels[hole] = -1
    return pts, labels


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    pts, labels = labelled_points(300 if args.small else 900)
    box = (0.0, 1.0, 0.0, 1.0)
    vor = tessera.voronoi(pts, labels=labels, bounds=box)
    dt = tessera.delaunay(pts, labels=labels, bounds=box)

    # The cells tile the square minus the hole the outside points carve.
    assert vor.validate().ok and dt.validate().ok
    assert 0.8 < vor.volumes.sum() < 0.95

    # Polygon of each cell: the first vertex of each of its edges, in order.
    polygon_vertices = vor.face_vertices[vor.face_vertex_offsets[:-1]]
    polygons = np.split(vor.vertices[polygon_vertices], vor.cell_face_offsets[1:-1])

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5.6), constrained_layout=True)
    left.add_collection(PolyCollection(polygons, facecolors=COLOURS[vor.regions], edgecolors="white",
                                       linewidths=0.6, alpha=0.9))
    inside = labels >= 0
    left.plot(*pts[inside].T, ".", color="k", ms=2)
    left.plot(*pts[~inside].T, "x", color="#C44E52", ms=3, mew=0.8)
    left.set_title(f"Voronoi: {vor.n_cells} cells, {int((~inside).sum())} outside points (x)", fontsize=11)
    left.legend(handles=[Patch(color=c, label=f"region {k}") for k, c in enumerate(COLOURS)],
                loc="lower left", fontsize=8, framealpha=0.9)

    tri_labels = labels[dt.simplices]
    same = (tri_labels == tri_labels[:, :1]).all(axis=1)
    face = np.where(same[:, None], matplotlib.colors.to_rgba_array(COLOURS[tri_labels[:, 0]]),
                    matplotlib.colors.to_rgba("#BBBBBB"))
    right.add_collection(PolyCollection(pts[dt.simplices], facecolors=face, edgecolors="k", linewidths=0.3))
    right.set_title(f"Delaunay: {dt.nsimplex} triangles (grey: mixed regions)", fontsize=11)

    for ax in (left, right):
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
    path = os.path.join(args.out, "voronoi_2d_labelled.png")
    fig.savefig(path, dpi=110, bbox_inches="tight", pad_inches=0.15)
    # A few flat colours: a 64-colour palette makes the PNG (the README's
    # picture) five times smaller and looks the same. Pillow comes with matplotlib.
    Image.open(path).convert("RGB").quantize(colors=64).save(path, optimize=True)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
