#!/usr/bin/env python3
"""Time to a first progress event: how long a field user waits, from starting `vc-client submit`,
until the job is accepted and until the first progress line appears (docs/BENCHMARKS.md).

Runs the client REPEAT times against a running vc-server with the scene cache off (every run
uploads), reading its stderr line by line as it comes, and prints the median of each time.

Usage: scripts/first-progress.py VC_CLIENT SERVER FILE [--repeat N] [-- extra submit flags...]
e.g.   scripts/first-progress.py build/release/client/vc-client 127.0.0.1:50777 /tmp/hall002.ply -- --raw-upload
"""
import argparse
import statistics
import subprocess
import sys
import tempfile
import time


def one_run(client, server, scene, extra):
    out = tempfile.mkdtemp(prefix="vc-first-progress-")
    cmd = [client, "--server", server, "--no-scene-cache", "submit", scene, "--out", out, "--detach-grace", "0"] + extra
    start = time.monotonic()
    accepted = first_progress = None
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    for line in p.stderr:
        now = time.monotonic() - start
        if accepted is None and " started" in line and line.startswith("job "):
            accepted = now
        if first_progress is None and line.startswith("progress:"):
            first_progress = now
    rc = p.wait()
    total = time.monotonic() - start
    if rc != 0:
        sys.exit(f"vc-client exited {rc}: {' '.join(cmd)}")
    return accepted, first_progress, total


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("client")
    ap.add_argument("server")
    ap.add_argument("scene")
    ap.add_argument("--repeat", type=int, default=3)
    argv = sys.argv[1:]
    extra = argv[argv.index("--") + 1:] if "--" in argv else []
    a = ap.parse_args(argv[:argv.index("--")] if "--" in argv else argv)
    a.extra = extra
    runs = [one_run(a.client, a.server, a.scene, a.extra) for _ in range(a.repeat)]
    med = [statistics.median(r[i] for r in runs) for i in range(3)]
    flags = " ".join(a.extra) or "(compact)"
    print(f"{a.scene} {flags}: accepted {med[0]:.2f} s, first progress {med[1]:.2f} s, "
          f"whole submit {med[2]:.2f} s (median of {a.repeat})")


if __name__ == "__main__":
    main()
