# SPDX-License-Identifier: MIT
# Bash completion for `whitted` (installed as share/bash-completion/completions/whitted).
# Subcommands, options and the choices of an option come from the program's own --help at the
# moment of completion, so this file never goes out of date with the program; only scene file
# names (by extension) are known here.

# The option lines of `whitted [SUBCOMMAND] --help`: "NAMES<TAB>CHOICES", e.g.
# "-o,--output<TAB>" or "--exr-compression<TAB>none,zip,zips,piz,rle".
_whitted_option_lines() {
  "$@" --help 2>/dev/null | awk '
    /^Options:/ { in_options = 1; next }
    /^[^ ]/ { in_options = 0 }
    in_options && /^  -/ {
      names = $1; choices = ""
      if (match($2, /:\{[^}]*\}/)) choices = substr($2, RSTART + 2, RLENGTH - 3)
      print names "\t" choices
    }'
}

_whitted() {
  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD - 1]}
  local program=${COMP_WORDS[0]} subcommand="" i line names choices
  COMPREPLY=()
  # The subcommand is the first word that is not an option (the program's own options take no value).
  for ((i = 1; i < COMP_CWORD; i++)); do
    case ${COMP_WORDS[i]} in
      -*) ;;
      *) subcommand=${COMP_WORDS[i]}; break ;;
    esac
  done

  if [[ -z $subcommand ]]; then
    if [[ $cur == -* ]]; then
      COMPREPLY=($(compgen -W "--help --version" -- "$cur"))
    else
      local subcommands
      subcommands=$("$program" --help 2>/dev/null | awk '
        /^Subcommands:/ { in_list = 1; next }
        /^[^ ]/ { in_list = 0 }
        in_list && /^  [a-z]/ { sub(/^  /, ""); split($0, words, /  +/); gsub(/,/, " ", words[1]); print words[1] }')
      COMPREPLY=($(compgen -W "$subcommands" -- "$cur"))
    fi
    return 0
  fi

  local options=() all_choices=""
  while IFS=$'\t' read -r names choices; do
    options+=(${names//,/ })
    if [[ -n $choices && ",$names," == *",$prev,"* ]]; then
      all_choices=${choices//,/ }
    fi
  done < <(_whitted_option_lines "$program" "$subcommand")

  if [[ -n $all_choices ]]; then
    COMPREPLY=($(compgen -W "$all_choices" -- "$cur"))
    return 0
  fi
  if [[ $cur == -* ]]; then
    COMPREPLY=($(compgen -W "${options[*]}" -- "$cur"))
    return 0
  fi
  case $prev in
    -o | --output | --report | --ocio-config | --write-config | --povray-image)
      compopt -o filenames 2>/dev/null
      COMPREPLY=($(compgen -f -- "$cur"))
      return 0
      ;;
  esac
  # A scene (or, for compare, an image): the files whose extension whitted reads, and folders.
  compopt -o filenames 2>/dev/null
  local file
  while IFS= read -r file; do
    if [[ -d $file ]]; then
      COMPREPLY+=("$file")
    else
      case ${file,,} in
        *.yaml | *.yml | *.json | *.xml | *.nff | *.exr | *.png | *.jpg | *.jpeg | *.tif | *.tiff) COMPREPLY+=("$file") ;;
      esac
    fi
  done < <(compgen -f -- "$cur")
  return 0
}
complete -F _whitted whitted
