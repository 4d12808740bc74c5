#!/usr/bin/env bash
# vc-client validate end to end (no server): a box room's points written by awk, validated with
# its scanner position; the table, validation.json and validation_1.ply; and each input error's
# exit status and message; an E57's two scans. Usage: validate_cli_test.sh VC_CLIENT
set -euo pipefail
client_bin="$1"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
fail() { echo "validate_cli_test: $*" >&2; exit 1; }

# The six walls of a 4 x 4 x 3 m box, a point every 0.05 m; the scanner stood at its centre.
awk 'BEGIN {
  for (i = 0; i <= 80; i++) for (j = 0; j <= 80; j++) {
    a = i * 0.05; b = j * 0.05
    printf "%.3f %.3f 0\n", a, b; if (b <= 3) { printf "%.3f 0 %.3f\n", a, b; printf "%.3f 4 %.3f\n", a, b
    printf "0 %.3f %.3f\n", a, b; printf "4 %.3f %.3f\n", a, b }; printf "%.3f %.3f 3\n", a, b
  } }' >"$work/box.xyz"
echo "x,y,z" >"$work/pos.csv"
echo "2,2,1.5" >>"$work/pos.csv"

"$client_bin" validate "$work/box.xyz" --positions "$work/pos.csv" --out "$work/out" >"$work/table" 2>"$work/err" \
  || { cat "$work/err" >&2; fail "validate failed"; }
grep -q "RECALL" "$work/table" || { cat "$work/table" >&2; fail "no table header"; }
grep -q "^note: " "$work/table" || { cat "$work/table" >&2; fail "no single-scan note"; }
python3 - "$work/out/validation.json" <<'PY' || fail "validation.json"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["selection_test"] == "surface", j["selection_test"]
assert len(j["scans"]) == 1 and j["scans"][0]["position_m"] == [2, 2, 1.5], j["scans"]
s = j["scans"][0]
assert s["captured"] > 0 and s["recall"] > 0.9, s  # a box seen from inside is in view everywhere
assert j["precision_meaningful"] is False
PY
head -c 600 "$work/out/validation_1.ply" | grep -aq "comment colour: green 40 180 40 = agree" || fail "PLY header"

# An E57's scans with their poses (the fuzz seed written by the tests' E57 writer: 8 points each).
e57="$(dirname "$0")/../../fuzz/corpus/e57_fuzzer/two_scans.e57"
"$client_bin" validate "$e57" >"$work/e57.table" 2>"$work/err" || { cat "$work/err" >&2; fail "validate FILE.e57"; }
grep -q "two_scans.e57, scan 2 (second)" "$work/e57.table" || { cat "$work/e57.table" >&2; fail "no E57 scan 2"; }

# Each input error: the exit status (3 invalid argument, 5 not found) and the file and scan named.
expect_error() {
  local code="$1" pattern="$2"; shift 2
  local rc=0
  "$client_bin" validate "$@" >/dev/null 2>"$work/err" || rc=$?
  [[ $rc -eq $code ]] || { cat "$work/err" >&2; fail "exit $rc, expected $code: validate $*"; }
  grep -qF -- "$pattern" "$work/err" || { cat "$work/err" >&2; fail "no '$pattern' in the message: validate $*"; }
}
expect_error 3 "box.xyz (scan 1) has no scanner position" "$work/box.xyz"
expect_error 3 "holds 1 positions but 2 point files" "$work/box.xyz" "$work/box.xyz" --positions "$work/pos.csv"
expect_error 5 "missing.xyz (scan 1): " "$work/missing.xyz" --positions "$work/pos.csv"
printf "900,2,1.5\n" >"$work/far.csv"
expect_error 3 "scan 1 (\"$work/box.xyz\")'s scanner position is" "$work/box.xyz" --positions "$work/far.csv"
echo "validate_cli_test: ok"
