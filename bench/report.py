#!/usr/bin/python3
"""Turn one bench/run_bench.sh results folder into docs/performance.md.

usage: report.py RUN_DIR [-o docs/performance.md]      markdown report (stdout without -o)
       report.py --write-meta RUN_DIR --command CMD ...  (run_bench.sh, before the runs)
       report.py --finish-meta RUN_DIR                   (run_bench.sh, after the runs)

RUN_DIR holds meta.json and one INPUT.jsonl per input: JSON lines in the peers' format
{"tool","op","n","threads","seconds","simplices","extra"}. Every figure is a median over the
timed runs of one configuration, and every ratio compares configurations of the same run.
"""
import argparse
import datetime
import json
import os
import platform
import statistics
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

META = "meta.json"


# ---------------------------------------------------------------- machine / run metadata
def cpu_model():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def mem_total_gib():
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemTotal:"):
                return round(int(line.split()[1]) / 2**20, 1)
    except OSError:
        pass
    return None


def loadavg():
    try:
        return " ".join(open("/proc/loadavg").read().split()[:3])
    except OSError:
        return "unknown"


def git(repo, *args):
    r = subprocess.run(["git", "-C", str(repo), *args], capture_output=True, text=True)
    return r.stdout.strip() if r.returncode == 0 else ""


def now():
    return datetime.datetime.now().astimezone().isoformat(timespec="seconds")


def write_meta(a):
    repo = Path(__file__).resolve().parent.parent
    rev = git(repo, "rev-parse", "--short", "HEAD") or "no commit"
    dirty = bool(git(repo, "status", "--porcelain", "--untracked-files=no")) or rev == "no commit"
    version = ""
    if a.tessera and a.tessera != "none":
        try:
            r = subprocess.run([a.tessera, "--version"], capture_output=True, text=True, timeout=30)
            lines = (r.stdout or r.stderr).strip().splitlines()
            version = lines[0] if r.returncode == 0 and lines else ""
        except OSError:
            pass
    meta = {
        "command": a.command, "started": now(), "load_start": loadavg(),
        "nproc": os.cpu_count(), "affinity": len(os.sched_getaffinity(0)), "cpu": cpu_model(),
        "mem_gib": mem_total_gib(), "kernel": platform.release(),
        "git": rev + (" (uncommitted changes)" if dirty else ""),
        "tessera": a.tessera, "tessera_version": version,
        "tessera_built": (datetime.datetime.fromtimestamp(os.path.getmtime(a.tessera)).astimezone().isoformat(timespec="seconds")
                          if os.path.isfile(a.tessera) else ""),
        "tessera_build_type": a.build_type, "reps": int(a.reps), "warmup": int(a.warmup),
        "threads": [int(t) for t in a.threads.split()], "peers": a.peers,
        "inputs": a.inputs.split(),
        "ops": a.ops.split() or ["voronoi"],
        "peer_threads": [int(t) for t in a.peer_threads.split()] or [1, 2],
    }
    Path(a.run_dir).mkdir(parents=True, exist_ok=True)
    (Path(a.run_dir) / META).write_text(json.dumps(meta, indent=1) + "\n")


def finish_meta(run_dir):
    p = Path(run_dir) / META
    meta = json.loads(p.read_text())
    meta.update(finished=now(), load_end=loadavg())
    p.write_text(json.dumps(meta, indent=1) + "\n")


# ---------------------------------------------------------------- results
class Group:
    """The timed runs of one configuration (input, tool, op, threads)."""

    def __init__(self, runs):
        self.runs = runs
        self.n = runs[0]["n"]
        self.secs = [self.seconds(r) for r in runs]
        self.med = statistics.median(self.secs)
        self.spread = (max(self.secs) - min(self.secs)) / self.med if self.med > 0 else 0.0
        self.simplices = statistics.median(r["simplices"] for r in runs)
        peaks = [r["extra"].get("peak_rss_bytes", r["extra"].get("max_rss_bytes")) for r in runs]
        self.peak = max(peaks) if all(isinstance(p, (int, float)) for p in peaks) else None
        self.threads = runs[0]["threads"]

    @staticmethod
    def seconds(r):
        # Voro++'s driver times the cell loop only; its container fill (put) is part of
        # computing the cells, as tessera's binning is, so it is added back.
        return r["seconds"] + (r["extra"].get("insert_seconds", 0.0) if r["tool"] == "voro++" else 0.0)

    def extra_med(self, key):
        v = [r["extra"][key] for r in self.runs if isinstance(r["extra"].get(key), (int, float))]
        return statistics.median(v) if len(v) == len(self.runs) else None


