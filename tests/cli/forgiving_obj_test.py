#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""OBJ/MTL files as other readers forgive them (docs/scene-format.md, "OBJ and MTL files"): a
`usemtl` naming a material no MTL file defines (or one whose MTL file is missing), and an MTL
statement before any `newmtl`, render (exit 0) with a warning naming FILE:LINE:COL; the faces
of an undefined material get the default material (kd 0.6 grey: equal channels where lit).

Usage: forgiving_obj_test.py WHITTED CASES_DIR WORK_DIR
"""
import os
import shutil
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

whitted, cases, work = sys.argv[1:4]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []

expected = {
    "mtl_missing_file.yaml": "mtl_missing_file.obj:5:8: material 'red' is not defined: the MTL file "
                             "'nothing_here.mtl' (mtllib at ",
    "mtl_usemtl_unknown.yaml": "mtl_usemtl_unknown.obj:5:8: material 'blue' is not defined in 'known.mtl'",
    "mtl_kd_before_newmtl.yaml": "bad_order.mtl:1:1: Kd before any newmtl belongs to no material; it is left out",
}
for scene, fragment in expected.items():
    output = os.path.join(work, scene.replace(".yaml", ".exr"))
    result = subprocess.run([whitted, "render", os.path.join(cases, scene), "-q", "-o", output],
                            capture_output=True, text=True)
    if result.returncode != 0:
        failures.append(f"{scene}: exit {result.returncode}: {result.stderr}")
        continue
    if f"whitted: warning: " not in result.stderr or fragment not in result.stderr:
        failures.append(f"{scene}: the warning lacks '{fragment}': {result.stderr!r}")
    if scene == "mtl_kd_before_newmtl.yaml":
        continue  # its face has material x, which the MTL file defines (without the Kd before it)
    image = oiio.ImageInput.open(output).read_image(format="float")
    # The triangle (0,0,0) (1,0,0) (0,1,0) faces the camera on +z; what covers the image centre
    # region's lower left is lit by the scene's light at n.l > 0: a grey pixel (r = g = b > 0).
    lit = image[np.all(image > 0, axis=-1)]
    if len(lit) == 0 or not np.all(np.isclose(lit[:, 0], lit[:, 1])) or not np.all(np.isclose(lit[:, 1], lit[:, 2])):
        failures.append(f"{scene}: the faces are not drawn in the grey default material")

if failures:
    print("FAIL:\n" + "\n".join(failures))
    sys.exit(1)
print("PASS: undefined materials, missing MTL files and statements before newmtl render with a warning")
