#!/usr/bin/env bash
# Runs every load script in turn and prints their PASS/FAIL lines; exits 1 when any failed.
# Usage: scripts/load/run-all.sh [--quick] [--build DIR (build/release)]
#   --quick (for CI, a few minutes): overload as is, soak of 200 jobs, sigterm (2 s and 60 s grace),
#   job-memory on geb079 alone at 1 MiB and 4 GiB (no hall). Full: soak of 1000 jobs, job-memory on
#   geb079, the real hall scan and the synthetic hall at 1 MiB, 16 MiB, 512 MiB and 4 GiB.
# The scripts build nothing; build vc-server, vc-client and vc-synth first.
set -uo pipefail
here=$(dirname "$0")
quick="" build=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --quick) quick=1; shift ;;
    --build) build=$2; shift 2 ;;
    *) echo "usage: $0 [--quick] [--build DIR]" >&2; exit 2 ;;
  esac
done
b=(); [[ -n "$build" ]] && b=(--build "$build")
summary=() failed=0
log=$(mktemp /tmp/vc-load-run.XXXXXX)
trap 'rm -f "$log"' EXIT
run() {  # run SCRIPT [ARGS...]
  echo "=== scripts/load/$*"
  local t0 rc line
  t0=$(date +%s)
  bash "$here/$1" "${@:2}" "${b[@]}" 2>&1 | tee "$log"
  rc=$?
  line=$(grep -E '^(PASS|FAIL) [a-z-]+(:|$)' "$log" | tail -1)
  [[ -n "$line" ]] || line="FAIL $1: no verdict (exit $rc)"
  [[ $line == PASS* ]] || failed=1
  summary+=("$line ($(( $(date +%s) - t0 )) s)")
}
if [[ -n "$quick" ]]; then
  run overload.sh
  run soak.sh 200
  run sigterm.sh
  run job-memory.sh --quick --budgets-mib "1 4096"
else
  run overload.sh
  run soak.sh 1000
  run sigterm.sh
  run job-memory.sh
fi
echo "=== summary"
printf '%s\n' "${summary[@]}"
exit $failed
