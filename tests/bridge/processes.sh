# Helpers for the multi-process tests (sourced): processes started and
# stopped on conditions, never on a fixed schedule, so that a slow or busy
# machine only makes a test take longer.

# Runs COMMAND... until it succeeds, up to SECONDS (polled every 0.1 s).
#   wait_for SECONDS COMMAND...
wait_for() {
  local seconds=$1
  shift
  for _ in $(seq $((seconds * 10))); do "$@" && return 0; sleep 0.1; done
  return 1
}

# Starts `sandbox run ...` in the background with its output in LOG, and
# returns once its loop runs (its first line is out). Sets sandbox_pid.
# LOG is emptied first, here: the background command truncates it only when
# it gets to run, and until then a reused LOG still shows the last run's line.
#   start_sandbox LOG SANDBOX ARGS...
start_sandbox() {
  local log=$1
  shift
  : > "$log"
  "$@" > "$log" 2>&1 &
  sandbox_pid=$!
  wait_for 120 grep -q "^sandbox run:" "$log" || { echo "the sandbox did not start:"; cat "$log"; return 1; }
}

# Stops a background process with SIGTERM and waits for it. (Not SIGINT:
# a script's background commands ignore it, unless they catch it as the
# sandbox does.)
#   stop PID
stop() {
  kill -TERM "$1" 2> /dev/null || true
  wait "$1" || true
}
