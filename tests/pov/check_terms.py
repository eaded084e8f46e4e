#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted check --terms` (docs/validation.md) against a live POV-Ray 3.7:

    check_terms.py WHITTED SCENE_DIR OUT_DIR

1. phong_blinn_mixed.yaml (ambient, diffuse, both highlight kinds, two lights): every term
   (ambient, diffuse, specular, light 1, light 2) is checked alone and agrees; exit 0.
2. The same with POV-Ray behind a wrapper that brightens its image by 0.01 only when the scene
   it renders has light 2 alone: exit 1, and the verdict names light 2 as the term that
   disagrees and the others as agreeing. So a failing term is found and named.
3. examples/meshes/meshes.yaml, whose meshes take their materials from an MTL file: refused,
   exit 2, naming the object's FILE:LINE:COL, before POV-Ray runs.
Like the rest of the pov tier, this needs POV-Ray and fails without it."""

import os
import re
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import fail, run  # noqa: E402  (tests/harness.py)

WRAPPER = r'''#!/usr/bin/python3
# Runs POV-Ray on the .ini given; brightens the image when the scene has only the light at <3, 3, 5>.
import os, re, subprocess, sys
ini = sys.argv[1]
code = subprocess.run([POVRAY, ini]).returncode
if code != 0:
    sys.exit(code)
text = open(ini).read()
here = os.path.dirname(os.path.abspath(ini))
pov = os.path.join(here, re.search(r'Input_File_Name="?([^"\n]*)', text).group(1))
out = os.path.join(here, re.search(r'Output_File_Name="?([^"\n]*)', text).group(1))
scene = open(pov).read()
if scene.count("light_source") == 1 and "<3, 3, 5>" in scene:
    subprocess.run(["oiiotool", out, "--addc", "0.01", "-d", "uint16", "-o", out], check=True)
'''


def main():
    whitted, scene_dir, out_dir = sys.argv[1:4]
    os.makedirs(out_dir, exist_ok=True)
    scene = os.path.join(scene_dir, "phong_blinn_mixed.yaml")
    terms = ["ambient", "diffuse", "specular", "light 1", "light 2"]

    result = run([whitted, "check", scene, "--terms", "-q"])
    for term in terms:
        if not re.search(rf"^PASS .*\[{term} only\]", result.stdout, re.M):
            fail(f"no PASS line for the term '{term}':\n{result.stdout}")
    last = result.stdout.strip().splitlines()[-1]
    if not last.startswith("whitted check --terms") or "PASS" not in last or ", ".join(terms) not in last:
        fail(f"last line should say every term passed: {last}")
    print(f"ok real POV-Ray: {last}")

    povray = shutil.which("povray")
    if not povray:
        fail("povray not found")
    wrapper = os.path.join(out_dir, "povray")
    with open(wrapper, "w") as f:
        f.write(WRAPPER.replace("POVRAY", repr(povray)))
    os.chmod(wrapper, 0o755)
    env = dict(os.environ, WHITTED_POVRAY=wrapper)
    result = run([whitted, "check", scene, "--terms", "-q"], expect=1, env=env)
    last = result.stdout.strip().splitlines()[-1]
    want = "FAIL: light 2 disagrees with POV-Ray (ambient, diffuse, specular, light 1 agree)"
    if want not in last:
        fail(f"the verdict should be '{want}', got: {last}")
    if not re.search(r"^FAIL .*\[light 2 only\]", result.stdout, re.M):
        fail(f"no FAIL line for light 2:\n{result.stdout}")
    print(f"ok light 2 made to disagree: {last}")

    meshes = os.path.join(scene_dir, "..", "..", "examples", "meshes", "meshes.yaml")
    result = run([whitted, "check", meshes, "--terms", "-q"], expect=2)
    want = "meshes.yaml:49:9: check --terms: this mesh takes its materials from the MTL file of 'icosphere.obj'"
    if want not in result.stderr:
        fail(f"MTL materials: stderr: {result.stderr}")
    print("ok MTL materials refused: exit 2 with the object's place")


if __name__ == "__main__":
    main()
