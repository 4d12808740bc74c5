#!/usr/bin/env bash
# One replica against three on this host (docs/BENCHMARKS.md, "Fanning out: overhead per shard"):
# plans SCENE through a lone vc-server, then through a coordinator with two peers (all three on
# loopback, sharing this machine's cores, so only the overhead shows, not a speed-up), in shards
# of SHARD candidates, and prints the visibility stage's time both ways, the shards, the bytes
# exchanged and per shard, and whether the stations agree. Greedy selection (deterministic).
# Usage: scripts/bench-fan-out.sh [BUILD_DIR (default build/release)] [SCENE (default geb079; hall, a file)]
#   [SHARD (default 128)] [-- vc-client FLAGS...]
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build/release}
scene=${2:-geb079}
shard=${3:-128}
shift $(( $# < 3 ? $# : 3 ))
[[ "${1:-}" == "--" ]] && shift
extra=("$@")
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

start() {  # start NAME [flags...] -> ${NAME}_addr
  "$bin/server/vc-server" --listen 127.0.0.1:0 --workers 1 "${@:2}" >"$work/$1.log" 2>&1 &
  pids+=($!)
  local port=""
  for _ in $(seq 1 100); do
    port=$(sed -n 's/.*listening on .* (port \([0-9]*\)).*/\1/p' "$work/$1.log" | head -1)
    [[ -n "$port" ]] && break
    sleep 0.1
  done
  [[ -n "$port" ]] || { cat "$work/$1.log"; exit 1; }
  printf -v "$1_addr" '%s' "127.0.0.1:$port"
}

case "$scene" in
  geb079) f=../shared/data/geb079/geb079.bt ;;
  hall-scan) f=../shared/data/hall-scan/scan.dat.bz2 ;;
  */* | *.*) f="$scene" ;;
  *) f="$work/${scene/:/_}.ply"; "$bin/client/vc-synth" "$scene" --spacing 0.05 --out "$f" >/dev/null ;;
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
plan warm_lone "$lone_addr"
plan warm_a "$a_addr"
plan one "$lone_addr"
plan three "$a_addr"
python3 - "$work/one/plan.json" "$work/three/plan.json" "$scene" "$shard" <<'PY'
import json, sys
one, three = (json.load(open(p)) for p in sys.argv[1:3])
d = three["distribution"]
same = one["viewpoints"] == three["viewpoints"] and one["coverage"] == three["coverage"]
v1, v3 = one["timings_s"]["visibility"], three["timings_s"]["visibility"]
print(f"| scene | candidates | shard | visibility, 1 replica | visibility, 3 replicas on 1 host | shards | replicas | retried | bytes exchanged | per shard | same plan |")
print(f"|---|---|---|---|---|---|---|---|---|---|---|")
print(f"| {sys.argv[3]} | {one['candidates']['count']} | {sys.argv[4]} | {v1:.2f} s | {v3:.2f} s ({v3 / v1:.2f}x) | {d['shards']} | {d['replicas']} | {d['retried']} | {d['bytes_exchanged'] / 1048576:.1f} MiB | {d['bytes_exchanged'] / d['shards'] / 1024:.0f} KiB, {(v3 - v1) / d['shards'] * 1000:+.0f} ms | {'yes' if same else 'NO'} |")
sys.exit(0 if same else 1)
PY
