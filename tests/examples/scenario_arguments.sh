#!/usr/bin/env bash
# examples/scenarios/run checks its arguments before it makes anything, and
# fails a run whose figures fall out of their bounds (a 2 s flat_drop cannot
# settle within the issue's bounds).
#
#   scenario_arguments.sh SOURCE_DIR BUILD_DIR
set -uo pipefail
source_dir=$1 build=$2
run=$source_dir/examples/scenarios/run
work=$(mktemp -d /tmp/sandbox-scenario-args-XXXXXX)
trap 'rm -rf "$work"' EXIT
cd "$work"
failed=0
refused() {  # EXPECTED_TEXT ARGS...: exit 2, the text said, nothing made
  local expected=$1; shift
  local output code
  output=$("$run" "$@" --build "$build" 2>&1); code=$?
  if [ "$code" -ne 2 ] || ! grep -qF -- "$expected" <<< "$output"; then
    echo "FAIL: run $* gave exit $code: $output"; failed=1
  fi
  if [ -n "$(ls -A "$work")" ]; then
    echo "FAIL: run $* made $(ls -A "$work")"; failed=1; rm -rf "${work:?}"/*
  fi
}
refused "unknown scenario '../../x'" ../../x
refused "unknown scenario '../../x'" ../../x --out here
refused "--pace is lockstep, 100hz or free, got 'fast'" flat_drop --pace fast
refused "--duration must be a positive number of seconds, got '-1'" flat_drop --duration -1
refused "--duration must be a positive number of seconds, got '0'" flat_drop --duration 0
refused "unknown option --bogus" flat_drop --bogus
# Out of bounds: a non-zero exit and the figure named.
output=$("$run" flat_drop --duration 2 --build "$build" --out "$work/short" 2>&1); code=$?
if [ "$code" -eq 0 ] || ! grep -q "OUT OF BOUNDS" <<< "$output"; then
  echo "FAIL: a 2 s flat_drop exited $code: $output"; failed=1
fi
[ "$failed" -eq 0 ] && echo "scenario arguments: 7 checks passed"
exit "$failed"
