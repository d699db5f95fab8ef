#!/usr/bin/env bash
# The highlands flight (100 km east, from the ground to 20 km) replayed in
# lock-step twice, 10 poses a second: every tile it needs streams in before
# the tick that needs it, so both runs publish byte-identical scans however
# fast the tile worker is; tiles come and go (memory bounded) and none fails.
#
#   highlands.sh SANDBOX FLY_WING LOG_DIFF LEVEL
set -euo pipefail
sandbox=$1 fly_wing=$2 log_diff=$3 level=$4
out=$(mktemp -d /tmp/sandbox-highlands-XXXXXX)
trap 'rm -rf "$out"' EXIT
"$fly_wing" --flight highlands --rate 10 --duration 345 --write-log "$out/flight.lcmlog"
for run in a b; do
  "$sandbox" run "$level" --replay "$out/flight.lcmlog" --record "$out/$run.lcmlog" \
    > "$out/$run.txt" 2>&1 || { cat "$out/$run.txt"; exit 1; }
done
cat "$out/a.txt" | tr '\r' '\n' | grep -v "^replay:"
"$log_diff" "$out/a.lcmlog" "$out/b.lcmlog" "ELAHA/(?!STATUS).*"
line=$(grep "terrain:" "$out/a.txt")
built=$(sed -n 's/.*terrain: \([0-9]*\) tiles built.*/\1/p' <<< "$line")
dropped=$(sed -n 's/.* \([0-9]*\) dropped.*/\1/p' <<< "$line")
peak=$(sed -n 's/.*peak \([0-9]*\) tiles.*/\1/p' <<< "$line")
failed=$(sed -n 's/.* \([0-9]*\) failed.*/\1/p' <<< "$line")
echo "tiles: $built built, $dropped dropped, peak $peak, $failed failed"
[ "$failed" = 0 ] || { echo "FAIL: tiles failed"; exit 1; }
[ "$dropped" -gt $((built / 2)) ] || { echo "FAIL: tiles were kept (memory grows with distance)"; exit 1; }
[ "$peak" -lt $((built / 2)) ] || { echo "FAIL: peak $peak of $built built"; exit 1; }
if grep -q "beyond every elevation raster" "$out/a.txt"; then echo "FAIL: flew off the raster"; exit 1; fi
grep -q "ELAHA/POSE: 3450 received, 0 superseded, 0 rejected" "$out/a.txt" ||
  { echo "FAIL: not every pose was applied"; exit 1; }
echo "PASS"
