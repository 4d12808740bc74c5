#!/usr/bin/env bash
# Survey coordinates and units end to end (docs/PLANNING.md, "Coordinates"; issue #35): the hall
# scan, a copy shifted to UTM-like coordinates (+512 km east, +5,612 km north) and a copy in
# millimetres planned by the real binaries give the same stations, in each file's own frame to the
# millimetre, and the same coverage and G; a copy also raised 312.5 m (heights above sea level stay
# in the local frame: its origin is whole kilometres) gives the same stations to the millimetre and
# coverage within float rounding; the millimetre copy planned as metres is refused with a message
# that names millimetres. The UTM copy is planned with --crs EPSG:25832: its stations.geojson is
# read by python's json and every station checked against pyproj's (Debian's python3-pyproj)
# longitude/latitude of stations.csv's position to 1e-7 degrees. Usage: survey_frame_cli_test.sh VC_SERVER VC_CLIENT HALL_SCAN
set -euo pipefail
server_bin="$1" client_bin="$2" scene="$3"
# The real scan lives in ../shared/data, which a container build does not have: skipped there.
[[ -f "$scene" ]] || { echo "skipped: $scene is not here"; exit 77; }
test_name=survey_frame
source "$(dirname "$0")/server_lib.sh"
start_server "$server_bin" --workers 1

bzcat "$scene" >"$work/hall.xyz"
awk '{ printf "%.7f %.7f %.7f\n", $1 + 512000, $2 + 5612000, $3 }' "$work/hall.xyz" >"$work/hall-utm.xyz"
awk '{ printf "%.7f %.7f %.7f\n", $1 + 512000, $2 + 5612000, $3 + 312.5 }' "$work/hall.xyz" >"$work/hall-utm-height.xyz"
awk '{ printf "%.4f %.4f %.4f\n", $1 * 1000, $2 * 1000, $3 * 1000 }' "$work/hall.xyz" >"$work/hall-mm.xyz"

plan() {  # plan NAME FILE [flags...]
  local name="$1" file="$2"
  shift 2
  "$client_bin" submit "$file" --server "$addr" --out "$work/$name" "$@" >"$work/$name.out" 2>"$work/$name.err" \
    || { cat "$work/$name.err" >&2; fail "$name: submit failed"; }
}
plan metres "$work/hall.xyz"
plan utm "$work/hall-utm.xyz" --crs EPSG:25832
plan utm-height "$work/hall-utm-height.xyz"
plan mm "$work/hall-mm.xyz" --units mm

if "$client_bin" submit "$work/hall-mm.xyz" --server "$addr" --out "$work/mm-as-m" >"$work/mm-as-m.out" 2>"$work/mm-as-m.err"; then
  fail "the millimetre copy planned as metres was accepted"
fi
grep -q "millimetres" "$work/mm-as-m.err" || { cat "$work/mm-as-m.err" >&2; fail "the refusal does not name millimetres"; }

python3 - "$work" <<'PY' || fail "the plans differ"
import csv, json, sys
work = sys.argv[1]
def stations(name):
    with open(f"{work}/{name}/stations.csv") as f:
        rows = csv.DictReader(l for l in f if not l.startswith("#"))
        return [(float(r["x_m"]), float(r["y_m"]), float(r["z_m"])) for r in rows]
def plan(name):
    return json.load(open(f"{work}/{name}/plan.json"))
base = stations("metres")
assert base, "no stations"
for name, shift in (("utm", (512000, 5612000, 0)), ("utm-height", (512000, 5612000, 312.5)), ("mm", (0, 0, 0))):
    got = stations(name)
    assert len(got) == len(base), (name, len(got), len(base))
    for a, b in zip(base, got):
        d = max(abs(b[k] - shift[k] - a[k]) for k in range(3))
        assert d <= 0.001, (name, a, b, d)
    mine, theirs = plan(name)["coverage"], plan("metres")["coverage"]
    if name == "utm-height":
        # Points 312.5 m up are floats with a 3e-5 m step: the few within that of a voxel boundary
        # may fall on its other side (measured: one coverable voxel of 22,524, G 0.71249 vs 0.71260).
        assert abs(mine["coverable_voxels"] - theirs["coverable_voxels"]) <= 0.001 * theirs["coverable_voxels"], name
        assert abs(mine["covered_voxels"] - theirs["covered_voxels"]) <= 0.001 * theirs["covered_voxels"], name
        assert abs(mine["global_visibility"] - theirs["global_visibility"]) <= 1e-3, name
        continue
    for key in ("covered_voxels", "coverable_voxels", "global_visibility"):
        assert mine[key] == theirs[key], (name, key, mine[key], theirs[key])
for name in ("utm", "utm-height"):
    assert plan(name)["frame"]["origin_m"] == [512000, 5612000, 0], plan(name)["frame"]
assert plan("mm")["frame"]["units"] == "mm", plan("mm")["frame"]
print(f"survey_frame: {len(base)} stations, the same in the UTM-shifted, raised and millimetre copies to 1 mm")
PY

grep -q "stations.geojson" "$work/utm.out" || fail "submit --crs does not name stations.geojson"
[[ ! -e "$work/metres/stations.geojson" ]] || fail "a plan without --crs wrote stations.geojson"
[[ $(grep -c "no stations.geojson: name the scene's CRS" "$work/metres.out") -eq 1 ]] \
  || fail "without --crs the client does not say once that there is no GeoJSON"
pyproj_python=/usr/bin/python3  # Debian's, which sees python3-pyproj
[[ -x "$pyproj_python" ]] || pyproj_python=python3
"$pyproj_python" - "$work/utm" <<'PY' || fail "stations.geojson"
import csv, json, sys
import pyproj
out = sys.argv[1]
with open(f"{out}/stations.csv") as f:
    lines = f.readlines()
assert "CRS EPSG:25832 (ETRS89 / UTM zone 32N)" in lines[0], lines[0]
rows = list(csv.DictReader(l for l in lines if not l.startswith("#")))
assert json.load(open(f"{out}/plan.json"))["crs"]["epsg"] == 25832
doc = json.load(open(f"{out}/stations.geojson"))
assert doc["type"] == "FeatureCollection", doc["type"]
points = [f for f in doc["features"] if f["geometry"]["type"] == "Point"]
assert len(points) == len(rows), (len(points), len(rows))
to_wgs84 = pyproj.Transformer.from_crs("EPSG:25832", "EPSG:4326", always_xy=True)
for feature, row in zip(points, rows):
    lon, lat = to_wgs84.transform(float(row["x_m"]), float(row["y_m"]))
    got = feature["geometry"]["coordinates"]
    assert abs(got[0] - lon) < 1e-7 and abs(got[1] - lat) < 1e-7, (row["name"], got, lon, lat)
    assert feature["properties"]["name"] == row["name"] and feature["properties"]["station"] == int(row["station"])
for line in (f for f in doc["features"] if f["geometry"]["type"] == "LineString"):
    assert len(line["geometry"]["coordinates"]) >= 2
    for lon, lat in line["geometry"]["coordinates"]:
        assert 9.1 < lon < 9.2 and 50.6 < lat < 50.7, (lon, lat)  # the site, 12 km east of 9°E at 50.65°N
print(f"survey_frame: stations.geojson agrees with pyproj for {len(points)} stations")
PY
stop_server
echo "survey_frame_cli_test: ok"
