#!/usr/bin/python3
"""Inputs of the walls benchmark: N uniform points in the unit cube inside a
convex polyhedron, and its walls as a (k, 4) float64 array (nx, ny, nz, d).

usage: gen_walls.py KIND N POINTS.npy WALLS.npy
  KIND: halfcube (x + y + z <= 1.5: one wall, half the cube),
        ball (64 tangent planes of the ball of radius 0.45 at the cube's
        centre: a polyhedron of 64 faces),
        hull (points uniform in that ball, walls their convex hull's facets,
        from tessera.hull_walls: thousands; needs PYTHONPATH=BUILD/python),
        sphere (points on that ball's sphere, every one a hull vertex: about
        two walls per point, the hull's facets as for hull)
Points are drawn in the cube (seed 88) and those outside the walls dropped
(with a margin of 1e-12, so that no tool's rounding puts one outside); the
hull's points are inside its walls exactly, by construction."""
import math
import sys

import numpy as np

kind, n, out_p, out_w = sys.argv[1], int(float(sys.argv[2])), sys.argv[3], sys.argv[4]
if kind == "halfcube":
    walls = np.array([[1.0, 1.0, 1.0, 1.5]])
elif kind == "ball":
    rows = []
    k = 64
    for i in range(k):  # a Fibonacci sphere of normals
        z = 1 - 2 * (i + 0.5) / k
        r = math.sqrt(1 - z * z)
        a = i * math.pi * (3 - math.sqrt(5))
        nrm = np.array([r * math.cos(a), r * math.sin(a), z])
        rows.append(list(nrm) + [0.45 + float(nrm @ np.array([0.5, 0.5, 0.5]))])
    walls = np.array(rows)
elif kind in ("hull", "sphere"):
    import tessera

    rng = np.random.default_rng(88)
    b = rng.normal(size=(n, 3))
    radius = rng.random((n, 1)) ** (1 / 3) if kind == "hull" else 1.0
    pts = 0.5 + 0.45 * b * radius / np.linalg.norm(b, axis=1)[:, None]
    np.save(out_p, np.ascontiguousarray(pts))
    np.save(out_w, np.ascontiguousarray(tessera.hull_walls(pts)))
    sys.exit(0)
else:
    sys.exit("gen_walls.py: KIND is halfcube, ball, hull or sphere")
rng = np.random.default_rng(88)
pts = np.empty((0, 3))
while len(pts) < n:
    p = rng.random((2 * n, 3))
    keep = np.all(p @ walls[:, :3].T <= walls[:, 3] - 1e-12, axis=1)
    pts = np.vstack([pts, p[keep]])
np.save(out_p, np.ascontiguousarray(pts[:n]))
np.save(out_w, np.ascontiguousarray(walls))
