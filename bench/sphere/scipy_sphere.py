#!/usr/bin/python3
"""scipy.spatial.SphericalVoronoi as a peer of `tessera bench sphere`: the
construction (Qhull's hull, the circumcentres, the regions), the sorting of
the regions' vertices and their areas, timed apart. One JSON line.

usage: scipy_sphere.py POINTS.npy   (float64 (N, 3) on the unit sphere)
"""
import json
import resource
import sys
import time

import numpy as np
import scipy
from scipy.spatial import SphericalVoronoi

p = np.load(sys.argv[1])
t0 = time.perf_counter()
try:
    sv = SphericalVoronoi(p, radius=1.0)
except ValueError as e:  # e.g. "Duplicate generators present." (pairs within its threshold)
    print(json.dumps({"tool": "scipy", "op": "sphere", "n": len(p), "threads": 1, "seconds": None,
                      "simplices": 0, "extra": {"error": str(e), "after_s": time.perf_counter() - t0,
                                                "scipy": scipy.__version__}}))
    sys.exit(0)
t1 = time.perf_counter()
sv.sort_vertices_of_regions()
t2 = time.perf_counter()
areas = sv.calculate_areas()
t3 = time.perf_counter()
print(json.dumps({"tool": "scipy", "op": "sphere", "n": len(p), "threads": 1, "seconds": t3 - t0,
                  "simplices": len(sv.vertices),
                  "extra": {"construct_s": t1 - t0, "sort_s": t2 - t1, "areas_s": t3 - t2,
                            "area_error": float(areas.sum() / (4 * np.pi) - 1), "scipy": scipy.__version__,
                            "peak_rss_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024}}))
