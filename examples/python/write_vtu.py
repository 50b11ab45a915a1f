#!/usr/bin/python3
"""Write 3D Voronoi cells and their Delaunay tetrahedra as .vtu files for ParaView.

Points in a cube with two region labels (lower and upper half); the points in a
ball are outside points (label -1), which carve a spherical cavity into the
cells. Open OUT/cells.vtu in ParaView and colour by "Region" or "Volume"; a
Clip filter shows the cavity. OUT/delaunay.vtu holds the tetrahedra between
inside points.

    /usr/bin/python3 examples/python/write_vtu.py --out out

--small uses fewer points (the ctest run).
"""

import argparse
import os

import numpy as np

import tessera


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    n = 5_000 if args.small else 100_000
    pts = np.random.default_rng(3).random((n, 3))
    labels = (pts[:, 2] > 0.5).astype(np.int32)
    labels[np.linalg.norm(pts - 0.5, axis=1) < 0.3] = -1

    vor = tessera.voronoi(pts, labels=labels, bounds=(0, 1, 0, 1, 0, 1))
    report = vor.validate()
    assert report.ok, report.messages
    cells_path = os.path.join(args.out, "cells.vtu")
    vor.save(cells_path)

    dt = tessera.delaunay(pts, labels=labels)
    delaunay_path = os.path.join(args.out, "delaunay.vtu")
    dt.save(delaunay_path)

    cavity = 1 - vor.volumes.sum()
    print(f"wrote {cells_path}: {vor.n_cells} polyhedra, {vor.n_vertices} vertices; "
          f"cavity volume {cavity:.4f} (ball: {4 / 3 * np.pi * 0.3**3:.4f})")
    print(f"wrote {delaunay_path}: {dt.nsimplex} tetrahedra")


if __name__ == "__main__":
    main()
