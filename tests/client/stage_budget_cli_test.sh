#!/usr/bin/env bash
# A stage's memory refusal end to end (#37): a job whose budget holds the stages before the
# reduction but not the reduction's table (docs/PLANNING.md, "Memory, stage by stage") is refused
# with RESOURCE_EXHAUSTED (vc-client exit 8) naming the stage and the budget that plans it; the
# server keeps running, and that budget plans the scene as the default budget does.
# Usage: stage_budget_cli_test.sh VC_SERVER VC_CLIENT VC_SYNTH
set -euo pipefail
server_bin="$1" client_bin="$2" synth_bin="$3"
test_name=stage_budget_cli_test
source "$(dirname "$0")/server_lib.sh"

"$synth_bin" comb:5 --out "$work/comb.ply" >/dev/null || fail "vc-synth comb:5 failed"
start_server "$server_bin" --workers 1 --shutdown-grace 2

submit() {  # submit NAME ARGS...: plans comb.ply into $work/NAME; its exit status in $rc
  local name="$1"
  shift
  rc=0
  "$client_bin" submit "$work/comb.ply" --server "$addr" --target-coverage 1 --out "$work/$name" "$@" \
    >"$work/$name.out" 2>"$work/$name.err" || rc=$?
}
submit default
[[ $rc -eq 0 ]] || { cat "$work/default.err" >&2; fail "the plan at the default budget failed ($rc)"; }
# The reduction's table: 278 bytes a voxel, in three quarters of the budget (ReductionTableBudgetBytes).
table_budget=$(python3 -c '
import json, sys
n = json.load(open(sys.argv[1]))["coverage"]["occupied_voxels"]
print((278 * n + 2) // 3 * 4)' "$work/default/plan.json")

submit refused --memory-budget-bytes $((table_budget - 4))
[[ $rc -eq 8 ]] || { cat "$work/refused.err" >&2; fail "a budget below the reduction's table gave exit $rc, not 8"; }
grep -q "status=RESOURCE_EXHAUSTED: reduction: " "$work/server.log" || fail "the server logged no RESOURCE_EXHAUSTED"
grep -qF "reduction: its table of the stations' best face values (" "$work/refused.err" \
  || { cat "$work/refused.err" >&2; fail "the refusal does not name the reduction's table"; }
grep -qF -- "--memory-budget-bytes $table_budget)" "$work/refused.err" \
  || { cat "$work/refused.err" >&2; fail "the refusal does not give the budget that plans the scene ($table_budget)"; }

kill -0 "$server_pid" 2>/dev/null || fail "vc-server exited after the refusal"
"$client_bin" health --server "$addr" >/dev/null 2>&1 || fail "vc-server does not answer after the refusal"
submit fits --memory-budget-bytes "$table_budget"
[[ $rc -eq 0 ]] || { cat "$work/fits.err" >&2; fail "the budget the refusal named did not plan ($rc)"; }
cmp <(python3 -c 'import json,sys; p = json.load(open(sys.argv[1])); print([(v["x"], v["y"], v["z"]) for v in p["viewpoints"]], p["coverage"]["covered_voxels"])' \
        "$work/default/plan.json") \
    <(python3 -c 'import json,sys; p = json.load(open(sys.argv[1])); print([(v["x"], v["y"], v["z"]) for v in p["viewpoints"]], p["coverage"]["covered_voxels"])' \
        "$work/fits/plan.json") || fail "the plan at the table's budget differs from the default budget's"
stop_server
echo "$test_name: OK"
