#!/usr/bin/env bash
# Plans that must not change by accident: plans geb079, the synthetic hall, the real hall scan and
# the known-optimum scenes (the hubs and tworooms since issue 36, the held-out star:4 and atrium:2
# since hx-hub2; court:K and tee are left to PlannerTest.*RoomsAroundAHall*) through a real
# vc-server and vc-client, and prints one line per scene:
# stations, G, covered/coverable voxels and a hash of the stations' coordinates. Run it on two
# builds and diff the output (docs/BENCHMARKS.md, "Plans must not change by accident").
# Usage: scripts/plan-fingerprints.sh [BUILD_DIR (default build/release)] [--quick] [--fan-out]
#        [--sparse] [--gain-rule-off] [--no-doorway-candidates]
#   --quick: geb079 and the known-optimum scenes only (skips the 1.7 M-point synthetic hall).
#   --fan-out: plan through a coordinator that leaves every shard of 16 candidates to two peer
#     vc-servers (docs/DEPLOY.md, "Scaling out"): the lines must be the same as without.
#   --sparse: every visibility set sparse (--sparse-set-gain 1e-9; vc/visibility/voxel_set.h):
#     the lines must be the same as without.
#   --gain-rule-off: the default gain rule switched off (--min-gain-m2-per-minute 0): the plans as
#     the 99 % target alone stops them, the lines from before the rule became the default.
#   --route: each line also gives the walking route: its length, parts and a hash of its order, legs
#     and polylines (to the micrometre), for changes to the route stage (route.h).
#   --no-doorway-candidates: the grid's candidates alone (doorway candidates are on by default
#     since issue 36): the lines from before they became the default.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/server_port.sh"
cd "$(dirname "$0")/.."
bin=${1:-build/release}
quick="" fan_out="" route="" client_flags=()
for a in "${@:2}"; do
  case "$a" in
    --quick) quick=--quick ;;
    --fan-out) fan_out=1 ;;
    --route) route=1 ;;
    --sparse) client_flags+=(--sparse-set-gain 1e-9) ;;
    --gain-rule-off) client_flags+=(--min-gain-m2-per-minute 0) ;;
    --no-doorway-candidates) client_flags+=(--no-doorway-candidates) ;;
    *) echo "plan-fingerprints: unknown option $a" >&2; exit 2 ;;
  esac
done
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

start_server() {  # start_server LOG [flags...]: prints the port
  vc_launch "$work/$1" "$bin/server/vc-server" --listen 127.0.0.1:0 --workers 1 "${@:2}"
  pids+=("$vc_pid")
  port=$(vc_wait_port "$work/$1" "$vc_pid") || { cat "$work/$1" >&2; exit 1; }
}
if [[ -n "$fan_out" ]]; then
  start_server peer1.log; p1=$port
  start_server peer2.log; p2=$port
  start_server server.log --peers "127.0.0.1:$p1,127.0.0.1:$p2" --shard-candidates 16 --local-shards=false
else
  start_server server.log
fi

scenes=(box lroom comb:3 comb:5 rooms:3 twofloor tworooms hub:1 hub:2 hub:3 star:4 atrium:2)
[[ "$quick" == "--quick" ]] || scenes+=(hall)
files=(../shared/data/geb079/geb079.bt)
[[ "$quick" == "--quick" ]] || files+=(../shared/data/hall-scan/scan.dat.bz2)
for s in "${scenes[@]}"; do
  "$bin/core/vc-synth" "$s" --spacing 0.05 --out "$work/${s/:/_}.ply" >/dev/null
  files+=("$work/${s/:/_}.ply")
done
for f in "${files[@]}"; do
  out="$work/out-$(basename "$f")"
  "$bin/client/vc-client" submit "$f" --server "127.0.0.1:$port" --out "$out" "${client_flags[@]}" >/dev/null 2>"$work/err" ||
    { cat "$work/err"; exit 1; }
  python3 - "$f" "$out/plan.json" "$route" <<'PY'
import hashlib, json, os, sys
p = json.load(open(sys.argv[2]))
xyz = [[v["x"], v["y"], v["z"]] for v in p["viewpoints"]]
h = hashlib.sha256(json.dumps(xyz).encode()).hexdigest()[:12]
c = p["coverage"]
line = (f'{os.path.basename(sys.argv[1]):16s} stations={len(xyz):3d} G={c["global_visibility"]:.6f} '
        f'covered={c["covered_voxels"]}/{c["coverable_voxels"]} stations_sha={h}')
if sys.argv[3]:
    r = p["route"]
    um = lambda v: None if v is None else round(v * 1e6)
    key = [r["order"], [um(v) for v in r["legs_m"]], r["parts"],
           [[[um(v) for v in q] for q in pl] for pl in r["polyline"]]]
    rh = hashlib.sha256(json.dumps(key).encode()).hexdigest()[:12]
    line += f' route={r["length_m"]:.3f}m/{r["parts"]}parts route_sha={rh}'
print(line)
PY
done
