#!/usr/bin/env bash
# Plans that must not change by accident: plans geb079, the synthetic hall, the real hall scan and
# every known-optimum scene through a real vc-server and vc-client, and prints one line per scene:
# stations, G, covered/coverable voxels and a hash of the stations' coordinates. Run it on two
# builds and diff the output (docs/BENCHMARKS.md, "Plans must not change by accident").
# Usage: scripts/plan-fingerprints.sh [BUILD_DIR (default build/release)] [--quick]
#   --quick: geb079 and the known-optimum scenes only (skips the 1.7 M-point synthetic hall).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build/release}
quick=${2:-}
work=$(mktemp -d)
server_pid=""
cleanup() {
  [[ -n "$server_pid" ]] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

"$bin/server/vc-server" --listen 127.0.0.1:0 --workers 1 >"$work/server.log" 2>&1 &
server_pid=$!
port=""
for _ in $(seq 1 100); do
  port=$(sed -n 's/.*listening on .* (port \([0-9]*\)).*/\1/p' "$work/server.log" | head -1)
  [[ -n "$port" ]] && break
  sleep 0.1
done
[[ -n "$port" ]] || { cat "$work/server.log"; exit 1; }

scenes=(box lroom comb:3 comb:5 rooms:3 twofloor)
[[ "$quick" == "--quick" ]] || scenes+=(hall)
files=(../shared/data/geb079/geb079.bt)
[[ "$quick" == "--quick" ]] || files+=(../shared/data/hall-scan/scan.dat.bz2)
for s in "${scenes[@]}"; do
  "$bin/client/vc-synth" "$s" --spacing 0.05 --out "$work/${s/:/_}.ply" >/dev/null
  files+=("$work/${s/:/_}.ply")
done
for f in "${files[@]}"; do
  out="$work/out-$(basename "$f")"
  "$bin/client/vc-client" submit "$f" --server "127.0.0.1:$port" --out "$out" >/dev/null 2>"$work/err" ||
    { cat "$work/err"; exit 1; }
  python3 - "$f" "$out/plan.json" <<'PY'
import hashlib, json, os, sys
p = json.load(open(sys.argv[2]))
xyz = [[v["x"], v["y"], v["z"]] for v in p["viewpoints"]]
h = hashlib.sha256(json.dumps(xyz).encode()).hexdigest()[:12]
c = p["coverage"]
print(f'{os.path.basename(sys.argv[1]):16s} stations={len(xyz):3d} G={c["global_visibility"]:.6f} '
      f'covered={c["covered_voxels"]}/{c["coverable_voxels"]} stations_sha={h}')
PY
done
