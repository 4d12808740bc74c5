#!/usr/bin/env bash
# Overload: N concurrent `vc-client submit` (default 30) against a server with --workers 1
# --queue 2, i.e. 10x its capacity. Expects: the excess gets RESOURCE_EXHAUSTED (vc-client exit
# code 8) at once; `vc-client health` answers SERVING throughout (polled during the storm); every
# accepted job finishes with a result (exit 0, plan.json written, one `status=OK` line in the
# server log per accepted job); no other outcome.
# Usage: scripts/load/overload.sh [--build DIR (build/release)] [--clients N (30)] [--scene FILE]
#   The default scene is geb079 (about 7 s a plan on 2 cores), so the accepted jobs overlap the storm.
source "$(dirname "$0")/lib.sh"
probe_ms=()
build="" n=30 scene="" workers=1 queue=2 limit_s=300
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --clients) n=$2; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--clients N] [--scene FILE]" >&2; exit 2 ;;
  esac
done
load_init "$build"
scene=${scene:-$DATA/geb079/geb079.bt}
[[ -f "$scene" ]] || { echo "overload: no scene $scene" >&2; exit 2; }

start_server "$WORK/server.log" --workers "$workers" --queue "$queue"
echo "overload: $n concurrent submits of $(basename "$scene") to $ADDR (--workers $workers --queue $queue)"

mkdir -p "$WORK/c"
t_start=$(now_ms)
for i in $(seq 1 "$n"); do
  (
    t0=$(now_ms)
    "$CLIENT" submit "$scene" --server "$ADDR" --out "$WORK/c/out$i" >"$WORK/c/$i.out" 2>&1
    rc=$?
    echo "$rc $(( $(now_ms) - t0 ))" >"$WORK/c/$i.rc"
  ) &
  CHILD_PIDS+=($!)
done

# Poll health during the storm, in the background (bounded in count and time) until told to stop.
(
  k=0
  while (( k < 5000 )) && (( $(now_ms) < t_start + limit_s * 1000 )) && [[ ! -e "$WORK/stop-health" ]]; do
    t0=$(now_ms)
    h=$(timeout 10 "$CLIENT" health --server "$ADDR" 2>&1)
    echo "$? $(( $(now_ms) - t0 )) ${h//[$'\n ']/_}" >>"$WORK/health.txt"
    k=$((k + 1))
    sleep 0.2
  done
) &
health_pid=$!
CHILD_PIDS+=($health_pid)

# Refusal time without the storm's process-start contention: once the storm's refusals are in
# (all but `capacity` clients have ended), PROBES sequential submits while the accepted jobs run.
probes=5
t_wait=$(now_ms)
while (( $(ls "$WORK/c" | grep -c '\.rc$') < n - workers - queue )) && (( $(now_ms) - t_wait < 60000 )); do sleep 0.1; done
for k in $(seq 1 "$probes"); do
  i=$((n + k))
  t0=$(now_ms)
  timeout 120 "$CLIENT" submit "$scene" --server "$ADDR" --out "$WORK/c/out$i" >"$WORK/c/$i.out" 2>&1
  rc=$?
  echo "$rc $(( $(now_ms) - t0 ))" >"$WORK/c/$i.rc"
  probe_ms+=("$rc:$(( $(now_ms) - t0 ))")
done
n_storm=$n
n=$((n + probes))

t_wait=$(now_ms)
while (( $(ls "$WORK/c" | grep -c '\.rc$') < n )) && (( $(now_ms) - t_wait < limit_s * 1000 )); do sleep 0.2; done
touch "$WORK/stop-health"
for p in "${CHILD_PIDS[@]}"; do wait_pid_bounded "$p" 10 || kill -TERM "$p" 2>/dev/null; done
t_total=$(( $(now_ms) - t_start ))

probe_rej=() probe_ms_list=""
for x in "${probe_ms[@]}"; do [[ ${x%%:*} == 8 ]] && probe_rej+=("${x#*:}"); probe_ms_list+="${x#*:} "; done
health_n=$(wc -l <"$WORK/health.txt")
health_bad=$(awk '$1 != 0 || $3 != "SERVING"' "$WORK/health.txt" | wc -l)
health_max_ms=$(awk '$2 > m { m = $2 } END { print m + 0 }' "$WORK/health.txt")
health_med_ms=$(awk '{ print $2 }' "$WORK/health.txt" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)] + 0}')
awk '$1 != 0 || $3 != "SERVING" { print "  health poll failed: " $0 }' "$WORK/health.txt" | head -5
ok=0 exhausted=0 other=0 lost=0 rej_ms=() ok_ms=()
for i in $(seq 1 "$n"); do
  if [[ ! -f "$WORK/c/$i.rc" ]]; then other=$((other + 1)); echo "  client $i: did not end"; continue; fi
  read -r rc ms <"$WORK/c/$i.rc"
  case $rc in
    0) ok=$((ok + 1)); ok_ms+=("$ms")
       [[ -s "$WORK/c/out$i/plan.json" ]] || { lost=$((lost + 1)); echo "  client $i: exit 0 but no plan.json"; } ;;
    8) exhausted=$((exhausted + 1)); rej_ms+=("$ms") ;;
    *) other=$((other + 1)); echo "  client $i: exit $rc: $(tail -1 "$WORK/c/$i.out")" ;;
  esac
done
log_ok=$(grep -c 'status=OK' "$WORK/server.log")
log_rejected=$(grep -c 'rejected status=8:' "$WORK/server.log")
stats() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {if (NR) printf "min %d / median %d / max %d ms", a[1], a[int((NR+1)/2)], a[NR]; else printf "none"}'; }
retry=$(grep -h -o 'retry[^ ]*' "$WORK"/c/*.out 2>/dev/null | sort | uniq -c | head -3 | tr -s ' ' | tr '\n' ';')

echo "clients:            $n_storm at once + $probes sequential probes (capacity workers+queue = $((workers + queue)))"
echo "accepted (exit 0):  $ok, each with plan.json: $((ok - lost)); server log status=OK: $log_ok"
echo "RESOURCE_EXHAUSTED: $exhausted (exit 8), server log rejected: $log_rejected; time to refusal in the storm (includes starting $n_storm vc-client processes at once): $(stats "${rej_ms[@]}")"
echo "probe refusals:     $(stats "${probe_rej[@]}") (${#probe_rej[@]} of $probes probes refused, each a new vc-client process)"
echo "accepted job times: $(stats "${ok_ms[@]}")"
echo "other outcomes:     $other"
echo "health polls:       $health_n during the storm, failed $health_bad, median ${health_med_ms} ms, slowest ${health_max_ms} ms"
echo "storm wall time:    ${t_total} ms${retry:+; client messages: $retry}"
rej_max=$(printf '%s\n' "${probe_rej[@]:-99999}" | sort -n | tail -1)
pass=0
(( ok >= 1 && ok + exhausted == n && other == 0 && lost == 0 && log_ok == ok && health_bad == 0 \
   && health_n >= 1 && exhausted >= 1 && rej_max < 2000 )) && pass=1
verdict overload $pass "accepted $ok, refused $exhausted (slowest probe refusal ${rej_max} ms), lost $lost, other $other, health failures $health_bad/$health_n"
