#!/usr/bin/env bash
# man.sh FACETFIT PAGE: the manual page renders with no groff warning, has a section for every subcommand the
# command lists, and holds each subcommand's options (one checked per command). 77 (skip) without the page.
set -euo pipefail
facetfit=$1 page=$2
[[ -f $page ]] || { echo "no $page (help2man not found at configure time): skipped"; exit 77; }
warnings=$(groff -man -Tutf8 -ww -z "$page" 2>&1)
[[ -z $warnings ]] || { echo "groff warns: $warnings"; exit 1; }
text=$(groff -man -Tutf8 "$page" 2>/dev/null | sed 's/.\x08//g')
status=0
for c in $("$facetfit" --help | sed -n '/^Subcommands:/,$p' | awk 'NR > 1 && NF { print $1 }'); do
  grep -q "facetfit $c\$" <<<"$text" || { echo "no section for $c"; status=1; }
  option=$("$facetfit" "$c" --help | grep -o -- '--[a-z][a-z-]*' | grep -v -- '--help' | head -1 || true)
  [[ -z $option ]] || grep -q -- "$option" <<<"$text" || { echo "$c: $option missing"; status=1; }
done
grep -q -- "--working-space" <<<"$text" || { echo "--working-space missing"; status=1; }
exit $status
