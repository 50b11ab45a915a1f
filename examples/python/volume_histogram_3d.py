#!/usr/bin/python3
"""Cell volumes and face counts of a 3D Poisson-Voronoi tessellation, as histograms.

Uniform random points in the unit cube; only cells without a face on the box
count (the box truncates the others). The volumes, over their mean, follow
closely a gamma distribution of shape about 5.59 and the mean number of faces
is about 15.54 (Ferenc and Neda, Physica A 385, 2007); both are drawn for
comparison. merge=False: only volumes and neighbours are needed, no mesh.

    /usr/bin/python3 examples/python/volume_histogram_3d.py --out docs/images

Writes OUT/volume_histogram_3d.png. --small uses fewer points (the ctest run).
"""

import argparse
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tessera  # noqa: E402

GAMMA_SHAPE = 5.586  # Poisson-Voronoi cell volumes in 3D (Ferenc and Neda)


def gamma_pdf(x, k):
    return k**k * x ** (k - 1) * np.exp(-k * x) / math.gamma(k)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=".", help="output folder")
    ap.add_argument("--small", action="store_true", help="few points (quick check)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)

    n = 20_000 if args.small else 200_000
    pts = np.random.default_rng(1).random((n, 3))
    vor = tessera.voronoi(pts, bounds=(0, 1, 0, 1, 0, 1), merge=False)
    assert abs(vor.volumes.sum() - 1) < 1e-9

    # Box faces count in num_faces but are not neighbours: interior cells have none.
    interior = vor.num_faces == np.diff(vor.neighbor_offsets)
    volumes = vor.volumes[interior] / vor.volumes[interior].mean()
    faces = vor.num_faces[interior]
    assert abs(faces.mean() - 15.54) < 0.3, faces.mean()

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4), constrained_layout=True)
    left.hist(volumes, bins=80, density=True, color="#4C72B0", alpha=0.8, label="tessera")
    x = np.linspace(0.01, volumes.max(), 300)
    left.plot(x, gamma_pdf(x, GAMMA_SHAPE), color="#C44E52", lw=2, label=f"gamma, shape {GAMMA_SHAPE}")
    left.set_xlabel("cell volume / mean volume")
    left.set_ylabel("density")
    left.set_title(f"{int(interior.sum())} interior cells of {n} uniform points")
    left.legend()

    counts = np.bincount(faces)
    right.bar(np.arange(len(counts)), counts / counts.sum(), color="#55A868", alpha=0.85)
    right.axvline(faces.mean(), color="k", lw=1.5, label=f"mean {faces.mean():.2f} (theory 15.54)")
    right.set_xlabel("faces per cell")
    right.set_ylabel("fraction of cells")
    right.set_title("Faces per cell")
    right.legend()

    path = os.path.join(args.out, "volume_histogram_3d.png")
    fig.savefig(path, dpi=110, bbox_inches="tight", pad_inches=0.15)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
