#!/usr/bin/env python3
"""Points and an alpha for the alpha-shape benchmark (bench/alpha/run.sh).

usage: gen_alpha.py KIND N POINTS.npy ALPHA.txt [SEED]
  KIND cube:    uniform in the unit cube, alpha = s (s = N^(-1/3) the mean
                spacing: most of the volume kept, ragged at the faces);
       torus:   uniform on a torus (R = 1, r = 0.3): surface samples, whose
                reconstructed surface is the singular triangles, alpha = 2 s
                (s = sqrt(area / N));
       square:  uniform in the unit square (2D), alpha = s = N^(-1/2);
       annulus: uniform in the annulus 0.5 < |x| < 1 (2D), alpha = s.
"""
import sys

import numpy as np


def main():
    if len(sys.argv) not in (5, 6):
        sys.exit(__doc__)
    kind, n, out_p, out_a = sys.argv[1], int(float(sys.argv[2])), sys.argv[3], sys.argv[4]
    rng = np.random.default_rng(int(sys.argv[5]) if len(sys.argv) == 6 else 1)
    if kind == "cube":
        p, alpha = rng.random((n, 3)), n ** (-1 / 3)
    elif kind == "torus":
        # Uniform by area: the angle around the tube weighted by its circle's length.
        u = rng.uniform(0, 2 * np.pi, n)
        v = np.empty(0)
        while len(v) < n:
            c = rng.uniform(0, 2 * np.pi, 2 * n)
            keep = rng.uniform(0, 1.3, 2 * n) < 1 + 0.3 * np.cos(c)
            v = np.concatenate([v, c[keep]])
        v = v[:n]
        p = np.c_[(1 + 0.3 * np.cos(v)) * np.cos(u), (1 + 0.3 * np.cos(v)) * np.sin(u), 0.3 * np.sin(v)]
        alpha = 2 * np.sqrt(4 * np.pi ** 2 * 0.3 / n)
    elif kind == "square":
        p, alpha = rng.random((n, 2)), n ** (-1 / 2)
    elif kind == "annulus":
        a = rng.uniform(0, 2 * np.pi, n)
        r = np.sqrt(rng.uniform(0.25, 1, n))
        p, alpha = np.c_[r * np.cos(a), r * np.sin(a)], np.sqrt(0.75 * np.pi / n)
    else:
        sys.exit(f"gen_alpha.py: unknown kind {kind!r}")
    np.save(out_p, p)
    with open(out_a, "w") as f:
        f.write(f"{alpha:.17g}\n")


if __name__ == "__main__":
    main()
