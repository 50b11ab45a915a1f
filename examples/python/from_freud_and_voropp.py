#!/usr/bin/python3
"""Coming from freud or Voro++: one frame of a sheared periodic box.

A frame of a molecular-dynamics run in a triclinic periodic box, given the way
freud's ``Box(Lx, Ly, Lz, xy, xz, yz)`` gives it: dimensionless tilt factors
and a box centred on the origin. What users of each tool ask of it, here:

* freud's ``Voronoi().compute((box, points))``: ``volumes``, and ``nlist``
  with the face areas as ``weights`` and the neighbour's image
  -> ``tessera.voronoi(points, bounds, periodic=True, tilt=...)`` for the
  volumes, ``tessera.adjacency(vor)`` for the neighbour pairs
  (``wheel_offsets``/``spokes``, both directions of every face, as freud
  lists them), ``spoke_measure`` (the face areas) and ``spoke_shifts`` (which
  image of the neighbour, in lattice vectors);
* Voro++'s ``container_periodic`` with ``compute_all`` and the custom output
  ``%i %v %s %n %f %F`` (id, volume, faces, neighbours, face areas, surface
  area) -> the same arrays; the surface area is the sum of a cell's spoke
  measures (in a walled box the wall faces' spokes are -1 .. -6, x-lo .. z-hi,
  Voro++'s numbering).

The box: freud's lattice vectors are a = (Lx, 0, 0), b = (xy Ly, Ly, 0),
c = (xz Lz, yz Lz, Lz), the box centred on the origin. tessera (as LAMMPS and
Voro++) takes the tilts as lengths, tilt = (xy Ly, xz Lz, yz Lz), and the box
as the parallelepiped spanned from ``bounds``' lower corner, here
-(a + b + c) / 2.

The example checks, then writes OUT/cell_shapes.csv (id, volume, surface
area, faces, sphericity):
* every cell's volume, and every face's area and image, equal those of scipy's
  (Qhull's) Voronoi diagram of the points' 27 explicit images, read at the
  central copy (to 1e-9 relative);
* each cell's surface area from its spokes equals the area of its polygons in
  the merged mesh;
* both directions of a face carry the same area and opposite shifts;
* the volumes tile the box: they sum to det[a b c] = Lx Ly Lz.

    /usr/bin/python3 examples/python/from_freud_and_voropp.py --out out

--small uses fewer points (the ctest run).
"""

import argparse
import itertools
import os

import numpy as np
from scipy.spatial import ConvexHull, Voronoi as ScipyVoronoi

import tessera


def freud_box_to_tessera(Lx, Ly, Lz, xy, xz, yz):
    """freud's box (dimensionless tilts, centred on the origin) as tessera's
    bounds and tilt lengths; also the lattice vectors, as rows."""
    lattice = np.array([[Lx, 0.0, 0.0], [xy * Ly, Ly, 0.0], [xz * Lz, yz * Lz, Lz]])
    lo = -lattice.sum(axis=0) / 2
    bounds = (lo[0], lo[0] + Lx, lo[1], lo[1] + Ly, lo[2], lo[2] + Lz)
    return bounds, (xy * Ly, xz * Lz, yz * Lz), lattice


