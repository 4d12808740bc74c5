#!/usr/bin/env bash
# evaluate --export-sets DIR (#34): one station_<n>.xyz per station (n from 1 in the CSV's order),
# voxel centres of what --test counts as seen, in the input's frame to the millimetre: the same
# files at survey coordinates as near the origin, plus the offset; the subvoxel test uploads the
# points; a non-empty DIR is refused unless --force, a DIR that cannot be created is refused, and
# --test without --export-sets is refused, each before anything is sent.
# Usage: export_sets_cli_test.sh VC_SERVER VC_CLIENT
set -euo pipefail
server_bin="$1" client_bin="$2"
test_name=export_sets_cli_test
source "$(dirname "$0")/server_lib.sh"

# A 4 x 3 x 2.5 m room with a pillar, as XYZ text near the origin and at survey coordinates.
python3 - "$work" <<'PY'
import os, sys
w = sys.argv[1]
origin = (512000.0, 5612000.0, 100.0)
pts = []
s = 0.04
def grid(n): return [i * s for i in range(int(round(n / s)) + 1)]
for x in grid(4.0):
    for y in grid(3.0):
        pts += [(x, y, 0.0), (x, y, 2.5)]
for x in grid(4.0):
    for z in grid(2.5):
        pts += [(x, 0.0, z), (x, 3.0, z)]
for y in grid(3.0):
    for z in grid(2.5):
        pts += [(0.0, y, z), (4.0, y, z)]
for x in [2.0 + 0.3 * i / 8 for i in range(9)]:
    for z in grid(2.5):
        pts += [(x, 1.2, z), (x, 1.5, z)]
# Off the voxel boundaries, so that no point's voxel depends on rounding.
pts = [(x + 0.013, y + 0.013, z + 0.013) for x, y, z in pts]
stations = [(1.0, 1.0, 1.5), (3.2, 2.3, 1.2)]
for name, o in (("near", (0.0, 0.0, 0.0)), ("far", origin)):
    with open(os.path.join(w, name + ".xyz"), "w") as f:
        f.writelines("%.4f %.4f %.4f\n" % (x + o[0], y + o[1], z + o[2]) for x, y, z in pts)
    with open(os.path.join(w, name + ".csv"), "w") as f:
        f.writelines("%.3f,%.3f,%.3f\n" % (x + o[0], y + o[1], z + o[2]) for x, y, z in stations)
PY
start_server "$server_bin" --workers 1 --shutdown-grace 2

# evaluate NAME SCENE ARGS...: evaluates $work/SCENE.xyz at its stations into $work/NAME, its output in $work/NAME.out/.err.
evaluate() {
  local name="$1" scene="$2"
  shift 2
  "$client_bin" evaluate "$work/$scene.xyz" --server "$addr" --viewpoints "$work/$scene.csv" --resolution 0.1 \
    --out "$work/$name" "$@" >"$work/$name.out" 2>"$work/$name.err" \
    || { cat "$work/$name.err" >&2; fail "evaluate $name ($*) failed"; }
}
for t in surface subvoxel; do
  evaluate "near-$t" near --export-sets "$work/sets-near-$t" --test "$t"
  evaluate "far-$t" far --export-sets "$work/sets-far-$t" --test "$t"
  grep -q "wrote station_1.xyz .. station_2.xyz (.* seen voxels, $t test, voxel centres in the input's frame) to $work/sets-near-$t" \
    "$work/near-$t.out" || { cat "$work/near-$t.out" >&2; fail "evaluate does not say what --export-sets wrote"; }
done
grep -q "the subvoxel test needs the points" "$work/near-subvoxel.err" \
  || { cat "$work/near-subvoxel.err" >&2; fail "the subvoxel test did not upload the points"; }
python3 - "$work" <<'PY' || fail "the exported sets"
import math, os, re, sys
w = sys.argv[1]
origin = (512000.0, 5612000.0, 100.0)
line = re.compile(r"^-?\d+\.\d{3} -?\d+\.\d{3} -?\d+\.\d{3}$")
def sets(name):
    d = os.path.join(w, "sets-" + name)
    assert sorted(os.listdir(d)) == ["station_1.xyz", "station_2.xyz"], os.listdir(d)
    out = []
    for n in (1, 2):
        rows = open(os.path.join(d, "station_%d.xyz" % n)).read().splitlines()
        assert all(line.match(r) for r in rows), rows[:3]
        out.append([tuple(float(v) for v in r.split()) for r in rows])
    return out
pts = [tuple(float(v) for v in l.split()) for l in open(os.path.join(w, "near.xyz"))]
occupied = {tuple(math.floor(c / 0.1) for c in p) for p in pts}
for t in ("surface", "subvoxel"):
    near, far = sets("near-" + t), sets("far-" + t)
    total = int(re.search(r"\((\d+) seen voxels", open(os.path.join(w, "near-%s.out" % t)).read()).group(1))
    assert sum(map(len, near)) == total, (t, sum(map(len, near)), total)
    for k in range(2):
        assert len(near[k]) > 100, (t, k, len(near[k]))
        assert len(set(near[k])) == len(near[k]), "a voxel listed twice"
        # Voxel centres of occupied voxels: on the 0.1 m lattice's centres, each holding input points.
        for p in near[k]:
            assert all(abs((c / 0.1) % 1 - 0.5) < 1e-6 for c in p), p
            assert tuple(math.floor(c / 0.1) for c in p) in occupied, p
        # At survey coordinates: the same voxels plus the offset, to the millimetre.
        moved = [tuple(round(c - o, 3) for c, o in zip(p, origin)) for p in far[k]]
        assert moved == [tuple(round(c, 3) for c in p) for p in near[k]], (t, k)
# The subvoxel test sees more of this clean room than the surface test's front faces, never less.
for k in range(2):
    s, v = set(sets("near-surface")[k]), set(sets("near-subvoxel")[k])
    assert len(v) >= len(s), (k, len(v), len(s))
PY

# The errors, each refused before anything is sent.
refused() {
  local want="$1"
  shift
  if "$client_bin" evaluate "$work/near.xyz" --server 127.0.0.1:1 --viewpoints "$work/near.csv" --out "$work/x" "$@" \
    >"$work/refused.out" 2>"$work/refused.err"; then
    fail "evaluate $* was not refused"
  fi
  grep -qF -- "$want" "$work/refused.err" || { cat "$work/refused.err" >&2; fail "evaluate $*: no \"$want\""; }
}
refused "--export-sets $work/sets-near-surface is not empty (2 entries" --export-sets "$work/sets-near-surface"
refused "add --force to write into it" --export-sets "$work/sets-near-surface"
refused "cannot create the directory" --export-sets "$work/near.xyz/sets"
refused "exists and is not a directory" --export-sets "$work/near.csv"
refused "--test names the selection test of --export-sets' files; add --export-sets DIR" --test subvoxel
refused "--force requires --export-sets" --force
# --force writes into a directory that holds older sets.
echo "notes" >"$work/sets-near-surface/notes.txt"
evaluate forced near --export-sets "$work/sets-near-surface" --force --test compatibility
[[ -s "$work/sets-near-surface/station_1.xyz" && -f "$work/sets-near-surface/notes.txt" ]] || fail "--force"
grep -q "compatibility test" "$work/forced.out" || fail "--force did not write the compatibility sets"
stop_server
echo "export_sets_cli_test: ok"
