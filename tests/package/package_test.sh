#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The Debian package as cpack makes it from this build (cmake/WhittedInstall.cmake): its control
# fields, its files, and the installed tree used in place (dpkg-deb -x into a folder, no root
# needed): the program finds its plug-in and names its docs there, the Python module imports
# from there with its library, the man page renders without warnings and holds every option of
# every subcommand, the completion registers. scripts/check-front-door installs the same package
# with apt-get into a bare Debian 12 root.
#   package_test.sh BUILD_DIR SOURCE_DIR VERSION PYTHON WORK_DIR
set -euo pipefail
build=$1 source=$2 version=$3 python=$4 work=$5
rm -rf "$work" && mkdir -p "$work"
fail() { echo "FAIL: $*"; exit 1; }

cpack -G DEB --config "$build/CPackConfig.cmake" -B "$work/out" >"$work/cpack.log" 2>&1 ||
  { cat "$work/cpack.log"; fail "cpack"; }
arch=$(dpkg --print-architecture)
deb="$work/out/whitted_${version}_${arch}.deb"
[ -f "$deb" ] || fail "no $deb (cpack made: $(ls "$work/out"))"
echo "package: $(basename "$deb"), $(stat -c %s "$deb") bytes"

# --- control fields -----------------------------------------------------------------------------
field() { dpkg-deb -f "$deb" "$1"; }
[ "$(field Package)" = whitted ] || fail "Package: $(field Package)"
[ "$(field Version)" = "$version" ] || fail "Version: $(field Version), the project's is $version"
[ "$(field Architecture)" = "$arch" ] || fail "Architecture: $(field Architecture)"
depends=$(field Depends)
# Computed by dpkg-shlibdeps from what the binaries link: each library the program needs at run
# time must be there with the package that ships it.
multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || gcc -print-multiarch)
for library in libembree3.so libtbb.so libOpenImageIO.so libOpenColorIO.so libOpenEXR; do
  path=$(ldconfig -p | awk -v l="$library" 'index($1, l) == 1 && !found { print $NF; found = 1 }')
  [ -n "$path" ] || fail "$library is not installed here"
  owner=$(dpkg -S "$(readlink -f "$path")" 2>/dev/null | head -n 1 | cut -d: -f1)
  [[ ", $depends" == *", $owner "* || ", $depends," == *", $owner,"* ]] ||
    fail "Depends lacks $owner (ships $library): $depends"
done
for package in python3-numpy "python3 (>= "; do
  [[ "$depends" == *"$package"* ]] || fail "Depends lacks $package: $depends"
done
[[ "$(field Recommends)" == *povray* ]] || fail "Recommends lacks povray: $(field Recommends)"

# --- files ----------------------------------------------------------------------------------------
dpkg-deb -c "$deb" | awk '{ print $6 }' | sed 's|^\./|/|' >"$work/files.txt"
python_version=$("$python" -c 'import sys; print(f"{sys.version_info[0]}{sys.version_info[1]}")')
for f in /usr/bin/whitted \
  "/usr/lib/$multiarch/libwhitted.so.${version%.*}" "/usr/lib/$multiarch/libwhitted_oiio.so" \
  "/usr/lib/$multiarch/libwhitted_exr.so" "/usr/lib/$multiarch/libwhitted_tiff.so" \
  "/usr/lib/$multiarch/libwhitted_jpeg.so" "/usr/lib/$multiarch/libwhitted_ocio.so" \
  "/usr/lib/$multiarch/cmake/Whitted/WhittedConfig.cmake" "/usr/lib/$multiarch/pkgconfig/whitted.pc" \
  /usr/include/whitted/whitted.h \
  "/usr/lib/python3/dist-packages/whitted.cpython-$python_version-$multiarch.so" \
  /usr/share/blender/scripts/addons/whitted_blender/__init__.py \
  /usr/share/man/man1/whitted.1.gz /usr/share/bash-completion/completions/whitted \
  /usr/share/doc/whitted/copyright /usr/share/doc/whitted/README.md \
  /usr/share/whitted/docs/scene-format.md /usr/share/whitted/docs/scene.schema.json \
  /usr/share/whitted/examples/lecture/01-lambertian-sphere.yaml; do
  grep -qxF "$f" "$work/files.txt" || fail "$f is not in the package"
done
# Every doc and example of the source tree is in it (not a hand-kept list).
(cd "$source" && find docs examples -type f) | while read -r f; do
  grep -qxF "/usr/share/whitted/$f" "$work/files.txt" || fail "$f is not in the package"
done
if grep -E '/(build|tmp|work)/|__pycache__|\.pyc$' "$work/files.txt"; then fail "stray files in the package"; fi

# --- the tree, used where it was unpacked --------------------------------------------------------
tree="$work/tree"
dpkg-deb -x "$deb" "$tree"
program="$tree/usr/bin/whitted"
"$program" --version | head -n 1 | grep -qx "whitted $version" || fail "--version: $("$program" --version)"
"$program" --help | tail -n 1 | grep -qF "are in $tree/usr/share/whitted/." ||
  fail "--help does not name the installed docs: $("$program" --help | tail -n 1)"
# A PNG needs the OpenColorIO plug-in (its sRGB display transform), which the program loads from
# beside its libraries.
(cd "$work" && "$program" render "$tree/usr/share/whitted/examples/lecture/01-lambertian-sphere.yaml" \
  --width 64 -q -o sphere.png) || fail "render to PNG from the unpacked tree"
[ "$(od -An -tx1 -N4 "$work/sphere.png" | tr -d ' ')" = 89504e47 ] || fail "sphere.png is not a PNG"

PYTHONPATH="$tree/usr/lib/python3/dist-packages" "$python" - "$tree" <<'PY' || fail "the Python module from the unpacked tree"
import sys
tree = sys.argv[1]
import whitted
assert whitted.__file__.startswith(tree), whitted.__file__
maps = open("/proc/self/maps").read()
assert tree + "/usr/lib/" in maps and "libwhitted.so" in maps, "libwhitted.so not loaded from the tree"
image = whitted.render(whitted.load(tree + "/usr/share/whitted/examples/lecture/01-lambertian-sphere.yaml", width=32))
assert image.shape[1] == 32 and image.max() > 0, image.shape
print("python: module, libwhitted.so and a render from the unpacked tree")
PY

# The man page: renders with no groff warning, and holds each option of each subcommand.
zcat "$tree/usr/share/man/man1/whitted.1.gz" >"$work/whitted.1"
groff -man -ww -Tutf8 -z "$work/whitted.1" 2>"$work/groff.log" || fail "groff failed: $(cat "$work/groff.log")"
[ ! -s "$work/groff.log" ] || fail "groff warnings: $(cat "$work/groff.log")"
groff -man -Tutf8 "$work/whitted.1" 2>/dev/null | sed 's/.\x08//g' >"$work/whitted.txt"
grep -qF "/usr/share/whitted/docs/" "$work/whitted.txt" || fail "the man page does not name /usr/share/whitted/docs/"
for sub in render explain convert check colour compare; do
  grep -q "whitted $sub\$" "$work/whitted.txt" || fail "man page: no section for $sub"
  for option in $("$program" "$sub" --help | awk '/^Options:/ { f = 1; next } /^[^ ]/ { f = 0 } f && /^  -/ { print $1 }' | tr ',' ' '); do
    grep -qF -- "$option" "$work/whitted.txt" || fail "man page lacks $sub $option"
  done
done
# The completion registers for whitted.
bash -c "source '$tree/usr/share/bash-completion/completions/whitted' && complete -p whitted" >/dev/null ||
  fail "the completion does not register"
echo "package test passed"
