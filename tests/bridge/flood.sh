#!/usr/bin/env bash
# Fault: a flood of garbage and oversized messages on every input channel
# (flood: 2000 a second for 10 s, none of them good) while the example model
# publishes its flight, inside a private network namespace
# (scripts/netns-run). Paced at 100 Hz, the sandbox receives every good
# pose and bone message (none is lost or displaced by the flood; the last is
# applied), rejects every bad one, keeps ticking and does not crash. In
# lock-step, every good pose is applied, one tick each. Counts of the
# real-time run are checked against bounds a machine ten times slower meets.
#
#   flood.sh SANDBOX FLY_WING FLOOD STATE_CHECK LEVEL
set -euo pipefail
sandbox=$1 fly_wing=$2 flood=$3 state_check=$4 level=$5
source "$(dirname "$0")/processes.sh"
run_log=$(mktemp /tmp/sandbox-flood-run-XXXXXX.log)
record=$(mktemp /tmp/sandbox-flood-XXXXXX.lcmlog)
trap 'rm -f "$run_log" "$record"' EXIT
status=0
# The count on one channel of the summary: "    ELAHA/POSE: 1 received, 2 superseded, 3 rejected".
count() { sed -n "s|^ *ELAHA/$1: \([0-9]*\) received, \([0-9]*\) superseded, \([0-9]*\) rejected.*|\\$2|p" "$run_log"; }

# 1. Paced at 100 Hz.
start_sandbox "$run_log" "$sandbox" run "$level"
"$flood" ELAHA --seconds 10 --rate 2000 &
flood_pid=$!
published=$("$fly_wing" --duration 10 --rate 100 | sed -n 's/fly_wing: published \([0-9]*\) poses/\1/p')
wait "$flood_pid"
"$state_check" ELAHA --good "$published" --seconds 60 || status=1
kill -INT "$sandbox_pid"
code=0
wait "$sandbox_pid" || code=$?
cat "$run_log"
[ "$code" -eq 0 ] || { echo "the sandbox ended with exit code $code"; status=1; }
for channel in POSE BONES; do
  good=$(($(count "$channel" 1) - $(count "$channel" 3)))
  [ "$good" -eq "$published" ] || { echo "$channel: $good good of $published published"; status=1; }
  [ "$(count "$channel" 3)" -gt 0 ] || { echo "$channel: the flood did not arrive"; status=1; }
done
[ "$(count ACTORS 1)" -eq "$(count ACTORS 3)" ] || { echo "ACTORS: a bad message was taken"; status=1; }
ticks=$(sed -n 's/^sandbox run: \([0-9]*\) ticks in \([0-9.]*\) s.*/\1/p' "$run_log")
seconds=$(sed -n 's/^sandbox run: \([0-9]*\) ticks in \([0-9.]*\) s.*/\2/p' "$run_log")
awk -v t="$ticks" -v s="$seconds" 'BEGIN { exit !(t >= 10 * s) }' ||
  { echo "the loop stalled: $ticks ticks in $seconds s"; status=1; }

# 2. In lock-step: one tick for each good pose, every one of them (300, seq 0
# to 299; the sandbox ticks only when a pose comes, so the watcher starts first).
start_sandbox "$run_log" "$sandbox" run "$level" --lockstep --record "$record"
"$state_check" ELAHA --seq 299 --seconds 120 &
check_pid=$!
"$flood" ELAHA --seconds 4 --rate 2000 &
flood_pid=$!
"$fly_wing" --poses 300 --rate 100 || status=1
wait "$flood_pid"
wait "$check_pid" || status=1
stop "$sandbox_pid"
cat "$run_log"
states=$("$sandbox" topics --log "$record" | awk '$1 == "ELAHA/STATE" { print $3 }')
echo "lock-step: $states states for 300 poses published"
[ "${states:-0}" -eq 300 ] || { echo "lock-step: not one tick per good pose"; status=1; }
# Datagrams the kernel dropped for full receive buffers (this namespace's own count).
awk '/^Udp:/ && ++n == 2 { print "udp: " $6 " datagrams dropped for full receive buffers" }' /proc/net/snmp
exit "$status"
