# Bash completion for facetfit: subcommands, then each one's options, read from the command's own help
# (so that it follows the command as it is). Installed to share/bash-completion/completions/facetfit;
# from a build: source share/facetfit-completion.bash.
_facetfit() {
  local cur=${COMP_WORDS[COMP_CWORD]} cmd="" word
  for word in "${COMP_WORDS[@]:1:COMP_CWORD-1}"; do
    [[ $word == -* ]] || { cmd=$word; break; }
  done
  local help
  if [[ -z $cmd ]]; then
    help=$("${COMP_WORDS[0]}" --help 2>/dev/null)
    if [[ $cur != -* ]]; then
      # The subcommands: the first word of each line under "Subcommands:".
      COMPREPLY=($(compgen -W "$(sed -n '/^Subcommands:/,$s/^  \([a-z-]*\) .*/\1/p' <<<"$help") help" -- "$cur"))
      return
    fi
  else
    help=$("${COMP_WORDS[0]}" "$cmd" --help 2>/dev/null)
    if [[ $cur != -* ]]; then
      COMPREPLY=($(compgen -f -- "$cur"))  # inputs, LUTs, scenes, folders
      return
    fi
  fi
  COMPREPLY=($(compgen -W "$(grep -oE -- '--[a-z0-9-]+' <<<"$help" | sort -u)" -- "$cur"))
}
complete -o filenames -F _facetfit facetfit
