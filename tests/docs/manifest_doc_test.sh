#!/usr/bin/env bash
# docs/reference/manifest.md against the parsers: for each kind of table, the
# keys the page lists are exactly the keys the parsers ask for while the
# given manifests load (manifest_keys prints those).
#
#   manifest_doc_test.sh MANIFEST_KEYS DOC LEVEL.toml ...
set -uo pipefail
program=$1 doc=$2
shift 2
asked=$("$program" "$@") || { echo "manifest_keys failed"; exit 1; }
# "TABLE<TAB>key" from the page: a heading's backticked names are tables
# (one or several sharing the rows below), each row's first cell a key.
documented=$(awk '
  /^## / { n = 0; line = $0
           while (match(line, /`[^`]+`/)) { tables[++n] = substr(line, RSTART + 1, RLENGTH - 2)
                                            line = substr(line, RSTART + RLENGTH) } next }
  /^\| `/ { match($0, /`[^`]+`/); key = substr($0, RSTART + 1, RLENGTH - 2)
            for (i = 1; i <= n; ++i) print tables[i] "\t" key }' "$doc" | sort -u)
asked=$(sort -u <<< "$asked")
status=0
missing=$(comm -13 <(echo "$documented") <(echo "$asked"))
extra=$(comm -23 <(echo "$documented") <(echo "$asked"))
[ -z "$missing" ] || { echo "asked for by the parsers, not in $doc:"; echo "$missing" | sed 's/^/  /'; status=1; }
[ -z "$extra" ] || { echo "in $doc, not asked for by the parsers:"; echo "$extra" | sed 's/^/  /'; status=1; }
[ -n "$asked" ] || { echo "the parsers asked for no key"; status=1; }
((status == 0)) && echo "manifest_doc_test: $(wc -l <<< "$asked") keys in $(cut -f1 <<< "$asked" | sort -u | wc -l) kinds of table, as documented"
exit $status
