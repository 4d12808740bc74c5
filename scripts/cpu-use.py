#!/usr/bin/env python3
"""How busy a vc-server's cores were during one plan, stage by stage (issue 37: what more
parallelism could still give on one machine).

Reads the server's log and samples of the server's CPU time taken while the plan ran, and prints
- the job's CPU seconds and the cores it kept busy on average, the core-seconds left idle, and the
  wall time the job would take were every core busy all along (the job's CPU seconds / cores: the
  most that running its serial parts in parallel could give);
- the cores busy in each stage;
- the longest stretches with fewer cores busy than LOW (default: cores - 0.5), each with its stage.

The stages' windows come from the log's job line (`job ID Plan ... read=Xs voxelize=Xs ...
route=Xs run=Xs elapsed=Xs ...`): the job ran for `run` seconds up to the line's time stamp; it
read the scene first, then ran the stages in the order the line names them, and whatever is left
of `run` after them (the plan's files and the reply) is "after". The windows are placed to the
millisecond of the log's clock; a stage shorter than the sampling interval gets a rough figure.

SAMPLES: one line per sample, "EPOCH_SECONDS CPU_TICKS", CPU_TICKS being utime + stime of the
server process (fields 14 and 15 of /proc/PID/stat, in clock ticks); scripts/campus-bench.sh
writes them every half second.

Usage: scripts/cpu-use.py SERVER_LOG SAMPLES [--cores N] [--clk-tck T] [--low X]
       (N: the machine's cores, os.cpu_count() by default; T: os.sysconf('SC_CLK_TCK'))
Tested by scripts/cpu_use_test.py."""
import argparse
import bisect
import datetime
import os
import re
import sys

# The job's timings (server/src/job_runner.cc: JobLog::timings(), `read=Xs` and each stage's
# `name=Xs` in the order they ran) sit between `queued=Xs` and `run=Xs`.
JOB_LINE = re.compile(r"^\[(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d+)\].* job \S+ Plan .* queued=[0-9.]+s(.*?) "
                      r"run=([0-9.]+)s")


def log_time(stamp):
    """The epoch seconds of a log time stamp (spdlog writes the local time, as `date +%s.%N` counts)."""
    return datetime.datetime.strptime(stamp, "%Y-%m-%d %H:%M:%S.%f").timestamp()


def job_windows(log_text):
    """[(name, start, end)] of the last plan in the log: read, the stages, after."""
    lines = [m for m in (JOB_LINE.match(line) for line in log_text.splitlines()) if m]
    if not lines:
        raise ValueError("no finished plan in the server's log (a line 'job ID Plan ... run=Xs')")
    m = lines[-1]
    end = log_time(m.group(1))
    start = end - float(m.group(3))
    windows, at = [], start
    for name, seconds in re.findall(r"\b(\w+)=([0-9.]+)s\b", m.group(2)):
        windows.append((name, at, at + float(seconds)))
        at += float(seconds)
    if end > at:
        windows.append(("after", at, end))
    return start, end, windows


def read_samples(text):
    samples = []
    for n, line in enumerate(text.splitlines(), 1):
        parts = line.split()
        if not parts:
            continue
        if len(parts) != 2:
            raise ValueError(f"sample line {n}: expected 'EPOCH_SECONDS CPU_TICKS', got {line!r}")
        samples.append((float(parts[0]), float(parts[1])))
    samples.sort()
    if len(samples) < 2:
        raise ValueError("fewer than two CPU samples: the sampler did not run while the plan did")
    return samples


def cpu_at(samples, t):
    """The server's CPU ticks at time t, interpolated between samples (clamped to the sampled span)."""
    if t <= samples[0][0]:
        return samples[0][1]
    if t >= samples[-1][0]:
        return samples[-1][1]
    hi = bisect.bisect_right(samples, (t, float("inf")))
    (t0, c0), (t1, c1) = samples[hi - 1], samples[hi]
    return c0 + (c1 - c0) * (t - t0) / (t1 - t0)


def busy(samples, a, b, clk_tck):
    """Cores busy on average over [a, b] (CPU seconds / wall seconds); None for an empty window."""
    if b - a <= 0:
        return None
    return (cpu_at(samples, b) - cpu_at(samples, a)) / clk_tck / (b - a)


def stage_of(windows, t):
    for name, a, b in windows:
        if a <= t < b:
            return name
    return "outside the job"


def low_stretches(samples, start, end, clk_tck, low):
    """[(a, b, cores busy)] of consecutive sample intervals inside [start, end] under `low` cores."""
    stretches = []
    for (t0, c0), (t1, c1) in zip(samples, samples[1:]):
        a, b = max(t0, start), min(t1, end)
        if b - a <= 0:
            continue
        if (c1 - c0) / clk_tck / (t1 - t0) < low:
            if stretches and abs(stretches[-1][1] - a) < 1e-6:
                stretches[-1][1] = b
            else:
                stretches.append([a, b])
    return [(a, b, busy(samples, a, b, clk_tck)) for a, b in stretches]


def report(log_text, samples_text, cores, clk_tck, low):
    start, end, windows = job_windows(log_text)
    samples = read_samples(samples_text)
    if samples[0][0] > start + 1.0 or samples[-1][0] < end - 1.0:
        raise ValueError("the CPU samples do not span the plan (first %.1f s after its start, last %.1f s "
                         "before its end)" % (samples[0][0] - start, end - samples[-1][0]))
    wall = end - start
    cpu = (cpu_at(samples, end) - cpu_at(samples, start)) / clk_tck
    out = [f"server CPU   {cpu:.1f} core-s in the job's {wall:.1f} s: {cpu / wall:.2f} of {cores} cores busy; "
           f"{cores * wall - cpu:.1f} core-s idle (were every core busy all along: {cpu / cores:.1f} s)"]
    out.append("cores busy   " + "  ".join(f"{name} {busy(samples, a, b, clk_tck):.2f}"
                                           for name, a, b in windows if b > a))
    stretches = sorted(low_stretches(samples, start, end, clk_tck, low), key=lambda s: s[0] - s[1])[:5]
    if stretches:
        out.append(f"under {low:g} cores (longest, at most 5): " + "; ".join(
            f"{a - start:.1f}-{b - start:.1f} s ({b - a:.1f} s, {u:.2f} busy, {stage_of(windows, (a + b) / 2)})"
            for a, b, u in sorted(stretches)))
    return "\n".join(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("server_log")
    parser.add_argument("samples")
    parser.add_argument("--cores", type=int, default=os.cpu_count())
    parser.add_argument("--clk-tck", type=float, default=os.sysconf("SC_CLK_TCK"))
    parser.add_argument("--low", type=float, default=None)
    args = parser.parse_args()
    low = args.low if args.low is not None else args.cores - 0.5
    try:
        with open(args.server_log, encoding="utf-8", errors="replace") as f:
            log_text = f.read()
        with open(args.samples, encoding="utf-8") as f:
            samples_text = f.read()
        print(report(log_text, samples_text, args.cores, args.clk_tck, low))
    except (OSError, ValueError) as e:
        print(f"cpu-use: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
