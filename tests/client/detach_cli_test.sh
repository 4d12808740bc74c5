#!/usr/bin/env bash
# Detachable jobs with the real binaries (docs/PROTOCOL.md, "Detachable jobs"): a plan survives a
# killed vc-client and a new vc-client process attaches to it and gets the same stations as a plan
# never interrupted; a second attach finds nothing (the result was delivered); `vc-client cancel`
# ends another detached job, and attaching to it then says why it ended; Ctrl-C on a submit cancels
# its job.
# Usage: detach_cli_test.sh VC_SERVER VC_CLIENT SCENE (a scene whose plan takes a few seconds)
set -euo pipefail
server_bin="$1" client_bin="$2" scene="$3"
# The real scan lives in ../shared/data, which a container build does not have: skipped there.
[[ -f "$scene" ]] || { echo "skipped: $scene is not here"; exit 77; }
test_name=detach
source "$(dirname "$0")/server_lib.sh"
start_server "$server_bin" --workers 1 --shutdown-grace 2

# Starts a submit (extra flags: $3...) in the background and kills it (SIGKILL, or $2) once its
# job runs and it has said how to re-attach; prints the job id.
submit_and_kill() {
  local name="$1" signal="${2:-KILL}"
  shift 2 || shift $#
  "$client_bin" submit "$scene" --server "$addr" --out "$work/$name" "$@" >"$work/$name.out" 2>"$work/$name.err" &
  local pid=$! job=""
  for _ in $(seq 1 600); do
    job=$(sed -n 's/.*: vc-client attach \(j-[0-9a-f]*\) (or cancel .*/\1/p' "$work/$name.err" | head -1)
    [[ -n "$job" ]] && break
    kill -0 "$pid" 2>/dev/null || { cat "$work/$name.err" >&2; fail "$name: vc-client ended before its job ran"; }
    sleep 0.05
  done
  [[ -n "$job" ]] || { cat "$work/$name.err" >&2; fail "$name: submit never said how to re-attach"; }
  grep -q "job $job started" "$work/$name.err" || fail "$name: no 'job $job started' line"
  kill -"$signal" "$pid"
  wait "$pid" 2>/dev/null || true
  echo "$job"
}

# The reference: a plan never interrupted (and it puts the scene in the server's cache). Greedy
# selection: with the default auto a plan that reaches the time limit may differ from run to run.
"$client_bin" submit "$scene" --server "$addr" --out "$work/direct" --solver greedy >/dev/null 2>"$work/direct.err" \
  || { cat "$work/direct.err" >&2; fail "the reference plan failed"; }

job=$(submit_and_kill killed KILL --solver greedy)
"$client_bin" attach "$job" --server "$addr" --out "$work/attached" >"$work/attach.out" 2>"$work/attach.err" \
  || { cat "$work/attach.err" >&2; fail "attach $job failed"; }
grep -q "job $job" "$work/attach.err" || fail "attach does not name the job it follows"
grep -q "job $job detached" "$work/server.log" || fail "the server did not log the detach"
cmp -s "$work/direct/stations.csv" "$work/attached/stations.csv" || fail "the attached plan's stations differ"
python3 - "$work/direct/plan.json" "$work/attached/plan.json" <<'PY' || fail "the attached plan.json differs"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert a["coverage"] == b["coverage"], (a["coverage"], b["coverage"])
assert a["viewpoints"] == b["viewpoints"]
assert a["parameters"] == b["parameters"]
PY
for f in plan.json stations.csv visibility.ply heatmap.png report.html; do
  [[ -s "$work/attached/$f" ]] || fail "attach wrote no $f"
done
# Delivered: a second attach finds nothing (NOT_FOUND, exit 5) and says what may have happened.
set +e
"$client_bin" attach "$job" --server "$addr" --out "$work/again" >/dev/null 2>"$work/again.err"
rc=$?
set -e
[[ $rc -eq 5 ]] || fail "a second attach exited $rc, not 5 (NOT_FOUND)"
grep -q "no detachable job $job" "$work/again.err" || fail "a second attach does not explain the NOT_FOUND"

# A slower plan (4x the candidates) for the jobs that must still run when they are cancelled.
job2=$(submit_and_kill cancelled KILL --grid-spacing 0.5)
"$client_bin" cancel "$job2" --server "$addr" | grep -qx "job $job2: cancelled" || fail "cancel $job2"
set +e
"$client_bin" attach "$job2" --server "$addr" --out "$work/cancelled-out" >/dev/null 2>"$work/cancelled.attach.err"
rc=$?
set -e
[[ $rc -eq 1 ]] || { cat "$work/cancelled.attach.err" >&2; fail "attaching to a cancelled job exited $rc, not 1 (CANCELLED)"; }
grep -q "cancelled by CancelJob" "$work/cancelled.attach.err" || fail "attaching to a cancelled job does not say why"
grep -q "rpc CancelJob job=$job2" "$work/server.log" || fail "the server did not log the CancelJob"

# Ctrl-C is not a dropped link: vc-client cancels its job on the server before it exits.
job3=$(submit_and_kill interrupted INT --grid-spacing 0.5)
grep -q "vc-client: interrupted; job $job3 cancelled on the server" "$work/interrupted.err" \
  || { cat "$work/interrupted.err" >&2; fail "Ctrl-C did not cancel the job"; }
grep -q "rpc CancelJob job=$job3 .*outcome=cancelled" "$work/server.log" || fail "the server did not log the Ctrl-C's CancelJob"

stop_server
echo "detach: OK (job $job attached from a new process; job $job2 cancelled; job $job3 cancelled by Ctrl-C)"
