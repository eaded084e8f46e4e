#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Embree is loaded when a run first makes a BVH (renderer/src/render/embree_library.cpp,
docs/performance.md "Start-up"): the program does not load it at start-up; a scene of a few
spheres, boxes and cones on few rays is traced without a BVH and never loads it (--stats says
so), while a mesh loads it; and where the library found first is no Embree (a file that is not
a library, a library without Embree's functions), the scene without a BVH still renders, and a
scene that needs one is refused with a message naming Embree and its Debian package, exit 1,
leaving no file and an existing one as it was.

usage: embree_loading_test.py WHITTED WORK_DIR NOT_EMBREE_LIBRARY
"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures  # noqa: E402  (tests/harness.py)

whitted, work, not_embree = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = Failures()
check = failures.check

linked = subprocess.run([whitted], env={**os.environ, "LD_TRACE_LOADED_OBJECTS": "1"}, capture_output=True,
                        text=True).stdout
check("libembree3" not in linked, "the program does not load Embree at start-up")

# One sphere on a 16 × 12 image: no BVH. Two triangles: a BVH.
sphere = os.path.join(work, "sphere.nff")
with open(sphere, "w") as f:
    f.write("v\nfrom 0 0 -5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 16 12\nb 0.1 0.1 0.1\n"
            "l 5 5 -5\nf 1 0.2 0.2 0.8 0.3 20 0 1\ns 0 0 0 1\n")
square = os.path.join(work, "square.nff")
with open(square, "w") as f:
    f.write("v\nfrom 0 0 -5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 16 12\nb 0.1 0.1 0.1\n"
            "l 5 5 -5\nf 1 0.2 0.2 0.8 0.3 20 0 1\np 4\n-1 -1 0\n1 -1 0\n1 1 0\n-1 1 0\n")


def render(scene, out, env=None):
    return subprocess.run([whitted, "render", scene, "-o", out, "--stats"],
                          env={**os.environ, "LD_DEBUG": "files", **(env or {})}, capture_output=True, text=True,
                          timeout=120)


r = render(sphere, os.path.join(work, "sphere.png"))
check(r.returncode == 0, f"the sphere renders: exit {r.returncode}, {r.stderr[-300:]!r}")
check("libembree3" not in r.stderr, "the sphere's render does not load Embree (LD_DEBUG=files)")
check("no BVH" in r.stderr, "--stats says the sphere is traced without a BVH")
r = render(square, os.path.join(work, "square.png"))
check(r.returncode == 0, f"the square renders: exit {r.returncode}, {r.stderr[-300:]!r}")
check("libembree3" in r.stderr, "the square's render loads Embree")
check("Embree (its choice)" in r.stderr, "--stats names Embree for the square")

# Something else first on the library path where Embree should be.
garbage = os.path.join(work, "garbage")
os.makedirs(garbage)
with open(os.path.join(garbage, "libembree3.so.3"), "w") as f:
    f.write("not a library\n")
other = os.path.join(work, "other")
os.makedirs(other)
shutil.copy(not_embree, os.path.join(other, "libembree3.so.3"))
for name, directory, words in (("a file that is not a library", garbage, "cannot load Embree"),
                               ("a library without Embree's functions", other, "has no rtc")):
    env = {"LD_LIBRARY_PATH": directory + ":" + os.environ.get("LD_LIBRARY_PATH", "")}
    out = os.path.join(work, f"sphere-{os.path.basename(directory)}.png")
    r = render(sphere, out, env)
    check(r.returncode == 0 and os.path.getsize(out) > 0,
          f"{name} in Embree's place: the sphere still renders (exit {r.returncode}, {r.stderr[-300:]!r})")
    out = os.path.join(work, f"square-{os.path.basename(directory)}.png")
    r = render(square, out, env)
    message = [line for line in r.stderr.splitlines() if line.startswith("whitted: error:")]
    check(r.returncode == 1, f"{name}: the square is refused with exit 1 (exit {r.returncode})")
    check(len(message) == 1 and words in message[0] and "libembree3-3" in message[0],
          f"{name}: one error naming Embree and its package: {message!r}")
    check(not os.path.exists(out), f"{name}: no file is left")
    leftovers = [p for p in os.listdir(work) if ".whitted-" in p]
    check(not leftovers, f"{name}: no temporary file is left: {leftovers}")
    kept = os.path.join(work, "kept.png")
    with open(kept, "w") as f:
        f.write("an earlier image\n")
    r = render(square, kept, env)
    check(r.returncode == 1, f"{name}: over an existing file, exit 1 (exit {r.returncode})")
    with open(kept) as f:
        check(f.read() == "an earlier image\n", f"{name}: an existing file is left as it was")

failures.finish("PASSED: Embree is loaded by the runs that make a BVH, and only by them")
