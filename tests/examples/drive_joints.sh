#!/usr/bin/env bash
# The robot-description examples for a few seconds, in a private network
# namespace: drive_joints waves the bundled URDF arm (examples/robots/
# arm_cell.toml) and, when ../shared is there, flies PX4's SDF plane round its
# circuit (examples/robots/px4_plane.toml); the sandbox applied every pose and
# joint message and rejected none.
#
#   drive_joints.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$1 build=$2
out=$(mktemp -d /tmp/sandbox-joints-XXXXXX)
trap 'rm -rf "$out"' EXIT
fail=0
run() {  # LEVEL ROBOT MOTION
  local level=$1 robot=$2 motion=$3 log=$out/$2.log
  "$build/sandbox" run "$level" --duration 30 --no-sensors > "$log" 2>&1 &
  local sandbox=$!
  # Publish once it listens (its first line), then stop it.
  for _ in $(seq 300); do grep -q "^sandbox run: " "$log" && break; sleep 0.1; done
  "$build/drive_joints" --motion "$motion" --duration 2 > "$out/$robot.driver"
  sleep 0.5
  kill -INT "$sandbox"
  wait "$sandbox" || true
  cat "$log" "$out/$robot.driver"
  local published received rejected
  published=$(sed -n 's/drive_joints: published \([0-9]*\) poses.*/\1/p' "$out/$robot.driver")
  for channel in POSE JOINTS; do
    line=$(grep "^ *$robot/$channel: " "$log")
    received=$(sed -n "s/.*$channel: \([0-9]*\) received.*/\1/p" <<< "$line")
    rejected=$(sed -n 's/.* \([0-9]*\) rejected.*/\1/p' <<< "$line")
    if [ -n "$published" ] && [ "$published" -gt 0 ] && [ "$received" = "$published" ] &&
       [ "$rejected" = 0 ]; then
      echo "drive_joints: $robot/$channel: $received of $published received, none rejected"
    else
      echo "FAILED: $robot/$channel: published '$published', received '$received', rejected '$rejected'"
      fail=1
    fi
  done
}
run "$source_dir/examples/robots/arm_cell.toml" arm wave
if [ -f "$source_dir/../shared/assets/px4-sitl-models/models/plane/plane.sdf" ]; then
  run "$source_dir/examples/robots/px4_plane.toml" plane circuit
else
  echo "drive_joints: no ../shared: the PX4 plane is skipped"
fi
exit $fail
