#!/usr/bin/python3
"""Markdown tables (medians over repeats) of bench/clustered/run.sh's .jsonl.

Usage: summarize.py RESULTS.jsonl
"""
import json
import statistics
import sys
from collections import defaultdict


def table2(runs, inputs, med, fmt, ratio):
    """2D inputs: Tessera's cells and Delaunay against CGAL's Delaunay_triangulation_2 and
    scipy's Delaunay and Voronoi (Qhull, one thread)."""
    print("| input | points | Tessera cells | method | scipy Voronoi | scipy / Tessera | Tessera Delaunay | "
          "CGAL | scipy Delaunay | CGAL / Tessera | scipy / Tessera | triangles (Tessera / CGAL) |")
    print("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for i in inputs:
        cells = med((i, "tessera", "voronoi2"))
        rs = runs.get((i, "tessera", "voronoi2"), [])
        how = "-" if not rs else ("insertion" if rs[0]["extra"].get("from_insertion") else "search")
        svor = next((med(k) for k in runs if k[0] == i and k[1].startswith("scipy") and "voronoi" in k[2]), None)
        dt = med((i, "tessera", "delaunay2"))
        cgal = med((i, "cgal", "delaunay2"))
        sdel = next((med(k) for k in runs if k[0] == i and k[1].startswith("scipy") and "delaunay" in k[2]), None)
        n = next(r["n"] for k, v in runs.items() if k[0] == i for r in v)
        simp = []
        for tool in ("tessera", "cgal"):
            r = runs.get((i, tool, "delaunay2"))
            simp.append(format(r[0]["simplices"], ",") if r else "-")
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            i, format(n, ","), fmt(cells), how, fmt(svor), ratio(svor, cells), fmt(dt), fmt(cgal), fmt(sdel),
            ratio(cgal, dt), ratio(sdel, dt), " / ".join(simp)))
    print()
    if any(k[1] == "tessera-search" and k[2] == "voronoi2" for k in runs):
        print("Tessera's 2D cells, automatic method against `--method search` (- : timed out). "
              "Speed-up = search seconds / automatic seconds.\n")
        print("| input | points | automatic s | search s | speed-up |")
        print("|---|---:|---:|---:|---:|")
        for i in inputs:
            auto, search = med((i, "tessera", "voronoi2")), med((i, "tessera-search", "voronoi2"))
            n = next(r["n"] for k, v in runs.items() if k[0] == i for r in v)
            print("| %s | %s | %s | %s | %s |" % (i, format(n, ","), fmt(auto), fmt(search), ratio(search, auto)))
        print()


def main():
    runs = defaultdict(list)
    inputs = []
    with open(sys.argv[1]) as f:
        for line in f:
            if line.strip():
                d = json.loads(line)
                runs[(d["input"], d["tool"], d["op"])].append(d)
                if d["input"] not in inputs:
                    inputs.append(d["input"])

    def med(key):
        rs = runs.get(key)
        return statistics.median(r["seconds"] for r in rs) if rs else None

    def fmt(x):
        return "-" if x is None else "%.3f" % x

    def ratio(peer, ours):
        return "-" if peer is None or ours is None else "%.2fx" % (peer / ours)

    inputs3 = [i for i in inputs if not any(k[0] == i and k[2].endswith("2") for k in runs)]
    inputs2 = [i for i in inputs if i not in inputs3]
    print("Seconds (wall, median). Ratio = peer seconds / Tessera seconds (> 1: Tessera faster).\n")
    if inputs2:
        table2(runs, inputs2, med, fmt, ratio)
    if not inputs3:
        return
    inputs = inputs3
    print("| input | points | Tessera cells | Voro++ cells (1 thread) | Voro++ / Tessera | Tessera Delaunay | "
          "CGAL | HXT | CGAL / Tessera | HXT / Tessera | simplices (Tessera / CGAL / HXT) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for i in inputs:
        cells = med((i, "tessera", "voronoi3"))
        voro = med((i, "voro++", "voronoi3"))
        dt = med((i, "tessera", "delaunay3"))
        cgal = med((i, "cgal", "delaunay3"))
        hxt = next((med(k) for k in runs if k[0] == i and k[1].startswith("gmsh")), None)
        n = next(r["n"] for k, rs in runs.items() if k[0] == i for r in rs)
        simp = []
        for tool in ("tessera", "cgal", "gmsh"):
            rs = [r for k, v in runs.items() if k[0] == i and k[1].startswith(tool) and k[2] == "delaunay3" for r in v]
            simp.append(format(rs[0]["simplices"], ",") if rs else "-")
        print("| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            i, format(n, ","), fmt(cells), fmt(voro), ratio(voro, cells), fmt(dt), fmt(cgal), fmt(hxt),
            ratio(cgal, dt), ratio(hxt, dt), " / ".join(simp)))

    # The cells by the automatic method against --method search (run.sh SEARCH=1).
    if any(k[1] == "tessera-search" for k in runs):
        print("\nTessera's cells, automatic method (`from_insertion`: clipped by Delaunay neighbours) against "
              "`--method search`. Speed-up = search seconds / automatic seconds.\n")
        print("| input | points | automatic s | method | search s | speed-up |")
        print("|---|---:|---:|---|---:|---:|")
        for i in inputs:
            auto = med((i, "tessera", "voronoi3"))
            search = med((i, "tessera-search", "voronoi3"))
            rs = runs.get((i, "tessera", "voronoi3"), [])
            how = "-" if not rs else ("insertion" if rs[0]["extra"].get("from_insertion") else "search")
            n = next(r["n"] for k, v in runs.items() if k[0] == i for r in v)
            print("| %s | %s | %s | %s | %s | %s |" % (i, format(n, ","), fmt(auto), how, fmt(search),
                                                      ratio(search, auto)))


if __name__ == "__main__":
    main()
