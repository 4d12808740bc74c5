#!/usr/bin/env bash
# Runs every test. Installs the dependencies, checks the layering, the code's health (functions at
# most 150 lines, every path named exists, every public header tested) and the formatting, then:
#   release  - the binaries and the slow tests: the tests of the real binaries (labels smoke and
#              slow: vc-server and vc-client end to end, the paper experiment), the `heavy` ones
#              (CBC against exhaustive search on hundreds of instances, geb079's full plan: 15 times
#              slower under ASan), the `meter` ones (resident memory, which ASan's quarantine hides)
#              and vc-bench --quick (also --visibility-only and a small --bar), vc-route-bench --quick
#   asan     - AddressSanitizer + UndefinedBehaviorSanitizer (clang++): every test except the `slow`
#              and `heavy` labels (every other unit test runs here, once); the same build holds the
#              libFuzzer targets
#   fuzz     - every libFuzzer target (fuzz/, from the asan build) for 10 s each, two at a time
#   tsan     - ThreadSanitizer (clang++) on the tests whose concurrency is all ours (label `tsan`): the worker
#              pool, upload assembler, outbox, job runner, shard board, status mapping, wire code,
#              ParallelChunks and the multi-threaded visibility engine. The gRPC
#              service tests are not run here: Debian's gRPC, absl and protobuf are not instrumented,
#              so tsan cannot see the ordering gRPC provides between its threads (README, Testing).
# Usage: scripts/test.sh [--quick]   (--quick: the release preset only, building and running every
#                                     test, the `slow` ones included)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --tests

presets=(release asan tsan fuzz)
if [[ "${1:-}" == "--quick" ]]; then presets=(release); fi

start=$(date +%s)
echo "=== layering (scripts/check-layers.py), code health (scripts/check-code-health.py) and formatting"
python3 scripts/check-layers.py
python3 scripts/check_code_health_test.py
python3 scripts/fan_out_projection_test.py
python3 scripts/cpu_use_test.py
python3 scripts/check-code-health.py
git ls-files '*.h' '*.cc' | xargs clang-format --dry-run --Werror
echo "clang-format: every tracked .h/.cc file is formatted"
for p in "${presets[@]}"; do
  echo "=== preset $p: configure and build"
  [[ "$p" == fuzz ]] || cmake --preset "$p" >/dev/null
  case "$p" in
    tsan)
      # Only the service and its tests: the core is covered by the other presets.
      cmake --build --preset "$p" --target base_tests server_jobs_tests proto_tests visibility_tests
      echo "=== preset $p: tests labelled tsan"
      ctest --preset "$p" -j2 -L tsan
      ;;
    fuzz)
      # Every libFuzzer target for 10 s from its seeds, built by the asan stage (scripts/fuzz.sh;
      # long runs: docs/RELIABILITY.md).
      bash scripts/fuzz.sh --preset asan --seconds 10 --jobs 2
      ;;
    asan)
      cmake --build --preset "$p"
      echo "=== preset $p: tests (except labels slow and heavy)"
      ctest --preset "$p" -j2 -LE 'slow|heavy'
      ;;
    release)
      if ((${#presets[@]} > 1)); then
        # The unit tests run once, under asan (below). The release build makes what only it can
        # test: the shipped binaries end to end (labels smoke and slow), the slow experiments, the
        # heavy solver tests (tests/core/CMakeLists.txt, plan_search_tests), the memory meter's tests
        # (meter_tests: they skip under ASan) and the benchmarks.
        cmake --build --preset "$p" --target vc-server vc-client vc-synth vc-bench vc-route-bench paper_result_test plan_search_tests meter_tests
        echo "=== preset $p: the tests of the binaries, the slow, heavy and meter ones (labels smoke, slow, heavy, meter)"
        ctest --preset "$p" -j2 -L 'smoke|slow|heavy|meter'
      else
        cmake --build --preset "$p"
        echo "=== preset $p: tests"
        ctest --preset "$p" -j2
      fi
      echo "=== preset $p: vc-bench --quick, --visibility-only and a small --bar (figures only, no timing assertions)"
      "build/$p/bench/vc-bench" --quick
      "build/$p/bench/vc-bench" --quick --visibility-only --repeat 1
      "build/$p/bench/vc-bench" --bar --scene rooms:3 --spacing 0.05 --bar-rays 2000
      "build/$p/bench/vc-route-bench" --quick
      ;;
  esac
  echo "=== preset $p done after $(( $(date +%s) - start )) s"
done
echo "=== all tests passed (${presets[*]}) in $(( $(date +%s) - start )) s"
