#!/usr/bin/env bash
# A closed-loop scenario (examples/scenarios/run) twice in lock-step, inside
# the private network namespace this test runs in: each run's figures within
# the issue's bounds (--check), and the two runs' pose logs identical.
#
#   scenario.sh SOURCE_DIR BUILD_DIR SCENARIO
set -euo pipefail
source_dir=$1 build=$2 scenario=$3
out=$(mktemp -d /tmp/sandbox-scenario-XXXXXX)
trap 'rm -rf "$out"' EXIT
for run in 1 2; do
  "$source_dir/examples/scenarios/run" "$scenario" --check --build "$build" --out "$out/$run"
done
grep -q " 0 resent" "$out/1/rigid_body.log" || { echo "the first run resent poses"; exit 1; }
cmp "$out/1/poses.csv" "$out/2/poses.csv" || { echo "two lock-step runs differ"; exit 1; }
echo "two lock-step runs: identical pose logs ($(wc -l < "$out/1/poses.csv") lines)"
