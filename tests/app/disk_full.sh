#!/usr/bin/env bash
# A disk that fills up while frames are written: a 256 KB tmpfs, mounted in a
# private mount namespace (needs root or unprivileged user namespaces; skipped
# otherwise). The loop keeps its rate, the failure is reported once, and the
# frames that could not be written are counted.
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
mount -t tmpfs -o size=256k tmpfs "$dir" || { echo "skipped: cannot mount a tmpfs"; exit 77; }
out=$("$sandbox" run --duration 2 --lcm-url memq:// --out "$dir" --frames png 2>&1)
code=$?
echo "$out"
umount "$dir"
rmdir "$dir"
status=0
[ "$code" -eq 0 ] || { echo "exit code $code"; status=1; }
echo "$out" | grep -Eq "sandbox run: (19[0-9]|20[0-9]) ticks" || { echo "the loop lost its rate"; status=1; }
failed=$(echo "$out" | sed -n 's/.*dropped, \([0-9]*\) failed (.*cannot write.*/\1/p')
[ "${failed:-0}" -ge 5 ] || { echo "failed frames not counted with the reason"; status=1; }
[ "$(echo "$out" | grep -c "^sandbox: frames: cannot write")" -eq 1 ] || { echo "the failure was reported more than once"; status=1; }
exit "$status"
