#!/usr/bin/env bash
# Issue 37's measurement, in one command (docs/BENCHMARKS.md, "A 3 m coarse grid, measured and not
# kept", and the sections after it): one whole plan of a campus map through a fresh vc-server with
# one worker and the defaults, as a crew's laptop would submit it, on whatever cores this machine
# has. Prints the plan's stages (plan.json timings_s), the job's total and the client's wall time
# against the issue's target (fr_campus 300 s, new_college 150 s; ratio > 1: slower than it), the
# server's peak resident memory (VmHWM) against the default 4 GiB job budget plus the process's own
# 0.5 GiB, and the plan (stations, covered voxels, G). For fr_campus with the defaults it also
# compares the plan with the one recorded at 2026-12-07 (905 stations, 861,374 voxels, G
# 0.555908754262561): a change there must be meant and explained (issue 37: "plans no worse").
# Last, how busy the server kept the cores, stage by stage, and the job's time were every core busy
# all along (scripts/cpu-use.py over the server's CPU time sampled every half second).
# Takes 5-7 minutes for fr_campus on 2 cores; run it on an otherwise idle machine.
#
# Usage: scripts/campus-bench.sh [BUILD_DIR (build/release)] [SCENE (../shared/data/fr-campus/fr_campus.bt)]
#          [-- vc-client submit FLAGS...]
# Environment: TARGET_S overrides the target (seconds); KEEP=DIR keeps the server log and the
# plan's files there instead of a temporary folder.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/server_port.sh"
cd "$(dirname "$0")/.."
bin=${1:-build/release}
scene=${2:-../shared/data/fr-campus/fr_campus.bt}
shift $(($# < 2 ? $# : 2))
[[ "${1:-}" == "--" ]] && shift
extra=("$@")
for tool in "$bin/server/vc-server" "$bin/client/vc-client"; do
  [[ -x "$tool" ]] || { echo "campus-bench: $tool is missing: build it first (cmake --build --preset release)" >&2; exit 2; }
done
[[ -r "$scene" ]] || { echo "campus-bench: cannot read the scene '$scene' (../shared/data/README.md lists the maps)" >&2; exit 2; }

name=$(basename "$scene")
case "$name" in
  fr_campus*) target=300 ;;
  new_college*) target=150 ;;
  *) target=0 ;;
esac
target=${TARGET_S:-$target}

if [[ -n "${KEEP:-}" ]]; then
  mkdir -p "$KEEP"
  work=$(cd "$KEEP" && pwd)
else
  work=$(mktemp -d)
fi
server_pid=""
sampler_pid=""
cleanup() {
  [[ -n "$sampler_pid" ]] && kill "$sampler_pid" 2>/dev/null && wait "$sampler_pid" 2>/dev/null
  [[ -n "$server_pid" ]] && kill "$server_pid" 2>/dev/null && wait "$server_pid" 2>/dev/null
  [[ -z "${KEEP:-}" ]] && rm -rf "$work"
  return 0
}
trap cleanup EXIT

vc_launch "$work/server.log" "$bin/server/vc-server" --listen 127.0.0.1:0 --workers 1
server_pid=$vc_pid
port=$(vc_wait_port "$work/server.log" "$server_pid") || { cat "$work/server.log" >&2; exit 1; }
echo "campus-bench: $scene through $bin (one worker, $(nproc) cores; load average $(cut -d' ' -f1-3 /proc/loadavg))"
# The server's CPU time every half second (epoch seconds, utime + stime in clock ticks: fields 14 and
# 15 of /proc/PID/stat) for scripts/cpu-use.py.
sample_cpu() {
  local f
  while read -r -a f <"/proc/$server_pid/stat" 2>/dev/null; do
    echo "$(date +%s.%N) $((f[13] + f[14]))"
    sleep 0.5
  done
}
sample_cpu >"$work/cpu.txt" &
sampler_pid=$!
start=$(date +%s.%N)
if ! "$bin/client/vc-client" submit "$scene" --server "127.0.0.1:$port" --out "$work/plan" "${extra[@]}" \
  >"$work/client.log" 2>&1; then
  tail -20 "$work/client.log" >&2
  if [[ -n "${KEEP:-}" ]]; then
    echo "campus-bench: the plan failed (the client's log above; the server's: $work/server.log)" >&2
  else
    echo "campus-bench: the plan failed (the client's log above; KEEP=DIR keeps the server's log)" >&2
  fi
  exit 1
fi
wall=$(python3 -c "import sys; print(f'{float(sys.argv[2]) - float(sys.argv[1]):.1f}')" "$start" "$(date +%s.%N)")
hwm_kb=$(awk '/^VmHWM:/ {print $2}' "/proc/$server_pid/status")
sleep 0.6  # one more sample after the job's end
kill "$sampler_pid" 2>/dev/null
wait "$sampler_pid" 2>/dev/null || true  # the sampler's status is the kill's
sampler_pid=""

python3 - "$work/plan/plan.json" "$wall" "$hwm_kb" "$target" "$name" "${#extra[@]}" <<'EOF'
import json, sys
plan_path, wall, hwm_kb, target, name, extra = sys.argv[1], float(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5], int(sys.argv[6])
p = json.load(open(plan_path))
t = p["timings_s"]
stages = ["voxelize", "candidates", "visibility", "selection", "reduction", "evaluation", "route"]
print("stages (s):  " + "  ".join(f"{s} {t[s]:.1f}" for s in stages if s in t))
print(f"job total    {t['total']:.1f} s   client wall {wall:.1f} s", end="")
if target > 0:
    print(f"   target {target:.0f} s: wall / target = {wall / target:.2f}" + ("  (met)" if wall <= target else "  (not met)"))
else:
    print()
budget_kb = (4 << 20) + (512 << 10)
print(f"server peak  VmHWM {hwm_kb / 1024:.0f} MiB against 4 GiB + 0.5 GiB = {budget_kb / 1024:.0f} MiB"
      + ("  (within)" if hwm_kb <= budget_kb else "  (over)"))
c = p["coverage"]
stations = len(p["viewpoints"])
print(f"plan         {stations} stations, {c['covered_voxels']:,} of {c['coverable_voxels']:,} coverable voxels "
      f"({c['covered_fraction_of_occupied'] * 100:.2f} % of {c['occupied_voxels']:,}), G {c['global_visibility']:.15g}")
if name == "fr_campus.bt" and extra == 0:
    ref = (905, 861374, 0.555908754262561)
    recorded = f"{ref[0]} stations, {ref[1]:,} voxels, G {ref[2]!r}"
    if (stations, c["covered_voxels"], c["global_visibility"]) == ref:
        print(f"reference    the same plan as recorded on 2026-12-07 ({recorded})")
    else:
        print(f"reference    DIFFERENT from 2026-12-07's plan: {recorded}; explain the change (issue 37: plans no worse)")
EOF
python3 scripts/cpu-use.py "$work/server.log" "$work/cpu.txt" ||
  echo "campus-bench: no figures of the cores' use (scripts/cpu-use.py says why above)"
[[ -n "${KEEP:-}" ]] && echo "campus-bench: the plan and the logs are in $work"
exit 0
