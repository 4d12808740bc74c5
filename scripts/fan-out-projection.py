#!/usr/bin/env python3
"""What a plan would take on three hosts, from a run of scripts/bench-fan-out.sh kept with KEEP=DIR
(docs/BENCHMARKS.md, "Fan-out on the campus maps").

Reads DIR/one/plan.json (one replica), DIR/three/plan.json (a coordinator with two peers, all on
this host), the coordinator's log DIR/a.log (its own shards, "own shard viewpoints=B+N
elapsed=Xs", and one "fan-out: STAGE: N viewpoints in S shards" line per fanned-out call) and the
peers' logs DIR/b.log, DIR/c.log ("rpc ComputeShard ... viewpoints=B+N elapsed=Xs status=OK").
Prints each fan-out call's shards per lane (seconds summed), and the projection: every stage as the
lone replica took it, less the fanned-out share of the visibility stage and of the reduction's
evaluation, which three hosts as this one split three ways (ideally; or as the shards fell here, the
busiest lane's share of the shard seconds). The reduction's calls are weighted by their stations
(the evaluation of the stations is nearly all of the stage). A call of the selection stage's sets
("the fine round's sets" of coarse-then-fine candidates, "the local candidates' sets") counts its
wall time here as its work (three replicas on one host take as long as one for the same sets). A
call of one shard runs on the coordinator alone and stays serial.
Usage: scripts/fan-out-projection.py DIR   (tested by scripts/fan_out_projection_test.py)
"""
import json
import re
import sys
from datetime import datetime, timedelta

STAMP = re.compile(r"^\[(\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\.\d+)\]")
OWN = re.compile(r"fan-out: (.+?): own shard viewpoints=(\d+)\+(\d+) elapsed=([\d.]+)s")
CALL = re.compile(r"fan-out: (.+?): (\d+) viewpoints in (\d+) shards over (\d+) replicas")
PEER = re.compile(r"rpc ComputeShard .* viewpoints=(\d+)\+(\d+) elapsed=([\d.]+)s status=OK")


def stamp(line):
    m = STAMP.match(line)
    return datetime.strptime(m.group(1), "%Y-%m-%d %H:%M:%S.%f") if m else None


def main(d):
    one = json.load(open(f"{d}/one/plan.json"))
    three = json.load(open(f"{d}/three/plan.json"))
    calls, shards = [], []  # calls: (time, stage, viewpoints, shards); shards: (time, lane, count, seconds)
    for line in open(f"{d}/a.log"):
        if m := OWN.search(line):
            shards.append((stamp(line), "coordinator", int(m.group(3)), float(m.group(4))))
        elif m := CALL.search(line):
            calls.append((stamp(line), m.group(1), int(m.group(2)), int(m.group(3))))
    for lane in ("b", "c"):
        for line in open(f"{d}/{lane}.log"):
            if m := PEER.search(line):
                shards.append((stamp(line), "peer " + lane, int(m.group(2)), float(m.group(3))))
    per_call = [dict() for _ in calls]
    began = [c[0] for c in calls]  # when each call's first shard began
    for t, lane, _, sec in shards:
        k = next((i for i, c in enumerate(calls) if t <= c[0]), None)
        if k is not None:
            per_call[k][lane] = per_call[k].get(lane, 0.0) + sec
            began[k] = min(began[k], t - timedelta(seconds=sec))
    print("| fan-out call | viewpoints | shards | shard seconds per lane | busiest lane's share |")
    print("|---|---|---|---|---|")
    for (t, stage, n, s), lanes in zip(calls, per_call):
        total = sum(lanes.values())
        lanes_text = ", ".join(f"{k} {v:.1f} s" for k, v in sorted(lanes.items()))
        print(f"| {stage} ({t:%H:%M:%S}) | {n} | {s} | {lanes_text} | {max(lanes.values()) / total:.2f} |")
    t1 = one["timings_s"]
    stations_evaluated = sum(c[2] for c in calls if c[1] == "the reduction") or 1
    saved_ideal = saved_fell = 0.0
    local_sets = 0.0  # the selection stage's fanned-out sets, taken out of its serial seconds
    seen_visibility = False
    for (t, stage, n, s), lanes, start in zip(calls, per_call, began):
        # Logs of b3da04e named the fine round's call "the visibility stage" too: only the first is.
        first_visibility = stage == "the visibility stage" and not seen_visibility
        seen_visibility = seen_visibility or stage == "the visibility stage"
        if s < 2:
            continue  # one shard: the coordinator alone
        share = max(lanes.values()) / sum(lanes.values())
        if first_visibility:
            work = t1["visibility"]
        elif stage == "the reduction":
            work = t1.get("reduction", 0) * n / stations_evaluated
        else:
            # The selection stage's local candidates ("the fine round's sets"): its wall time with
            # the three replicas on this host, which take as long as one for the same sets.
            work = (t - start).total_seconds()
            local_sets += work
        saved_ideal += work * (1 - 1 / 3)
        saved_fell += work * (1 - share)
    total1 = t1["total"]
    print()
    print(f"one replica: {total1:.1f} s; coordinator and two peers on this host: {three['timings_s']['total']:.1f} s")
    print(f"three hosts, projected: {total1 - saved_ideal:.1f} s split ideally, {total1 - saved_fell:.1f} s as the "
          f"shards fell here ({total1 / (total1 - saved_ideal):.2f} x and {total1 / (total1 - saved_fell):.2f} x)")
    serial = {k: v for k, v in t1.items() if k not in ("visibility", "reduction", "total")}
    if "selection" in serial:
        serial["selection"] = max(0.0, serial["selection"] - local_sets)
    print("serial on the coordinator (one replica's seconds, less the fanned-out sets): " + ", ".join(
        f"{k} {v:.1f} s" for k, v in serial.items()))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
