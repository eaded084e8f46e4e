#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""OBJ/MTL files as other readers forgive them (docs/scene-format.md, "OBJ and MTL files"): a
`usemtl` naming a material no MTL file defines (or one whose MTL file is missing), and an MTL
statement before any `newmtl`, render (exit 0) with a warning naming FILE:LINE:COL; the faces
of an undefined material get the default material (kd 0.6 grey: equal channels where lit).

Usage: forgiving_obj_test.py WHITTED CASES_DIR WORK_DIR
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fresh_folder, read_pixels  # noqa: E402  (tests/harness.py)

whitted, cases, work = sys.argv[1:4]
fresh_folder(work)
failures = Failures()

expected = {
    "mtl_missing_file.yaml": "mtl_missing_file.obj:5:8: material 'red' is not defined: the MTL file "
                             "'nothing_here.mtl' (mtllib at ",
    "mtl_usemtl_unknown.yaml": "mtl_usemtl_unknown.obj:5:8: material 'blue' is not defined in 'known.mtl'",
    "mtl_kd_before_newmtl.yaml": "bad_order.mtl:1:1: Kd before any newmtl belongs to no material; it is left out",
}
for scene, fragment in expected.items():
    output = os.path.join(work, scene.replace(".yaml", ".exr"))
    result = failures.run([whitted, "render", os.path.join(cases, scene), "-q", "-o", output])
    if result.returncode != 0:
        continue
    failures.check("whitted: warning: " in result.stderr and fragment in result.stderr,
                   f"{scene}: the warning says '{fragment}': {result.stderr!r}")
    if scene == "mtl_kd_before_newmtl.yaml":
        continue  # its face has material x, which the MTL file defines (without the Kd before it)
    image = read_pixels(output)
    # The triangle (0,0,0) (1,0,0) (0,1,0) faces the camera on +z; what covers the image centre
    # region's lower left is lit by the scene's light at n.l > 0: a grey pixel (r = g = b > 0).
    lit = image[np.all(image > 0, axis=-1)]
    failures.check(len(lit) > 0 and np.all(np.isclose(lit[:, 0], lit[:, 1])) and np.all(np.isclose(lit[:, 1], lit[:, 2])),
                   f"{scene}: the faces are drawn in the grey default material")

failures.finish("PASS: undefined materials, missing MTL files and statements before newmtl render with a warning")
