#!/usr/bin/env bash
# completion.sh FACETFIT SOURCE_DIR: the bash completion (share/facetfit-completion.bash) completes
# subcommands, a subcommand's own options, and the global options, from the command's help.
set -euo pipefail
facetfit=$1
source "$2/share/facetfit-completion.bash"
complete_of() { COMP_WORDS=("$facetfit" "$@"); COMP_CWORD=$#; _facetfit; echo "${COMPREPLY[*]}"; }
status=0
expect() { local got; got=$(complete_of "${@:2}"); [[ $got == "$1" ]] || { echo "FAIL: ${*:2} -> '$got', expected '$1'"; status=1; }; }
expect "bake" b
expect "render report" re
expect "--tolerance" bake --to
expect "--material --material-type" render --mat
expect "--refine --resolution" -q fit --re
expect "--threads" --th
exit $status
