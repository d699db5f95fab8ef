#!/usr/bin/env bash
# Fault: the pose publisher dies mid-flight and comes back (publisher_dies
# kills and restarts the example model and watches the sandbox's STATUS and
# STATE), inside a private network namespace (scripts/netns-run).
#
#   publisher_dies.sh SANDBOX FLY_WING PUBLISHER_DIES LEVEL
set -euo pipefail
sandbox=$1 fly_wing=$2 publisher_dies=$3 level=$4
source "$(dirname "$0")/processes.sh"
run_log=$(mktemp /tmp/sandbox-publisher-dies-XXXXXX.log)
trap 'rm -f "$run_log"' EXIT
start_sandbox "$run_log" "$sandbox" run "$level"
status=0
"$publisher_dies" "$fly_wing" || status=$?
stop "$sandbox_pid"
cat "$run_log"
exit "$status"
