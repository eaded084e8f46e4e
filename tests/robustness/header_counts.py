#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A count in a file's header is a claim, not memory (docs/robustness.md): a course .msh file
whose header claims the most vertices or triangles the reader allows (3 × 64 Mi, 64 Mi), with
almost nothing after it, must fail at once with "the file ends early" naming the file, in about
the memory of a tiny render. The program maps the pages of large blocks when it allocates them
(renderer/app/large_blocks.cpp): a reservation sized by the header alone took 2.4 GB and 1.2 s.
Usage: header_counts.py WHITTED"""

import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures  # noqa: E402  (tests/harness.py)

COURSE = """<?xml version="1.0" encoding="UTF-8" ?>
<scene>
  <camera><viewPoint>0 0 5</viewPoint><viewWidth>2</viewWidth><viewHeight>2</viewHeight></camera>
  <image>8 8</image>
  <shader name="green" type="Lambertian"><diffuseColor>.2 1 .3</diffuseColor></shader>
  <surface type="Mesh"><shader ref="green"/><data>claim.msh</data></surface>
</scene>
"""
MOST_TRIANGLES = 64 << 20
# Far above a failed 8×8 render (about 15 MB), far below the claims (0.8–2.4 GB).
MOST_KB = 200 * 1024
CASES = {
    "vertices": f"{3 * MOST_TRIANGLES}\n1\nvertices\n0 0 0\n",
    "triangles": f"3\n{MOST_TRIANGLES}\nvertices\n0 0 0 1 0 0 0 1 0\ntriangles\n0 1 2\n",
    "normals": f"{3 * MOST_TRIANGLES}\n1\nnormals\n0 0 1\n",
}


def peak_kb(command, cwd):
    """Runs COMMAND in a child of its own and returns (CompletedProcess, its peak resident kB)."""
    probe = ("import resource, subprocess, sys\n"
             "r = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
             "sys.stdout.write(f'{r.returncode}\\n{resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss}\\n')\n"
             "sys.stdout.write(r.stderr)\n")
    out = subprocess.run([sys.executable, "-c", probe, *command], cwd=cwd, capture_output=True, text=True,
                         timeout=60).stdout.split("\n", 2)
    return int(out[0]), int(out[1]), out[2]


def main():
    whitted = os.path.abspath(sys.argv[1])
    failures = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-header-") as d:
        with open(os.path.join(d, "scene.xml"), "w", encoding="utf-8") as f:
            f.write(COURSE)
        for name, text in CASES.items():
            with open(os.path.join(d, "claim.msh"), "w", encoding="utf-8") as f:
                f.write(text)
            code, kb, stderr = peak_kb([whitted, "render", "scene.xml", "-o", "out.png", "-q"], d)
            print(f"{name}: exit {code}, peak {kb / 1024:.0f} MB: {stderr.strip()[:200]}")
            failures.check(code == 2, f"{name}: exit {code}, expected 2")
            failures.check("claim.msh" in stderr and "ends early" in stderr,
                           f"{name}: the message names claim.msh and says the file ends early")
            failures.check(kb < MOST_KB, f"{name}: peak {kb} kB, expected under {MOST_KB} kB")
            failures.check(not os.path.exists(os.path.join(d, "out.png")), f"{name}: no image written")
    failures.finish()


if __name__ == "__main__":
    main()
