#!/usr/bin/env bash
# vc-client checks before it uploads (#38): each refusal's exact message and exit status, and that
# no connection was made for it. vc-client is pointed at a TCP listener (python3) that counts the
# connections it accepts: after every refusal the count is still 0; a good command line then
# connects, so the count is seen to move. Usage: preflight_cli_test.sh VC_CLIENT
set -euo pipefail
client_bin="$1"
# An E57 of two scans (the fuzz seed written by the tests' E57 writer).
e57_seed="$(cd "$(dirname "$0")" && pwd)/../../fuzz/corpus/e57_fuzzer/two_scans.e57"
work="$(mktemp -d)"
listener=""
cleanup() {
  if [[ -n "$listener" ]]; then kill "$listener" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "preflight_cli_test: $*" >&2; exit 1; }

python3 - "$work/port" "$work/connections" <<'PY' &
import socket, sys
s = socket.socket()
s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
s.bind(("127.0.0.1", 0))
s.listen(16)
open(sys.argv[2], "w").write("0")
open(sys.argv[1] + ".tmp", "w").write(str(s.getsockname()[1]))
import os
os.rename(sys.argv[1] + ".tmp", sys.argv[1])
n = 0
while True:
    c, _ = s.accept()
    n += 1
    open(sys.argv[2], "w").write(str(n))
    c.close()
PY
listener=$!
for _ in $(seq 100); do [[ -s "$work/port" ]] && break; sleep 0.05; done
[[ -s "$work/port" ]] || fail "the listener did not start"
server="127.0.0.1:$(cat "$work/port")"

cd "$work"
printf '1 2 3\n4 5 6\n' >cloud.xyz
printf '1 2 3\n4 x 6\n' >text.ply
: >empty.ply
printf 'xmin,ymin,zmin,xmax,ymax,zmax\n# the crane\n0,0,0,10,10,3\n' >zones.csv
printf 'x,y,z\n1,1,1.5\n' >fixed.csv

# expect STATUS MESSAGE ARGS...: vc-client exits with STATUS, prints MESSAGE as a line of its
# stderr, and nobody connected.
expect() {
  local want_status="$1" want="$2"
  shift 2
  local status=0
  "$client_bin" --server "$server" "$@" >out 2>err || status=$?
  [[ "$status" == "$want_status" ]] || { cat err >&2; fail "$* exited $status, not $want_status"; }
  grep -qxF -- "$want" err || { cat err >&2; fail "$*: no line '$want'"; }
  [[ "$(cat connections)" == 0 ]] || fail "$*: connected to the server"
}

expect 3 "vc-client: --max-range must be > 0 m, got -5 (nothing was sent)" submit cloud.xyz --max-range -5
expect 3 "vc-client: --grid-spacing must be > 0 m, got 0 (nothing was sent)" submit cloud.xyz --grid-spacing 0
expect 3 "vc-client: --target-coverage must be in (0, 1], got 1.5 (nothing was sent)" \
  submit cloud.xyz --target-coverage 1.5
expect 3 "vc-client: --clearance (2 m) must be smaller than --tripod-height (1.5 m): the scanner would touch the floor (nothing was sent)" \
  submit cloud.xyz --clearance 2
expect 3 "vc-client: --keep-out line 3: --fixed-stations fixed.csv:2 (1, 1, 1.5) lies inside this zone (nothing was sent)" \
  submit cloud.xyz --keep-out zones.csv --fixed-stations fixed.csv
expect 3 "vc-client: --max-range must be > 0 m, got -5 (nothing was sent)" \
  evaluate cloud.xyz --viewpoints fixed.csv --max-range -5
# evaluate --plan: a file that is not a plan is refused naming it and the field.
printf 'x,y,z\n1,1,1.5\n' >notjson.json
printf '{"schema": "vc.plan/1", "viewpoints": [{"x": 1, "y": 1}]}' >noz.json
expect 3 "vc-client: notjson.json: not JSON (expected a plan.json written by vc-client submit) (nothing was sent)" \
  evaluate cloud.xyz --plan notjson.json
expect 3 "vc-client: noz.json: no viewpoints[0].z (expected a plan.json written by vc-client submit) (nothing was sent)" \
  evaluate cloud.xyz --plan noz.json
printf '{"schema": "vc.plan/1", "resolution_m": 0.1, "viewpoints": [{"x": 1, "y": 1, "z": 1.5}], "parameters": {"scanner": {"min_range_m": 0.5, "max_range_m": 75, "vfov_min_deg": null, "vfov_max_deg": null, "max_incidence_deg": null, "angular_step_deg": null, "max_spacing_m": null, "hfov_deg": 180}}}' >hfov.json
expect 3 "vc-client: hfov.json's scanner sees 180 deg around its heading, and evaluate takes no headings: add --hfov 360 to evaluate its stations all round (nothing was sent)" \
  evaluate cloud.xyz --plan hfov.json
