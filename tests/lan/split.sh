#!/usr/bin/env bash
# The work split over two machines (scripts/lan-run 3): the model on h1
# flies POSES poses at 100 Hz; on h2 a lock-step sandbox scans and publishes
# (recording what it publishes), on h3 a lock-step sandbox only renders the
# cameras (--frames-only). Then one sandbox replays the model's own log doing
# both. The scans must be byte-identical and the frame indexes identical (and
# the chase camera's images, which carry no overlay).
#
#   split.sh SANDBOX FLY_WING LOG_DIFF LEVEL [POSES]
set -euo pipefail
sandbox=$1 fly_wing=$2 log_diff=$3 level=$4 poses=${5:-300}
source "$(dirname "$0")/../bridge/processes.sh"
out=$(mktemp -d /tmp/sandbox-lan-split-XXXXXX)
trap 'kill $(jobs -p) 2> /dev/null || true; rm -rf "$out"' EXIT
lockstep=(run "$level" --lcm-url "$LAN_URL" --lockstep --ticks "$poses" --realtime off)

start_sandbox "$out/scanner.log" ip netns exec h2 "$sandbox" "${lockstep[@]}" \
  --record "$out/scans.lcmlog"
scanner=$sandbox_pid
start_sandbox "$out/renderer.log" ip netns exec h3 "$sandbox" "${lockstep[@]}" \
  --frames-only --out "$out/frames"
renderer=$sandbox_pid
ip netns exec h1 "$fly_wing" --poses "$poses" --rate 100 --lcm-url "$LAN_URL" \
  --log "$out/model.lcmlog"
# Each stops after its POSES ticks (lock-step: one a pose), however slowly.
wait_for 600 bash -c "! kill -0 $scanner 2> /dev/null && ! kill -0 $renderer 2> /dev/null" ||
  { echo "the two sandboxes did not finish their $poses ticks"; stop "$scanner"; stop "$renderer"; }
wait "$scanner" "$renderer" || true
"$sandbox" run "$level" --replay "$out/model.lcmlog" --record "$out/both.lcmlog" \
  --out "$out/both" > "$out/both.log" 2>&1
cat "$out/scanner.log" "$out/renderer.log" "$out/both.log"

fail=0
"$log_diff" "$out/scans.lcmlog" "$out/both.lcmlog" 'ELAHA/(SCAN_FACE|RANGE)' | tee "$out/diff.log" ||
  fail=1
[ "$(sed -n 's/log_diff: \([0-9]*\) messages.*/\1/p' "$out/diff.log")" -gt 0 ] ||
  { echo "FAILED: no scans published"; fail=1; }
for camera in chase trailing belly; do
  lines=$(wc -l < "$out/both/$camera.csv")
  if cmp "$out/frames/$camera.csv" "$out/both/$camera.csv"; then
    echo "split: $camera: frame indexes identical ($((lines - 1)) frames)"
  else
    echo "FAILED: $camera: frame indexes differ"
    fail=1
  fi
done
differ=0 frames=0
for image in "$out/both"/chase/chase_*.jpg; do
  frames=$((frames + 1))
  cmp -s "$image" "$out/frames/chase/$(basename "$image")" || differ=$((differ + 1))
done
echo "split: chase: $frames images, $differ differ"
[ "$frames" -gt 0 ] && [ "$differ" = 0 ] || fail=1
grep -q "sensors off, publishing nothing" "$out/renderer.log" || { echo "FAILED: renderer ran sensors"; fail=1; }
exit $fail
