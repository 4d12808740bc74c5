#!/usr/bin/env bash
# SIGTERM while jobs run and wait: a server with --workers 1 --queue 2 gets 3 geb079 plans (one
# runs, two queue), then SIGTERM. Checks: the server exits 0; every job either finishes (exit 0 and
# plan.json) or ends CANCELLED (vc-client exit 1), no other outcome; the time from SIGTERM to exit is
# at most grace + SLACK seconds. Two cases: a short grace (2 s; the running job cannot finish and
# must be cancelled) and a long one (60 s; every job must complete). During the drain it also
# tries a new submit and a health check (figures only).
# Usage: scripts/load/sigterm.sh [--build DIR (build/release)] [--short-only] [--slack S (5)]
source "$(dirname "$0")/lib.sh"
build="" short_only="" slack=5 jobs=3
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --short-only) short_only=1; shift ;;
    --slack) slack=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--short-only] [--slack S]" >&2; exit 2 ;;
  esac
done
load_init "$build"
scene=$DATA/geb079/geb079.bt
[[ -f "$scene" ]] || { echo "sigterm: no scene $scene" >&2; exit 2; }

all_pass=1
run_case() {  # run_case GRACE_S MUST_COMPLETE(0/1)
  local grace=$1 must=$2 d="$WORK/grace$1" i pids=() t_term t_exit srv_rc exit_ms
  mkdir -p "$d"
  start_server "$d/server.log" --workers 1 --queue 2 --shutdown-grace "$grace"
  for i in $(seq 1 $jobs); do
    ( t0=$(now_ms)
      timeout $((grace + 120)) "$CLIENT" submit "$scene" --server "$ADDR" --out "$d/out$i" >"$d/$i.out" 2>&1
      echo "$? $(now_ms)" >"$d/$i.rc" ) &
    pids+=($!); CHILD_PIDS+=($!)
    sleep 0.2
  done
  sleep 2  # the first job is past its upload and running, the others wait
  t_term=$(now_ms)
  kill -TERM "$SERVER_PID"
  # A new submit and a health check during the drain, in the background (figures only).
  ( sleep 0.3; t0=$(now_ms)
    timeout 20 "$CLIENT" submit "$scene" --server "$ADDR" --out "$d/late" >"$d/late.out" 2>&1
    echo "$? $(( $(now_ms) - t0 ))" >"$d/late.rc"
    timeout 10 "$CLIENT" health --server "$ADDR" >"$d/health.out" 2>&1 ) &
  local late_pid=$!; CHILD_PIDS+=($late_pid)
  wait_pid_bounded "$SERVER_PID" $((grace + 60)); srv_rc=$?
  t_exit=$(now_ms); exit_ms=$((t_exit - t_term))
  [[ $srv_rc == 124 ]] && { echo "  server did not exit within grace + 60 s; killing it"; kill -KILL "$SERVER_PID"; }
  wait "$SERVER_PID" 2>/dev/null; SERVER_PID=""
  for i in "${pids[@]}"; do wait_pid_bounded "$i" 30 || kill -TERM "$i" 2>/dev/null; done
  wait_pid_bounded "$late_pid" 40 || kill -TERM "$late_pid" 2>/dev/null
  local late_rc=x late_ms=x health
  [[ -f "$d/late.rc" ]] && read -r late_rc late_ms <"$d/late.rc"
  health=$(tail -1 "$d/health.out" 2>/dev/null)
  local ok=0 cancelled=0 other=0 rc when outcomes=""
  for i in $(seq 1 $jobs); do
    if [[ ! -f "$d/$i.rc" ]]; then other=$((other + 1)); outcomes+=" job$i:hung"; continue; fi
    read -r rc when <"$d/$i.rc"
    local rel=$(( when - t_term ))
    if [[ $rc == 0 && -s "$d/out$i/plan.json" ]]; then ok=$((ok + 1)); outcomes+=" job$i:OK@${rel}ms"
    elif [[ $rc == 1 ]]; then cancelled=$((cancelled + 1)); outcomes+=" job$i:CANCELLED@${rel}ms"
    else other=$((other + 1)); outcomes+=" job$i:exit$rc@${rel}ms"; echo "  job $i: $(tail -1 "$d/$i.out" | cut -c1-160)"; fi
  done
  local log_ok log_cancel
  log_ok=$(grep -c 'status=OK' "$d/server.log"); log_cancel=$(grep -c 'status=CANCELLED' "$d/server.log")
  local log_exit_ms
  log_exit_ms=$(python3 - "$d/server.log" <<'PY'
import re, sys, datetime
t = {}
for line in open(sys.argv[1]):
    m = re.match(r"\[(\S+ \S+)\]", line)
    if m and ("received; draining" in line or "vc-server: stopped" in line):
        t["stop" if "stopped" in line else "term"] = datetime.datetime.strptime(m.group(1), "%Y-%m-%d %H:%M:%S.%f")
print(int((t["stop"] - t["term"]).total_seconds() * 1000) if len(t) == 2 else "n/a")
PY
)
  echo "grace ${grace}s: server exit code $srv_rc, SIGTERM to exit ${exit_ms} ms (limit $((grace + slack)) s; its log: draining to stopped ${log_exit_ms} ms)"
  echo "  jobs:$outcomes (times relative to SIGTERM)"
  echo "  finished $ok, cancelled $cancelled, other $other; server log status=OK $log_ok, status=CANCELLED $log_cancel"
  echo "  during the drain: a new submit exited $late_rc after ${late_ms} ms ($(tail -1 "$d/late.out" | cut -c1-120)); health: $(echo "$health" | cut -c1-120)"
  local pass=0
  (( srv_rc == 0 && other == 0 && ok + cancelled == jobs && exit_ms <= (grace + slack) * 1000 )) &&
    { (( must == 0 )) || (( ok == jobs )); } && pass=1
  verdict "sigterm grace=${grace}s" $pass "exit $srv_rc after ${exit_ms} ms, finished $ok, cancelled $cancelled, other $other" || all_pass=0
}

echo "sigterm: $jobs geb079 plans on --workers 1 --queue 2, SIGTERM 2 s after the first"
run_case 2 0
[[ -n "$short_only" ]] || run_case 60 1
verdict sigterm $all_pass
