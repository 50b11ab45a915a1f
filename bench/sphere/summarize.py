#!/usr/bin/env python3
"""Markdown table of bench/sphere/run.sh's JSON lines: the fastest of each
tool's repeats per size and thread count, with the ratios of the peers'
times to Tessera's (1 thread; 2 threads against the peers' single thread:
neither runs in parallel) and the triangles each found."""
import json
import sys


def main():
    best = {}
    for line in open(sys.argv[1]):
        j = json.loads(line)
        key = (j["input"], j["n"], j["tool"], j["threads"])
        if j["seconds"] is None:  # the peer refused the input (its message is kept)
            best.setdefault(key, j)
            continue
        if key not in best or best[key]["seconds"] is None or j["seconds"] < best[key]["seconds"]:
            best[key] = j
    print("| input | n | Tessera 1 thread | Tessera 2 threads | CGAL (tri + dual) | scipy (construct + sort + areas) "
          "| vs CGAL (1 / 2 threads) | vs scipy (1 / 2 threads) | triangles (Tessera; CGAL; scipy) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for inp, n in sorted({k[:2] for k in best}, key=lambda x: (x[0] != "uniform", x[0], x[1])):
        t1, t2 = best.get((inp, n, "tessera", 1)), best.get((inp, n, "tessera", 2))
        cg, sp = best.get((inp, n, "cgal", 1)), best.get((inp, n, "scipy", 1))

        def s(j):
            return "–" if j is None else f"{j['seconds']:.3f} s"

        def ratio(peer):
            if peer is None or t1 is None or t2 is None or peer["seconds"] is None:
                return "–"
            return f"{peer['seconds'] / t1['seconds']:.1f}x / {peer['seconds'] / t2['seconds']:.1f}x"

        cgs = "–" if cg is None else f"{cg['seconds']:.3f} s ({cg['extra']['triangulate_s']:.3f} + {cg['extra']['dual_s']:.3f})"
        sps = "–" if sp is None else f"refused: {sp['extra']['error']}" if sp["seconds"] is None else (
            f"{sp['seconds']:.2f} s ({sp['extra']['construct_s']:.2f} + "
                                      f"{sp['extra']['sort_s']:.2f} + {sp['extra']['areas_s']:.2f})")
        tri = "; ".join("?" if j is None or j["seconds"] is None else f"{j['simplices']:,}" for j in (t1, cg, sp))
        print(f"| {inp} | {n:,} | {s(t1)} | {s(t2)} | {cgs} | {sps} | {ratio(cg)} | {ratio(sp)} | {tri} |")


if __name__ == "__main__":
    main()