def tool_key(r):
    """The tool name results are grouped by: gmsh_delaunay's HXT runs apart from its delaunay3d ones."""
    if r["tool"] == "gmsh" and str(r.get("extra", {}).get("algo", "")).startswith("HXT"):
        return "gmsh-hxt"
    return r["tool"]


def load(run_dir):
    meta = json.loads((Path(run_dir) / META).read_text())
    names = list(meta.get("inputs", []))
    names += sorted(p.stem for p in Path(run_dir).glob("*.jsonl") if p.stem not in names)
    data = {}
    for name in names:
        p = Path(run_dir) / f"{name}.jsonl"
        if not p.exists():
            continue
        by = defaultdict(list)
        for line in p.read_text().splitlines():
            if line.startswith("{"):
                r = json.loads(line)
                by[(tool_key(r), r["op"], r["threads"])].append(r)
        data[name] = {k: Group(v) for k, v in by.items()}
    return meta, data


# ---------------------------------------------------------------- formatting
DASH = "–"


def fs(x):  # seconds
    return DASH if x is None else (f"{x:.3f}" if x < 100 else f"{x:.1f}")


def fr(x):  # ratio
    return DASH if x is None else f"{x:.2f}x"


def frate(x):  # cells/s in millions
    return DASH if x is None else (f"{x / 1e6:.2f} M" if x >= 1e6 else f"{x / 1e3:.0f} k")


def fb(x):  # bytes per point
    return DASH if x is None else f"{x:.0f}"


def fn(n):
    return f"{int(n):,}"


def div(a, b):
    return a / b if a is not None and b not in (None, 0) else None


NOISY = 0.10  # spread above which a median is flagged


def med(g):
    return g.med if g else None


def fm(g):  # a group's median seconds, flagged when its runs disagree
    return DASH if g is None else fs(g.med) + (" ‡" if g.spread > NOISY else "")


def per_core(g):
    return g.simplices / (g.med * g.threads) if g and g.med > 0 else None


def bpp(g):
    return g.peak / g.n if g and g.peak is not None else None


