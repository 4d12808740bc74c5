#!/usr/bin/env bash
# Paired A/B of the visibility sets alone (docs/BENCHMARKS.md, "the paired method"): vc-bench
# --visibility-only with selection test A pinned to CPU 0 and test B to CPU 1 at the same time, then
# swapped; prints each side's seconds, the ratio A/B and each side's check value (visible voxels
# and a hash of the sets), and the geometric mean of the ratios; the same for the CPU seconds of
# each side (on a loaded machine the wall-time ratio drifts towards 1 as other work takes the CPUs;
# the CPU-time ratio does not, docs/BENCHMARKS.md "The paired method").
# Usage: scripts/ab-visibility.sh BUILD SCENE EVERY TEST_A TEST_B [ROUNDS (1)] [BUILD_B (BUILD)]
#   TEST_*: surface, subvoxel, surface-per-voxel or subvoxel-per-voxel (vc-bench --test);
#   SCENE: a synthetic scene (hall, twofloor, ...) or a file; EVERY: every how many candidates.
set -euo pipefail
cd "$(dirname "$0")/.."
build=$1 scene=$2 every=$3 test_a=$4 test_b=$5 rounds=${6:-1} build_b=${7:-$1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ratios=()
cpu_ratios=()
cpu_seconds() { sed -n 's/^visibility sets.*; cpu \([0-9.]*\) s at least.*/\1/p' "$1"; }
seconds() { sed -n 's/^visibility sets.*best \([0-9.]*\) s.*/\1/p' "$1"; }
check() { grep -o '[0-9]* visible, hash [0-9a-f]*' "$1"; }
for r in $(seq 1 "$rounds"); do
  for swap in 0 1; do
    ca=$swap cb=$((1 - swap))
    taskset -c "$ca" "$build/bench/vc-bench" --scene "$scene" --visibility-only --every "$every" --threads 1 \
      --repeat 1 --test "$test_a" >"$work/a" 2>&1 &
    pa=$!
    taskset -c "$cb" "$build_b/bench/vc-bench" --scene "$scene" --visibility-only --every "$every" --threads 1 \
      --repeat 1 --test "$test_b" >"$work/b" 2>&1 &
    pb=$!
    wait "$pa" "$pb"
    ta=$(seconds "$work/a") tb=$(seconds "$work/b")
    ratio=$(python3 -c "print(f'{$ta / $tb:.3f}')")
    ratios+=("$ratio")
    ca_s=$(cpu_seconds "$work/a") cb_s=$(cpu_seconds "$work/b")
    cpu_ratio=$(python3 -c "print(f'{$ca_s / $cb_s:.3f}')")
    cpu_ratios+=("$cpu_ratio")
    echo "$(basename "$scene") round $r  A $test_a on CPU $ca: $ta s, cpu $ca_s s ($(check "$work/a"))   B $test_b on CPU $cb: $tb s, cpu $cb_s s ($(check "$work/b"))   A/B $ratio, cpu $cpu_ratio"
  done
done
gmean() { python3 -c "import math,sys; r=[float(x) for x in sys.argv[2:]]; print(f'geometric mean A/B {sys.argv[1]} over {len(r)} runs: {math.exp(sum(map(math.log,r))/len(r)):.3f}')" "$@"; }
gmean "(wall)" "${ratios[@]}"
gmean "(cpu)" "${cpu_ratios[@]}"
