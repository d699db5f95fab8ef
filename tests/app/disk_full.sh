#!/usr/bin/env bash
# A disk that fills up while frames are written, and then has room again: a
# 256 KB tmpfs, mounted in a private mount namespace (needs root or
# unprivileged user namespaces; skipped otherwise). The failure is reported
# once and the lost frames counted; the loop keeps ticking and publishing
# scans (every output is recorded to a log on another disk); once space
# returns, frames are written again; the files left are whole; the exit code
# says output was lost (3). Counts are checked against bounds a machine ten
# times slower still meets, never against a rate.
#
#   disk_full.sh SANDBOX
set -euo pipefail
sandbox=$1
if [ "${SANDBOX_IN_MOUNTNS:-}" != 1 ]; then
  userns=""
  [ "$(id -u)" -eq 0 ] || userns="-r"
  unshare $userns -m true 2> /dev/null || { echo "skipped: cannot make a mount namespace"; exit 77; }
  exec unshare $userns -m -- env SANDBOX_IN_MOUNTNS=1 bash "$0" "$@"
fi
dir=$(mktemp -d /tmp/sandbox-disk-full-XXXXXX)
log=$(mktemp /tmp/sandbox-disk-full-XXXXXX.txt)
record=$(mktemp /tmp/sandbox-disk-full-XXXXXX.lcmlog)
mount -t tmpfs -o size=4m tmpfs "$dir" || { echo "skipped: cannot mount a tmpfs"; exit 77; }
cleanup() { umount "$dir" 2> /dev/null || true; rmdir "$dir"; rm -f "$log" "$record"; }
trap cleanup EXIT

# Waits up to 120 s for a command to succeed.
wait_for() {
  for _ in $(seq 1200); do "$@" && return 0; sleep 0.1; done
  return 1
}
pngs() { find "$dir" -name 'chase_*.png' | wc -l; }
some_frames() { [ "$(pngs)" -ge 3 ]; }

"$sandbox" run --lcm-url memq:// --out "$dir" --frames png --record "$record" > "$log" 2>&1 &
pid=$!
status=0
wait_for grep -q "^sandbox: frames: cannot write" "$log" ||
  { echo "the full disk was not reported"; status=1; }
# Space returns: the frames written so far are moved away.
before=$(pngs)
find "$dir" -name '*.png' -delete
wait_for some_frames || { echo "writing did not resume when space returned"; status=1; }
kill -INT "$pid"
code=0
wait "$pid" || code=$?
cat "$log"
echo "frames before the disk filled: $before; after space returned: $(pngs)"

[ "$code" -eq 3 ] || { echo "exit code $code, not 3 (output lost)"; status=1; }
[ "$(grep -c "^sandbox: frames: cannot write" "$log")" -eq 1 ] ||
  { echo "the failure was reported more than once"; status=1; }
failed=$(sed -n 's/.*dropped, \([0-9]*\) failed (.*cannot write.*/\1/p' "$log")
[ "${failed:-0}" -ge 1 ] || { echo "failed frames not counted with the reason"; status=1; }
# The loop kept ticking (a tenth of 100 Hz is enough) ...
ticks=$(sed -n 's/^sandbox run: \([0-9]*\) ticks in \([0-9.]*\) s.*/\1/p' "$log")
seconds=$(sed -n 's/^sandbox run: \([0-9]*\) ticks in \([0-9.]*\) s.*/\2/p' "$log")
awk -v t="$ticks" -v s="$seconds" 'BEGIN { exit !(t >= 10 * s) }' ||
  { echo "the loop stalled: $ticks ticks in $seconds s"; status=1; }
# ... and published a face every tick (the six-stage scanner), full disk or not.
faces=$("$sandbox" topics --log "$record" | awk '$1 == "ELAHA/SCAN_FACE" { print $3 }')
[ "${faces:-0}" -eq "$ticks" ] ||
  { echo "$faces faces published in $ticks ticks"; status=1; }
# What is on the disk is whole: every index row has all of its columns, and
# every frame left is listed in its index.
awk -F, 'NR > 1 && NF != 31 { bad = 1 } END { exit bad }' "$dir/chase.csv" ||
  { echo "chase.csv has a cut row"; status=1; }
for png in $(find "$dir" -name 'chase_*.png'); do
  grep -q ",chase/$(basename "$png")," "$dir/chase.csv" || { echo "$png is not indexed"; status=1; }
done
exit "$status"