def report(meta, data):
    ths = meta.get("threads", [1, 2])
    t1, t2 = (ths[0], ths[-1]) if ths else (1, 2)
    L = []
    w = L.append
    w("# Performance")
    w("")
    w("Generated by `bench/report.py` from one run of `bench/run_bench.sh`; do not edit by hand, rerun it.")
    w("See `bench/README.md` for what every number means. Surface nets are measured by their own")
    w("script: `docs/performance-surface-nets.md`; power cells (`--radii`) against Voro++'s container_poly by theirs:")
    w("`docs/performance-power.md`; cells on a sphere against CGAL and scipy: `docs/performance-sphere.md`.")
    w("")
    w("Command (from the repository root):")
    w("")
    w("```")
    w(meta["command"])
    w("```")
    w("")
    w(f"* Run: {meta['started']} to {meta.get('finished', '?')}; load average (1/5/15 min) {meta['load_start']} "
      f"before the first input, {meta.get('load_end', '?')} after the last (the benchmark itself adds 1 to 2; "
      "more means other work shared the cores: check the spread column).")
    w(f"* Machine: {meta['cpu']}, nproc {meta['nproc']} (affinity {meta['affinity']}), "
      f"{meta['mem_gib']} GiB, Linux {meta['kernel']}.")
    w(f"* Tessera: `{meta['tessera']}` ({meta['tessera_build_type']} build{', ' + meta['tessera_version'] if meta.get('tessera_version') else ''}), "
      f"binary built {meta.get('tessera_built') or '?'}, git {meta['git']}.")
    w(f"* Every figure is the median of {meta['reps']} timed runs after {meta['warmup']} untimed warm-up run(s); "
      "ratios compare medians of this run only.")
    w("")

    w(f"‡: the timed runs of that configuration differ by more than {NOISY:.0%} of their median (another "
      "process shared the cores; its CPU seconds in the last table stay put while wall time moves): "
      "treat its ratios as rough.")
    w("")

    have_tessera = any(k[0] == "tessera" for groups in data.values() for k in groups)
    if not have_tessera:
        w("**No tessera results in this run** (the binary failed or was missing): only the peers are shown.")
        w("")

    def g(groups, tool, op, th=None):
        for (tl, o, t), grp in groups.items():
            if tl == tool and o == op and (th is None or t == th):
                return grp
        return None

    d3 = {k: v for k, v in data.items() if any(o == "voronoi3" for (_, o, _) in v)}
    d2 = {k: v for k, v in data.items() if any(o == "voronoi2" for (_, o, _) in v)}
    dd = {k: v for k, v in data.items() if any(tl == "tessera" and o in ("delaunay3", "delaunay2") for (tl, o, _) in v)}

    if d3:
        w("## 3D Voronoi cells: Tessera vs Voro++ 0.4.6")
        w("")
        w(f"Seconds (wall). Speed-up = Voro++ seconds / Tessera seconds (> 1: Tessera faster). "
          f"Scaling = Tessera {t1}-thread seconds / {t2}-thread seconds.")
        w("")
        w(f"| input | points | cells | Voro++ s | Tessera {t1}T s | Tessera {t2}T s | speed-up {t1}T | speed-up {t2}T | scaling {t1}→{t2} |")
        w("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for name, grp in d3.items():
            v, a, b = g(grp, "voro++", "voronoi3"), g(grp, "tessera", "voronoi3", t1), g(grp, "tessera", "voronoi3", t2)
            n = (a or v or b).n
            cells = (a or b or v).simplices
            w(f"| {name} | {fn(n)} | {fn(cells)} | {fm(v)} | {fm(a)} | {fm(b)} | "
              f"{fr(div(med(v), med(a)))} | {fr(div(med(v), med(b)))} | {fr(div(med(a), med(b)))} |")
        w("")
        w("Throughput and memory. Cells/s/core = cells / (seconds x threads). Peak bytes/point = the "
          "process's peak resident set / points (whole process: input array and output included).")
        w("")
        w(f"| input | Voro++ cells/s | Tessera {t1}T cells/s/core | Tessera {t2}T cells/s/core | "
          f"Voro++ peak B/pt | Tessera {t1}T peak B/pt | Tessera {t2}T peak B/pt |")
        w("|---|---:|---:|---:|---:|---:|---:|")
        for name, grp in d3.items():
            v, a, b = g(grp, "voro++", "voronoi3"), g(grp, "tessera", "voronoi3", t1), g(grp, "tessera", "voronoi3", t2)
            w(f"| {name} | {frate(per_core(v))} | {frate(per_core(a))} | {frate(per_core(b))} | "
              f"{fb(bpp(v))} | {fb(bpp(a))} | {fb(bpp(b))} |")
        w("")

    if d2:
        w("## 2D Voronoi cells (no 2D Voro++ in Debian): references CGAL and scipy")
        w("")
        w("CGAL 5.5.1 `Delaunay_triangulation_2` (the dual triangulation only, no cells) and "
          "`scipy.spatial.Voronoi` (Qhull; vertices + ridges, no clipping). Speed-up = reference seconds / Tessera seconds.")
        w("")
        w(f"| input | points | cells | CGAL DT2 s | scipy Voronoi s | Tessera {t1}T s | Tessera {t2}T s | "
          f"vs CGAL {t1}T | vs scipy {t1}T | vs scipy {t2}T | scaling {t1}→{t2} | Tessera {t1}T cells/s/core | "
          f"Tessera {t1}T peak B/pt | scipy peak B/pt |")
        w("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for name, grp in d2.items():
            c, s = g(grp, "cgal", "delaunay2"), g(grp, "scipy", "voronoi2")
            a, b = g(grp, "tessera", "voronoi2", t1), g(grp, "tessera", "voronoi2", t2)
            n = (a or c or s or b).n
            cells = (a or b).simplices if (a or b) else None
            w(f"| {name} | {fn(n)} | {DASH if cells is None else fn(cells)} | {fm(c)} | {fm(s)} | "
              f"{fm(a)} | {fm(b)} | {fr(div(med(c), med(a)))} | {fr(div(med(s), med(a)))} | "
              f"{fr(div(med(s), med(b)))} | {fr(div(med(a), med(b)))} | {frate(per_core(a))} | {fb(bpp(a))} | {fb(bpp(s))} |")
        w("")

    dm = {k: v for k, v in data.items() if any(o in ("voronoi3_mesh", "voronoi2_mesh") for (_, o, _) in v)}
    if dm:
        w("## Cells with the merged mesh (`--mesh`, MESH=1)")
        w("")
        w("What VTK output computes (`tessera voronoi INPUT -o FILE.vtu`, the README's main job): the cells "
          "above plus their conformal mesh, vertices merged by topological coordinate (timed without writing "
          "the file). Mesh / cells = seconds with the mesh / seconds without, same thread count. Voro++ / "
          "Tessera = Voro++ seconds (3D: its cells, each with its own vertex list, no merged mesh) / Tessera "
          "seconds with the mesh.")
        w("")
        w(f"| input | points | Tessera {t1}T s | Tessera {t2}T s | mesh / cells {t1}T | mesh / cells {t2}T | "
          f"Voro++ / Tessera {t2}T | Tessera {t1}T peak B/pt | Tessera {t2}T peak B/pt |")
        w("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for name, grp in dm.items():
            op = "voronoi3_mesh" if g(grp, "tessera", "voronoi3_mesh") else "voronoi2_mesh"
            cells = op[:-len("_mesh")]
            a, b = g(grp, "tessera", op, t1), g(grp, "tessera", op, t2)
            ca, cb = g(grp, "tessera", cells, t1), g(grp, "tessera", cells, t2)
            v = g(grp, "voro++", "voronoi3") if op == "voronoi3_mesh" else None
            n = (a or b).n
            w(f"| {name} | {fn(n)} | {fm(a)} | {fm(b)} | {fr(div(med(a), med(ca)))} | {fr(div(med(b), med(cb)))} | "
              f"{fr(div(med(v), med(b)))} | {fb(bpp(a))} | {fb(bpp(b))} |")
        w("")

    if dd:
        delaunay_section(w, meta, dd, g, t1, t2)

    w("## Every configuration")
    w("")
    w("Spread = (max - min) / median over the timed runs. CPU = median user/sys seconds of the timed "
      "region. Busy cores = (user + sys) / wall, medians: about 1 for one busy thread, up to 2 when two "
      "threads both work; below the thread count means idle or preempted threads. Voro++ seconds "
      "include its container fill.")
    w("")
    w("| input | tool | op | threads | runs | median s | min s | max s | spread | CPU user/sys s | busy cores | simplices | peak B/pt |")
    w("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, grp in data.items():
        for (tool, op, th), x in sorted(grp.items(), key=lambda kv: (kv[0][0] != "tessera", kv[0])):
            u, s = x.extra_med("cpu_user_s"), x.extra_med("cpu_sys_s")
            ok = u is not None and s is not None
            cpu = f"{u:.2f}/{s:.2f}" if ok else DASH
            busy = f"{(u + s) / x.med:.2f}" if ok and x.med > 0 else DASH
            w(f"| {name} | {tool} | {op} | {th} | {len(x.runs)} | {fs(x.med)} | {fs(min(x.secs))} | {fs(max(x.secs))} | "
              f"{100 * x.spread:.0f} % | {cpu} | {busy} | {fn(x.simplices)} | {fb(bpp(x))} |")
    w("")
    if dd:
        w("Simplices: cells for Tessera voronoi and Voro++, Voronoi ridges for scipy, tetrahedra / triangles "
          "for the delaunay ops (Tessera, CGAL, Gmsh HXT = `gmsh-hxt`).")
    else:
        w("Simplices: cells for Tessera and Voro++, triangles for CGAL, Voronoi ridges for scipy.")
    return "\n".join(L) + "\n"


def delaunay_section(w, meta, dd, g, t1, t2):
    pts = meta.get("peer_threads") or [1, 2]
    p1, p2 = pts[0], pts[-1]
    NA = "n/a"
    w("## Delaunay: Tessera vs CGAL 5.5.1 and Gmsh 4.8.4 HXT")
    w("")
    w("Tessera: `tessera bench delaunay` (the `tessera::delaunay` call with its automatic method: "
      "tetrahedra / triangles from the cells plus hull completion, or in 3D by incremental insertion "
      "where the method chooses it; the table below says which). CGAL: `Delaunay_triangulation_3` range constructor (sequential, and "
      "`Parallel_tag` with TBB), `Delaunay_triangulation_2` in 2D (sequential only). HXT: Gmsh's "
      "`tetrahedralize` with `Mesh.Algorithm3D = 10` (OpenMP). All three return the Delaunay "
      "triangulation of the convex hull. Seconds (wall); ratio = peer seconds / Tessera seconds at the "
      f"thread counts shown (> 1: Tessera faster). Scaling = Tessera {t1}-thread seconds / {t2}-thread seconds. "
      "n/a: no such peer configuration (no parallel 2D CGAL, no 2D HXT).")
    w("")
    w(f"| input | points | Tessera {t1}T s | Tessera {t2}T s | CGAL {p1}T s | CGAL {p2}T s | HXT {p1}T s | HXT {p2}T s | "
      f"CGAL {p1}T / Tessera {t1}T | CGAL {p2}T / Tessera {t2}T | HXT {p1}T / Tessera {t1}T | HXT {p2}T / Tessera {t2}T | "
      f"scaling {t1}→{t2} |")
    w("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    rows = []
    for name, grp in dd.items():
        op = "delaunay3" if any(o == "delaunay3" for (_, o, _) in grp) else "delaunay2"
        a, b = g(grp, "tessera", op, t1), g(grp, "tessera", op, t2)
        if op == "delaunay3":
            c1, c2 = g(grp, "cgal", op, p1), g(grp, "cgal", op, p2)
            h1, h2 = g(grp, "gmsh-hxt", op, p1), g(grp, "gmsh-hxt", op, p2)
        else:  # CGAL 2D is sequential; Gmsh's 2D triangulate is not HXT
            c1, c2, h1, h2 = g(grp, "cgal", op, 1), None, None, None
        rows.append((name, op, a, b, c1, c2, h1, h2))
        n = (a or b).n
        d3 = op == "delaunay3"
        w(f"| {name} | {fn(n)} | {fm(a)} | {fm(b)} | {fm(c1)} | {fm(c2) if d3 else NA} | "
          f"{fm(h1) if d3 else NA} | {fm(h2) if d3 else NA} | {fr(div(med(c1), med(a)))} | "
          f"{fr(div(med(c2), med(b))) if d3 else NA} | {fr(div(med(h1), med(a))) if d3 else NA} | "
          f"{fr(div(med(h2), med(b))) if d3 else NA} | {fr(div(med(a), med(b)))} |")
    w("")
    w("Simplex counts and memory. Tessera's count must equal CGAL's (and HXT's) on general-position input "
      "such as uniform points; on degenerate input (lattices: cospherical points) the Delaunay "
      "triangulation is not unique and counts may legitimately differ. From cells / from hull completion / "
      "by insertion = Tessera's simplices read off the Voronoi cells / added by completing the convex hull / "
      "built by incremental insertion (the method chosen where cells cost far more than they find); exact calls "
      "= exact-arithmetic fallbacks. Peak B/pt = the process's peak resident set / points.")
    w("")
    w(f"| input | Tessera simplices | CGAL simplices | Tessera − CGAL | HXT simplices | from cells | "
      f"from hull completion | by insertion | exact calls | Tessera {t1}T peak B/pt | Tessera {t2}T peak B/pt | "
      f"CGAL {p1}T peak B/pt | CGAL {p2}T peak B/pt | HXT {p2}T peak B/pt |")
    w("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")

    def cnt(x):
        return DASH if x is None else fn(x.simplices)

    def fx(x):
        return DASH if x is None else fn(x)

    for name, op, a, b, c1, c2, h1, h2 in rows:
        d3 = op == "delaunay3"
        ta = a or b
        tcount = cnt(ta)
        if a and b and int(a.simplices) != int(b.simplices):  # must not depend on the thread count
            tcount = f"{fn(a.simplices)} ({t1}T) / {fn(b.simplices)} ({t2}T) **differ**"
        c = c1 or c2
        d = int(ta.simplices) - int(c.simplices) if ta and c else None
        diff = DASH if d is None else ("0" if d == 0 else f"{d:+,d}")
        h = h2 or h1
        w(f"| {name} | {tcount} | {cnt(c)} | {diff} | {cnt(h) if d3 else NA} | "
          f"{fx(ta.extra_med('from_cells')) if ta else DASH} | {fx(ta.extra_med('from_hull_completion')) if ta else DASH} | "
          f"{fx(ta.extra_med('from_insertion')) if ta else DASH} | {fx(ta.extra_med('exact_calls')) if ta else DASH} | {fb(bpp(a))} | {fb(bpp(b))} | {fb(bpp(c1))} | "
          f"{fb(bpp(c2)) if d3 else NA} | {fb(bpp(h2)) if d3 else NA} |")
    w("")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir", nargs="?")
    ap.add_argument("-o", "--output")
    ap.add_argument("--write-meta", metavar="RUN_DIR")
    ap.add_argument("--finish-meta", metavar="RUN_DIR")
    for k in ("command", "tessera", "build-type", "reps", "warmup", "threads", "peers", "inputs", "ops",
              "peer-threads"):
        ap.add_argument(f"--{k}", default="")
    a = ap.parse_args()
    if a.write_meta:
        a.run_dir = a.write_meta
        write_meta(a)
    elif a.finish_meta:
        finish_meta(a.finish_meta)
    elif a.run_dir:
        meta, data = load(a.run_dir)
        if not data:
            sys.exit(f"report.py: no results in {a.run_dir}")
        text = report(meta, data)
        if a.output:
            tmp = Path(a.output + ".tmp")
            tmp.write_text(text)
            tmp.replace(a.output)
        else:
            sys.stdout.write(text)
    else:
        ap.error("RUN_DIR, --write-meta or --finish-meta is required")


if __name__ == "__main__":
    main()
