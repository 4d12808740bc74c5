# Shared helpers of the scripts in scripts/load/ (sourced, not run). They build nothing: BIN is a
# build directory holding BIN/server/vc-server, BIN/client/vc-client and BIN/core/vc-synth. Every server is
# started on 127.0.0.1 with port 0 (a free port) and stopped by the EXIT trap; every wait is bounded.
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../lib/server_port.sh"

LOAD_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
DATA=${VC_DATA:-$LOAD_ROOT/../shared/data}

load_init() {  # load_init BUILD_DIR
  BIN=${1:-$LOAD_ROOT/build/release}
  SERVER="$BIN/server/vc-server"
  CLIENT="$BIN/client/vc-client"
  SYNTH="$BIN/core/vc-synth"
  for b in "$SERVER" "$CLIENT" "$SYNTH"; do
    [[ -x "$b" ]] || { echo "$(basename "$0"): $b not found; build it first (cmake --build --preset release)" >&2; exit 2; }
  done
  WORK=$(mktemp -d /tmp/vc-load.XXXXXX)
  SERVER_PID=""
  CHILD_PIDS=()
  trap load_cleanup EXIT
  trap 'exit 130' INT TERM
}

load_cleanup() {
  local p
  for p in "${CHILD_PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; done
  stop_server_kill
  for p in "${CHILD_PIDS[@]}"; do wait "$p" 2>/dev/null; done
  [[ -n "${KEEP_WORK:-}" ]] && echo "work dir kept: $WORK" || rm -rf "$WORK"
}

now_ms() { echo $(( $(date +%s%N) / 1000000 )); }

# start_server LOG [vc-server flags...]: sets SERVER_PID, PORT, ADDR.
start_server() {
  local log=$1; shift
  vc_launch "$log" "$SERVER" --listen 127.0.0.1:0 "$@"
  SERVER_PID=$vc_pid
  if ! PORT=$(vc_wait_port "$log" "$SERVER_PID"); then
    cat "$log" >&2; echo "$(basename "$0"): vc-server did not start" >&2; exit 1
  fi
  ADDR="127.0.0.1:$PORT"
}

# wait_pid_bounded PID SECONDS: waits for a child; returns its exit code, or 124 after SECONDS.
wait_pid_bounded() {
  local pid=$1 limit_ms=$(( $2 * 1000 )) t0
  t0=$(now_ms)
  while kill -0 "$pid" 2>/dev/null; do
    (( $(now_ms) - t0 > limit_ms )) && return 124
    sleep 0.05
  done
  wait "$pid"
}

# stop_server_kill: SIGTERM, wait at most STOP_LIMIT_S (default 90) seconds, then SIGKILL.
stop_server_kill() {
  [[ -n "${SERVER_PID:-}" ]] || return 0
  if kill -0 "$SERVER_PID" 2>/dev/null; then
    kill -TERM "$SERVER_PID" 2>/dev/null
    if ! wait_pid_bounded "$SERVER_PID" "${STOP_LIMIT_S:-90}"; then
      kill -KILL "$SERVER_PID" 2>/dev/null
    fi
  fi
  wait "$SERVER_PID" 2>/dev/null
  SERVER_PID=""
}

# status_kb PID FIELD (VmRSS, VmHWM): the field of /proc/PID/status in KiB.
status_kb() { awk -v f="$2:" '$1 == f { print $2 }' "/proc/$1/status" 2>/dev/null; }

verdict() {  # verdict NAME OK(0/1) [details]
  if [[ $2 == 1 ]]; then echo "PASS $1${3:+: $3}"; return 0; fi
  echo "FAIL $1${3:+: $3}"; return 1
}
