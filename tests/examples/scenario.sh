#!/usr/bin/env bash
# A closed-loop scenario (examples/scenarios/run) in lock-step, RUNS times
# (default 2), inside the private network namespace this test runs in: each
# run's figures within the issue's bounds (--check), and all runs' pose logs
# identical.
#
#   scenario.sh SOURCE_DIR BUILD_DIR SCENARIO [RUNS]
set -euo pipefail
source_dir=$1 build=$2 scenario=$3 runs=${4:-2}
out=$(mktemp -d /tmp/sandbox-scenario-XXXXXX)
trap 'rm -rf "$out"' EXIT
for run in $(seq "$runs"); do
  "$source_dir/examples/scenarios/run" "$scenario" --check --build "$build" --out "$out/$run"
done
grep -q " 0 resent" "$out/1/rigid_body.log" || { echo "the first run resent poses"; exit 1; }
for run in $(seq 2 "$runs"); do
  cmp "$out/1/poses.csv" "$out/$run/poses.csv" || { echo "lock-step runs 1 and $run differ"; exit 1; }
done
echo "$runs lock-step run(s): identical pose logs ($(wc -l < "$out/1/poses.csv") lines)"
