#!/usr/bin/env bash
# Smoke test of the real binaries over loopback: vc-synth makes a box room, vc-server plans it for
# vc-client, and the output files are checked. Usage: smoke_test.sh VC_SERVER VC_CLIENT VC_SYNTH
set -euo pipefail
server_bin="$1" client_bin="$2" synth_bin="$3"
test_name=smoke
source "$(dirname "$0")/server_lib.sh"

"$synth_bin" box --out "$work/box.ply" >/dev/null || fail "vc-synth box failed"
[[ -s "$work/box.ply" ]] || fail "vc-synth wrote no box.ply"

# inspect FILE.e57 lists the scans and their poses (the fuzz seed written by the tests' E57 writer).
e57="$(dirname "$0")/../../fuzz/corpus/e57_fuzzer/two_scans.e57"
"$client_bin" inspect "$e57" >"$work/inspect.out" 2>&1 || { cat "$work/inspect.out" >&2; fail "inspect FILE.e57"; }
grep -q "format:            e57 (E57 1.0, 2 scans)" "$work/inspect.out" || fail "inspect: no E57 format line"
grep -q '1 "second": 8 points, at (4.000, -2.000, 1.500) m, rotation (w, x, y, z) (0.9689, 0.0000, 0.0000, 0.2474)' \
  "$work/inspect.out" || { cat "$work/inspect.out" >&2; fail "inspect: no line for the second scan"; }
"$client_bin" inspect "$e57" --json | python3 -c '
import json, sys
scans = json.load(sys.stdin)["e57_scans"]
assert [s["points"] for s in scans] == [8, 8], scans
assert scans[1]["translation_m"] == [4, -2, 1.5], scans
' || fail "inspect --json: e57_scans"

start_server "$server_bin" --workers 1 --shutdown-grace 2

"$client_bin" health --server "$addr" | grep -qx SERVING || fail "health is not SERVING"

"$client_bin" submit "$work/box.ply" --server "$addr" --out "$work/out" >"$work/client.out" 2>"$work/client.err" \
  || { cat "$work/client.err" >&2; fail "vc-client submit failed"; }
grep -q "progress:" "$work/client.err" || fail "no progress lines on a non-terminal"
grep -q "station(s)" "$work/client.out" || fail "no station list printed"
grep -q "heat map ready" "$work/client.err" || fail "no heat map line"
[[ $(grep -c "heat map ready" "$work/client.err") -eq 1 ]] || fail "the heat map was noted more than once"
grep -q "final stations:" "$work/client.err" || fail "no final stations line"
grep -q "report.html to " "$work/client.out" || fail "vc-client does not name report.html among the files it wrote"

for f in plan.json stations.csv stations.dxf fieldsheet.pdf visibility.ply heatmap.png reduction.png report.html; do
  [[ -s "$work/out/$f" ]] || fail "missing or empty $f"
done
python3 - "$work/out" <<'PY' || fail "output contents"
import json, sys, os
out = sys.argv[1]
plan = json.load(open(os.path.join(out, "plan.json")))
assert isinstance(plan, dict), "plan.json is not an object"
for key in ("schema", "resolution_m", "viewpoints", "coverage", "reduction", "candidates", "parameters"):
    assert key in plan, "plan.json lacks " + key
stations = plan["viewpoints"]
assert isinstance(stations, list) and len(stations) >= 1, "plan.json has no stations"
assert plan["coverage"]["covered_voxels"] > 0, "nothing covered"
rows = [l for l in open(os.path.join(out, "stations.csv")) if l.strip() and not l.startswith("#")]
data = [r for r in rows if not r[0].isalpha()]
assert len(data) == len(stations), f"stations.csv has {len(data)} rows, plan.json {len(stations)} stations"
for r in data:
    assert len(r.split(",")) >= 3, f"bad row {r!r}"
