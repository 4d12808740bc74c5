#!/usr/bin/env bash
# One replica against three on this host (docs/BENCHMARKS.md, "Fanning out: overhead per shard"):
# plans SCENE through a lone vc-server, then through a coordinator with two peers (all three on
# loopback, sharing this machine's cores, so only the overhead shows, not a speed-up), in shards
# of SHARD candidates (and stations, in the reduction), and prints the visibility stage's and the
# reduction's time both ways, the shards, the bytes exchanged and per shard, and whether the
# stations, coverage and reduction agree. Greedy selection (deterministic).
# Usage: scripts/bench-fan-out.sh [BUILD_DIR (default build/release)] [SCENE (default geb079; hall, a file)]
#   [SHARD (default 128)] [-- vc-client FLAGS...]
# Environment: WARM=0 skips the two warm-up plans (a campus plan takes minutes: each replica then
# voxelizes the scene inside the measured plan, the peers inside their first shard); KEEP=DIR keeps
# the servers' logs and both plans there (scripts/fan-out-projection.py reads them) instead of a
# temporary folder.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/server_port.sh"
cd "$(dirname "$0")/.."
bin=${1:-build/release}
scene=${2:-geb079}
shard=${3:-128}
shift $(( $# < 3 ? $# : 3 ))
[[ "${1:-}" == "--" ]] && shift
extra=("$@")
keep=${KEEP:-}
if [[ -n "$keep" ]]; then
  mkdir -p "$keep"
  work=$(cd "$keep" && pwd)
else
  work=$(mktemp -d)
fi
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
  [[ -n "$keep" ]] || rm -rf "$work"
}
trap cleanup EXIT

start() {  # start NAME [flags...] -> ${NAME}_addr
  vc_launch "$work/$1.log" "$bin/server/vc-server" --listen 127.0.0.1:0 --workers 1 "${@:2}"
  pids+=("$vc_pid")
  local port
  port=$(vc_wait_port "$work/$1.log" "$vc_pid") || { cat "$work/$1.log"; exit 1; }
  printf -v "$1_addr" '%s' "127.0.0.1:$port"
}

case "$scene" in
  geb079) f=../shared/data/geb079/geb079.bt ;;
  hall-scan) f=../shared/data/hall-scan/scan.dat.bz2 ;;
  */* | *.*) f="$scene" ;;
  *) f="$work/${scene/:/_}.ply"; "$bin/core/vc-synth" "$scene" --spacing 0.05 --out "$f" >/dev/null ;;
esac

start lone
start b
start c
start a --peers "$b_addr,$c_addr" --shard-candidates "$shard"
plan() {  # plan NAME ADDR
  "$bin/client/vc-client" submit "$f" --server "$2" --out "$work/$1" --solver greedy "${extra[@]}" >"$work/$1.out" 2>&1 \
    || { cat "$work/$1.out"; exit 1; }
}
# Warm both (each replica voxelizes the scene once and keeps it), then measure.
if [[ "${WARM:-1}" != 0 ]]; then
  plan warm_lone "$lone_addr"
  plan warm_a "$a_addr"
fi
plan one "$lone_addr"
plan three "$a_addr"
python3 - "$work/one/plan.json" "$work/three/plan.json" "$scene" "$shard" <<'PY'
import json, sys
one, three = (json.load(open(p)) for p in sys.argv[1:3])
d, shard = three["distribution"], int(sys.argv[4])
same = (one["viewpoints"] == three["viewpoints"] and one["coverage"] == three["coverage"]
        and one["reduction"] == three["reduction"])
t1, t3 = one["timings_s"], three["timings_s"]
v1, v3 = t1["visibility"], t3["visibility"]
r1, r3 = t1.get("reduction", 0.0), t3.get("reduction", 0.0)
s1, s3 = t1.get("selection", 0.0), t3.get("selection", 0.0)
print("| scene | candidates | stations | shard | visibility, 1 → 3 replicas | selection, 1 → 3 replicas | reduction, 1 → 3 replicas | shards in all | replicas | retried | bytes exchanged | per shard | same plan |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
per = (f"{d['bytes_exchanged'] / d['shards'] / 1024:.0f} KiB, {((v3 - v1) + (s3 - s1) + (r3 - r1)) / d['shards'] * 1000:+.0f} ms"
       if d and d["shards"] else "(computed locally)")
print(f"| {sys.argv[3]} | {one['candidates']['count']} | {one['reduction']['size']} | {shard} | {v1:.2f} → {v3:.2f} s "
      f"| {s1:.2f} → {s3:.2f} s | {r1:.2f} → {r3:.2f} s | {d['shards'] if d else 0} | {d['replicas'] if d else 1} "
      f"| {d['retried'] if d else 0} | {(d['bytes_exchanged'] if d else 0) / 1048576:.1f} MiB | {per} | {'yes' if same else 'NO'} |")
stages = list(dict.fromkeys(list(t1) + list(t3)))
print("\nper stage, 1 → 3 replicas: " + ", ".join(f"{k} {t1.get(k, 0):.2f} → {t3.get(k, 0):.2f} s" for k in stages))
sys.exit(0 if same else 1)
PY
