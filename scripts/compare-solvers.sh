#!/usr/bin/env bash
# Greedy against the exact selector (docs/PLANNING.md, "Exact selection"): plans geb079 and the
# synthetic scenes through a real vc-server and vc-client once per solver, with the default
# parameters (target coverage 0.99), and prints one row per scene and solver: stations, coverage,
# the optimality status, lower bound and gap, the selection stage's time and the whole plan's, the
# model's size, then the share of the whole scene (occupied voxels) covered, the field time (set-up,
# scans and walking, minutes), G and the stop reason (and, with --local-candidates among FLAGS, the
# positions it added and the stations of each selection).
# Usage: scripts/compare-solvers.sh [BUILD_DIR (default build/release)] [SOLVERS (default "greedy exact")]
#   [SCENES (default: geb079 and the synthetic scenes; "hall" and "hall-scan" add the halls,
#   "room-scan1" the real furnished room, "room-merged" both room scans in one frame,
#   scripts/merge-room-scans.py)] [-- FLAGS...]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/server_port.sh"
cd "$(dirname "$0")/.."
bin=${1:-build/release}
solvers=${2:-greedy exact}
scenes=${3:-geb079 box lroom comb:3 comb:5 rooms:3 twofloor tworooms}
shift $(( $# < 3 ? $# : 3 ))
[[ "${1:-}" == "--" ]] && shift
extra=("$@")
work=$(mktemp -d)
server_pid=""
cleanup() {
  [[ -n "$server_pid" ]] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

vc_launch "$work/server.log" "$bin/server/vc-server" --listen 127.0.0.1:0 --workers 1
server_pid=$vc_pid
port=$(vc_wait_port "$work/server.log" "$server_pid") || { cat "$work/server.log"; exit 1; }

printf '%-10s %-7s %8s %9s %-10s %6s %6s %9s %8s  %s\n' scene solver stations coverage status bound gap select_s total_s \
  "model (candidates/classes/rows; before)  scene% field_min G stop"
for s in $scenes; do
  case "$s" in
    geb079) f=../shared/data/geb079/geb079.bt ;;
    hall-scan) f=../shared/data/hall-scan/scan.dat.bz2 ;;
    room-scan1) f=../shared/data/room-2scans/room_scan1.pcd ;;
    room-merged) f="$work/room-merged.ply"; [[ -f "$f" ]] || python3 scripts/merge-room-scans.py "$f" >/dev/null ;;
    *) f="$work/${s/:/_}.ply"; [[ -f "$f" ]] || "$bin/core/vc-synth" "$s" --spacing 0.05 --out "$f" >/dev/null ;;
  esac
  for solver in $solvers; do
    out="$work/out-${s/:/_}-$solver"
    "$bin/client/vc-client" submit "$f" --server "127.0.0.1:$port" --out "$out" --solver "$solver" "${extra[@]}" \
      >/dev/null 2>"$work/err" || { cat "$work/err"; exit 1; }
    python3 - "$s" "$solver" "$out/plan.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[3]))
c, o, t = p["coverage"], p["optimality"], p["timings_s"]
m, b = o["model"], o["before"]
bound = f'{o["lower_bound"]:.0f}' if o["status"] != "heuristic" else "-"
gap = f'{100 * o["gap"]:.0f}%' if o["status"] != "heuristic" else "-"
print(f'{sys.argv[1]:10s} {sys.argv[2]:7s} {len(p["viewpoints"]):8d} {100 * c["covered_voxels"] / c["coverable_voxels"]:8.2f}% '
      f'{o["status"]:10s} {bound:>6s} {gap:>6s} {t["selection"]:9.2f} {t["total"]:8.2f}  '
      f'{m["candidates"]}/{m["voxel_classes"]}/{m["rows"]}; {b["candidates"]}/{b["voxel_classes"]}'
      f'  {100 * c["covered_voxels"] / c["occupied_voxels"]:.2f}% {p["field_time_s"]["total"] / 60:.0f} '
      f'{c["global_visibility"]:.3f} {p["stop_reason"]}'
      + (f'  [{o["note"]}]' if o.get("note") else '')
      + (f'  local: +{o["local_candidates"]["added"]} positions, stations per selection '
         + ' -> '.join(str(n) for n in o["local_candidates"]["stations_per_solve"]) if o.get("local_candidates") else ''))
PY
  done
done
