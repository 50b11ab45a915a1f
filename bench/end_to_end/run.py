#!/usr/bin/python3
"""End to end: what a user's `tessera voronoi INPUT -o FILE` costs, files included.

The main benchmark (bench/run_bench.sh) times the library call only, as the
peers are timed. This one times the command a user runs, the README's main job
shape: read, compute the cells with their merged mesh, write the .vtu (.vtp in
2D), the per-cell .csv table and the neighbour lists. It reports the CLI's own
phase times (read, compute, write), the wall time of the whole process and its
peak resident size, each the minimum over REPEAT runs with `sync` before each
run (so the page cache's write-back of one run's 0.8 GB does not land on the
next). With --base BINARY it alternates runs of that binary and this one, for
an A/B in the same run.

usage: bench/end_to_end/run.py [--tessera BIN] [--base BIN [--base-label TEXT]] [--repeat K]
                               [--threads T] [--out FILE.md] INPUT...
Inputs are .npy point files (bench/run_bench.sh writes uniform3_1e6.npy and
uniform2_1e6.npy into bench/data). Outputs go to a temporary directory.
"""
import argparse
import datetime
import os
import re
import subprocess
import sys
import tempfile

PHASES = re.compile(r"compute\s+([0-9.]+) s on (\d+) threads? \(read ([0-9.]+) s, write ([0-9.]+) s\)")


def run_once(binary, inp, dim, threads, outdir):
    ext = ".vtu" if dim == 3 else ".vtp"
    cmd = ["/usr/bin/time", "-f", "TIME %e %M", binary, "voronoi", inp, "-o", os.path.join(outdir, "cells" + ext),
           "--cell-table", os.path.join(outdir, "cells.csv"), "--neighbors", os.path.join(outdir, "nb.npy"),
           "--threads", str(threads)]
    for f in os.listdir(outdir):
        os.remove(os.path.join(outdir, f))
    subprocess.run(["sync"], check=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("end_to_end: %s failed: %s" % (" ".join(cmd), r.stderr.strip().splitlines()[-1:]))
    m = PHASES.search(r.stdout)
    t = re.search(r"TIME ([0-9.]+) (\d+)", r.stderr)
    if not m or not t:
        sys.exit("end_to_end: cannot parse the output of %s" % " ".join(cmd))
    size = sum(os.path.getsize(os.path.join(outdir, f)) for f in os.listdir(outdir))
    return {"compute": float(m.group(1)), "read": float(m.group(3)), "write": float(m.group(4)),
            "wall": float(t.group(1)), "peak_mb": int(t.group(2)) / 1024.0, "bytes": size}


def dim_of(path):
    import numpy as np
    return np.load(path, mmap_mode="r").shape[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("inputs", nargs="+")
    ap.add_argument("--tessera", default="build/tessera")
    ap.add_argument("--base", help="a second binary, run alternately, for an A/B")
    ap.add_argument("--base-label", help="how the table names --base (default: its path)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", help="write the markdown table here (default: stdout only)")
    a = ap.parse_args()
    binaries = [("this", a.tessera)] + ([("base", a.base)] if a.base else [])
    rows = []
    with tempfile.TemporaryDirectory(prefix="tessera_e2e_") as outdir:
        for inp in a.inputs:
            dim = dim_of(inp)
            best = {name: None for name, _ in binaries}
            for _ in range(a.repeat):
                for name, binary in binaries:
                    r = run_once(binary, inp, dim, a.threads, outdir)
                    b = best[name]
                    best[name] = r if b is None else {k: min(b[k], r[k]) for k in r}
            for name, _ in binaries:
                rows.append((os.path.basename(inp), name, best[name]))
    git = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    lines = [
        "Command: `bench/end_to_end/run.py %s`" % " ".join(sys.argv[1:]),
        "",
        "Run %s on git %s, %d threads; every figure is the minimum of %d runs (sync before each)."
        % (datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"), git, a.threads, a.repeat),
        "",
        "| input | binary | read s | compute s | write s | process wall s | peak RSS MB | files MB |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for inp, name, r in rows:
        label = a.tessera if name == "this" else (a.base_label or a.base)
        lines.append("| %s | %s | %.3f | %.3f | %.3f | %.2f | %.0f | %.0f |" % (
            inp, label, r["read"], r["compute"], r["write"], r["wall"], r["peak_mb"], r["bytes"] / 1e6))
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
