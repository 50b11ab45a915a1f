#!/usr/bin/python3
"""Surface nets of three touching spheres: a .vtp for ParaView and a picture.

Random points in the unit cube are labelled 0, 1, 2 by the nearest of three
overlapping balls (points in no ball are outside points, label -1).
tessera.surface_nets() turns them into smooth, watertight, consistently
oriented surfaces: one interface per pair of touching balls, capped outer
skins, and junction curves where all three meet. Each face carries
BoundaryLabels (the labels on its two sides).

OUT/spheres_net.vtp: triangles with cell data BoundaryLabels; in ParaView,
colour by BoundaryLabels (component 1 shows the interfaces against the
outside, -1) or Threshold on it to pull one region out.

OUT/surface_nets_spheres.png: left, the same construction in 2D (three
disks: the net is a set of curves, coloured by the pair of labels they
separate, junction points in black); right, the 3D net's faces counted per
BoundaryLabels pair.

    /usr/bin/python3 examples/python/surface_nets_spheres.py --out out

--small uses fewer points (the ctest run).
"""

import argparse
import os
from collections import Counter

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

import tessera  # noqa: E402

CENTRES = np.array([[0.36, 0.40, 0.50], [0.64, 0.40, 0.50], [0.50, 0.64, 0.50]])
RADIUS = 0.2
REGION_COLOURS = np.array(["#9ECAE1", "#FDD0A2", "#C7E9C0"])  # light: the points
PAIR_COLOURS = {(0, 1): "#8172B3", (0, 2): "#C44E52", (1, 2): "#2A9D8F",  # the interfaces
                (0, -1): "#555555", (1, -1): "#6E6E6E", (2, -1): "#878787"}  # the capping skins


def three_balls(n, dim, seed=1):
    """n random points, labelled by the nearest centre within RADIUS, else -1."""
    pts = np.random.default_rng(seed).random((n, dim))
    d = np.linalg.norm(pts[:, None, :] - CENTRES[None, :, :dim], axis=2)
    labels = np.where(d.min(axis=1) < RADIUS, d.argmin(axis=1), -1)
    return pts, labels


def check_closed(net):
    """Every region's surface is closed and outward: each directed edge of its
    (outward-turned) faces has its reverse exactly once."""
    for r in net.selected:
        ids, flip = net.region_faces(r)
        edges = Counter()
        for f, rev in zip(ids, flip):
            loop = net.face(f)[::-1] if rev else net.face(f)
            edges.update(zip(loop.tolist(), np.roll(loop, -1).tolist()))
        assert max(edges.values()) == 1 and all(edges[(b, a)] == 1 for a, b in edges), r


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # ---- 3D: the .vtp ------------------------------------------------------
    pts, labels = three_balls(30_000 if args.small else 300_000, 3)
    net = tessera.surface_nets(pts, labels, capping=True, triangles=True, bounds=(0, 1, 0, 1, 0, 1))
    check_closed(net)
    path = os.path.join(args.out, "spheres_net.vtp")
    net.save(path)
    kinds = np.bincount(net.vertex_kind, minlength=3)
    print(f"wrote {path}: {net.n_faces} triangles, {net.n_vertices} vertices "
          f"({kinds[1]} on junction curves, {kinds[2]} corners), max vertex move {net.max_displacement:.4f}")
    pairs = Counter(map(tuple, net.boundary_labels.tolist()))
    assert {(0, 1), (0, 2), (1, 2)} <= set(pairs)

    # ---- 2D: the picture -----------------------------------------------------
    pts2, labels2 = three_balls(3_000 if args.small else 12_000, 2, seed=2)
    net2 = tessera.surface_nets(pts2, labels2, capping=True, bounds=(0, 1, 0, 1))
    segments = net2.vertices[net2.face_vertices.reshape(-1, 2)]
    colours = [PAIR_COLOURS[tuple(p)] for p in net2.boundary_labels.tolist()]

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5.2), constrained_layout=True,
                                      gridspec_kw={"width_ratios": [1, 1.1]})
    inside = labels2 >= 0
    left.scatter(*pts2[inside].T, s=2, c=REGION_COLOURS[labels2[inside]], linewidths=0)
    for k, c in enumerate(CENTRES[:, :2]):
        left.annotate(str(k), c, ha="center", va="center", fontsize=16, color="#333333")
    left.add_collection(LineCollection(segments, colors=colours, linewidths=1.8))
    corners = net2.vertices[net2.vertex_kind == tessera.NET_CORNER]
    left.plot(*corners.T, "o", color="k", ms=4)
    left.set_xlim(0.1, 0.9)
    left.set_ylim(0.1, 0.9)
    left.set_aspect("equal")
    left.set_xticks([])
    left.set_yticks([])
    left.set_title(f"2D surface net: {net2.n_faces} segments, {len(corners)} junctions (black)", fontsize=11)
    left.legend(handles=[Line2D([], [], color=PAIR_COLOURS[p], lw=2, label=f"{p[0]} | {p[1]}")
                         for p in [(0, 1), (0, 2), (1, 2)]]
                + [Line2D([], [], color=PAIR_COLOURS[(1, -1)], lw=2, label="k | -1 (skin)")],
                title="BoundaryLabels", loc="upper right", fontsize=8, title_fontsize=8, framealpha=0.9)

    names = sorted(pairs, key=lambda p: (p[1] < 0, p))
    right.bar([f"{a} | {b}" for a, b in names], [pairs[p] for p in names],
              color=[PAIR_COLOURS.get(p, "#777777") for p in names])
    right.set_xlabel("BoundaryLabels (side 0 | side 1; -1 = outside)")
    right.set_ylabel("triangles")
    right.set_title(f"3D net of {len(pts):,} points: triangles per label pair", fontsize=11)
    path = os.path.join(args.out, "surface_nets_spheres.png")
    fig.savefig(path, dpi=100)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
