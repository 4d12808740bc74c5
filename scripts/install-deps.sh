#!/usr/bin/env bash
# Installs every build and test dependency of vc from Debian 12's packages.
# Used by the README commands, .ci/run and the Dockerfile, so a brand-new Debian 12 machine needs nothing else.
# Usage: scripts/install-deps.sh [--runtime | --tests]
#   --runtime: only what the built binaries need to run
#   --tests:   the build packages and what the tests need besides (headless chromium for
#              report_html_browser_test, ezdxf and pyproj for field_exports_test, poppler-utils for
#              field_sheet_test); scripts/test.sh uses it,
#              the demo does not
set -euo pipefail

BUILD_PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libgrpc++-dev libprotobuf-dev protobuf-compiler protobuf-compiler-grpc
  liboctomap-dev libeigen3-dev libspdlog-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev libhwy-dev coinor-libcbc-dev libroaring-dev libproj-dev
  zlib1g-dev libbz2-dev libpng-dev libcairo2-dev libssl-dev libexpat1-dev
  fonts-dejavu-core  # DejaVu Sans, the font of fieldsheet.pdf
  openssl python3 bzip2 gzip
  clang clang-format libfuzzer-14-dev
  libjs-three  # three.js, inlined into report.html at build time
)
TEST_PKGS=(
  chromium  # report_html_browser_test opens report.html in headless chromium
  python3-ezdxf  # field_exports_test reads stations.dxf with a real DXF reader
  python3-pyproj  # field_exports_test checks stations.geojson's coordinates with pyproj
  poppler-utils  # field_sheet_test reads fieldsheet.pdf with pdfinfo and rasterises it with pdftoppm
)
RUNTIME_PKGS=(
  libgrpc++1.51 libgrpc29 libprotobuf32 liboctomap1.9 libspdlog1.10 libfmt9 libhwy1
  coinor-libcbc3 coinor-libcgl1 coinor-libclp1 coinor-libosi1v5 coinor-libcoinutils3v5
  zlib1g libbz2-1.0 libpng16-16 libcairo2 fonts-dejavu-core libexpat1 ca-certificates libroaring0 libproj25
)

pkgs=("${BUILD_PKGS[@]}")
case "${1:-}" in
  --runtime) pkgs=("${RUNTIME_PKGS[@]}") ;;
  --tests) pkgs=("${BUILD_PKGS[@]}" "${TEST_PKGS[@]}") ;;
  "") ;;
  *) echo "install-deps: unknown option $1 (use --runtime or --tests)" >&2; exit 2 ;;
esac

missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#pkgs[@]} packages already installed"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
