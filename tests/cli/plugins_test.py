#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The plug-ins loaded when a run needs them (docs/performance.md, "Start-up"): the program
itself links none of OpenEXR, libtiff, libjpeg, OpenColorIO and the web server's OpenSSL; with
no plug-in to be found ($WHITTED_PLUGIN_DIR an empty directory) `whitted --version` still runs
and a PNG with the built-in colour config renders (the program computes that config itself),
while asking for EXR, TIFF, JPEG, a PNG through a config file (OpenColorIO's display transform)
or `whitted live` is a usage error (exit 2) naming the plug-in and what needs it, given before
any rendering and leaving no file; with OpenColorIO's plug-in alone a PNG through a config file
renders; neither an EXR nor a PNG with the built-in config loads OpenColorIO.

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

# The built-in config, written out by the program as it is: a config file for the runs below.
config = os.path.join(work, "builtin.ocio")
r = subprocess.run([whitted, "colour", "--write-config", config], capture_output=True, text=True, timeout=60)
check(r.returncode == 0 and os.path.exists(config), f"colour --write-config: exit {r.returncode}")

# With no plug-in at all, a PNG with the built-in config (every display and view) renders.
for display, view in (("sRGB", "Standard"), ("Display P3", "Standard"), ("Gamma 2.2", "Raw")):
    png = os.path.join(work, f"builtin-{display}-{view}.png".replace(" ", "_"))
    r = subprocess.run([whitted, "render", scene, "-o", png, "--quiet", "--display", display, "--view", view],
                       env=no_plugins, capture_output=True, text=True, timeout=60)
    check(r.returncode == 0 and os.path.exists(png) and os.path.getsize(png) > 0,
          f"PNG ({display}/{view}, built-in config) with no plug-in: exit {r.returncode}, {r.stderr.strip()!r}")

# OpenColorIO's plug-in alone (a link to the built one) is all a PNG through a config file needs.
ocio_only = os.path.join(work, "ocio-only")
os.makedirs(ocio_only)
built_plugins = os.path.join(os.path.dirname(os.path.dirname(os.path.realpath(whitted))), "lib")
os.symlink(os.path.join(built_plugins, "libwhitted_ocio.so"), os.path.join(ocio_only, "libwhitted_ocio.so"))
png = os.path.join(work, "rendered.png")
r = subprocess.run([whitted, "render", scene, "-o", png, "--quiet", "--ocio-config", config],
                   env={**os.environ, "WHITTED_PLUGIN_DIR": ocio_only}, capture_output=True, text=True, timeout=60)
check(r.returncode == 0 and os.path.exists(png) and os.path.getsize(png) > 0,
      f"PNG through a config file with OpenColorIO's plug-in alone: exit {r.returncode}, {r.stderr.strip()!r}")

# An EXR holds scene-linear floats, and the built-in config is the program's own: neither render
# maps OpenColorIO (the loader's own record); a config file does.
for out, writer, config_args, loads_ocio in (("linear.exr", "libwhitted_exr.so", [], False),
                                             ("builtin.png", None, [], False),
                                             ("from-file.png", None, ["--ocio-config", config], True)):
    out = os.path.join(work, out)
    r = subprocess.run([whitted, "render", scene, "-o", out, "--quiet", *config_args],
                       env={**os.environ, "LD_DEBUG": "files"}, capture_output=True, text=True, timeout=60)
    check(r.returncode == 0 and os.path.exists(out), f"{os.path.basename(out)}: exit {r.returncode}")
    if writer:
        check(writer in r.stderr, f"{os.path.basename(out)} loads {writer}")
    check(("libOpenColorIO" in r.stderr) == loads_ocio,
          f"{os.path.basename(out)} {'loads' if loads_ocio else 'does not load'} OpenColorIO")

for ext, plugin, words, extra in ((".png", "libwhitted_ocio.so", "--ocio-config", ["--ocio-config", config]),
                                  (".exr", "libwhitted_exr.so", ".exr files", []),
                                  (".tif", "libwhitted_tiff.so", ".tif files", []),
                                  (".jpg", "libwhitted_jpeg.so", ".jpg files", [])):
    out = os.path.join(work, "out" + ext)
    r = subprocess.run([whitted, "render", scene, "-o", out, "--stats", *extra], env=no_plugins, capture_output=True,
                       text=True, timeout=60)
    check(r.returncode == 2, f"{ext} {' '.join(extra)} with no plug-in: exit {r.returncode}")
    check(plugin in r.stderr and words in r.stderr and empty in r.stderr,
          f"{ext}: the message names {plugin}, {words} and where it looked: {r.stderr.strip()!r}")
    check("render" not in r.stdout.lower() and not os.path.exists(out), f"{ext}: refused before rendering, no file")

r = subprocess.run([whitted, "colour", "--list", "--ocio-config", config], env=no_plugins, capture_output=True,
                   text=True, timeout=60)
check(r.returncode == 2 and "libwhitted_ocio.so" in r.stderr and r.stdout == "",
      f"colour --list with no plug-in: exit {r.returncode}, {r.stderr.strip()!r}")

r = subprocess.run([whitted, "live", scene, "--no-open"], env=no_plugins, capture_output=True, text=True, timeout=60)
check(r.returncode == 2 and "libwhitted_live.so" in r.stderr and r.stdout == "",
      f"live with no plug-in: exit {r.returncode}, {r.stderr.strip()!r}")

failures.finish()
