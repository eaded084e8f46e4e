#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The installed package, as docs/library.md tells a user to use it: `cmake --install` into a
# fresh prefix under the build tree, then examples/library built out of tree against it twice,
# with find_package(Whitted 0.2) and with pkg-config, and run: it renders a scene built in code
# and checks its centre pixel against the lecture's formula (exit 0 only when it is right).
# Also: the installed `whitted` finds the plug-in next to libwhitted.so, and its EXR matches the
# consumer's, which writes the same scene through api::write_image.
# The module goes where Debian's python3 looks under a prefix that is not /usr:
# lib/python3.X/dist-packages (site.getsitepackages names it for the prefix).
# Usage: consumer_test.sh BUILD_DIR SOURCE_DIR LIBDIR [PYTHON_MODULE=ON|OFF]
set -euo pipefail
build=$1 source=$2 libdir=$3 python_module=${4:-ON}
work="$build/library-test"
rm -rf "$work"
mkdir -p "$work"
prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" >"$work/install.log"
for f in include/whitted/whitted.h include/whitted/image.h include/whitted/progress.h include/whitted/version.h \
         "$libdir/cmake/Whitted/WhittedConfig.cmake" "$libdir/cmake/Whitted/WhittedConfigVersion.cmake" \
         "$libdir/pkgconfig/whitted.pc" bin/whitted "$libdir/libwhitted_oiio.so" \
         "$libdir/libwhitted_live.so" "$libdir/libwhitted_exr.so" "$libdir/libwhitted_tiff.so" "$libdir/libwhitted_jpeg.so" \
         "$libdir/libwhitted_ocio.so"; do
  [ -e "$prefix/$f" ] || { echo "FAIL: $f not installed"; exit 1; }
done
ls "$prefix/$libdir/libwhitted.so.0.2" >/dev/null

echo "== find_package(Whitted 0.2) build"
cmake -S "$source/examples/library" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release >"$work/consumer.configure.log" || { cat "$work/consumer.configure.log"; exit 1; }
cmake --build "$work/consumer" >"$work/consumer.build.log" || { cat "$work/consumer.build.log"; exit 1; }
# $WHITTED_TEST_PRELOAD: the ASan runtime in a sanitizer build (CMakeLists.txt), for the
# uninstrumented programs that load our instrumented library; empty otherwise.
with_runtime() { LD_PRELOAD="${WHITTED_TEST_PRELOAD:-${LD_PRELOAD:-}}" "$@"; }
with_runtime "$work/consumer/one_sphere" "$work/consumer.exr"

echo "== a version the package does not promise is refused: find_package(Whitted 0.3)"
mkdir -p "$work/wrong_version"
cat >"$work/wrong_version/CMakeLists.txt" <<'CMAKE'
cmake_minimum_required(VERSION 3.25)
project(wrong LANGUAGES CXX)
find_package(Whitted 0.3 REQUIRED)
CMAKE
if cmake -S "$work/wrong_version" -B "$work/wrong_version/build" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null 2>&1; then
  echo "FAIL: find_package(Whitted 0.3) accepted version 0.2"; exit 1
fi

echo "== pkg-config build"
export PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig"
[ "$(pkg-config --modversion whitted)" = "$("$prefix/bin/whitted" --version | head -n 1 | cut -d' ' -f2)" ] ||
  { echo "FAIL: pkg-config version differs from whitted --version"; exit 1; }
# shellcheck disable=SC2046
c++ -O2 -o "$work/one_sphere_pc" "$source/examples/library/one_sphere.cpp" $(pkg-config --cflags --libs whitted) \
  -Wl,-rpath,"$prefix/$libdir"
with_runtime "$work/one_sphere_pc"

echo "== the installed program and the plug-in beside the library"
# Not the build tree's plug-in: the installed one, found from PREFIX/bin/whitted.
"$prefix/bin/whitted" compare "$work/consumer.exr" "$work/consumer.exr" --tolerance 0 --max-error 0
echo "== the installed Python module, and the plug-in found beside the installed libwhitted.so"
python=${WHITTED_TEST_PYTHON:-/usr/bin/python3}
if [ "$python_module" = OFF ]; then
  echo "(built with -DWHITTED_BUILD_PYTHON=OFF: no Python module to check)"
else
  site=$("$python" -c 'import site, sys; print(site.getsitepackages([sys.argv[1]])[-1])' "$prefix")
  [ -d "$site" ] || { echo "FAIL: no Python module installed under $site, where $python looks under $prefix"; exit 1; }
  PYTHONPATH="$site" with_runtime "$python" - "$prefix" "$work/consumer.exr" <<'PY'
import sys
import numpy as np
import whitted
prefix, exr = sys.argv[1], sys.argv[2]
assert whitted.__file__.startswith(prefix), whitted.__file__
scene = (whitted.SceneBuilder().image(65, 65).background([0.25, 0.5, 0.75])
         .camera([0, 0, 5], [0, 0, 0], fov=30).ambient([0.5] * 3).point_light([0, 0, 5], [0.8] * 3)
         .sphere([0, 0, 0], 1, {"ka": [0.2, 0.1, 0.05], "kd": [0.5, 0.25, 0.125]}).build())
image = whitted.render(scene, threads=2)
# The same scene as one_sphere's, so the same pixels as the EXR it wrote through the C++ API.
whitted.write_image(image, exr + ".py.exr")
maps = open("/proc/self/maps").read()
assert prefix + "/lib/" in maps and "libwhitted.so" in maps, "libwhitted.so not loaded from the prefix"
print("python: module and libwhitted.so from the prefix")
PY
  # Bit for bit, through the installed plug-in (whitted compare loads it).
  "$prefix/bin/whitted" compare "$work/consumer.exr" "$work/consumer.exr.py.exr" --tolerance 0 --max-error 0
fi
echo "PASS"
