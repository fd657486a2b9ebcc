#!/usr/bin/env bash
# make-man.sh FACETFIT OUT.1: the manual page facetfit(1), by help2man from `facetfit --help` and
# `--version`, with every subcommand's own help as its section COMMANDS. Written through a temporary file.
set -euo pipefail
facetfit=$1 out=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
commands=$("$facetfit" --help | sed -n '/^Subcommands:/,$p' | awk 'NR > 1 && NF { print $1 }')
{
  echo "[COMMANDS]"
  for c in $commands; do
    echo ".SS \"facetfit $c\""
    echo ".nf"
    # roff: a leading dot or quote would be read as a request, a backslash as an escape.
    "$facetfit" "$c" --help | sed -e 's/\\/\\e/g' -e "s/^\([.']\)/\\\\\&\1/"
    echo ".fi"
  done
  cat <<'TEXT'
[EXIT STATUS]
0 success; 1 some input failed (a batch goes on past it); 2 usage (a bad flag or value); 3 report
\-\-fail\-on\-regression found regressions.
[ENVIRONMENT]
.TP
.B OCIO
the OpenColorIO config that names working spaces and views, unless \-\-ocio\-config is given.
.TP
.B FACETFIT_RGL_DIR
where the tests find the RGL database.
[SEE ALSO]
The documentation in docs/ of the facetfit sources: README.md, docs/commands.md, docs/lut-format.md, docs/scene-format.md,
docs/colour.md.
TEXT
} > "$work/include"
help2man --no-info --no-discard-stderr --section 1 --name "measured BRDFs to microfacet components, LUT textures and renders" \
  --include "$work/include" --output "$work/facetfit.1" "$facetfit"
mv "$work/facetfit.1" "$out"
