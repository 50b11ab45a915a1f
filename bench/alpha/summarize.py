#!/usr/bin/env python3
"""Markdown table of bench/alpha/run.sh's JSON lines: the fastest of each
tool's repeats per input, size and thread count (the time of the
triangulation and of the alpha shape beside the total), with the parts'
counts from both tools (kept simplices, boundary and singular facets)."""
import json
import sys
from collections import defaultdict


def main():
    best = {}
    for line in open(sys.argv[1]):
        j = json.loads(line)
        key = (j["input"], j["n"], j["tool"], j["threads"])
        if key not in best or j["seconds"] < best[key]["seconds"]:
            best[key] = j
    print("| input | n | CGAL 1 thread (tri + shape) | CGAL 2 threads | Tessera 1 thread (tri + shape) "
          "| Tessera 2 threads | vs CGAL (1 / 2 threads) | kept / boundary / singular (Tessera; CGAL) |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    cases = sorted({(k[0], k[1]) for k in best})
    for inp, n in cases:
        def cell(tool, t):
            j = best.get((inp, n, tool, t))
            if j is None:
                return "–", float("nan")
            e = j["extra"]
            return f"{j['seconds']:.2f} s ({e['triangulate_s']:.2f} + {e['alpha_s']:.2f})", j["seconds"]
        c1, c1s = cell("cgal", 1)
        c2, c2s = cell("cgal", 2)
        t1, t1s = cell("tessera", 1)
        t2, t2s = cell("tessera", 2)
        cgal_best = min(c1s, c2s) if c2s == c2s else c1s

        def parts(tool):
            j = best.get((inp, n, tool, 1)) or best.get((inp, n, tool, 2))
            return "?" if j is None else f"{j['simplices']:,} / {j['extra']['boundary']:,} / {j['extra']['singular']:,}"
        ratio = f"{c1s / t1s:.1f}x / {cgal_best / t2s:.1f}x"
        print(f"| {inp} | {n:,} | {c1} | {c2} | {t1} | {t2} | {ratio} | {parts('tessera')}; {parts('cgal')} |")


if __name__ == "__main__":
    main()
