#!/bin/sh
# run_if_cpu_has.sh "FLAG..." COMMAND [ARG...]: runs COMMAND when every FLAG
# is among the CPU's flags in /proc/cpuinfo; exits 77 (ctest: skipped) when not.
flags=$1
shift
for flag in $flags; do
  if ! grep -qw "$flag" /proc/cpuinfo; then
    echo "this CPU lacks $flag: skipped"
    exit 77
  fi
done
exec "$@"
