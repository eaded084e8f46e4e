#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Re-makes the image tier's references with POV-Ray 3.7: for every scene in scenes.txt (or
# only the scene names given), ref/<name>.png is POV-Ray's own output, unmodified.
#
#   tests/image/update_references.sh BUILD_DIR [name ...]      e.g. build
#
# How each reference is made: `whitted check SCENE --report DIR` converts the scene (exactly
# what `whitted convert` writes, at a power-of-two exposure <= 1 when the scene has values
# above 1) and runs POV-Ray on it (private $HOME, the command line of reference/povray.cpp),
# which writes DIR/povray-16bit.png: linear (File_Gamma 1) 16-bit RGB, samples*W x samples*H.
# That file is copied byte for byte to ref/<name>.png, and ref/references.txt records the
# exposure it was made at, its SHA-256 and the POV-Ray version. The check must PASS (Whitted
# agrees with POV-Ray under the pass rule) or nothing is copied for that scene: a reference
# Whitted does not match today would only make a failing test.
set -euo pipefail

if [[ $# -lt 1 || "$1" == -h || "$1" == --help ]]; then
  sed -n '3,15p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
build_dir=$(cd "$1" && pwd)
shift
whitted="$build_dir/bin/whitted"
[[ -x "$whitted" ]] || { echo "update_references.sh: no $whitted; build first" >&2; exit 2; }
povray=${WHITTED_POVRAY:-povray}
command -v "$povray" >/dev/null || { echo "update_references.sh: POV-Ray 3.7 ($povray) is required" >&2; exit 2; }

here=$(cd "$(dirname "$0")" && pwd)
mapfile -t scenes < <(grep -v '^#' "$here/scenes.txt" | grep -v '^[[:space:]]*$')
mkdir -p "$here/ref"
manifest="$here/ref/references.txt"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/home"  # POV-Ray wants a writable $HOME; a private one, as check gives it
povray_version=$(HOME="$work/home" "$povray" --version 2>&1 | grep -m1 -o 'POV-Ray [0-9][0-9A-Za-z.]*' || true)
[[ -n "$povray_version" ]] || { echo "update_references.sh: cannot tell $povray's version" >&2; exit 2; }

# The manifest's old rows, kept for the scenes not re-made now.
declare -A row
if [[ -f "$manifest" ]]; then
  while read -r name rest; do
    [[ -z "$name" || "$name" == \#* ]] || row[$name]="$name $rest"
  done <"$manifest"
fi

made=() changed=() failed=()
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .yaml)
  if [[ $# -gt 0 ]] && ! printf '%s\n' "$@" | grep -qx "$name"; then continue; fi
  made+=("$name")
  if ! "$whitted" check -q "$here/$scene" --report "$work/$name"; then
    failed+=("$name")
    continue
  fi
  exposure=$(/usr/bin/python3 -c 'import json,sys; print(repr(json.load(open(sys.argv[1]))["exposure"]))' \
    "$work/$name/metrics.json")
  png="$work/$name/povray-16bit.png"
  # Leave a reference with the same pixels at the same exposure untouched, so git shows only
  # real changes (POV-Ray's PNG holds its render date, so the bytes always differ).
  old_exposure=$(set -- ${row[$name]:-}; echo "${2:-}")
  if [[ -f "$here/ref/$name.png" && "$old_exposure" == "$exposure" ]] &&
    "$whitted" compare --tolerance 0 --min-fraction 1 --max-error 0 "$png" "$here/ref/$name.png" >/dev/null; then
    echo "unchanged ref/$name.png"
    continue
  fi
  cp "$png" "$here/ref/$name.png"
  row[$name]="$name $exposure $(sha256sum "$png" | cut -d' ' -f1) $povray_version"
  changed+=("$name")
  echo "CHANGED   ref/$name.png"
done
[[ ${#made[@]} -gt 0 ]] || { echo "update_references.sh: no scene matched '$*'" >&2; exit 2; }

{
  echo "# Written by update_references.sh; one row per ref/<name>.png, which is POV-Ray's own output,"
  echo "# unmodified: name, the exposure its scene was converted at, the file's SHA-256 (the test"
  echo "# checks it), and the POV-Ray that rendered it."
  for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .yaml)
    [[ -n "${row[$name]:-}" ]] && echo "${row[$name]}"
  done
} >"$manifest"

if [[ ${#failed[@]} -gt 0 ]]; then
  echo
  echo "NOT UPDATED: these scenes disagree with POV-Ray (or POV-Ray could not run):" >&2
  printf '  %s\n' "${failed[@]}" >&2
  echo "Investigate with: $whitted check <scene> --report DIR" >&2
  exit 1
fi
echo
echo "Changed references: ${changed[*]:-none}. Say in the commit message why they changed."
