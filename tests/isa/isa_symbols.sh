#!/bin/sh
# isa_symbols.sh ISA OBJECT...: fails when an object built for instruction set
# ISA (sandbox_isa_kernel) defines a weak function outside the namespace ISA.
# The linker keeps one copy of a weak function for the whole program; a copy
# compiled for a wider set than the CPU's would crash every caller.
isa=$1
shift
status=0
for object in "$@"; do
  stray=$(nm -C --defined-only "$object" | awk '$2 == "W" || $2 == "u" || $2 == "i"' |
          grep -v "::$isa::")
  if [ -n "$stray" ]; then
    echo "$object: weak functions outside namespace $isa:"
    echo "$stray"
    status=1
  else
    echo "$object: every weak function is in namespace $isa"
  fi
done
exit $status
