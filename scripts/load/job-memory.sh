#!/usr/bin/env bash
# A job's peak memory against its budget: for each scene and each --memory-budget-bytes, starts a
# fresh vc-server (--workers 1), records its idle VmRSS (after one health call), plans the scene with
# that budget and records the server's VmHWM; the job's peak is VmHWM - idle. A job must either
# finish with peak <= budget + CONSTANT, or be refused with RESOURCE_EXHAUSTED (exit 8) with the
# same bound; any other outcome fails. Prints, per run, the peak, the budget and peak - budget, and
# the largest peak - budget seen (the constant to document).
# Usage: scripts/load/job-memory.sh [--build DIR (build/release)] [--quick] [--constant-mib C (128)]
#                                   [--budgets-mib "1 16 512 4096"]
#   scenes: geb079.bt; the real hall scan (scan.dat.bz2) and vc-synth hall --spacing 0.05 (1.7 M
#   points), both skipped by --quick. Budgets: 1 MiB, 16 MiB, 512 MiB, 4 GiB.
source "$(dirname "$0")/lib.sh"
build="" quick="" constant_mib=128 budgets_mib="1 16 512 4096"
while [[ $# -gt 0 ]]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --quick) quick=1; shift ;;
    --constant-mib) constant_mib=$2; shift 2 ;;
    --budgets-mib) budgets_mib=$2; shift 2 ;;
    *) echo "usage: $0 [--build DIR] [--quick] [--constant-mib C] [--budgets-mib LIST]" >&2; exit 2 ;;
  esac
done
load_init "$build"
mib=$((1 << 20))
budgets=()
for b in $budgets_mib; do budgets+=($((b * mib))); done
scenes=("$DATA/geb079/geb079.bt")
if [[ -z "$quick" ]]; then
  scenes+=("$DATA/hall-scan/scan.dat.bz2")
  "$SYNTH" hall --spacing 0.05 --out "$WORK/hall-synth.ply" >/dev/null || exit 1
  scenes+=("$WORK/hall-synth.ply")
fi
for s in "${scenes[@]}"; do [[ -f "$s" ]] || { echo "job-memory: no scene $s" >&2; exit 2; }; done

printf '%-16s %10s %8s %10s %10s %12s %11s %8s\n' scene budget_MiB outcome idle_MiB hwm_MiB job_peak_MiB peak-budget time_s
all_pass=1 worst=-999999 k=0
for s in "${scenes[@]}"; do
  for b in "${budgets[@]}"; do
    k=$((k + 1))
    start_server "$WORK/server$k.log" --workers 1 --queue 1
    timeout 20 "$CLIENT" health --server "$ADDR" >/dev/null 2>&1
    idle=$(status_kb "$SERVER_PID" VmRSS)
    t0=$(now_ms)
    timeout 600 "$CLIENT" submit "$s" --server "$ADDR" --memory-budget-bytes "$b" --out "$WORK/out$k" >"$WORK/c$k.out" 2>&1
    rc=$?
    t=$(( $(now_ms) - t0 ))
    hwm=$(status_kb "$SERVER_PID" VmHWM)
    stop_server_kill
    case $rc in 0) outcome=OK ;; 8) outcome=REFUSED ;; *) outcome="exit$rc" ;; esac
    read -r peak over < <(awk -v h="$hwm" -v i="$idle" -v b="$b" 'BEGIN { p = (h - i) / 1024; printf "%.1f %.1f\n", p, p - b / 1048576 }')
    printf '%-16s %10d %8s %10.1f %10.1f %12s %11s %8.1f\n' "$(basename "$s")" $((b / mib)) "$outcome" \
      "$(awk -v x="$idle" 'BEGIN{print x/1024}')" "$(awk -v x="$hwm" 'BEGIN{print x/1024}')" "$peak" "$over" \
      "$(awk -v x="$t" 'BEGIN{print x/1000}')"
    [[ $rc == 0 || $rc == 8 ]] || { all_pass=0; echo "  $(tail -1 "$WORK/c$k.out" | cut -c1-200)"; }
    [[ $rc == 8 ]] && echo "  refused: $(grep -o 'failed (8).*' "$WORK/c$k.out" | cut -c1-200)"
    awk -v o="$over" -v c="$constant_mib" 'BEGIN { exit !(o > c) }' && all_pass=0
    worst=$(awk -v o="$over" -v w="$worst" 'BEGIN { print (o > w ? o : w) }')
  done
done
echo "largest job peak - budget: $worst MiB (allowed constant $constant_mib MiB)"
verdict job-memory $all_pass "largest peak over budget $worst MiB, constant $constant_mib MiB"
