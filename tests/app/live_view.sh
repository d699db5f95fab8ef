#!/usr/bin/env bash
# The live view on a virtual display (Xvfb): the window opens and shows
# frames; keys typed into it (xdotool) switch the camera, toggle the overlay
# and stop the run long before its duration. Without a display, --view fails
# with a clear message.
#
#   live_view.sh SANDBOX
set -euo pipefail
# On a virtual display of its own (xvfb-run picks a free number), which
# never resets (by default Xvfb resets each time its last client leaves,
# and in CI a display answered once and then no more); Xvfb's own messages
# are shown when the display fails.
if [ -z "${LIVE_VIEW_XVFB_LOG:-}" ]; then
  xvfb_log=$(mktemp /tmp/sandbox-live-view-xvfb-XXXXXX.log)
  status=0
  LIVE_VIEW_XVFB_LOG=$xvfb_log xvfb-run -a -e "$xvfb_log" -s "-noreset -screen 0 1280x1024x24" \
    bash "$0" "$@" || status=$?
  rm -f "$xvfb_log"
  exit "$status"
fi
xvfb_failed() {
  echo "$1 (display $DISPLAY; Xvfb's messages follow)"
  cat "$LIVE_VIEW_XVFB_LOG"
}
# No session bus on the virtual display: Qt's accessibility would have
# libdbus autolaunch one, forking the threaded sandbox; under the sanitizers
# that fork's child deadlocked in the allocator and the window never came.
# An address that fails at once makes it give up without forking.
export DBUS_SESSION_BUS_ADDRESS=unix:path=/nonexistent/sandbox-test-bus
sandbox=$1
out=$(mktemp /tmp/sandbox-live-view-XXXXXX.txt)
trap 'rm -f "$out"' EXIT
status=0
if env -u DISPLAY -u WAYLAND_DISPLAY "$sandbox" run --view --duration 1 --lcm-url memq:// > "$out" 2>&1; then
  echo "--view without a display did not fail"; status=1
fi
grep -q -- "--view needs a display" "$out" || { cat "$out"; status=1; }

# The virtual display answers first (once, in CI under the sanitizers, the
# sandbox found no server at xvfb-run's display and aborted at once).
answered=0
for _ in $(seq 300); do
  xdotool getdisplaygeometry > /dev/null 2>&1 && { answered=1; break; }
  sleep 0.1
done
[ "$answered" -eq 1 ] || { xvfb_failed "the virtual display does not answer"; exit 1; }

# Long enough that only the q key can have ended it.
"$sandbox" run --view --duration 600 --lcm-url memq:// > "$out" 2>&1 &
pid=$!
window=""
for _ in $(seq 1200); do
  window=$(xdotool search --name "^sandbox: " 2> /dev/null | head -1) && [ -n "$window" ] && break
  sleep 0.1
done
if [ -z "$window" ]; then
  # The sandbox's own words (kill fails when it is gone already).
  echo "no window appeared"; kill "$pid" 2> /dev/null || true; wait "$pid" || echo "exit status $?"
  cat "$out"; xvfb_failed "the display at the end"; exit 1
fi
sleep 1
for key in c o q; do xdotool key --window "$window" "$key" 2> /dev/null; sleep 0.3; done
# Ended by q, or stopped here after 120 s (not at the run's 600 s).
for _ in $(seq 1200); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
kill -0 "$pid" 2> /dev/null && { echo "still running 120 s after q"; kill -9 "$pid"; status=1; }
wait "$pid" || { echo "exit status $?"; status=1; }
cat "$out"
grep -q "last camera trailing, overlay toggled, quit by key" "$out" || { echo "the keys did not act"; status=1; }
shown=$(sed -n 's/.*live view: \([0-9]*\) frames shown.*/\1/p' "$out")
[ "${shown:-0}" -ge 1 ] || { echo "no frame shown"; status=1; }
seconds=$(sed -n 's/^sandbox run: \([0-9]*\) ticks in \([0-9.]*\) s.*/\2/p' "$out")
awk -v s="$seconds" 'BEGIN { exit !(s < 300) }' || { echo "q did not stop the run ($seconds s)"; status=1; }
exit "$status"
