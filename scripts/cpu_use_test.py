#!/usr/bin/env python3
"""Tests of scripts/cpu-use.py on a made-up server log and CPU samples whose figures are worked out by
hand: a 20 s plan on 2 cores (read 1 s and voxelize 1 s on one core, candidates 2 s and visibility
10 s on both, selection 4 s of which the first 2 on one core, route 1 s on one, then 1 s idle).
Run: python3 scripts/cpu_use_test.py (scripts/test.sh runs it)."""
import importlib.util
import pathlib
import subprocess
import sys
import tempfile
import unittest

SCRIPT = pathlib.Path(__file__).resolve().parent / "cpu-use.py"
spec = importlib.util.spec_from_file_location("cpu_use", SCRIPT)
cpu_use = importlib.util.module_from_spec(spec)
spec.loader.exec_module(cpu_use)

END_STAMP = "2026-12-07 12:00:20.000"
JOB = (f"[2026-12-07 12:00:00.000] [info] vc-server listening on 127.0.0.1:0 (port 1), 1 workers x 2 threads\n"
       f"[{END_STAMP}] [info] job j-1 Plan peer=ipv4:127.0.0.1:2 upload=2.0 MiB upload=0.100s cache=miss "
       "queued=0.000s read=1.000s voxelize=1.000s candidates=2.000s visibility=10.000s selection=4.000s "
       "route=1.000s run=20.000s elapsed=20.500s stations=3 status=OK\n")
# Cores busy from the job's start: [0, 2) 1, [2, 14) 2, [14, 16) 1, [16, 18) 2, [18, 19) 1, [19, 20) 0.
RATES = [(0, 2, 1), (2, 14, 2), (14, 16, 1), (16, 18, 2), (18, 19, 1), (19, 20, 0)]


def samples_text(every=0.5):
    start = cpu_use.log_time(END_STAMP) - 20.0
    lines, ticks, t = [], 0.0, -1.0
    while t <= 21.0 + 1e-9:
        lines.append(f"{start + t:.3f} {ticks:.0f}")
        for a, b, cores in RATES:  # CPU ticks (100 a second) spent in [t, t + every)
            ticks += 100 * cores * max(0.0, min(b, t + every) - max(a, t))
        t += every
    return "\n".join(lines) + "\n"


def run(log, samples, *extra):
    with tempfile.TemporaryDirectory() as d:
        (pathlib.Path(d) / "server.log").write_text(log)
        (pathlib.Path(d) / "cpu.txt").write_text(samples)
        return subprocess.run([sys.executable, str(SCRIPT), f"{d}/server.log", f"{d}/cpu.txt", "--cores", "2",
                               "--clk-tck", "100", *extra], capture_output=True, text=True)


class CpuUseTest(unittest.TestCase):
    def test_the_hand_worked_plan(self):
        r = run(JOB, samples_text())
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.splitlines(), [
            # 1 + 1 + 4 + 20 + 2 + 4 + 1 + 0 = 33 core-s in 20 s; 40 - 33 idle; 33 / 2 at full use
            "server CPU   33.0 core-s in the job's 20.0 s: 1.65 of 2 cores busy; 7.0 core-s idle "
            "(were every core busy all along: 16.5 s)",
            "cores busy   read 1.00  voxelize 1.00  candidates 2.00  visibility 2.00  selection 1.50  route 1.00  "
            "after 0.00",
            "under 1.5 cores (longest, at most 5): 0.0-2.0 s (2.0 s, 1.00 busy, voxelize); "
            "14.0-16.0 s (2.0 s, 1.00 busy, selection); 18.0-20.0 s (2.0 s, 0.50 busy, after)",
        ])

    def test_a_lower_threshold_leaves_only_the_idle_second(self):
        r = run(JOB, samples_text(), "--low", "0.5")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.splitlines()[-1], "under 0.5 cores (longest, at most 5): 19.0-20.0 s (1.0 s, 0.00 busy, after)")

    def test_samples_a_second_apart_give_the_same_stages(self):
        r = run(JOB, samples_text(every=1.0))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("selection 1.50  route 1.00", r.stdout)

    def test_a_log_without_a_finished_plan_is_refused(self):
        r = run(JOB.splitlines()[0] + "\n", samples_text())
        self.assertEqual(r.returncode, 2)
        self.assertIn("no finished plan in the server's log", r.stderr)

    def test_samples_that_miss_the_plan_are_refused(self):
        late = "\n".join(line for line in samples_text().splitlines()
                         if float(line.split()[0]) > cpu_use.log_time(END_STAMP) - 10)
        r = run(JOB, late)
        self.assertEqual(r.returncode, 2)
        self.assertIn("do not span the plan", r.stderr)
        r = run(JOB, "12.5\n")
        self.assertEqual(r.returncode, 2)
        self.assertIn("sample line 1: expected 'EPOCH_SECONDS CPU_TICKS'", r.stderr)


if __name__ == "__main__":
    unittest.main()
