#!/usr/bin/env bash
# examples/formation/run for a few seconds: three model processes fly the
# wing and its two wingmen; the sandbox applied every pose of each robot and
# rejected none.
#
#   formation.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
source_dir=$1 build=$2
out=$(mktemp -d /tmp/sandbox-formation-XXXXXX)
trap 'rm -rf "$out"' EXIT
"$source_dir/examples/formation/run" --duration 3 --out "$out" --build "$build" > "$out/run.log"
cat "$out/run.log"
fail=0
for pair in wing:ELAHA left:QUAD1 right:QUAD2; do
  slot=${pair%%:*} robot=${pair##*:}
  published=$(sed -n 's/fly_wing: published \([0-9]*\) poses/\1/p' "$out/fly_$slot.log")
  line=$(grep "^ *$robot/POSE: " "$out/sandbox.log")
  received=$(sed -n 's/.*POSE: \([0-9]*\) received.*/\1/p' <<< "$line")
  rejected=$(sed -n 's/.* \([0-9]*\) rejected.*/\1/p' <<< "$line")
  if [ -n "$published" ] && [ "$published" -gt 0 ] && [ "$received" = "$published" ] &&
     [ "$rejected" = 0 ]; then
    echo "formation: $robot: $received of $published poses received, none rejected"
  else
    echo "FAILED: $robot: published '$published', received '$received', rejected '$rejected'"
    fail=1
  fi
done
exit $fail