def polygon_area(corners):
    """Area of a planar convex polygon given by its corners in any order."""
    c = corners.mean(axis=0)
    # The plane's normal from the widest pair of spokes (the corners' order
    # is not known, so a ring sum could cancel).
    spokes = corners - c
    normals = np.cross(spokes[0], spokes)
    normal = normals[np.argmax(np.linalg.norm(normals, axis=1))]
    if len(corners) < 3 or np.linalg.norm(normal) == 0:
        return 0.0
    u = spokes[0] / np.linalg.norm(spokes[0])
    n = normal / np.linalg.norm(normal)
    v = np.cross(n, u)
    angle = np.arctan2((corners - c) @ v, (corners - c) @ u)
    ring = corners[np.argsort(angle)]
    return 0.5 * np.linalg.norm(sum(np.cross(ring[k] - c, ring[(k + 1) % len(ring)] - c) for k in range(len(ring))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="output folder")
    parser.add_argument("--small", action="store_true", help="fewer points (the test run)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    # A frame: freud's box and points in it (fractional coordinates in
    # [-1/2, 1/2) along a, b, c).
    Lx, Ly, Lz, xy, xz, yz = 6.0, 5.0, 4.0, 0.25, -0.2, 0.1
    n = 300 if args.small else 2000
    bounds, tilt, lattice = freud_box_to_tessera(Lx, Ly, Lz, xy, xz, yz)
    rng = np.random.default_rng(7)
    points = (rng.random((n, 3)) - 0.5) @ lattice

    vor = tessera.voronoi(points, bounds=bounds, periodic=True, tilt=tilt)
    graph = tessera.adjacency(vor)
    assert vor.n_cells == n
    # The box and the points along periodic axes are rounded to a grid of
    # doubles (2^-49 here) so that every image is exact: compare against the
    # points as tessera placed them.
    placed = vor.periodic_points

    # Voro++'s %F and the sphericity: surface area from the spokes.
    off = graph.wheel_offsets
    area = np.add.reduceat(graph.spoke_measure, off[:-1])
    faces = np.diff(off)
    assert np.array_equal(faces, vor.num_faces)
    sphericity = np.pi ** (1 / 3) * (6 * vor.volumes) ** (2 / 3) / area
    assert np.all((sphericity > 0.5) & (sphericity < 1))  # a sphere's is 1

    # The same areas from the merged mesh's polygons, cell by cell.
    verts = vor.vertices
    for c in range(0, n, 7):
        mesh_area = sum(polygon_area(verts[f]) for f in vor.cell_faces(c))
        assert abs(mesh_area - area[c]) <= 1e-9 * area[c], (c, mesh_area, area[c])

    # freud's nlist: pairs (i, j) both ways, weights = face areas; the twin
    # of i -> (j, s) is j -> (i, -s), with the same area.
    i_of = np.repeat(np.arange(n), faces)
    shifts = graph.spoke_shifts.astype(int)
    twin = {}
    for k in range(len(graph.spokes)):
        twin.setdefault((i_of[k], graph.spokes[k], tuple(shifts[k])), []).append(graph.spoke_measure[k])
    for (i, j, s), w in twin.items():
        back = twin[(j, i, tuple(-x for x in s))]
        assert len(w) == len(back) == 1 and abs(w[0] - back[0]) <= 1e-12 * w[0]
    # Neighbour distances, as freud's nlist.distances: to the image across the face.
    vectors = placed[graph.spokes] + shifts @ lattice - placed[i_of]
    distances = np.linalg.norm(vectors, axis=1)
    assert distances.min() > 0

    # Oracle: Qhull's diagram of the 27 explicit images; the central copy's
    # cells are the periodic cells (the box is several cells wide).
    # tessera's spoke_shifts count lattice vectors; the images here are
    # ordered by (s_a, s_b, s_c), the central copy at index 13.
    offsets = list(itertools.product((-1, 0, 1), repeat=3))
    images = np.concatenate([placed + np.array(s) @ lattice for s in offsets])
    qh = ScipyVoronoi(images)
    centre = offsets.index((0, 0, 0))
    for i in range(n):
        region = qh.regions[qh.point_region[centre * n + i]]
        assert -1 not in region
        volume = ConvexHull(qh.vertices[region]).volume
        assert abs(volume - vor.volumes[i]) <= 1e-9 * vor.volumes[i], (i, volume, vor.volumes[i])
    ridges = {}
    for (p, q), rv in zip(qh.ridge_points, qh.ridge_vertices):
        for a, b in ((p, q), (q, p)):
            if a // n == centre:
                ridges[(a % n, b % n, offsets[b // n])] = polygon_area(qh.vertices[rv])
    got = {key: w[0] for key, w in twin.items()}
    # Qhull's vertices are rounded doubles: a tiny face's area is only good
    # to rounding of the cell's size, hence the absolute floor.
    floor = 1e-9 * vor.volumes.mean() ** (2 / 3)
    # Random points have no faces of zero area. (Exact ties, as on a
    # lattice, give such faces in both: Qhull's from rounding, ours from
    # symbolic perturbation, not necessarily the same ones; prune_tolerance
    # drops them.)
    assert got.keys() == ridges.keys(), len(set(got) ^ set(ridges))
    for key, a in got.items():
        assert abs(a - ridges[key]) <= max(1e-9 * a, floor), (key, a, ridges[key])

    total = vor.volumes.sum()
    det = np.linalg.det(lattice)
    assert abs(total - det) <= 1e-12 * det, (total, det)

    table = np.column_stack([np.arange(n), vor.volumes, area, faces, sphericity])
    path = os.path.join(args.out, "cell_shapes.csv")
    np.savetxt(path, table, delimiter=",", header="id,volume,area,faces,sphericity", comments="",
               fmt=["%d", "%.17g", "%.17g", "%d", "%.17g"])
    print(f"{n} cells in a sheared periodic box ({Lx} x {Ly} x {Lz}, tilts {xy}, {xz}, {yz}): "
          f"volumes sum to {total:.12g} (box {det:.12g}); {len(graph.spokes)} spokes, "
          f"mean {faces.mean():.2f} faces, mean sphericity {sphericity.mean():.3f}; "
          f"volumes and {len(got)} face areas equal Qhull's of the 27 images; wrote {path}")


if __name__ == "__main__":
    main()
