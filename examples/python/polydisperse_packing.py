#!/usr/bin/python3
"""Local packing fractions of a polydisperse sphere packing: power cells.

A granular packing of spheres of two sizes (here a random sequential
addition: spheres placed at random where they overlap no other). The ordinary
Voronoi cell of a large sphere cuts through it: the bisector with a small
neighbour lies halfway between the centres, inside the large sphere. The
power (radical) cell, tessera.voronoi(points, radii=...), puts each face on
the two spheres' radical plane, which separates them: every sphere lies
inside its own cell, and the cells still tile the box. The local packing
fraction of a sphere (its volume over its cell's) is then at most 1 for
every sphere, and the two sizes' fractions are comparable. Ordinary cells give
large spheres fractions above 1.

The example checks the following, then draws the picture:
* every sphere lies within its power cell: its distance to each of the cell's
  radical planes is at least its radius;
* with ordinary cells some large spheres cross their cells' faces;
* both tessellations tile the box;
* validate() passes (exact measures of sampled cells, with the radii);
* the regular triangulation, tessera.delaunay(points, radii=...), is the
  power cells' dual: every pair of face neighbours among the cells is one of
  its edges, no sphere is hidden (none overlaps another, so each holds its
  own centre's cell), and its validate() passes (local regularity).

OUT/packing_cells.vtu: the power cells (open in ParaView beside the spheres).
OUT/packing_regular.vtu: the regular triangulation's tetrahedra.

OUT/polydisperse_packing.png: left, a 2D packing of discs with its power
cells (solid) and ordinary cells (dotted); right, the 3D local packing
fractions by size class, power against ordinary cells.

    /usr/bin/python3 examples/python/polydisperse_packing.py --out out

--small packs fewer spheres (the ctest run).
"""

import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402

import tessera  # noqa: E402


def random_packing(n_tries, dim, radii_choices, seed, batch=4000):
    """Random sequential addition in the unit box: each try places a sphere of
    a random size at a random point where it overlaps no placed sphere and
    stays inside the box. Tries come in batches: a k-d tree of the placed
    spheres rejects a batch's overlaps with them, and the survivors are then
    taken in order unless they overlap an earlier one of their batch."""
    rng = np.random.default_rng(seed)
    rmax = max(radii_choices)
    centres, radii = np.empty((0, dim)), np.empty(0)
    for start in range(0, n_tries, batch):
        m = min(batch, n_tries - start)
        r = rng.choice(radii_choices, m)
        c = r[:, None] + rng.random((m, dim)) * (1 - 2 * r[:, None])
        if len(centres):
            near = cKDTree(centres).query_ball_point(c, r + rmax)
            free = np.array([all(np.sum((centres[j] - c[k]) ** 2) >= (radii[j] + r[k]) ** 2 for j in near[k])
                             for k in range(m)], dtype=bool)
            c, r = c[free], r[free]
        keep = np.ones(len(c), dtype=bool)
        tree = cKDTree(c)
        for k in range(len(c)):
            if keep[k]:
                for j in tree.query_ball_point(c[k], r[k] + rmax):
                    if j > k and keep[j] and np.sum((c[j] - c[k]) ** 2) < (r[j] + r[k]) ** 2:
                        keep[j] = False
        centres, radii = np.concatenate([centres, c[keep]]), np.concatenate([radii, r[keep]])
    return centres, radii


def sphere_volume(r, dim):
    return np.pi * r**2 if dim == 2 else 4 / 3 * np.pi * r**3


