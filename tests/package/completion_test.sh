#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The bash completion (renderer/app/whitted.bash) driven as bash drives it: COMP_WORDS and
# COMP_CWORD set, _whitted called, COMPREPLY read. What it must offer is taken from the
# program's --help here too, so the test holds the completion to the program, not to a list.
#   completion_test.sh WHITTED COMPLETION_FILE WORK_DIR
set -uo pipefail
program=$1 completion=$2 work=$3
rm -rf "$work" && mkdir -p "$work/bin" "$work/files/scenes" && cd "$work/files" || exit 1
ln -s "$program" "$work/bin/whitted"
PATH="$work/bin:$PATH"
touch a.yaml b.YML c.json d.xml e.nff f.exr notes.txt image.png
# shellcheck source=/dev/null
source "$completion" || { echo "FAIL: sourcing $completion"; exit 1; }
complete -p whitted >/dev/null || { echo "FAIL: no completion registered for whitted"; exit 1; }

failures=0
complete_words() {  # words...: COMPREPLY, sorted, on one line
  COMP_WORDS=("$@")
  COMP_CWORD=$((${#COMP_WORDS[@]} - 1))
  COMPREPLY=()
  _whitted
  printf '%s\n' "${COMPREPLY[@]}" | sort | tr '\n' ' ' | sed 's/ $//'
}
expect() {  # expected, words...
  local expected=$1
  shift
  local got
  got=$(complete_words "$@")
  if [ "$got" = "$expected" ]; then
    echo "ok   [$*] -> $got"
  else
    echo "FAIL [$*]: expected '$expected', got '$got'"
    failures=$((failures + 1))
  fi
}

# Subcommands: the names --help lists (aliases too), and only those.
subcommands=$(whitted --help | awk '/^Subcommands:/ { f = 1; next } /^[^ ]/ { f = 0 }
  f && /^  [a-z]/ { sub(/^  /, ""); split($0, w, /  +/); gsub(/,/, " ", w[1]); print w[1] }' | tr ' ' '\n' |
  grep . | sort | tr '\n' ' ' | sed 's/ $//')
[ -n "$subcommands" ] && [[ " $subcommands " == *" render "* ]] || { echo "FAIL: no subcommands in --help"; exit 1; }
expect "$subcommands" whitted ""
expect "render" whitted re
expect "--help --version" whitted --
# Every option of every subcommand, as its --help prints it, and the prefix narrowing them.
for sub in $subcommands; do
  options=$(whitted "$sub" --help | awk '/^Options:/ { f = 1; next } /^[^ ]/ { f = 0 } f && /^  -/ { print $1 }' |
    tr ',' '\n' | grep . | sort | tr '\n' ' ' | sed 's/ $//')
  [ -n "$options" ] || { echo "FAIL: no options in 'whitted $sub --help'"; failures=$((failures + 1)); continue; }
  expect "$options" whitted "$sub" -
done
expect "--width" whitted render --wi
expect "--width" whitted -q render --wi 2>/dev/null || true
# An option's choices, from its {a,b,c} in --help.
expect "none piz rle zip zips" whitted render --exr-compression ""
expect "exact povray" whitted render --intersection ""
expect "povray" whitted render --intersection p
# A scene: the extensions whitted reads (any case) and folders, not other files.
expect "a.yaml b.YML c.json d.xml e.nff f.exr image.png scenes" whitted render ""
expect "a.yaml" whitted render a
# An output: any file.
expect "a.yaml b.YML c.json d.xml e.nff f.exr image.png notes.txt scenes" whitted render a.yaml -o ""

if [ "$failures" -gt 0 ]; then
  echo "$failures case(s) failed"
  exit 1
fi
echo "all cases passed"
