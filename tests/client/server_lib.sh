# Shared by the scripts that test the real binaries (source it): a temporary directory, a vc-server
# on a free loopback port, cleanup on exit, and `fail`.
# After `start_server SERVER_BIN [flags...]`: $work, $server_pid, $addr (127.0.0.1:port);
# the server's log is $work/server.log. `stop_server` sends SIGTERM and checks it exits 0.
source "$(dirname "${BASH_SOURCE[0]}")/../../scripts/lib/server_port.sh"
work=$(mktemp -d)
server_pid=""
cleanup() {
  if [[ -n "$server_pid" ]]; then kill "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "${test_name:-test}: FAIL: $*" >&2; [[ -f "$work/server.log" ]] && tail -20 "$work/server.log" >&2; exit 1; }

start_server() {
  local bin="$1"
  shift
  # Port 0: the server picks a free port and logs it.
  vc_launch "$work/server.log" "$bin" --listen 127.0.0.1:0 "$@"
  server_pid=$vc_pid
  local port
  port=$(vc_wait_port "$work/server.log" "$server_pid") || fail "vc-server exited or did not report its port"
  addr="127.0.0.1:$port"
}

stop_server() {
  kill -TERM "$server_pid"
  local rc=0
  wait "$server_pid" || rc=$?
  server_pid=""
  [[ $rc -eq 0 ]] || fail "vc-server exited $rc after SIGTERM"
}
