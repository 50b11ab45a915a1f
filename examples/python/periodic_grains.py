#!/usr/bin/python3
"""Grain boundaries of a periodic polycrystal: surface nets in a periodic box.

A polycrystal in a periodic simulation box (molecular dynamics, phase field):
atoms labelled by their grain. Here the atoms are random points and each takes
the label of its nearest grain seed, measured across the box's faces (the
minimum image), so grains wrap around the box. tessera.surface_nets(...,
periodic=True) gives the grain boundaries as smooth, watertight surfaces that
continue across the box's faces: each face lies where the cell on its first
side is (side_shifts names the image of the second side), and the copies of a
vertex seen from several sides of the box move as one.

OUT/grains_net.vtp: the 3D boundaries (triangles, cell data BoundaryLabels =
the two grains, SideShift); faces near the box's faces stick out of it and fit
the opposite side by one box length.

OUT/periodic_grains.png: left, the 2D construction drawn in 2 x 2 copies of
the box (the boundaries join seamlessly across its edges, dashed); right, the
3D boundary area per grain pair, from the exact Voronoi faces and after
smoothing.

    /usr/bin/python3 examples/python/periodic_grains.py --out out

--small uses fewer points (the ctest run).
"""

import argparse
import os
from collections import Counter, defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

import tessera  # noqa: E402


def polycrystal(n_atoms, n_grains, dim, seed):
    """Random atoms in the unit box, labelled by the nearest grain seed under
    the minimum-image convention (so grains wrap around the box)."""
    rng = np.random.default_rng(seed)
    atoms, seeds = rng.random((n_atoms, dim)), rng.random((n_grains, dim))
    d = atoms[:, None, :] - seeds[None, :, :]
    d -= np.round(d)  # minimum image
    return atoms, np.linalg.norm(d, axis=2).argmin(axis=1).astype(np.int32)


def polygon_areas(fs):
    """Area of each face of a 3D face set (Newell's formula)."""
    areas = np.empty(fs.n_faces)
    for f in range(fs.n_faces):
        p = fs.vertices[fs.face(f)]
        areas[f] = 0.5 * np.linalg.norm(np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0))
    return areas


def check_closed_across_the_box(net):
    """Every grain's surface is closed once the copies of a vertex (keys equal
    up to a common shift) are identified: each directed edge, as a pair of
    copies and the translation between them, has its reverse exactly once."""
    keys, shifts = net.vertex_keys, net.vertex_key_shifts.astype(int)
    lead = shifts[:, 0, :]
    groups = {}
    group = np.array([groups.setdefault((tuple(k), tuple((s - t).ravel())), len(groups))
                      for k, s, t in zip(keys.tolist(), shifts, lead)])
    for grain in net.selected:
        ids, flip = net.region_faces(grain)
        edges = Counter()
        for f, rev in zip(ids, flip):
            loop = net.face(f)[::-1] if rev else net.face(f)
            for a, b in zip(loop, np.roll(loop, -1)):
                edges[(group[a], group[b], tuple(lead[b] - lead[a]))] += 1
        assert all(edges[(b, a, tuple(-x for x in d))] == 1 for a, b, d in edges), grain
    return len(groups)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    box3 = (0, 1, 0, 1, 0, 1)

    # ---- 3D: the boundaries and their areas ---------------------------------
    atoms, grain = polycrystal(20_000 if args.small else 200_000, 12, 3, seed=4)
    net = tessera.surface_nets(atoms, grain, bounds=box3, periodic=True, triangles=True)
    distinct = check_closed_across_the_box(net)
    path = os.path.join(args.out, "grains_net.vtp")
    net.save(path)
    print(f"wrote {path}: {net.n_faces} triangles, {net.n_vertices} vertices "
          f"({net.n_vertices - distinct} copies across the box's faces), every grain closed")

    raw = tessera.faces(tessera.voronoi(atoms, labels=grain, bounds=box3, periodic=True, merge=True),
                        kind="surface-net")
    exact, smooth = defaultdict(float), defaultdict(float)
    for pair, a in zip(map(tuple, raw.boundary_labels.tolist()), polygon_areas(raw)):
        exact[pair] += a
    for pair, a in zip(map(tuple, net.boundary_labels.tolist()), polygon_areas(net)):
        smooth[pair] += a
    total_exact, total_smooth = sum(exact.values()), sum(smooth.values())
    print(f"grain boundary area: {total_exact:.3f} (Voronoi faces), {total_smooth:.3f} (smoothed), "
          f"{len(exact)} grain pairs")
    assert set(exact) == set(smooth) and total_smooth < total_exact

    # ---- 2D: the picture, in 2 x 2 copies of the box -------------------------
    atoms2, grain2 = polycrystal(3_000 if args.small else 6_000, 7, 2, seed=5)
    net2 = tessera.surface_nets(atoms2, grain2, bounds=(0, 1, 0, 1), periodic=True)
    segments = net2.vertices[net2.face_vertices.reshape(-1, 2)]
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5.4), constrained_layout=True,
                                      gridspec_kw={"width_ratios": [1, 1.25]})
    colours = plt.get_cmap("tab10")(grain2 % 10)
    for sx in (0, 1):
        for sy in (0, 1):
            shift = np.array([sx, sy], float)
            left.scatter(*(atoms2 + shift).T, s=0.6, c=colours, linewidths=0, rasterized=True)
            left.add_collection(LineCollection(segments + shift, colors="k", linewidths=1.2))
    for t in (0, 1, 2):
        left.axvline(t, color="#777777", ls="--", lw=0.8)
        left.axhline(t, color="#777777", ls="--", lw=0.8)
    left.set_xlim(-0.05, 2.05)
    left.set_ylim(-0.05, 2.05)
    left.set_aspect("equal")
    left.set_xticks([0, 1, 2])
    left.set_yticks([0, 1, 2])
    left.set_title(f"2D periodic grain boundaries ({net2.n_faces} segments), box drawn 2 x 2", fontsize=11)

    pairs = sorted(exact, key=lambda p: -exact[p])
    x = np.arange(len(pairs))
    right.bar(x - 0.2, [exact[p] for p in pairs], 0.4, label="Voronoi faces", color="#8172B3")
    right.bar(x + 0.2, [smooth[p] for p in pairs], 0.4, label="smoothed net", color="#2A9D8F")
    right.set_xticks(x, [f"{a}|{b}" for a, b in pairs], rotation=90, fontsize=7)
    right.set_xlabel("grain pair")
    right.set_ylabel("boundary area (box = 1)")
    right.set_title(f"3D: {len(atoms):,} atoms, 12 grains, area per grain pair", fontsize=11)
    right.legend(fontsize=9)
    path = os.path.join(args.out, "periodic_grains.png")
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
