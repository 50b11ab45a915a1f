#!/usr/bin/env python3
"""Markdown table of bench/power/run.sh's JSON lines: the fastest of each
tool's repeats per input, size and thread count, with Voro++'s container_poly
(one thread) as the reference."""
import json
import sys
from collections import defaultdict


def main():
    best = defaultdict(lambda: float("inf"))
    cells = {}
    for line in open(sys.argv[1]):
        j = json.loads(line)
        key = (j["input"], j["n"], j["tool"], j["threads"])
        best[key] = min(best[key], j["seconds"])
        cells[key] = j["simplices"]
    print("| input | n | Voro++ poly (1 thread) | Tessera power, 1 thread | 2 threads | vs Voro++ (2 threads) "
          "| Tessera ordinary cells, 2 threads | cells (Tessera / Voro++) |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for (inp, n, tool, t) in sorted(k for k in best if k[2] == "voro++-poly"):
        v = best[(inp, n, tool, t)]
        p1 = best.get((inp, n, "tessera-power", 1), float("nan"))
        p2 = best.get((inp, n, "tessera-power", 2), float("nan"))
        o2 = best.get((inp, n, "tessera", 2), float("nan"))
        c = f"{cells.get((inp, n, 'tessera-power', 2), '?')} / {cells[(inp, n, tool, t)]}"
        print(f"| {inp} | {n:,} | {v:.2f} s | {p1:.2f} s | {p2:.2f} s | {v / p2:.1f}x | {o2:.2f} s | {c} |")


if __name__ == "__main__":
    main()
