#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The plug-ins loaded when a run needs them (docs/performance.md, "Start-up"): the program
itself links none of OpenEXR, libtiff, libjpeg, OpenColorIO and the web server's OpenSSL; with
no plug-in to be found ($WHITTED_PLUGIN_DIR an empty directory) `whitted --version` still runs,
and asking for EXR, TIFF, JPEG, a display-referred PNG (OpenColorIO's display
transform) or `whitted live` is a usage error (exit 2) naming the plug-in and the format, given
before any rendering and leaving no file; with the display transform's plug-in alone a PNG
renders, and an EXR render never loads OpenColorIO.

usage: plugins_test.py WHITTED WORK_DIR
"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures  # noqa: E402  (tests/harness.py)


whitted, work = sys.argv[1:3]
shutil.rmtree(work, ignore_errors=True)
empty = os.path.join(work, "no-plugins")
os.makedirs(empty)
failures = Failures()
check = failures.check


linked = subprocess.run([whitted], env={**os.environ, "LD_TRACE_LOADED_OBJECTS": "1"}, capture_output=True,
                        text=True).stdout
for library in ("libOpenEXR", "libtiff", "libjpeg", "libOpenColorIO", "libyaml-cpp", "libssl", "libcrypto",
                "libcpp-httplib"):
    check(library not in linked, f"the program does not load {library} at start-up")

scene = os.path.join(work, "sphere.nff")
with open(scene, "w") as f:
    f.write("v\nfrom 0 0 -5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 16 12\nb 0.1 0.1 0.1\n"
            "l 5 5 -5\nf 1 0.2 0.2 0.8 0.3 20 0 1\ns 0 0 0 1\n")
no_plugins = {**os.environ, "WHITTED_PLUGIN_DIR": empty}

r = subprocess.run([whitted, "--version"], env=no_plugins, capture_output=True, text=True, timeout=60)
check(r.returncode == 0 and r.stdout.startswith("whitted "), f"--version with no plug-in: exit {r.returncode}")

# The display transform's plug-in alone (a link to the built one) is all a PNG needs.
ocio_only = os.path.join(work, "ocio-only")
os.makedirs(ocio_only)
built_plugins = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(whitted))), "lib")
os.symlink(os.path.join(built_plugins, "libwhitted_ocio.so"), os.path.join(ocio_only, "libwhitted_ocio.so"))
png = os.path.join(work, "rendered.png")
r = subprocess.run([whitted, "render", scene, "-o", png, "--quiet"], env={**os.environ, "WHITTED_PLUGIN_DIR": ocio_only},
                   capture_output=True, text=True, timeout=60)
check(r.returncode == 0 and os.path.exists(png) and os.path.getsize(png) > 0,
      f"PNG with the display transform's plug-in alone: exit {r.returncode}, {r.stderr.strip()!r}")

# An EXR holds scene-linear floats: its render never maps OpenColorIO (the loader's own record).
exr = os.path.join(work, "linear.exr")
r = subprocess.run([whitted, "render", scene, "-o", exr, "--quiet"], env={**os.environ, "LD_DEBUG": "files"},
                   capture_output=True, text=True, timeout=60)
check(r.returncode == 0 and os.path.exists(exr), f"EXR render: exit {r.returncode}")
check("libwhitted_exr.so" in r.stderr and "libOpenColorIO" not in r.stderr,
      "an EXR render loads the EXR writer and not OpenColorIO")

for ext, plugin, format_words in ((".png", "libwhitted_ocio.so", ".png"),
                                  (".exr", "libwhitted_exr.so", ".exr files"),
                                  (".tif", "libwhitted_tiff.so", ".tif files"),
                                  (".jpg", "libwhitted_jpeg.so", ".jpg files")):
    out = os.path.join(work, "out" + ext)
    r = subprocess.run([whitted, "render", scene, "-o", out, "--stats"], env=no_plugins, capture_output=True,
                       text=True, timeout=60)
    check(r.returncode == 2, f"{ext} with no plug-in: exit {r.returncode}")
    check(plugin in r.stderr and format_words in r.stderr and empty in r.stderr,
          f"{ext}: the message names {plugin}, {format_words} and where it looked: {r.stderr.strip()!r}")
    check("render" not in r.stdout.lower() and not os.path.exists(out), f"{ext}: refused before rendering, no file")

r = subprocess.run([whitted, "live", scene, "--no-open"], env=no_plugins, capture_output=True, text=True, timeout=60)
check(r.returncode == 2 and "libwhitted_live.so" in r.stderr and r.stdout == "",
      f"live with no plug-in: exit {r.returncode}, {r.stderr.strip()!r}")

failures.finish()
