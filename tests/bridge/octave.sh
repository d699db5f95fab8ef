#!/usr/bin/env bash
# The Octave example model moves the robot of a running sandbox over LCM
# (lcm.jar and the types jar of this build), inside a private network
# namespace (scripts/netns-run). Skipped (exit 77) when octave is not installed.
#
#   octave.sh SANDBOX STATE_CHECK LEVEL REPO TYPES_JAR
set -euo pipefail
sandbox=$1 check=$2 level=$3 repo=$4 jar=$5
source "$(dirname "$0")/processes.sh"
command -v octave > /dev/null || { echo "octave is not installed: skipped"; exit 77; }
[ -f "$jar" ] || { echo "no types jar at $jar (no JDK at build time?)"; exit 1; }
run_log=$(mktemp /tmp/sandbox-octave-run-XXXXXX.log)
trap 'rm -f "$run_log"' EXIT
start_sandbox "$run_log" "$sandbox" run "$level"
(cd "$repo" && SANDBOX_MSGS_JAR=$jar octave --no-gui --quiet examples/fly_wing.m 300 hover) &
octave_pid=$!
# Octave and its JVM take a few seconds to start (more on a busy machine).
status=0
"$check" ELAHA 12 34 56 0.001 --seconds 180 || status=$?
kill -KILL "$octave_pid" 2> /dev/null || true  # SIGTERM would make Octave save its workspace
wait "$octave_pid" || true
stop "$sandbox_pid"
cat "$run_log"
exit "$status"
