#!/usr/bin/env bash
# The Octave example model moves the robot of a running sandbox over LCM
# (lcm.jar), inside a private network namespace (scripts/netns-run).
# Skipped (exit 77) when octave is not installed.
#
#   octave.sh SANDBOX STATE_CHECK LEVEL REPO
set -euo pipefail
sandbox=$1 check=$2 level=$3 repo=$4
run_log=$(mktemp /tmp/sandbox-octave-run-XXXXXX.log)
trap 'rm -f "$run_log"' EXIT
command -v octave > /dev/null || { echo "octave is not installed: skipped"; exit 77; }
"$sandbox" run "$level" --duration 12 > "$run_log" &
run_pid=$!
(cd "$repo" && octave --no-gui --quiet examples/fly_wing.m 9 hover) &
octave_pid=$!
# Octave and its JVM take a few seconds to start; wait for the hover pose.
"$check" ELAHA 12 34 56 0.001 --seconds 10
status=$?
wait "$octave_pid" "$run_pid"
cat "$run_log"
exit "$status"
