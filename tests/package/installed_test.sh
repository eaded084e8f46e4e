#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The Debian package as a newcomer uses it: run by scripts/check-front-door as root in a bare
# Debian 12 root into which `apt-get install ./whitted_*.deb` (and nothing else of this
# repository) was installed. Each documented workflow from the installed files alone:
# render, convert, check against POV-Ray (a Recommends), compare, explain, the man page, the
# completion, the Python module, the C++ library through pkg-config, and, with Debian's Blender
# installed after it, the add-on enabled and rendering Blender's default scene.
#   installed_test.sh [--blender]
set -euo pipefail
fail() { echo "installed: FAIL: $*" >&2; exit 1; }
say() { echo "installed: $*" >&2; }
work=$(mktemp -d)
cd "$work"

command -v whitted >/dev/null || fail "no whitted on PATH"
examples=/usr/share/whitted/examples
[ -d "$examples/lecture" ] || fail "no $examples/lecture"
whitted --help | grep -qF "are in /usr/share/whitted/." || fail "--help does not name /usr/share/whitted"

scene="$examples/lecture/03-several-lights.yaml"
whitted render "$scene" -q -o several.png || fail "render to PNG"
whitted render "$scene" -q -o several.exr || fail "render to EXR"
[ "$(od -An -tx1 -N4 several.png | tr -d ' ')" = 89504e47 ] || fail "several.png is not a PNG"
say "render: PNG and EXR"
whitted explain "$scene" --pixel 10,10 --summary >explain.txt || fail "explain"
whitted convert "$scene" several.pov || fail "convert"
[ -s several.pov ] && [ -s several.ini ] || fail "convert wrote no .pov/.ini"
command -v povray >/dev/null || fail "povray (Recommends) was not installed with the package"
whitted check "$scene" -q --report report || fail "check against POV-Ray"
[ -s report/report.html ] && [ -s report/metrics.json ] || fail "check wrote no report"
whitted compare several.exr several.exr --tolerance 0 --max-error 0 >/dev/null || fail "compare"
say "explain, convert, check (report in report/), compare"

[ -s /usr/share/man/man1/whitted.1.gz ] || fail "no man page"
zcat /usr/share/man/man1/whitted.1.gz | grep -q '^\.TH WHITTED 1' || fail "the man page has no .TH"
bash -c 'source /usr/share/bash-completion/completions/whitted && complete -p whitted' >/dev/null ||
  fail "the completion does not register"

python3 - "$scene" <<'PY' || fail "the Python module"
import sys
import whitted
assert whitted.__file__.startswith("/usr/lib/python3/dist-packages/"), whitted.__file__
image = whitted.render(whitted.load(sys.argv[1], width=40))
assert image.shape[:2] == (30, 40) or image.shape[1] == 40, image.shape
assert image.max() > 0
whitted.write_image(image, "python.png")
print("installed: python: import whitted, render, write a PNG", file=sys.stderr)
PY

pkg-config --modversion whitted >/dev/null 2>&1 && say "pkg-config: whitted $(pkg-config --modversion whitted)" ||
  say "pkg-config not installed (not a dependency): the C++ library is checked by library.consumer"

if [ "${1:-}" = --blender ]; then
  command -v blender >/dev/null || fail "--blender: no blender installed"
  [ -f /usr/share/blender/scripts/addons/whitted_blender/__init__.py ] || fail "the add-on is not installed"
  cat >blender_render.py <<'PY'
import sys
import addon_utils
import bpy
addon_utils.enable("whitted_blender", default_set=True)
scene = bpy.context.scene
scene.render.engine = "WHITTED"
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 64, 48, 100
scene.render.filepath = sys.argv[-1]
scene.render.image_settings.file_format = "PNG"
bpy.ops.render.render(write_still=True)
PY
  blender -b --factory-startup --python blender_render.py -- "$work/blender.png" >blender.log 2>&1 ||
    { tail -n 20 blender.log >&2; fail "Blender with the add-on"; }
  [ -s blender.png ] || { tail -n 20 blender.log >&2; fail "Blender wrote no image through the add-on"; }
  say "blender: the add-on enabled and the default scene rendered through it"
fi
say "PASSED"
