# Starting a vc-server on a free loopback port and learning the port (source it; bash).
# Used by scripts/*.sh, scripts/load/lib.sh and tests/client/server_lib.sh, so that the wait is
# written once.
#
#   vc_launch LOG COMMAND [ARGS...]   runs COMMAND in the background with stdout and stderr in LOG,
#                                     which is created first; sets vc_pid to its process id.
#   vc_wait_port LOG [PID]            prints the port the server logged ("listening on … (port N)")
#                                     and returns 0; returns 1 if PID exits first or no port is
#                                     logged within 10 s.
#
# The server is started with --listen 127.0.0.1:0: it picks a free port and logs it. LOG is
# created before the server starts because the wait may read it before the server's own redirect
# has made it (a missing file once ended tests under set -euo pipefail).

vc_launch() {
  local log="$1"
  shift
  : >"$log"
  "$@" >"$log" 2>&1 &
  vc_pid=$!
}

vc_wait_port() {
  local log="$1" pid="${2:-}" port="" _
  for _ in $(seq 1 100); do
    port=$(sed -n 's/.*listening on .* (port \([0-9]*\)).*/\1/p' "$log" 2>/dev/null | head -1)
    if [[ -n "$port" ]]; then
      echo "$port"
      return 0
    fi
    if [[ -n "$pid" ]] && ! kill -0 "$pid" 2>/dev/null; then return 1; fi
    sleep 0.1
  done
  return 1
}
