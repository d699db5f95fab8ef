#!/usr/bin/env bash
# Record and replay a session, inside a private network namespace
# (scripts/netns-run): lcm-logger records the example model's flight;
# lcm-logplayer replays the log into a running sandbox, which receives every
# recorded pose and whose scan faces face_check compares with one-shot scans
# at the replayed poses; and `sandbox run --replay` reads the log twice in
# lock-step, giving byte-identical output logs with one tick per recorded pose.
#
#   log_replay.sh SANDBOX FLY_WING FACE_CHECK STATE_CHECK LEVEL
set -euo pipefail
sandbox=$1 fly_wing=$2 face_check=$3 state_check=$4 level=$5
source "$(dirname "$0")/processes.sh"
log=$(mktemp /tmp/sandbox-flight-XXXXXX.lcmlog)
out1=$(mktemp /tmp/sandbox-replay1-XXXXXX.lcmlog)
out2=$(mktemp /tmp/sandbox-replay2-XXXXXX.lcmlog)
run_log=$(mktemp /tmp/sandbox-replay-run-XXXXXX.txt)
replay_log=$(mktemp /tmp/sandbox-replay1-XXXXXX.txt)
trap 'rm -f "$log" "$out1" "$out2" "$run_log" "$replay_log"' EXIT
lcm-logger --force --channel='ELAHA/(POSE|BONES)' "$log" > /dev/null &
logger_pid=$!
sleep 0.3  # the logger's start; poses it misses are simply not in the log
"$fly_wing" --duration 2 --rate 100 > /dev/null
sleep 0.3  # poses still on their way to the logger may be missed: the log is what counts
kill -INT "$logger_pid"
wait "$logger_pid" || true
recorded=$("$sandbox" topics --log "$log" | awk '$1 == "ELAHA/POSE" { print $3 }')
echo "recorded $recorded poses, $(stat -c %s "$log") bytes"
start_sandbox "$run_log" "$sandbox" run "$level"
lcm-logplayer "$log" &
player_pid=$!
status=0
"$face_check" "$level" --faces 12 --seconds 120 || status=$?
wait "$player_pid"
# Every recorded pose reaches the sandbox (its heartbeat counts them).
"$state_check" ELAHA --good "$recorded" --seconds 60 ||
  { echo "not all $recorded logged poses arrived"; status=1; }
stop "$sandbox_pid"
cat "$run_log"
# Lock-step replays of the log: one tick per pose, the same bytes every time.
"$sandbox" run "$level" --replay "$log" --record "$out1" 2> /dev/null > "$replay_log"
"$sandbox" run "$level" --replay "$log" --record "$out2" 2> /dev/null > /dev/null
grep -q "sandbox run: $recorded ticks" "$replay_log" ||
  { echo "the replay did not run one tick per pose:"; cat "$replay_log"; status=1; }
cmp "$out1" "$out2" || { echo "two replays of one log differ"; status=1; }
echo "replayed twice: $(stat -c %s "$out1") bytes of outputs, identical"
exit "$status"
