#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A plane normal and a light direction of length 4.9e-324 are directions like any other
(docs/scene-format.md): the scene renders exactly as with unit vectors (whitted compare
--tolerance 0), and converts to POV-Ray (no NaN). Usage: denormal_directions.py WHITTED SCENE WORK"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import fail, run  # noqa: E402  (tests/harness.py)

whitted, scene, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
with open(scene) as f:
    text = f.read()
unit = os.path.join(work, "unit.yaml")
with open(unit, "w") as f:
    f.write(text.replace("[0, -4.9e-324, 0]", "[0, -1, 0]").replace("[0, 4.9e-324, 0]", "[0, 1, 0]"))
for source, out in ((scene, "denormal.exr"), (unit, "unit.exr")):
    run([whitted, "render", source, "-o", os.path.join(work, out), "-q"])
run([whitted, "compare", os.path.join(work, "denormal.exr"), os.path.join(work, "unit.exr"), "--tolerance", "0"])
run([whitted, "convert", scene, os.path.join(work, "denormal.pov")])
with open(os.path.join(work, "denormal.pov")) as f:
    if "nan" in f.read().lower():
        fail("the POV-Ray scene holds a NaN")
print("denormal directions: the same pixels as unit vectors, and a POV-Ray scene without NaN")
