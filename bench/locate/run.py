#!/usr/bin/python3
"""Point location and Delaunay edge lists: tessera against scipy.spatial.Delaunay.

Times, on uniform random points in the unit square / cube (fixed seeds), what a
scipy user calls after triangulating: `find_simplex` on M random queries in
[-0.1, 1.1]^D (so some lie outside the hull), `vertex_neighbor_vertices` and
`neighbors` (scipy's comes with its triangulation, from Qhull). Tessera's first
`find_simplex` call builds its locator (a walk's seeds and the simplices'
neighbours), which is timed apart and kept for later calls. The triangulations themselves
are timed by bench/run_bench.sh. Each figure is one run (these take minutes on
scipy's side); the two libraries must agree on which queries lie inside.

usage: bench/locate/run.py [--points N] [--queries M] [--threads T] [--dims 2,3] [--out FILE.md]
Run with Debian's /usr/bin/python3 and PYTHONPATH=build/python (numpy, scipy).
"""
import argparse
import datetime
import os
import subprocess
import sys
import time

import numpy as np
import scipy
import scipy.spatial

import tessera


def timed(fn):
    t = time.perf_counter()
    r = fn()
    return time.perf_counter() - t, r


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--queries", type=int, default=1_000_000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--dims", default="2,3")
    ap.add_argument("--out")
    a = ap.parse_args()
    rows = []
    for dim in [int(d) for d in a.dims.split(",")]:
        rng = np.random.default_rng(dim)
        pts = rng.random((a.points, dim))
        q = rng.random((a.queries, dim)) * 1.2 - 0.1
        dt = tessera.delaunay(pts, threads=a.threads)
        build, _ = timed(lambda: dt.find_simplex(q[:1]))
        query, ours = timed(lambda: dt.find_simplex(q))
        vnv, _ = timed(lambda: dt.vertex_neighbor_vertices)
        nbr, _ = timed(lambda: dt.neighbors)
        sp = scipy.spatial.Delaunay(pts)
        s_query, theirs = timed(lambda: sp.find_simplex(q))
        s_vnv, _ = timed(lambda: sp.vertex_neighbor_vertices)
        if not np.array_equal(ours >= 0, theirs >= 0):
            sys.exit("locate bench: tessera and scipy disagree on which queries lie inside")
        rows.append((dim, build, query, s_query, vnv, s_vnv, nbr, int((ours >= 0).sum())))
        print(rows[-1], file=sys.stderr, flush=True)
    git = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                         cwd=os.path.dirname(os.path.abspath(__file__))).stdout.strip()
    lines = [
        "# Point location and Delaunay edges: tessera vs scipy",
        "",
        "Written by `bench/locate/run.py` (see its docstring for what is timed); do not edit by hand, rerun it:",
        "",
        "```",
        "PYTHONPATH=build/python /usr/bin/python3 bench/locate/run.py --out docs/performance-locate.md",
        "```",
        "",
        f"Run {datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%dT%H:%M:%SZ')} on git {git}: "
        f"{a.points:,} uniform points, {a.queries:,} queries, tessera on {a.threads} threads, scipy "
        f"{scipy.__version__} (Qhull; single-threaded). Seconds, one run each.",
        "",
        "| dim | tessera locator build s | tessera find_simplex s | scipy find_simplex s | find_simplex speed-up "
        "| tessera vertex_neighbor_vertices s | scipy vertex_neighbor_vertices s | tessera neighbors s | queries inside |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for dim, build, query, s_query, vnv, s_vnv, nbr, inside in rows:
        lines.append(f"| {dim} | {build:.2f} | {query:.2f} | {s_query:.1f} | {s_query / (build + query):.0f}x "
                     f"(build included) | {vnv:.2f} | {s_vnv:.2f} | {nbr:.2f} | {inside:,} |")
    lines += ["", "The locator (a walk here: the triangulations cover their hull) and the grid it falls back to "
              "for labelled triangulations: docs/design.md, \"Delaunay and hull completion\" (point location)."]
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
