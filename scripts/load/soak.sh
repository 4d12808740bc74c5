#!/usr/bin/env bash
# Soak: N small jobs in a row (default 1000) through one vc-server (--workers 1); samples the
# server's VmRSS and VmHWM (/proc/PID/status) after a warm-up of 50 jobs, every 50 jobs after it and
# at the end. PASS when every job succeeds and the peak RSS (VmHWM) grew by less than 5 % after the
# warm-up. Prints jobs/s (each job is a new vc-client process, so that is included).
# Usage: scripts/load/soak.sh [N (1000)] [--build DIR (build/release)] [--rpc plan|evaluate (plan)]
#   plan:     vc-client submit box.ply (vc-synth box --spacing 0.1) --resolution 0.2 --grid-spacing 1.5
#   evaluate: vc-client evaluate of the same scene at the stations of one plan (lighter)
source "$(dirname "$0")/lib.sh"
n=1000 build="" rpc=plan warmup=50 every=50 limit_s=1800
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --rpc) rpc=$2; shift 2 ;;
    [0-9]*) n=$1; shift ;;
    *) echo "usage: $0 [N] [--build DIR] [--rpc plan|evaluate]" >&2; exit 2 ;;
  esac
done
(( n > warmup )) || { echo "soak: N must exceed the warm-up of $warmup jobs" >&2; exit 2; }
load_init "$build"
"$SYNTH" box --spacing 0.1 --out "$WORK/box.ply" >/dev/null || exit 1
start_server "$WORK/server.log" --workers 1 --queue 2
flags=(--resolution 0.2 --grid-spacing 1.5)
"$CLIENT" submit "$WORK/box.ply" --server "$ADDR" "${flags[@]}" --out "$WORK/first" >/dev/null 2>&1 ||
  { echo "soak: the first plan failed" >&2; exit 1; }
job() {
  if [[ $rpc == plan ]]; then
    timeout 60 "$CLIENT" submit "$WORK/box.ply" --server "$ADDR" "${flags[@]}" --out "$WORK/out" >"$WORK/last.out" 2>&1
  else
    timeout 60 "$CLIENT" evaluate "$WORK/box.ply" --server "$ADDR" --resolution 0.2 \
      --viewpoints "$WORK/first/stations.csv" --out "$WORK/out" >"$WORK/last.out" 2>&1
  fi
}
idle_rss=$(status_kb "$SERVER_PID" VmRSS)
echo "soak: $n $rpc jobs in a row against $ADDR (--workers 1); idle VmRSS ${idle_rss} KiB"
failed=0 warm_rss=0 warm_hwm=0 max_rss=0 t0=$(now_ms) t_warm=0 done_n=0
for i in $(seq 1 "$n"); do
  if ! job; then
    failed=$((failed + 1)); echo "  job $i failed: $(tail -1 "$WORK/last.out")"
    (( failed >= 10 )) && { echo "  stopping after 10 failures"; break; }
  fi
  done_n=$i
  if (( i == warmup )); then
    warm_rss=$(status_kb "$SERVER_PID" VmRSS); warm_hwm=$(status_kb "$SERVER_PID" VmHWM); t_warm=$(now_ms)
    max_rss=$warm_rss
    echo "  after $i (warm-up): VmRSS $warm_rss KiB, VmHWM $warm_hwm KiB"
  elif (( i > warmup && (i % every == 0 || i == n) )); then
    rss=$(status_kb "$SERVER_PID" VmRSS); hwm=$(status_kb "$SERVER_PID" VmHWM)
    (( rss > max_rss )) && max_rss=$rss
    (( i % (every * 4) == 0 || i == n )) && echo "  after $i: VmRSS $rss KiB, VmHWM $hwm KiB"
  fi
  (( $(now_ms) - t0 > limit_s * 1000 )) && { echo "  time limit ${limit_s}s reached after $i jobs"; break; }
done
t_end=$(now_ms)
end_rss=$(status_kb "$SERVER_PID" VmRSS); end_hwm=$(status_kb "$SERVER_PID" VmHWM)
log_ok=$(grep -c 'status=OK' "$WORK/server.log")
stop_server_kill
rate=$(awk -v n="$done_n" -v ms=$((t_end - t0)) 'BEGIN { printf "%.1f", n * 1000 / ms }')
rate_warm=$(awk -v n=$((done_n - warmup)) -v ms=$((t_end - t_warm)) 'BEGIN { if (ms > 0) printf "%.1f", n * 1000 / ms; else print "n/a" }')
hwm_growth=$(awk -v a="$warm_hwm" -v b="$end_hwm" 'BEGIN { if (a > 0) printf "%.2f", (b - a) * 100 / a; else print 999 }')
rss_growth=$(awk -v a="$warm_rss" -v b="$max_rss" 'BEGIN { if (a > 0) printf "%.2f", (b - a) * 100 / a; else print 999 }')
echo "jobs:               $done_n of $n, failed $failed, server log status=OK $log_ok (incl. the first plan)"
echo "throughput:         $rate jobs/s overall, $rate_warm jobs/s after the warm-up ($(( (t_end - t0) / 1000 )) s)"
echo "VmRSS:              idle $idle_rss KiB, after warm-up $warm_rss KiB, highest sample $max_rss KiB (+$rss_growth %), end $end_rss KiB"
echo "VmHWM:              after warm-up $warm_hwm KiB, end $end_hwm KiB (+$hwm_growth %)"
pass=0
(( failed == 0 && done_n == n && log_ok == n + 1 )) && awk -v g="$hwm_growth" 'BEGIN { exit !(g < 5) }' && pass=1
verdict soak $pass "$done_n $rpc jobs, $failed failed, $rate jobs/s, peak RSS growth after warm-up $hwm_growth % (limit 5 %)"