for png in ("heatmap.png", "reduction.png"):
    assert open(os.path.join(out, png), "rb").read(8) == b"\x89PNG\r\n\x1a\n", png + " is not a PNG"
assert open(os.path.join(out, "visibility.ply"), "rb").read(4) == b"ply\n", "visibility.ply is not a PLY"
print(f"smoke: {len(stations)} station(s)")
PY

# The compact upload (the default) and --raw-upload give the same plan; plan.json says which ran.
grep -q "compact upload: .* voxels of 0.1 m" "$work/client.err" || fail "no compact upload line"
"$client_bin" submit "$work/box.ply" --server "$addr" --out "$work/raw" --raw-upload >/dev/null 2>"$work/raw.err" \
  || { cat "$work/raw.err" >&2; fail "vc-client submit --raw-upload failed"; }
grep -q "raw upload of .* (--raw-upload)" "$work/raw.err" || fail "no raw upload line"
cmp -s "$work/out/stations.csv" "$work/raw/stations.csv" || fail "compact and raw uploads planned different stations"
python3 - "$work/out/plan.json" "$work/raw/plan.json" <<'PY' || fail "plan.json upload"
import json, sys
compact, raw = (json.load(open(p)) for p in sys.argv[1:3])
assert compact["upload"]["format"] == "vc-voxels", compact["upload"]
assert raw["upload"]["format"] == "raw" and raw["upload"]["why_raw"] == "--raw-upload", raw["upload"]
assert compact["upload"]["bytes_sent"] * 20 < raw["upload"]["bytes_sent"], (compact["upload"], raw["upload"])
assert compact["upload"]["voxels"] == compact["coverage"]["occupied_voxels"], compact["upload"]
assert compact["coverage"]["global_visibility"] == raw["coverage"]["global_visibility"]
PY

# The same scene again with other parameters: the server has it in its cache, nothing is uploaded.
"$client_bin" submit "$work/box.ply" --server "$addr" --out "$work/again" --grid-spacing 0.5 >/dev/null \
  2>"$work/again.err" || { cat "$work/again.err" >&2; fail "the second submit failed"; }
grep -q "in its cache: nothing uploaded" "$work/again.err" || { cat "$work/again.err" >&2; fail "no cache hit"; }
python3 -c 'import json,sys; u=json.load(open(sys.argv[1]))["upload"]; assert u["from_cache"] and u["bytes_sent"] == 0 and len(u["scene_hash"]) == 64, u' \
  "$work/again/plan.json" || fail "plan.json upload after a cache hit"
# A station already scanned, named in its file: stations.csv and stations.dxf call it by that name.
python3 - "$work/out/stations.csv" "$work/fixed.csv" <<'PY' || fail "cannot write fixed.csv"
import csv, sys
first = next(csv.DictReader(l for l in open(sys.argv[1]) if not l.startswith("#")))
open(sys.argv[2], "w").write(f"name,x,y,z\nBM-7,{first['x_m']},{first['y_m']},{first['z_m']}\n")
PY
"$client_bin" submit "$work/box.ply" --server "$addr" --out "$work/fixed" --fixed-stations "$work/fixed.csv" \
  >/dev/null 2>"$work/fixed.err" || { cat "$work/fixed.err" >&2; fail "submit --fixed-stations failed"; }
grep -q ",BM-7,.*,existing," "$work/fixed/stations.csv" || { cat "$work/fixed/stations.csv" >&2; fail "stations.csv does not name the fixed station"; }
grep -q "^BM-7 h=" "$work/fixed/stations.dxf" || fail "stations.dxf does not label the fixed station by its name"
grep -q "cache=hit" "$work/server.log" || fail "the server log has no cache=hit"
grep -q "cache=miss" "$work/server.log" || fail "the server log has no cache=miss"

