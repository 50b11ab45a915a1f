#!/usr/bin/env python3
"""Points in the unit cube with sphere radii, for the power-cell benchmark.

usage: gen_power.py KIND N POINTS.npy RADII.npy [SEED]
  KIND uniform: radii uniform in [0, s/2), s = N^(-1/3) the mean spacing
       (spheres overlap a little; few cells empty);
       bimodal: half the radii 0.2 s, half 0.45 s (two sizes of grains).
"""
import sys

import numpy as np


def main():
    if len(sys.argv) not in (5, 6):
        sys.exit(__doc__)
    kind, n, out_p, out_r = sys.argv[1], int(float(sys.argv[2])), sys.argv[3], sys.argv[4]
    rng = np.random.default_rng(int(sys.argv[5]) if len(sys.argv) == 6 else 1)
    p = rng.random((n, 3))
    s = n ** (-1.0 / 3.0)
    if kind == "uniform":
        r = rng.random(n) * 0.5 * s
    elif kind == "bimodal":
        r = np.where(rng.random(n) < 0.5, 0.2 * s, 0.45 * s)
    else:
        sys.exit(f"gen_power.py: unknown kind {kind!r}")
    np.save(out_p, p)
    np.save(out_r, r)


if __name__ == "__main__":
    main()
