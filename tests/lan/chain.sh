#!/usr/bin/env bash
# The chain across machines (scripts/lan-run 3): the model on h1, the
# sandbox on h2, a listener on h3 and one beside the model on h1. Checks that
# every pose crosses the LAN and is applied, that the sandbox's state echoes
# and scans come back with nothing lost, at 100 Hz for SECONDS (default 30),
# and reports the latency the LAN hop adds (h3's pose latency over h1's).
# `sandbox topics --json` on h3 shows the live table meanwhile.
#
#   chain.sh SANDBOX FLY_WING LAN_PROBE LEVEL [SECONDS]
set -euo pipefail
sandbox=$1 fly_wing=$2 probe=$3 level=$4 seconds=${5:-30}
source "$(dirname "$0")/../bridge/processes.sh"
out=$(mktemp -d /tmp/sandbox-lan-chain-XXXXXX)
trap 'kill $(jobs -p) 2> /dev/null || true; rm -rf "$out"' EXIT
probe_url="$LAN_URL&recv_buf_size=4194304"

start_sandbox "$out/sandbox.log" ip netns exec h2 "$sandbox" run "$level" --lcm-url "$LAN_URL"
sandbox_run=$sandbox_pid
ip netns exec h3 "$probe" --lcm-url "$probe_url" --idle 3 --seconds $((seconds + 120)) > "$out/remote.log" &
remote=$!
ip netns exec h1 "$probe" --lcm-url "$probe_url" --idle 3 --seconds $((seconds + 120)) > "$out/local.log" &
local_probe=$!
wait_for 60 grep -q listening "$out/remote.log"
wait_for 60 grep -q listening "$out/local.log"
# The live topic table on h3, as JSON lines, for the first seconds.
ip netns exec h3 "$sandbox" topics --lcm-url "$probe_url" --seconds 6 --every 1 --json \
  > "$out/topics.jsonl" &
topics=$!
published=$(ip netns exec h1 "$fly_wing" --rate 100 --duration "$seconds" --lcm-url "$LAN_URL" |
  sed -n 's/fly_wing: published \([0-9]*\) poses/\1/p')
wait "$remote" "$local_probe" "$topics"
stop "$sandbox_run"
cat "$out/sandbox.log" "$out/local.log" "$out/remote.log"

field() { sed -n "s/.*$2.*/\1/p" "$1"; }
fail=0
check() { if ! eval "$2"; then echo "FAILED: $1 ($2)"; fail=1; fi; }
received=$(sed -n 's|^ *ELAHA/POSE: \([0-9]*\) received.*|\1|p' "$out/sandbox.log")
for side in local remote; do
  heard=$(field "$out/$side.log" 'poses \([0-9]*\) heard')
  check "$side: every pose heard" "[ '$heard' = '$published' ]"
  check "$side: no pose lost" "[ '$(field "$out/$side.log" 'heard, \([0-9]*\) lost, latency')' = 0 ]"
done
check "the sandbox on h2 received every pose" "[ '$received' = '$published' ]"
check "no state echo lost on the way to h3" \
  "[ '$(field "$out/remote.log" 'states [0-9]* heard, \([0-9]*\) lost')' = 0 ]"
check "state echoes reached h3" "[ '$(field "$out/remote.log" 'states \([0-9]*\) heard')' -gt 0 ]"
check "scan faces reached h3" "[ '$(field "$out/remote.log" 'faces \([0-9]*\)')' -gt 0 ]"
check "sandbox topics on h3 printed a table a second" "[ $(wc -l < "$out/topics.jsonl") -ge 5 ]"
check "the live table shows the poses' type and size" \
  "[ $(grep -c '{"channel":"ELAHA/POSE","type":"robot_pose_t","messages":[0-9]*,"bytes":[0-9]*,"rate_hz":[0-9.e+]*,"mean_bytes":80,' "$out/topics.jsonl") -ge 3 ]"
local_ms=$(field "$out/local.log" 'latency median \([0-9.]*\) ms')
remote_ms=$(field "$out/remote.log" 'latency median \([0-9.]*\) ms')
echo "chain: $published poses at 100 Hz over $seconds s; pose latency median on the model's" \
  "machine $local_ms ms, across the LAN $remote_ms ms (the hop adds" \
  "$(awk -v a="$remote_ms" -v b="$local_ms" 'BEGIN { printf "%.3f", a - b }') ms)"
exit $fail
