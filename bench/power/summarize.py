#!/usr/bin/env python3
"""Markdown tables of bench/power/run.sh's JSON lines: the fastest of each
tool's repeats per input, size and thread count. Power cells against Voro++'s
container_poly (one thread); regular triangulations against CGAL's
Regular_triangulation_3, and periodic ones against its
Periodic_3_regular_triangulation_3."""
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
    if any(k[2] == "voro++-poly" for k in best):
        print_cells(best, cells)
    if any(k[2] == "cgal-regular" for k in best):
        print()
        print_regular(best, cells)
    if any(k[2] == "cgal-periodic-regular" for k in best):
        print()
        print_periodic_regular(best, cells)


def print_cells(best, cells):
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


def print_regular(best, simplices):
    """The regular triangulations: CGAL's Regular_triangulation_3 (sequential
    and Parallel_tag) against Tessera's, simplices compared."""
    print("| input | n | CGAL regular, 1 thread | 2 threads | Tessera regular, 1 thread | 2 threads "
          "| vs CGAL (2 threads) | Tessera Delaunay, 2 threads | simplices (Tessera / CGAL) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for (inp, n) in sorted({(k[0], k[1]) for k in best if k[2] == "cgal-regular"}):
        g = lambda tool, t: best.get((inp, n, tool, t), float("nan"))
        c1, c2, t1, t2, d2 = (g("cgal-regular", 1), g("cgal-regular", 2), g("tessera-regular", 1),
                              g("tessera-regular", 2), g("tessera-delaunay", 2))
        s = f"{simplices.get((inp, n, 'tessera-regular', 2), '?')} / {simplices.get((inp, n, 'cgal-regular', 2), '?')}"
        print(f"| {inp} | {n:,} | {c1:.2f} s | {c2:.2f} s | {t1:.2f} s | {t2:.2f} s | {c2 / t2:.2f}x | {d2:.2f} s | {s} |")


def print_periodic_regular(best, simplices):
    """Periodic regular triangulations of the unit cube: CGAL's
    Periodic_3_regular_triangulation_3 (sequential) against Tessera's."""
    print("| input | n | CGAL periodic regular (1 thread) | Tessera, 1 thread | 2 threads | vs CGAL (1 thread) "
          "| vs CGAL (2 threads) | simplices (Tessera / CGAL) |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for (inp, n) in sorted({(k[0], k[1]) for k in best if k[2] == "cgal-periodic-regular"}):
        g = lambda tool, t: best.get((inp, n, tool, t), float("nan"))
        c, t1, t2 = g("cgal-periodic-regular", 1), g("tessera-periodic-regular", 1), g("tessera-periodic-regular", 2)
        s = (f"{simplices.get((inp, n, 'tessera-periodic-regular', 2), '?')} / "
             f"{simplices.get((inp, n, 'cgal-periodic-regular', 1), '?')}")
        print(f"| {inp} | {n:,} | {c:.2f} s | {t1:.2f} s | {t2:.2f} s | {c / t1:.1f}x | {c / t2:.1f}x | {s} |")


if __name__ == "__main__":
    main()
