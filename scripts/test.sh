#!/usr/bin/env bash
# Runs every test: installs dependencies, builds the release and asan+ubsan presets, runs ctest in
# each, and (with --tsan or VC_TSAN=1) the server tests under ThreadSanitizer.
# Usage: scripts/test.sh [--quick]   (--quick: release preset only)
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh

presets=(release asan)
if [[ "${1:-}" == "--quick" ]]; then presets=(release); fi
if [[ "${VC_TSAN:-0}" == "1" || "${1:-}" == "--tsan" ]]; then presets+=(tsan); fi

for p in "${presets[@]}"; do
  echo "=== preset $p: configure and build"
  cmake --preset "$p" >/dev/null
  cmake --build --preset "$p"
  echo "=== preset $p: test"
  if [[ "$p" == tsan ]]; then
    ctest --preset "$p" -L server
  else
    ctest --preset "$p" -j2
  fi
done
echo "=== all tests passed (${presets[*]})"
