#!/usr/bin/env bash
# The main job: plan the scanner stations for one real office floor (geb079, OctoMap) end to end.
# Installs the dependencies, builds vc-server and vc-client only (release preset: no tests, no
# benchmarks, no vc-synth; README records the first run's time), starts vc-server on a free loopback port,
# inspects the scene locally, submits it with vc-client (live progress) with the Leica RTC360 preset
# and --min-overlap 0.3, prints the stations, the scan graph, the walking route and the field time,
# leaves plan.json, stations.csv, stations.dxf, fieldsheet.pdf, visibility.ply, heatmap.png, reduction.png and report.html in
# vc-out/, and stops the server.
# Usage: scripts/demo.sh [extra vc-client submit flags...]
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/server_port.sh"
cd "$(dirname "$0")/.."

scene=../shared/data/geb079/geb079.bt
out=vc-out

bash scripts/install-deps.sh
build_start=$(date +%s)
cmake --preset release >/dev/null
cmake --build --preset release --target vc-server vc-client
echo "=== built vc-server and vc-client in $(( $(date +%s) - build_start )) s"

bin=build/release
server="$bin/server/vc-server"
client="$bin/client/vc-client"

log=$(mktemp)
server_pid=""
stop_server() {
  if [[ -n "$server_pid" ]] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid"
    wait "$server_pid" || true
  fi
  server_pid=""
}
trap 'stop_server; rm -f "$log"' EXIT

echo "=== starting vc-server on a free loopback port"
vc_launch "$log" "$server" --listen 127.0.0.1:0 --workers 1
server_pid=$vc_pid
port=$(vc_wait_port "$log" "$server_pid") || { cat "$log"; echo "demo: vc-server did not start or report its port" >&2; exit 1; }
addr="127.0.0.1:$port"
"$client" health --server "$addr"

echo "=== vc-client inspect $scene"
"$client" inspect "$scene"

# A real instrument and registrable scans (30 % overlap between linked stations), unless the
# caller chose otherwise; the summary ends with the scan graph, the walking route and the field time.
defaults=()
[[ " $* " == *" --scanner "* ]] || defaults+=(--scanner leica-rtc360)
[[ " $* " == *" --min-overlap "* ]] || defaults+=(--min-overlap 0.3)
echo "=== vc-client submit $scene --out $out ${defaults[*]} $*"
"$client" submit "$scene" --server "$addr" --out "$out" "${defaults[@]}" "$@"

echo "=== server log"
stop_server
cat "$log"
echo "=== results in $out/:"
ls -l "$out"