def min_face_clearance(vor, points, radii):
    """Per cell: the least distance from its point to its faces' planes, less
    the point's radius (>= 0: the sphere lies within its cell). A face with
    neighbour j lies on the plane q.y = d, q = p_j - p_i, d = |q|^2 / 2 for
    ordinary cells and (|q|^2 + r_i^2 - r_j^2) / 2 for power cells; the box
    faces are at least a radius away by construction."""
    w = radii**2 if vor.power else np.zeros_like(radii)
    out = np.empty(vor.n_cells)
    for c in range(vor.n_cells):
        i = vor.generators[c]
        nb = vor.cell_neighbors(c)
        q = points[nb] - points[i]
        qq = np.sum(q * q, axis=1)
        d = 0.5 * (qq + w[i] - w[nb])
        out[c] = np.min(d / np.sqrt(qq)) - radii[i]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="fewer spheres (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # ---- 3D: spheres of radii 0.01 and 0.025 ---------------------------------
    sizes3 = (0.01, 0.025)
    points, radii = random_packing(20_000 if args.small else 400_000, 3, sizes3, seed=7)
    box = (0, 1, 0, 1, 0, 1)
    power = tessera.voronoi(points, radii=radii, bounds=box)
    ordinary = tessera.voronoi(points, bounds=box)
    assert power.power and len(power.empty_cells) == 0  # no sphere overlaps another
    report = power.validate()
    assert report.ok, report.messages
    for vor in (power, ordinary):
        assert abs(vor.volumes.sum() - 1) < 1e-12
    clear_power = min_face_clearance(power, points, radii)
    clear_ordinary = min_face_clearance(ordinary, points, radii)
    assert clear_power.min() >= -1e-12, "a sphere crosses its power cell's face"
    crossing = int((clear_ordinary < 0).sum())
    assert crossing > 0
    power.save(os.path.join(args.out, "packing_cells.vtu"))
    fraction_power = sphere_volume(radii, 3) / power.volumes
    fraction_ordinary = sphere_volume(radii, 3) / ordinary.volumes
    print(f"{len(points):,} spheres (packing fraction {sphere_volume(radii, 3).sum():.3f}); "
          f"every sphere inside its power cell; {crossing} spheres cross their ordinary cells' faces; "
          f"validate: {report.measures_checked} cells measured exactly, worst {report.measure_rel_error:.1e}")
    for r in sizes3:
        big = radii == r
        print(f"  radius {r}: local packing fraction {fraction_power[big].mean():.3f} (power cells), "
              f"{fraction_ordinary[big].mean():.3f} (ordinary), max {fraction_power[big].max():.3f} / "
              f"{fraction_ordinary[big].max():.3f}")
    assert fraction_power.max() <= 1

    # ---- The dual: the regular triangulation ------------------------------
    regular = tessera.delaunay(points, radii=radii)
    assert regular.power and len(regular.hidden) == 0
    assert regular.validate().ok
    indptr, indices = regular.vertex_neighbor_vertices
    counts = np.diff(power.neighbor_offsets)
    owner = np.repeat(power.generators, counts)
    inside = power.neighbors >= 0  # (box faces have negative ids)
    edges = set(zip(np.repeat(np.arange(len(points)), np.diff(indptr)).tolist(), indices.tolist()))
    missing = sum((a, b) not in edges for a, b in zip(owner[inside].tolist(), power.neighbors[inside].tolist()))
    assert missing == 0, f"{missing} face neighbours are not regular edges"
    regular.save(os.path.join(args.out, "packing_regular.vtu"))
    shared = int(inside.sum()) // 2
    print(f"regular triangulation: {regular.nsimplex:,} tetrahedra; every face between two power cells is one "
          f"of its {len(indices) // 2:,} edges ({shared:,}; the other {len(indices) // 2 - shared:,} are dual "
          f"to faces beyond the box)")

    # ---- 2D: the picture ---------------------------------------------------
    sizes2 = (0.012, 0.03)
    p2, r2 = random_packing(20_000, 2, sizes2, seed=8)
    box2 = (0, 1, 0, 1)
    pw2 = tessera.voronoi(p2, radii=r2, bounds=box2)
    or2 = tessera.voronoi(p2, bounds=box2)
    assert min_face_clearance(pw2, p2, r2).min() >= -1e-12

    def edges(vor):
        return vor.vertices[vor.face_vertices.reshape(-1, 2)]

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5.6), constrained_layout=True)
    colours = np.where(r2 == sizes2[1], "#E9C46A", "#8ECAE6")
    left.add_collection(PatchCollection([Circle(c, r) for c, r in zip(p2, r2)], facecolors=colours,
                                        edgecolors="none"))
    left.add_collection(LineCollection(edges(or2), colors="#C1121F", linewidths=0.9, linestyles=":"))
    left.add_collection(LineCollection(edges(pw2), colors="k", linewidths=0.7))
    left.set_xlim(0.3, 0.7)
    left.set_ylim(0.3, 0.7)
    left.set_aspect("equal")
    left.set_title("2D discs: power cells (black), ordinary cells (red, dotted)", fontsize=11)

    bins = np.linspace(0, 1.8, 73)
    for r, colour in zip(sizes3, ("#219EBC", "#E76F51")):
        big = radii == r
        right.hist(fraction_power[big], bins, histtype="stepfilled", alpha=0.45, color=colour, density=True,
                   label=f"r = {r}: power cells")
        right.hist(fraction_ordinary[big], bins, histtype="step", lw=1.6, color=colour, density=True,
                   label=f"r = {r}: ordinary cells")
    right.axvline(1, color="k", lw=0.8, ls="--")
    right.set_xlabel("local packing fraction (sphere volume / cell volume)")
    right.set_ylabel("density (each size class)")
    right.set_title(f"3D: {len(points):,} spheres of two sizes", fontsize=11)
    right.legend(fontsize=8)
    path = os.path.join(args.out, "polydisperse_packing.png")
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
