#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Re-renders the image tier's references, ref/<name>.exr, with Whitted for every scene in
# scenes.txt (or only the scene names given as arguments).
#
#   tests/image/update_references.sh BUILD_DIR [name ...]      e.g. build, or build-pov
#
# A reference is only as good as the render it was made from. THESE FILES MUST BE REVIEWED
# BEFORE THEY ARE COMMITTED: every scene is then cross-checked against POV-Ray with
# `whitted check` (2/65535 per channel on >= 99.9 % of pixels), and the script stops with an
# error if POV-Ray is missing or a check fails. Look at the images too. References are never
# rendered with POV-Ray itself: comparing with POV-Ray is the pov tier's job; this tier pins
# Whitted's own output.
set -euo pipefail

if [[ $# -lt 1 || "$1" == -h || "$1" == --help ]]; then
  sed -n '3,13p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
build_dir=$(cd "$1" && pwd)
shift
whitted="$build_dir/bin/whitted"
[[ -x "$whitted" ]] || { echo "update_references.sh: no $whitted; build first" >&2; exit 2; }
for tool in oiiotool idiff; do
  command -v $tool >/dev/null || { echo "update_references.sh: $tool (OpenImageIO tools) is required" >&2; exit 2; }
done

here=$(cd "$(dirname "$0")" && pwd)
mapfile -t scenes < <(grep -v '^#' "$here/scenes.txt" | grep -v '^[[:space:]]*$')
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

rendered=() changed=() failed=()
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .yaml)
  if [[ $# -gt 0 ]] && ! printf '%s\n' "$@" | grep -qx "$name"; then continue; fi
  "$whitted" render -q "$here/$scene" -o "$work/$name.exr"
  rendered+=("$name")
  # Leave a reference whose pixels did not change untouched, so git shows only real changes.
  if [[ -f "$here/ref/$name.exr" ]] && idiff -q -fail 0 -warn 0 "$work/$name.exr" "$here/ref/$name.exr" >/dev/null; then
    echo "unchanged ref/$name.exr"
    continue
  fi
  # Float (half would lose the 2e-5 tolerance), zip, and without the metadata that changes on
  # every render (absolute scene path, ray counts, timing).
  oiiotool --nosoftwareattrib "$work/$name.exr" --eraseattrib "whitted:scene" \
    --eraseattrib "whitted:rays" --eraseattrib "whitted:render_seconds" \
    -d float --compression zip -o "$here/ref/$name.exr"
  changed+=("$name")
  echo "CHANGED   ref/$name.exr"
done
[[ ${#rendered[@]} -gt 0 ]] || { echo "update_references.sh: no scene matched '$*'" >&2; exit 2; }

echo
echo "REVIEW REQUIRED: a reference is Whitted's own output; it is only correct if Whitted is."
echo "Cross-checking every rendered scene against POV-Ray (whitted check) ..."
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .yaml)
  printf '%s\n' "${rendered[@]}" | grep -qx "$name" || continue
  if ! "$whitted" check -q "$here/$scene" --report "$work/check-$name"; then failed+=("$name"); fi
done
if [[ ${#failed[@]} -gt 0 ]]; then
  echo
  echo "DO NOT COMMIT: these scenes disagree with POV-Ray (or POV-Ray could not run):" >&2
  printf '  %s\n' "${failed[@]}" >&2
  echo "Investigate with: $whitted check <scene> --report DIR" >&2
  exit 1
fi
echo
echo "All rendered scenes agree with POV-Ray. Changed references: ${changed[*]:-none}."
echo "Look at each changed one (e.g. oiiotool ref/NAME.exr -o /tmp/NAME.png) and say in the commit"
echo "message why it changed."
