#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `pip install .` as a user runs it (docs/library.md "pip"): into a fresh venv of Debian's python3
# (NumPy from python3-numpy through --system-site-packages; no network, hence --no-build-isolation
# --no-index), then, from outside the source tree and with the build directory deleted, the
# installed module imports, renders, writes a PNG, runs `check` (in its plug-in), and its metadata, files,
# RPATH and type stubs are what docs/library.md says. Then the error path: a CMake configure that
# fails stops pip with setup.py's message and installs nothing.
# Usage: pip_install_test.sh SOURCE_DIR WORK_DIR VERSION
set -euo pipefail
source_dir=$(cd "$1" && pwd)
work=$2
version=$3
python=/usr/bin/python3

fail() { echo "FAIL: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work/outside"
work=$(cd "$work" && pwd)
top_level_before=$(ls -A "$source_dir")

# ---- the install --------------------------------------------------------------------------
"$python" -m venv --system-site-packages "$work/venv"
venv_python=$work/venv/bin/python
unset PYTHONPATH
echo "pip install (its output: $work/pip.log)"
if ! WHITTED_PIP_BUILD_DIR=$work/build "$venv_python" -m pip install -v --no-build-isolation --no-index \
    "$source_dir" > "$work/pip.log" 2>&1; then
  tail -40 "$work/pip.log"
  fail "pip install failed"
fi
[[ "$(ls -A "$source_dir")" == "$top_level_before" ]] ||
  fail "pip install left files in the source tree: $(diff <(echo "$top_level_before") <(ls -A "$source_dir"))"
# The installed module must not need anything of the build.
rm -rf "$work/build"

site=$("$venv_python" -c 'import sysconfig; print(sysconfig.get_paths()["platlib"])')
module=$(ls "$site"/whitted.cpython-*.so)
# The plug-ins: OpenImageIO (check), the EXR/TIFF/JPEG writers and OpenColorIO's display transform.
for f in whitted.pyi whitted.libs/libwhitted_{oiio,exr,tiff,jpeg,ocio}.so; do
  [[ -f "$site/$f" ]] || fail "$site/$f not installed"
done
sonames=("$site"/whitted.libs/libwhitted.so.*)
[[ ${#sonames[@]} == 1 && -f ${sonames[0]} ]] || fail "not one libwhitted.so.M.m in $site/whitted.libs: ${sonames[*]}"
cmp -s "$site/whitted.pyi" "$source_dir/renderer/python/whitted.pyi" || fail "the installed whitted.pyi is not the source's"

# RPATH: the module finds the library beside it; no path of the build tree anywhere.
runpath=$(readelf -d "$module" | sed -n 's/.*(\(RPATH\|RUNPATH\)).*\[\(.*\)\]/\2/p')
[[ "$runpath" == '$ORIGIN/whitted.libs' ]] || fail "$module: RPATH/RUNPATH '$runpath', expected \$ORIGIN/whitted.libs"
for lib in "$site"/whitted.libs/*; do
  if readelf -d "$lib" | grep -E '\((RPATH|RUNPATH)\)'; then fail "$lib has an RPATH"; fi
done
if grep -rl "$work/build" "$module" "$site"/whitted.libs; then fail "the files above name the build directory"; fi

# Metadata.
"$venv_python" -m pip show -f whitted > "$work/show.txt"
cat "$work/show.txt"
grep -qx "Name: whitted" "$work/show.txt" || fail "pip show: no 'Name: whitted'"
grep -qx "Version: $version" "$work/show.txt" || fail "pip show: no 'Version: $version'"
grep -qx "Requires: numpy" "$work/show.txt" || fail "pip show: no 'Requires: numpy'"
grep -qx "License: MIT" "$work/show.txt" || fail "pip show: no 'License: MIT'"
for f in whitted.pyi "$(basename "$module")" whitted.libs/libwhitted_oiio.so "whitted.libs/$(basename "${sonames[0]}")"; do
  grep -qx "  $f" "$work/show.txt" || fail "pip show -f: $f is not among the installed files"
done
metadata=$(ls "$site"/whitted-"$version".dist-info/METADATA)
grep -qx "Requires-Dist: numpy" "$metadata" || fail "$metadata: no 'Requires-Dist: numpy'"

# Use, from outside the source tree, with no LD_LIBRARY_PATH.
cd "$work/outside"
env -u LD_LIBRARY_PATH -u WHITTED_PLUGIN_DIR "$venv_python" - "$site" "$version" \
    "$source_dir/examples/lecture/02-shadows.yaml" <<'EOF'
import os
import sys

import numpy as np

site, version, scene_file = sys.argv[1:]
import whitted

assert os.path.dirname(whitted.__file__) == site, whitted.__file__
assert whitted.__version__ == version, (whitted.__version__, version)
scene = whitted.load(scene_file, width=40, samples=1)
image = whitted.render(scene, threads=2)
assert image.shape == (scene.height, scene.width, 3) and scene.width == 40, image.shape
assert image.dtype == np.float32
assert np.isfinite(image).all() and image.max() > 0.05, image.max()
whitted.write_image(image, "shadows.png")
with open("shadows.png", "rb") as f:
    assert f.read(8) == b"\x89PNG\r\n\x1a\n"
# A config file goes through OpenColorIO, the plug-in beside the library (the built-in config
# needs none): the built-in config written out, then used by name.
whitted.write_colour_config("builtin.ocio")
whitted.write_image(image, "shadows-ocio.png", ocio_config="builtin.ocio", display="Display P3")
with open("shadows-ocio.png", "rb") as f:
    assert f.read(8) == b"\x89PNG\r\n\x1a\n"
# `check` runs in the OpenImageIO plug-in: a small copy of a lecture example against POV-Ray.
with open(scene_file.replace("02-shadows", "01-lambertian-sphere")) as f:
    text = f.read()
small = text.replace("width: 640", "width: 64").replace("height: 480", "height: 48")
assert small.count("width: 64\n") == 1 and small.count("height: 48\n") == 1, "the example changed"
with open("small.yaml", "w") as f:
    f.write(small)
result = whitted.check("small.yaml", threads=2)
assert isinstance(result, whitted.CheckResult) and result.verdict, result
with open("/proc/self/maps") as f:
    mapped = {line.split()[-1] for line in f if "libwhitted" in line}
libs = os.path.join(site, "whitted.libs")
assert mapped and all(os.path.dirname(p) == libs for p in mapped), mapped
assert any(p.endswith("libwhitted_oiio.so") for p in mapped), mapped
# The config file's PNG went through OpenColorIO's display transform, the plug-in beside the library.
assert any(p.endswith("libwhitted_ocio.so") for p in mapped), mapped
print("rendered", image.shape, "max", image.max(), "; check:", result.verdict, "; loaded", sorted(mapped))
EOF

# The installed stubs against the installed module.
WHITTED_STUB=$site/whitted.pyi "$venv_python" -m pytest -q -p no:cacheprovider --rootdir "$work/outside" \
  "$source_dir/tests/python/test_stub.py"

# ---- the error path: CMake's configure fails -------------------------------------------------
"$python" -m venv --system-site-packages "$work/venv-bad"
bad_python=$work/venv-bad/bin/python
if CMAKE_ARGS="-DCMAKE_CXX_COMPILER=/nonexistent/c++" WHITTED_PIP_BUILD_DIR=$work/build-bad \
    "$bad_python" -m pip install --no-build-isolation --no-index "$source_dir" > "$work/pip-bad.log" 2>&1; then
  fail "pip install succeeded with a compiler that does not exist"
fi
grep -q "whitted: CMake configure failed (exit 1); its messages are above" "$work/pip-bad.log" ||
  { cat "$work/pip-bad.log"; fail "no setup.py message for the failed configure"; }
grep -q "/nonexistent/c++" "$work/pip-bad.log" || { cat "$work/pip-bad.log"; fail "CMake's own error is not shown"; }
bad_site=$("$bad_python" -c 'import sysconfig; print(sysconfig.get_paths()["platlib"])')
if compgen -G "$bad_site/whitted*" > /dev/null; then fail "a failed install left $(ls -d "$bad_site"/whitted*)"; fi
if "$bad_python" -m pip show whitted > /dev/null 2>&1; then fail "pip show whitted after a failed install"; fi
echo "the failed install says:"
grep "whitted: CMake configure failed" "$work/pip-bad.log"
echo "PASS"
