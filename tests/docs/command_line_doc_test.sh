#!/usr/bin/env bash
# docs/reference/command-line.md against the program: the commands it has a
# section for are the ones `sandbox --help` lists, and each section names
# exactly the options that command's --help names.
#
#   command_line_doc_test.sh SANDBOX DOC
set -uo pipefail
sandbox=$1 doc=$2
options() { grep -o -- '--[a-z][a-z-]*' | grep -vx -- '--help' | sort -u; }
# The commands: the first word of each indented line of `sandbox --help`'s list.
commands=$("$sandbox" --help | sed -n '/^commands:/,/^run /p' | sed -n 's/^  \([a-z][a-z-]*\) .*/\1/p' | sort -u)
documented=$(sed -n 's/^## `sandbox \([a-z][a-z-]*\).*/\1/p' "$doc" | sort -u)
status=0
if [ "$commands" != "$documented" ]; then
  echo "commands in --help: $(echo $commands)"
  echo "commands in $doc: $(echo $documented)"
  status=1
fi
for command in $commands; do
  # The section: from its heading to the next.
  section=$(awk -v c="$command" 'index($0, "## `sandbox " c) == 1 { on = 1; next } /^## / { on = 0 } on' "$doc")
  in_doc=$(options <<< "$section")
  in_help=$("$sandbox" "$command" --help 2>&1 | options)
  missing=$(comm -13 <(echo "$in_doc") <(echo "$in_help") | tr '\n' ' ')
  extra=$(comm -23 <(echo "$in_doc") <(echo "$in_help") | tr '\n' ' ')
  [ -z "${missing// }" ] || { echo "sandbox $command: in --help, not in $doc: $missing"; status=1; }
  [ -z "${extra// }" ] || { echo "sandbox $command: in $doc, not in --help: $extra"; status=1; }
  [ -n "$in_help" ] || { echo "sandbox $command: --help names no option"; status=1; }
done
((status == 0)) && echo "command_line_doc_test: $(echo $commands | wc -w) commands, their options as documented"
exit $status