expect 3 "vc-client: evaluate needs the stations: --viewpoints stations.csv or --plan plan.json (nothing was sent)" \
  evaluate cloud.xyz
expect 3 "vc-client: the scene file empty.ply is empty (0 bytes): nothing to upload; export the scene again (nothing was sent)" \
  submit empty.ply
expect 5 "vc-client: cannot read the scene file missing.ply: No such file or directory (nothing was sent)" \
  submit missing.ply
expect 3 "vc-client: text.ply is not a PLY file (it looks like XYZ text; rename it .xyz, or export it again as PLY): text.ply: line 2: expected a number for y (column 2), found \"x\" (nothing was sent)" \
  submit text.ply
# --crs is checked with PROJ before anything is sent (vc/client/crs_flag.h).
expect 3 "vc-client: --crs: \"EPSG:99999\" is not a CRS PROJ knows (proj_create: crs not found) (nothing was sent)" \
  submit cloud.xyz --crs EPSG:99999
expect 3 "vc-client: --crs: \"EPSG:4326\" (WGS 84) is a geographic CRS: its coordinates are degrees of longitude and latitude, not a site frame in metres or feet. Give the projected CRS the scan is in (e.g. the UTM zone, EPSG:25832 for ETRS89 / UTM zone 32N, or the national grid) (nothing was sent)" \
  submit cloud.xyz --crs EPSG:4326
expect 3 "vc-client: --crs EPSG:25832 (ETRS89 / UTM zone 32N) has its axes in metre (--units m) but --units says mm: a file in the CRS's coordinates is in its unit. Drop --units (the CRS's unit is used), or give the CRS the file is in (nothing was sent)" \
  submit cloud.xyz --crs EPSG:25832 --units mm
expect 3 "vc-client: --crs EPSG:2263 (NAD83 / New York Long Island (ftUS)) has its axes in US survey foot (--units us-ft) but --units says m: a file in the CRS's coordinates is in its unit. Drop --units (the CRS's unit is used), or give the CRS the file is in (nothing was sent)" \
  evaluate cloud.xyz --viewpoints fixed.csv --crs EPSG:2263 --units m
expect 3 "vc-client: --crs: \"EPSG:99999\" is not a CRS PROJ knows (proj_create: crs not found) (nothing was sent)" \
  attach j-0123456789abcdef --crs EPSG:99999
# An E57 holds metres by its standard (ASTM E2807), whatever the CRS's unit: no --units for it.
cp "$e57_seed" site.e57
expect 3 "vc-client: --units us-ft does not apply to the scene file: it is E57, in metres by its standard (ASTM E2807), whatever the CRS's unit. Drop --units; --crs EPSG:2263 (NAD83 / New York Long Island (ftUS)) still labels the outputs (nothing was sent)" \
  submit site.e57 --crs EPSG:2263 --units us-ft
expect 3 "vc-client: site.e57: E57 files hold metres by the standard (ASTM E2807), but units of 0.3048 m were given; read the E57 without units (with a CRS in feet, vc-client --crs alone: the file is read in metres) (nothing was sent)" \
  submit site.e57 --units ft
expect 109 "vc-client: unknown flag --grid-spaceing; did you mean --grid-spacing?" submit cloud.xyz --grid-spaceing 2
expect 106 "vc-client: unknown command 'sumbit'; did you mean submit?" sumbit cloud.xyz

# A good command line connects (the listener closes at once: UNAVAILABLE, after one attempt).
status=0
"$client_bin" --server "$server" --retries 1 submit cloud.xyz >out 2>err || status=$?
[[ "$status" == 14 ]] || { cat err >&2; fail "a good submit exited $status, not 14"; }
[[ "$(cat connections)" -ge 1 ]] || fail "a good submit did not connect: the count proves nothing"
# The E57 with a CRS in feet goes, read in metres, and vc-client says so.
status=0
"$client_bin" --server "$server" --retries 1 submit site.e57 --crs EPSG:2263 >out 2>err || status=$?
[[ "$status" == 14 ]] || { cat err >&2; fail "submit site.e57 --crs EPSG:2263 exited $status, not 14"; }
grep -qF "the scene file is E57, in metres by its standard (ASTM E2807): read in metres, not in --crs EPSG:2263 (NAD83 / New York Long Island (ftUS))'s US survey foot; the outputs are in metres (the CRS's coordinates times 0.3048006096) and stations.geojson is converted" err ||
  { cat err >&2; fail "submit site.e57 --crs EPSG:2263: no note that it is read in metres"; }
echo "preflight_cli_test: ok"
