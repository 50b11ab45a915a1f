#!/usr/bin/python3
"""Markdown table (medians over repeats) of a surface-nets benchmark .jsonl.

Usage: summarize.py RESULTS.jsonl
"""
import json
import statistics
import sys
from collections import defaultdict


def main():
    runs = defaultdict(list)
    with open(sys.argv[1]) as f:
        for line in f:
            if line.strip():
                d = json.loads(line)
                runs[(d["tool"], d["op"])].append(d)
    print("| method | threads | seconds (median) | spread | triangles | points/vertices | watertight | "
          "open labels | boundary edges | non-manifold edges | stages (s) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for (tool, op), rs in runs.items():
        secs = sorted(r["seconds"] for r in rs)
        med = statistics.median(secs)
        e = rs[0]["extra"]
        spread = "%.0f %%" % (100 * (secs[-1] - secs[0]) / med) if len(secs) > 1 else "-"
        if tool == "tessera":
            verts = "%s pts -> %s verts" % (format(e["points"], ","), format(e["vertices"], ","))
            stages = "sample %.2f, cells %.2f, faces %.2f, smooth %.2f, tri %.2f" % tuple(
                statistics.median(r["extra"][k] for r in rs)
                for k in ("sample_s", "cells_s", "faces_s", "smoothing_s", "triangulation_s"))
            tris = "%s (%s polygons)" % (format(e["triangles"], ","), format(e["polygons"], ","))
        else:
            verts = format(e["points"], ",")
            stages = "-"
            tris = format(e["triangles"], ",")
        name = op.split(":", 1)[1] if ":" in op else op
        print("| %s %s | %d | %.3f | %s | %s | %s | %s | %d / %d | %d | %d | %s |" % (
            tool, name, rs[0]["threads"], med, spread, tris, verts, "yes" if e["watertight"] else "no",
            e["open_labels"], e["labels"], e["boundary_edges"], e["nonmanifold_edges"], stages))


if __name__ == "__main__":
    main()
