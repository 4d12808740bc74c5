#!/usr/bin/env bash
# Proves the Dockerfile for real with podman/buildah (no Docker engine needed; see
# /work/shared/CONTAINERS.md): makes a Debian 12 base image with debootstrap, builds the image from
# a clean export of HEAD, runs vc-server inside it and checks that it answers the gRPC health
# service from outside. Takes several minutes; not part of the default test run.
# Usage (as root): scripts/container-test.sh [--keep]
set -euo pipefail
cd "$(dirname "$0")/.."
keep=0; [[ "${1:-}" == "--keep" ]] && keep=1

apt-get install -y -qq podman buildah debootstrap >/dev/null

base=localhost/debian:bookworm
if ! podman image exists "$base"; then
  # The Debian mirror apt uses: URIs: lines of *.sources, deb lines of *.list (either may be absent).
  mirror=$( { grep -hE '^URIs:' /etc/apt/sources.list.d/*.sources 2>/dev/null | awk '{print $2}';
              grep -hE '^deb ' /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null | awk '{print $2}'; } \
            | grep -v security | head -1 || true)
  mirror=${mirror:-http://deb.debian.org/debian}
  rootfs=$(mktemp -d)
  echo "container-test: debootstrap bookworm from $mirror"
  debootstrap --variant=minbase bookworm "$rootfs" "$mirror" >/dev/null
  tar -C "$rootfs" -c . | podman import - "$base" >/dev/null
  rm -rf "$rootfs"
fi

# A clean build context: the committed tree only (no build/ directories).
ctx=$(mktemp -d)
git archive HEAD | tar -x -C "$ctx"
echo "container-test: building vc:dev"
podman build --isolation chroot --network host --build-arg BASE="$base" -t vc:dev "$ctx"
rm -rf "$ctx"

port=$((20000 + RANDOM % 20000))
c=$(buildah from localhost/vc:dev)
cleanup() {
  [[ -n "${pid:-}" ]] && kill "$pid" 2>/dev/null || true
  wait 2>/dev/null || true
  buildah rm "$c" >/dev/null 2>&1 || true
  if [[ $keep -eq 0 ]]; then podman rmi vc:dev >/dev/null 2>&1 || true; fi
}
trap cleanup EXIT
buildah run --isolation chroot --network host "$c" -- vc-server --listen "127.0.0.1:$port" &
pid=$!

client=build/release/client/vc-client
[[ -x "$client" ]] || client=build/svc/client/vc-client
ok=0
for _ in $(seq 1 60); do
  if "$client" health --server "127.0.0.1:$port" --retries 1 --timeout 2 >/dev/null 2>&1; then ok=1; break; fi
  sleep 1
done
[[ $ok -eq 1 ]] || { echo "container-test: FAIL: the server in the image never answered health" >&2; exit 1; }
# The image's own client works too (what HEALTHCHECK runs).
buildah run --isolation chroot --network host "$c" -- vc-client health --server "127.0.0.1:$port" | grep -qx SERVING
echo "container-test: OK (vc-server in vc:dev answers SERVING)"
