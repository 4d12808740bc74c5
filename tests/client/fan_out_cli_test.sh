#!/usr/bin/env bash
# Scaling out with the real binaries (docs/DEPLOY.md, "Scaling out"): three vc-server processes on
# loopback plan a real scan exactly as one does (same stations.csv, coverage and G); then one of the
# two peers is killed (SIGKILL) while it computes a shard, and the plan still completes, the same,
# (the shards are of candidates in the visibility stage and of stations in the reduction)
# with the retry in plan.json's `distribution` and a warning naming the dead replica.
# Usage: fan_out_cli_test.sh VC_SERVER VC_CLIENT SCENE
set -euo pipefail
server_bin="$1" client_bin="$2" scene="$3"
# The real scan lives in ../shared/data, which a container build does not have: skipped there.
[[ -f "$scene" ]] || { echo "skipped: $scene is not here"; exit 77; }
test_name=fan_out
source "$(dirname "$0")/server_lib.sh"
pids=()
trap 'for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done; cleanup' EXIT

# start NAME [flags...]: a vc-server on a free port; sets ${NAME}_addr and ${NAME}_pid.
start() {
  local name="$1"
  shift
  vc_launch "$work/$name.log" "$server_bin" --listen 127.0.0.1:0 --workers 1 "$@"
  local pid=$vc_pid port
  pids+=("$pid")
  port=$(vc_wait_port "$work/$name.log" "$pid") || { cat "$work/$name.log" >&2; fail "$name did not start"; }
  printf -v "${name}_addr" '%s' "127.0.0.1:$port"
  printf -v "${name}_pid" '%s' "$pid"
}

# plan NAME ADDR: vc-client submit into $work/NAME (greedy: a time-limited solve may differ by machine).
plan() {
  "$client_bin" submit "$scene" --server "$2" --out "$work/$1" --solver greedy >"$work/$1.out" 2>"$work/$1.err" \
    || { cat "$work/$1.err" >&2; fail "the plan $1 failed"; }
}

same_plan() {
  cmp -s "$work/alone/stations.csv" "$work/$1/stations.csv" || fail "$1: the stations differ from one replica's"
  python3 - "$work/alone/plan.json" "$work/$1/plan.json" <<'PY' || fail "$1: plan.json differs from one replica's"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert a["coverage"] == b["coverage"], (a["coverage"], b["coverage"])
assert a["viewpoints"] == b["viewpoints"]
assert a["candidates"] == b["candidates"]
assert a["distribution"] is None, a["distribution"]
PY
}

start b
start c
# A leaves its shards to B and C while they work (so both must), in shards of 4 candidates.
start a --peers "$b_addr,$c_addr" --shard-candidates 4 --local-shards=false

plan alone "$b_addr"
plan fanned "$a_addr"
same_plan fanned
python3 - "$work/fanned/plan.json" <<'PY' || fail "fanned: wrong distribution"
import json, sys
d = json.load(open(sys.argv[1]))["distribution"]
p = json.load(open(sys.argv[1]))
n, m = p["candidates"]["count"], p["reduction"]["size"]
assert d["shards"] == (n + 3) // 4 + (m + 3) // 4, d  # the candidates', then the reduction's stations'
assert m >= len(p["viewpoints"]) > 0, (m, len(p["viewpoints"]))  # the reduction saw every station
assert d["replicas"] == 2, d
assert d["bytes_exchanged"] > 0, d
PY
grep -q "fanned out: .* shard(s) on 2 replica(s)" "$work/fanned.out" || fail "vc-client printed no distribution line"
grep -q "rpc ComputeShard .* status=OK" "$work/b.log" || fail "B computed no shard"
grep -q "rpc ComputeShard .* status=OK" "$work/c.log" || fail "C computed no shard"

# Kill C as soon as it starts a shard of the next plan (its log line comes when a shard ends, so
# wait for the coordinator to have sent it one: C's ComputeShard count grows).
before=$(grep -c "rpc ComputeShard" "$work/c.log" || true)
plan killed "$a_addr" &
plan_pid=$!
for _ in $(seq 1 600); do
  now=$(grep -c "rpc ComputeShard" "$work/c.log" || true)
  ((now > before)) && break
  sleep 0.02
done
((now > before)) || fail "C got no shard of the second plan"
kill -9 "$c_pid"
wait "$plan_pid" || fail "the plan failed when a replica died"
same_plan killed
python3 - "$work/killed/plan.json" "$c_addr" <<'PY' || fail "killed: the dead replica left no trace"
import json, sys
p = json.load(open(sys.argv[1]))
assert any(sys.argv[2] in w for w in p["warnings"]), p["warnings"]
assert p["distribution"]["replicas"] >= 1, p["distribution"]
PY
echo "fan_out_cli_test: OK (3 replicas = 1; a replica killed mid-plan)"
