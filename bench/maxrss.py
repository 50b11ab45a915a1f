#!/usr/bin/python3
"""Run a command, pass its output through, and add its peak memory to its JSON lines.

usage: maxrss.py CMD [ARGS...]

stdout lines that are JSON objects with an "extra" object get
extra.max_rss_bytes = the largest resident set of any process the command waited for
(getrusage(RUSAGE_CHILDREN).ru_maxrss: whole-process peak, including reading the input).
When CMD runs several processes (run_peers.sh: warm-up + repeats), it is the maximum over
them; they all do the same work, so it is each run's peak. Other lines pass unchanged.
The exit status is CMD's.
"""
import json
import resource
import subprocess
import sys


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    r = subprocess.run(sys.argv[1:], stdout=subprocess.PIPE, text=True)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024  # KiB on Linux
    for line in r.stdout.splitlines():
        if line.startswith("{"):
            try:
                rec = json.loads(line)
            except json.JSONDecodeError:
                rec = None
            if isinstance(rec, dict) and isinstance(rec.get("extra"), dict):
                rec["extra"]["max_rss_bytes"] = peak
                line = json.dumps(rec, separators=(",", ":"))
        print(line, flush=True)
    sys.exit(r.returncode)


if __name__ == "__main__":
    main()
