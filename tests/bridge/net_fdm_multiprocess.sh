#!/usr/bin/env bash
# A net_fdm sender (as Simulink's FlightGear blocks) moves the robot of a
# running sandbox; state_check reads the robot state the sandbox publishes.
# Inside a private network namespace (scripts/netns-run).
#
#   net_fdm_multiprocess.sh SANDBOX SEND_NET_FDM STATE_CHECK LEVEL
set -euo pipefail
sandbox=$1 sender=$2 check=$3 level=$4
source "$(dirname "$0")/processes.sh"
run_log=$(mktemp /tmp/sandbox-net-fdm-run-XXXXXX.log)
trap 'rm -f "$run_log"' EXIT
start_sandbox "$run_log" "$sandbox" run "$level"
"$sender" --hover --duration 300 --rate 100 > /dev/null &
send_pid=$!
# Hovering one arc second north of 47 N (the meridian radius there, 6369620 m,
# plus 600 m, times 4.8481e-6 rad: 30.883 m) and 100 m above the origin.
status=0
"$check" ELAHA 0 30.883 100 0.05 --seconds 120 || status=$?
stop "$send_pid"
stop "$sandbox_pid"
cat "$run_log"
exit "$status"
