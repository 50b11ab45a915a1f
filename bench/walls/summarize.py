#!/usr/bin/python3
"""Markdown table of bench/walls/run.sh's JSON lines: per input, the fastest
run of each tool and thread count, and Voro++'s time over Tessera's.

usage: summarize.py RESULTS.jsonl"""
import json
import sys
from collections import defaultdict

runs = defaultdict(list)
cells = {}
for line in open(sys.argv[1]):
    r = json.loads(line)
    runs[(r["input"], r["tool"], r["threads"])].append(r["seconds"])
    cells[(r["input"], r["tool"])] = r["simplices"]
inputs = sorted({k[0] for k in runs}, key=lambda s: (float(s.split()[1]), s))
print("| input | cells | Voro++ walls (1 thread) | Tessera walls 1T | 2T | Voro++ / Tessera 2T | Tessera box only 2T (all points' cells) |")
print("|---|---:|---:|---:|---:|---:|---:|")
for inp in inputs:
    med = {k[1:]: min(v) for k, v in runs.items() if k[0] == inp}
    v = med.get(("voro++-walls", 1))
    t1, t2 = med.get(("tessera-walls", 1)), med.get(("tessera-walls", 2))
    box2 = med.get(("tessera-box", 2))
    ratio = "%.2f×" % (v / t2) if v and t2 else "–"
    f = lambda x: "%.3f s" % x if x else "–"
    print(f"| {inp} | {cells.get((inp, 'tessera-walls'), '–')} | {f(v)} | {f(t1)} | {f(t2)} | {ratio} | {f(box2)} |")
