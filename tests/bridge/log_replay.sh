#!/usr/bin/env bash
# Record and replay a session, inside a private network namespace
# (scripts/netns-run): lcm-logger records the example model's flight;
# lcm-logplayer replays the log into a running sandbox, whose scan faces
# face_check compares with one-shot scans at the replayed poses; and
# `sandbox run --replay` reads the log twice in lock-step, giving
# byte-identical output logs with one tick per recorded pose.
#
#   log_replay.sh SANDBOX FLY_WING FACE_CHECK LEVEL
set -euo pipefail
sandbox=$1 fly_wing=$2 face_check=$3 level=$4
log=$(mktemp /tmp/sandbox-flight-XXXXXX.lcmlog)
out1=$(mktemp /tmp/sandbox-replay1-XXXXXX.lcmlog)
out2=$(mktemp /tmp/sandbox-replay2-XXXXXX.lcmlog)
run_log=$(mktemp /tmp/sandbox-replay-run-XXXXXX.txt)
replay_log=$(mktemp /tmp/sandbox-replay1-XXXXXX.txt)
trap 'rm -f "$log" "$out1" "$out2" "$run_log" "$replay_log"' EXIT
lcm-logger --force --channel='ELAHA/(POSE|BONES)' "$log" > /dev/null &
logger_pid=$!
sleep 0.3
published=$("$fly_wing" --duration 2 --rate 100 | sed -n 's/fly_wing: published \([0-9]*\) poses/\1/p')
sleep 0.3
kill -INT "$logger_pid"
wait "$logger_pid" || true
echo "recorded $(stat -c %s "$log") bytes"
"$sandbox" run "$level" --duration 4 > "$run_log" &
run_pid=$!
# Play only once the sandbox has subscribed (its first line): a slow start
# on a busy machine would otherwise miss the first poses.
for _ in $(seq 100); do grep -q "^sandbox run:" "$run_log" && break; sleep 0.1; done
lcm-logplayer "$log" &
player_pid=$!
"$face_check" "$level" --faces 12 --seconds 3
status=$?
wait "$player_pid" "$run_pid"
cat "$run_log"
# Every pose recorded reached the sandbox (the log plays at recorded speed).
grep -q "ELAHA/POSE: $published received" "$run_log" ||
  { echo "not all $published logged poses arrived"; status=1; }
# Lock-step replays of the log: one tick per pose, the same bytes every time.
"$sandbox" run "$level" --replay "$log" --record "$out1" 2> /dev/null > "$replay_log"
"$sandbox" run "$level" --replay "$log" --record "$out2" 2> /dev/null > /dev/null
grep -q "sandbox run: $published ticks" "$replay_log" ||
  { echo "the replay did not run one tick per pose:"; cat "$replay_log"; status=1; }
cmp "$out1" "$out2" || { echo "two replays of one log differ"; status=1; }
echo "replayed twice: $(stat -c %s "$out1") bytes of outputs, identical"
exit "$status"
