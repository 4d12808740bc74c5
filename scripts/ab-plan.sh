#!/usr/bin/env bash
# Paired A/B of the end-to-end plan through the real server and client (docs/BENCHMARKS.md, "the
# paired method"): for each scene, build A's vc-server pinned to CPU 0 and build B's to CPU 1 plan
# the same file at the same time with --threads 1, then the CPUs are swapped; prints each plan's
# total_seconds (plan.json timings_s.total), the stations and G of each side (they must agree),
# and the geometric mean of the ratios A/B over the pairs.
# Usage: scripts/ab-plan.sh BUILD_A BUILD_B [ROUNDS (2)] [FILE...]   (default files: the synthetic
#        hall at 0.05 m and geb079)
# AB_ARGS_A / AB_ARGS_B: extra vc-client submit arguments for side A / B, to compare two settings
# on one build, e.g. AB_ARGS_A="--scanner leica-rtc360" scripts/ab-plan.sh build/release build/release
# (the stations and G then differ by design).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/lib/server_port.sh"
cd "$(dirname "$0")/.."
a=$1 b=$2 rounds=${3:-2}
shift $(( $# >= 3 ? 3 : 2 ))
work=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; rm -rf "$work"; }
trap cleanup EXIT
files=("$@")
if ((${#files[@]} == 0)); then
  "$b/core/vc-synth" hall --spacing 0.05 --out "$work/hall.ply" >/dev/null
  files=("$work/hall.ply" ../shared/data/geb079/geb079.bt)
fi

start_server() {  # start_server BUILD CPU VAR: starts it (in this shell, so pids holds it), VAR=port
  local log="$work/server-$RANDOM.log" port
  vc_launch "$log" taskset -c "$2" "$1/server/vc-server" --listen 127.0.0.1:0 --workers 1 --threads-per-job 1
  pids+=("$vc_pid")
  port=$(vc_wait_port "$log" "$vc_pid") || { cat "$log" >&2; exit 1; }
  printf -v "$3" '%s' "$port"
}

summary() {  # summary plan.json -> "total stations G visibility-stage-seconds"
  python3 -c 'import json,sys; p=json.load(open(sys.argv[1])); t=p["timings_s"]; print(t["total"], len(p["viewpoints"]), p["coverage"]["global_visibility"], t["visibility"])' "$1"
}

gmean() {  # gmean LABEL RATIO...: prints "LABEL: geometric mean"
  python3 -c "import math,sys; r=[float(x) for x in sys.argv[2:]]; print(f'{sys.argv[1]}: {math.exp(sum(map(math.log,r))/len(r)):.3f}')" "$@"
}

for f in "${files[@]}"; do
  ratios=()
  vratios=()
  for r in $(seq 1 "$rounds"); do
    for swap in 0 1; do
      ca=$swap cb=$((1 - swap))
      start_server "$a" "$ca" pa
      start_server "$b" "$cb" pb
      "$a/client/vc-client" submit "$f" --server "127.0.0.1:$pa" --threads 1 ${AB_ARGS_A:-} --out "$work/a" >/dev/null 2>&1 &
      ja=$!
      "$b/client/vc-client" submit "$f" --server "127.0.0.1:$pb" --threads 1 ${AB_ARGS_B:-} --out "$work/b" >/dev/null 2>&1 &
      jb=$!
      wait "$ja" "$jb"
      read -r ta sa ga va < <(summary "$work/a/plan.json")
      read -r tb sb gb vb < <(summary "$work/b/plan.json")
      ratio=$(python3 -c "print(f'{$ta/$tb:.3f}')")
      vratio=$(python3 -c "print(f'{$va/$vb:.3f}')")
      ratios+=("$ratio")
      vratios+=("$vratio")
      printf '%-12s round %d  A on CPU %d: %6.2f s (%s stations, G %.6f, sets %.2f s)   B on CPU %d: %6.2f s (%s stations, G %.6f, sets %.2f s)   A/B %s, sets %s\n' \
        "$(basename "$f")" "$r" "$ca" "$ta" "$sa" "$ga" "$va" "$cb" "$tb" "$sb" "$gb" "$vb" "$ratio" "$vratio"
      for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
      wait 2>/dev/null || true
      pids=()
    done
  done
  gmean "$(printf "%-12s" "$(basename "$f")") geometric mean A/B over ${#ratios[@]} runs" "${ratios[@]}"
  gmean "$(printf "%-12s" "$(basename "$f")") geometric mean A/B of the visibility stage" "${vratios[@]}"
done