# evaluate voxelises a cloud at its own --resolution: compact at 0.05 m, the same figures as raw.
for mode in compact raw; do
  flag=""; [[ $mode == raw ]] && flag="--raw-upload"
  "$client_bin" evaluate "$work/box.ply" --viewpoints "$work/out/stations.csv" --resolution 0.05 $flag \
    --no-scene-cache --server "$addr" --out "$work/eval-$mode" >/dev/null 2>"$work/eval-$mode.err" \
    || { cat "$work/eval-$mode.err" >&2; fail "vc-client evaluate ($mode) failed"; }
done
grep -q "compact upload: .* voxels of 0.05 m" "$work/eval-compact.err" \
  || { cat "$work/eval-compact.err" >&2; fail "evaluate did not upload compactly at its --resolution"; }
python3 - "$work/eval-compact/evaluation.json" "$work/eval-raw/evaluation.json" <<'PY' || fail "evaluate: compact and raw differ"
import json, sys
compact, raw = (json.load(open(p)) for p in sys.argv[1:3])
assert compact["resolution_m"] == raw["resolution_m"] == 0.05, (compact["resolution_m"], raw["resolution_m"])
for k in ("faces_total", "global_visibility", "fully_visible_fraction", "per_viewpoint"):
    assert compact[k] == raw[k], (k, compact[k], raw[k])
PY

# A bad input gives a clear error and the INVALID_ARGUMENT exit status (3).
head -c 100 "$work/box.ply" > "$work/broken.ply"
set +e
"$client_bin" submit "$work/broken.ply" --server "$addr" --out "$work/out2" >/dev/null 2>"$work/err2"
rc=$?
set -e
[[ $rc -eq 3 ]] || fail "broken upload exited $rc, expected 3 ($(cat "$work/err2"))"

# An instrument preset with one flag overriding it: the server plans with the resolved model and
# plan.json names the preset (docs/SCANNERS.md). `scanners` lists the presets without a server.
"$client_bin" scanners | grep -q "^leica-rtc360 " || fail "vc-client scanners does not list leica-rtc360"
"$client_bin" submit "$work/box.ply" --server "$addr" --scanner leica-rtc360 --max-range 40 --out "$work/out4" \
  >/dev/null 2>"$work/err4" || { cat "$work/err4" >&2; fail "vc-client submit --scanner failed"; }
python3 - "$work/out4/plan.json" <<'PY' || fail "plan.json's scanner with a preset"
import json, sys
s = json.load(open(sys.argv[1]))["parameters"]["scanner"]
assert s["name"] == "leica-rtc360", s
assert s["max_range_m"] == 40 and s["min_range_m"] == 0.5 and s["vfov_min_deg"] == -60, s
PY

# --tls against this plain server: no retry (it cannot mend), and the message says what to do.
set +e
"$client_bin" --tls --retries 4 submit "$work/box.ply" --server "$addr" --out "$work/out5" >/dev/null 2>"$work/err5"
rc=$?
set -e
[[ $rc -eq 14 ]] || fail "--tls against a plain server exited $rc, expected 14 ($(cat "$work/err5"))"
grep -q "the server does not speak TLS: drop --tls" "$work/err5" || fail "--tls message: $(cat "$work/err5")"
if grep -q "retrying" "$work/err5"; then fail "--tls against a plain server was retried: $(cat "$work/err5")"; fi

# SIGTERM: the server drains and exits 0.
stop_server

# Nothing listens now: UNAVAILABLE (14), worded for people.
set +e
"$client_bin" submit "$work/box.ply" --server "$addr" --retries 1 --out "$work/out3" >/dev/null 2>"$work/err3"
rc=$?
set -e
[[ $rc -eq 14 ]] || fail "an unreachable server exited $rc, expected 14 ($(cat "$work/err3"))"
grep -q "cannot reach vc-server at $addr" "$work/err3" || fail "unreachable server message: $(cat "$work/err3")"
grep -q "job .* status=OK" "$work/server.log" || fail "no job log line"
echo "smoke: OK"
