#!/usr/bin/env bash
# evaluate --plan (#38): a plan.json from a real submit is evaluated with the plan's stations and
# scanner, so a plan made with --max-range 2 evaluates without the flag as with it, and not as the
# default scanner would; a flag given overrides the plan and is named on stderr; the files written
# are listed; the plan's CRS labels evaluation.json.
# Usage: evaluate_plan_cli_test.sh VC_SERVER VC_CLIENT VC_SYNTH
set -euo pipefail
server_bin="$1" client_bin="$2" synth_bin="$3"
test_name=evaluate_plan_cli_test
source "$(dirname "$0")/server_lib.sh"

"$synth_bin" box --out "$work/box.ply" >/dev/null || fail "vc-synth box failed"
start_server "$server_bin" --workers 1 --shutdown-grace 2

"$client_bin" submit "$work/box.ply" --server "$addr" --max-range 2 --max-incidence 80 --out "$work/plan" \
  >/dev/null 2>"$work/submit.err" || { cat "$work/submit.err" >&2; fail "submit failed"; }

# evaluate NAME ARGS...: evaluates box.ply into $work/NAME, its stdout in $work/NAME.out.
evaluate() {
  local name="$1"
  shift
  "$client_bin" evaluate "$work/box.ply" --server "$addr" --out "$work/$name" "$@" >"$work/$name.out" \
    2>"$work/$name.err" || { cat "$work/$name.err" >&2; fail "evaluate $name ($*) failed"; }
}
evaluate from-plan --plan "$work/plan/plan.json"
# The plan's CRS labels evaluation.json (a plan submitted with --crs names it in plan.json's crs).
python3 -c '
import json, sys
plan = json.load(open(sys.argv[1]))
plan["crs"] = {"definition": "EPSG:25832"}
json.dump(plan, open(sys.argv[2], "w"))' "$work/plan/plan.json" "$work/plan-crs.json"
evaluate with-crs --plan "$work/plan-crs.json"
python3 -c '
import json, sys
crs = json.load(open(sys.argv[1]))["crs"]
assert crs is not None and crs["definition"] == "EPSG:25832", crs' "$work/with-crs/evaluation.json" \
  || fail "evaluation.json does not name the plan's CRS"
evaluate with-flags --plan "$work/plan/plan.json" --max-range 2 --max-incidence 80
evaluate csv-default --viewpoints "$work/plan/stations.csv"
evaluate overridden --plan "$work/plan/plan.json" --max-range 30

for f in evaluation.json stations.csv; do
  [[ -s "$work/from-plan/$f" ]] || fail "evaluate --plan wrote no $f"
done
grep -q "wrote evaluation.json, stations.csv, .* to $work/from-plan" "$work/from-plan.out" \
  || { cat "$work/from-plan.out" >&2; fail "evaluate does not list the files it wrote"; }
! grep -q "overrides" "$work/with-flags.err" || fail "flags equal to the plan's were reported as overriding it"
grep -qxF "vc-client: --max-range 30 m (the plan: 2 m) overrides $work/plan/plan.json" "$work/overridden.err" \
  || { cat "$work/overridden.err" >&2; fail "no note that --max-range overrides the plan"; }

python3 - "$work" <<'PY' || fail "evaluation figures"
import json, os, sys
w = sys.argv[1]
ev = {n: json.load(open(os.path.join(w, n, "evaluation.json"))) for n in ("from-plan", "with-flags", "csv-default", "overridden")}
plan = json.load(open(os.path.join(w, "plan", "plan.json")))
for k in ("faces_total", "global_visibility", "fully_visible_fraction", "per_viewpoint"):
    assert ev["from-plan"][k] == ev["with-flags"][k], (k, ev["from-plan"][k], ev["with-flags"][k])
g = {n: e["global_visibility"] for n, e in ev.items()}
assert g["from-plan"] != g["csv-default"], f"the plan's 2 m range made no difference: {g}"
assert g["overridden"] != g["from-plan"], f"--max-range 30 did not override the plan: {g}"
assert len(ev["from-plan"]["per_viewpoint"]) == len(plan["viewpoints"]), "not the plan's stations"
print(f"evaluate_plan_cli_test: G from the plan {g['from-plan']:.4f}, default scanner {g['csv-default']:.4f}")
PY
stop_server
echo "evaluate_plan_cli_test: ok"
