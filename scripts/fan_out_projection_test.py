#!/usr/bin/env python3
"""Tests of scripts/fan-out-projection.py on made-up logs of a coordinator and two peers whose figures
are worked out by hand: the visibility stage's call, the fine round's sets (named as now, and as
b3da04e named it, "the visibility stage" again), a reduction batch of one shard (serial) and one
spread over the three lanes.
Run: python3 scripts/fan_out_projection_test.py (scripts/test.sh runs it)."""
import json
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

SCRIPT = pathlib.Path(__file__).resolve().parent / "fan-out-projection.py"

# One replica's stage seconds: visibility 60, selection 10 (7.5 of them the fine round's sets, as the
# logs below time its call), reduction 30.
ONE = {"timings_s": {"visibility": 60.0, "selection": 10.0, "reduction": 30.0, "route": 1.0, "total": 101.0}}
THREE = {"timings_s": {"visibility": 62.0, "selection": 10.5, "reduction": 31.0, "route": 1.0, "total": 104.5}}


def own(t, what, n, sec):
    return f"[2026-12-06 12:00:{t:02d}.000] [info] fan-out: {what}: own shard viewpoints=0+{n} elapsed={sec}s\n"


def call(t, what, n, shards):
    return (f"[2026-12-06 12:00:{t:02d}.500] [info] fan-out: {what}: {n} viewpoints in {shards} shards over 3 "
            "replicas, 0 retried, 1 MiB exchanged\n")


def peer(t, n, sec):
    return (f"[2026-12-06 12:00:{t:02d}.000] [info] rpc ComputeShard peer=ipv4:127.0.0.1:1 viewpoints=0+{n} "
            f"elapsed={sec}s status=OK\n")


def run(fine_name):
    with tempfile.TemporaryDirectory() as d:
        root = pathlib.Path(d)
        for name, plan in (("one", ONE), ("three", THREE)):
            (root / name).mkdir()
            (root / name / "plan.json").write_text(json.dumps(plan))
        (root / "a.log").write_text(
            own(10, "the visibility stage", 100, 20) + call(21, "the visibility stage", 300, 3) +
            own(27, fine_name, 10, 6) + call(28, fine_name, 30, 3) +
            own(31, "the reduction", 6, 2) + call(32, "the reduction", 6, 1) +
            own(50, "the reduction", 18, 15) + call(51, "the reduction", 54, 3))
        (root / "b.log").write_text(peer(10, 100, 20) + peer(27, 10, 6) + peer(50, 18, 15))
        (root / "c.log").write_text(peer(10, 100, 20) + peer(26, 10, 5) + peer(49, 18, 14))
        return subprocess.run([sys.executable, str(SCRIPT), d], check=True, capture_output=True, text=True).stdout


class ProjectionTest(unittest.TestCase):
    def check(self, out):
        m = re.search(r"three hosts, projected: ([\d.]+) s split ideally, ([\d.]+) s as the shards fell", out)
        self.assertIsNotNone(m, out)
        # Ideally: 101 - (60 + 7.5 + 30 * 54 / 60) * 2 / 3; the fine round's work is its wall time,
        # 12:00:21 (its first shard began: 27 - 6) to 12:00:28.5 = 7.5 s.
        ideal = 101 - (60 + 7.5 + 27) * 2 / 3
        # As the shards fell: each call's work times one less the busiest lane's share.
        fell = 101 - (60 * (1 - 20 / 60) + 7.5 * (1 - 6 / 17) + 27 * (1 - 15 / 44))
        self.assertAlmostEqual(float(m.group(1)), ideal, delta=0.05, msg=out)
        self.assertAlmostEqual(float(m.group(2)), fell, delta=0.05, msg=out)
        self.assertIn("selection 2.5 s", out)  # 10 s less the fine round's 7.5 s
        self.assertRegex(out, r"\| the reduction \(12:00:32\) \| 6 \| 1 \| coordinator 2\.0 s \| 1\.00 \|")

    def test_the_fine_rounds_call_by_its_name(self):
        self.check(run("the fine round's sets"))

    def test_the_fine_rounds_call_as_b3da04e_named_it(self):
        self.check(run("the visibility stage"))


if __name__ == "__main__":
    unittest.main()
