#!/usr/bin/env bash
# Builds the libFuzzer targets (the `fuzz` preset: clang++, ASan + UBSan, no tests; or the `asan`
# preset, which builds the same targets beside its tests) and runs them, --jobs targets at a time
# (default: one per core; each target is one process), from the checked-in seeds plus slices of
# ../shared/data.
# Usage: scripts/fuzz.sh [--seconds N] [--only TARGET] [--preset fuzz|asan] [--jobs N]
#        (default 180 s per target and the fuzz preset; CI: --seconds 10 --preset asan, whose build
#        scripts/test.sh has just made, so the core is not compiled a third time)
# Findings (crash-*, leak-*, timeout-*, oom-*) land in build/<preset>/findings/<target>/; the script
# exits non-zero if any target found one. Turn each into a regression test (docs/RELIABILITY.md).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=180
only=""
preset=fuzz
jobs=$(nproc)
while (($#)); do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --only) only="$2"; shift 2 ;;
    --preset) preset="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2 ;;
    *) echo "usage: scripts/fuzz.sh [--seconds N] [--only TARGET] [--preset fuzz|asan] [--jobs N]" >&2; exit 2 ;;
  esac
done

targets=(read_scene_fuzzer ply_fuzzer pcd_fuzzer xyz_fuzzer las_fuzzer e57_fuzzer octomap_bt_fuzzer
         octomap_ot_fuzzer octomap_graph_fuzzer gzip_fuzzer bzip2_fuzzer lzf_fuzzer stations_csv_fuzzer
         keep_out_csv_fuzzer upload_assembler_fuzzer)
if [[ -n "$only" ]]; then targets=("$only"); fi

case "$preset" in
  fuzz | asan) ;;
  *) echo "scripts/fuzz.sh: --preset must be fuzz or asan (the presets that build the fuzzers)" >&2; exit 2 ;;
esac
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" --target "${targets[@]}"

build="build/$preset"
data=../shared/data
work="$build/corpus"
mkdir -p "$work"
# Slices of the real data: the first KiB of each file (headers and the first records), and a
# compressed slice of the hall scan for the decompressors.
slices="$build/slices"
mkdir -p "$slices"
if [[ -d "$data" ]]; then
  head -c 4096 "$data/geb079/geb079.bt" >"$slices/geb079-head.bt" || true
  for f in "$data"/room-2scans/*.pcd; do head -c 4096 "$f" >"$slices/$(basename "$f" .pcd)-head.pcd"; done
  bzcat "$data/hall-scan/scan.dat.bz2" | head -c 4096 >"$slices/hall-head.xyz" || true
  gzip -9 -c "$slices/hall-head.xyz" >"$slices/hall-head.xyz.gz"
  bzip2 -9 -c "$slices/hall-head.xyz" >"$slices/hall-head.xyz.bz2"
fi
slice_for() {  # the slices that suit a target
  case "$1" in
    read_scene_fuzzer) ls "$slices"/* ;;
    pcd_fuzzer) ls "$slices"/*.pcd ;;
    xyz_fuzzer) ls "$slices"/*.xyz ;;
    octomap_bt_fuzzer) ls "$slices"/*.bt ;;
    gzip_fuzzer) ls "$slices"/*.gz ;;
    bzip2_fuzzer) ls "$slices"/*.bz2 ;;
  esac 2>/dev/null || true
}

# fuzz_one TARGET: runs one target; its summary goes to $build/TARGET.summary, and it exits
# non-zero on a finding.
fuzz_one() {
  local t="$1" corpus="$work/$1" findings="$build/findings/$1" rc=0
  mkdir -p "$corpus" "$findings"
  cp -n fuzz/corpus/"$t"/* "$corpus"/ 2>/dev/null || true
  for s in $(slice_for "$t"); do cp -n "$s" "$corpus"/; done
  # -malloc_limit_mb: the targets read with 1 MiB decompressed / 32 MiB result limits
  # (fuzz/fuzz_options.h); any single allocation above 256 MiB is a missing bound.
  "$build/fuzz/$t" "$corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -malloc_limit_mb=256 -max_len=65536 -artifact_prefix="$findings/" -print_final_stats=1 \
    2>"$build/$t.log" || rc=1
  {
    echo "== $t: ${seconds}s"
    if ((rc)); then echo "   FOUND: $(ls "$findings")"; fi
    grep -E "^stat::number_of_executed_units|^#[0-9]+.*DONE" "$build/$t.log" | tail -2 | sed 's/^/   /'
  } >"$build/$t.summary"
  return "$rc"
}

# Up to $jobs targets at once; each summary is printed when its target ends.
failed=0
running=()
finish_one() {  # waits for the oldest running target and prints its summary
  local pid="${running[0]%%:*}" t="${running[0]#*:}"
  wait "$pid" || failed=1
  cat "$build/$t.summary"
  running=("${running[@]:1}")
}
for t in "${targets[@]}"; do
  while ((${#running[@]} >= jobs)); do finish_one; done
  fuzz_one "$t" &
  running+=("$!:$t")
done
while ((${#running[@]})); do finish_one; done
exit "$failed"
