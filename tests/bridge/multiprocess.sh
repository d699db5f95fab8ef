#!/usr/bin/env bash
# Three processes over LCM multicast inside a private network namespace
# (scripts/netns-run): the example model flies the wing, the sandbox runs its
# loop, and face_check compares the scan faces it receives with one-shot scans
# at the same poses.
#
#   multiprocess.sh SANDBOX FLY_WING FACE_CHECK LEVEL
set -euo pipefail
sandbox=$1 fly_wing=$2 face_check=$3 level=$4
source "$(dirname "$0")/processes.sh"
run_log=$(mktemp /tmp/sandbox-multiprocess-run-XXXXXX.log)
trap 'rm -f "$run_log"' EXIT
start_sandbox "$run_log" "$sandbox" run "$level"
"$fly_wing" --duration 300 --rate 200 > /dev/null &
fly_pid=$!
status=0
"$face_check" "$level" --faces 24 --seconds 120 || status=$?
stop "$fly_pid"
stop "$sandbox_pid"
cat "$run_log"
exit "$status"
