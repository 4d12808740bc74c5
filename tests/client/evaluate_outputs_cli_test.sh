#!/usr/bin/env bash
# evaluate writes submit's family of files (#38): evaluation.json, the crew's stations.csv (submit's
# header), stations.dxf, fieldsheet.pdf, visibility.ply, heatmap.png (what the stations miss) and
# report.html, stations.geojson with --crs; a sampled evaluation writes the station files only;
# evaluate --plan takes the plan's resolution unless --resolution overrides it, and says so.
# Usage: evaluate_outputs_cli_test.sh VC_SERVER VC_CLIENT VC_SYNTH
set -euo pipefail
server_bin="$1" client_bin="$2" synth_bin="$3"
test_name=evaluate_outputs_cli_test
source "$(dirname "$0")/server_lib.sh"

"$synth_bin" box --out "$work/box.ply" >/dev/null || fail "vc-synth box failed"
start_server "$server_bin" --workers 1 --shutdown-grace 2

"$client_bin" submit "$work/box.ply" --server "$addr" --resolution 0.2 --out "$work/plan" \
  >/dev/null 2>"$work/submit.err" || { cat "$work/submit.err" >&2; fail "submit failed"; }

# evaluate NAME ARGS...: evaluates box.ply into $work/NAME, its stdout in $work/NAME.out.
evaluate() {
  local name="$1"
  shift
  "$client_bin" evaluate "$work/box.ply" --server "$addr" --out "$work/$name" "$@" >"$work/$name.out" \
    2>"$work/$name.err" || { cat "$work/$name.err" >&2; fail "evaluate $name ($*) failed"; }
}
evaluate csv --viewpoints "$work/plan/stations.csv" --resolution 0.2 --crs EPSG:25832
for f in evaluation.json stations.csv stations.dxf stations.geojson fieldsheet.pdf visibility.ply heatmap.png \
  report.html; do
  [[ -s "$work/csv/$f" ]] || fail "evaluate wrote no $f"
done
for f in plan.json reduction.png; do
  [[ ! -e "$work/csv/$f" ]] || fail "evaluate wrote a plan's $f"
done
grep -q "wrote evaluation.json, stations.csv, stations.dxf, stations.geojson, fieldsheet.pdf, visibility.ply, heatmap.png (what the stations miss), report.html to $work/csv" \
  "$work/csv.out" || { cat "$work/csv.out" >&2; fail "evaluate does not list the files it wrote"; }
# The crew's header, as submit writes it, and the same stations in the same walking order.
[[ "$(sed -n 2p "$work/csv/stations.csv")" == "$(sed -n 2p "$work/plan/stations.csv")" ]] \
  || fail "evaluate's stations.csv header is not submit's: $(sed -n 2p "$work/csv/stations.csv")"
sed -n 2p "$work/csv/stations.csv" | grep -q '^station,name,x_m,y_m,z_m,' || fail "no crew header in stations.csv"
python3 - "$work" <<'PY' || fail "evaluate's files"
import csv, json, os, sys
w = sys.argv[1]
def rows(path):
    with open(path) as f:
        return list(csv.DictReader(line for line in f if not line.startswith("#")))
plan, ev = rows(os.path.join(w, "plan", "stations.csv")), rows(os.path.join(w, "csv", "stations.csv"))
assert len(ev) == len(plan), (len(ev), len(plan))
assert sorted((r["x_m"], r["y_m"], r["z_m"]) for r in ev) == sorted((r["x_m"], r["y_m"], r["z_m"]) for r in plan)
geo = json.load(open(os.path.join(w, "csv", "stations.geojson")))
assert sum(f["properties"]["kind"] == "station" for f in geo["features"]) == len(plan), geo
with open(os.path.join(w, "csv", "visibility.ply"), "rb") as f:
    assert f.read(4) == b"ply\n"
with open(os.path.join(w, "csv", "heatmap.png"), "rb") as f:
    assert f.read(8) == b"\x89PNG\r\n\x1a\n"
assert open(os.path.join(w, "csv", "fieldsheet.pdf"), "rb").read(5) == b"%PDF-"
assert "<html" in open(os.path.join(w, "csv", "report.html")).read(2000).lower()
PY

# A sampled evaluation has no per-voxel values: the station files only, and it says so.
evaluate sampled --viewpoints "$work/plan/stations.csv" --resolution 0.2 --sample 2000
for f in evaluation.json stations.csv stations.dxf fieldsheet.pdf; do
  [[ -s "$work/sampled/$f" ]] || fail "a sampled evaluate wrote no $f"
done
[[ ! -e "$work/sampled/visibility.ply" ]] || fail "a sampled evaluate wrote visibility.ply"
grep -q "a sampled evaluation has no per-voxel values" "$work/sampled.out" || fail "no note on the sampled files"

# --plan: the plan's resolution (0.2 m, not the 0.1 m default of a cloud), unless --resolution says otherwise.
evaluate from-plan --plan "$work/plan/plan.json"
evaluate same-resolution --plan "$work/plan/plan.json" --resolution 0.2
evaluate other-resolution --plan "$work/plan/plan.json" --resolution 0.25
! grep -q "resolution" "$work/from-plan.err" "$work/same-resolution.err" \
  || fail "a resolution equal to the plan's was reported as overriding it"
grep -qxF "vc-client: --resolution 0.25 m (the plan: 0.2 m) overrides $work/plan/plan.json" "$work/other-resolution.err" \
  || { cat "$work/other-resolution.err" >&2; fail "no note that --resolution overrides the plan"; }
python3 - "$work" <<'PY' || fail "resolutions"
import json, os, sys
w = sys.argv[1]
res = {n: json.load(open(os.path.join(w, n, "evaluation.json")))["resolution_m"]
       for n in ("from-plan", "same-resolution", "other-resolution")}
assert res == {"from-plan": 0.2, "same-resolution": 0.2, "other-resolution": 0.25}, res
PY
stop_server
echo "evaluate_outputs_cli_test: ok"
