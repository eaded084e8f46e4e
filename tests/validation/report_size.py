#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""The size of a `whitted check --report` folder for a 640x480 image (docs/validation.md, "Reading
a report"): tests/pov/three_coloured_lights.yaml at 640x480, checked against the real POV-Ray;
every file's size is printed and the total must stay under BOUND bytes.

usage: report_size.py WHITTED SOURCE_DIR"""
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import fail, run  # noqa: E402  (tests/harness.py)

BOUND = 6_500_000  # measured 5.9 MB; the uncompressed EXRs or the raw floats in report-data.js break it


def main():
    if len(sys.argv) != 3:
        print(__doc__)
        sys.exit(2)
    whitted, source = sys.argv[1:]
    with open(os.path.join(source, "tests", "pov", "three_coloured_lights.yaml")) as f:
        scene = f.read()
    if "image: { width: 96, height: 72 }" not in scene:
        fail("three_coloured_lights.yaml no longer has the image line this test resizes")
    with tempfile.TemporaryDirectory(prefix="whitted-report-size-") as d:
        path = os.path.join(d, "scene.yaml")
        with open(path, "w") as f:
            f.write(scene.replace("image: { width: 96, height: 72 }", "image: { width: 640, height: 480 }"))
        report = os.path.join(d, "report")
        print(run([whitted, "check", path, "-q", "--report", report], timeout=300,
                  env=dict(os.environ, HOME=d)).stdout, end="")
        total = 0
        for name in sorted(os.listdir(report)):
            size = os.path.getsize(os.path.join(report, name))
            total += size
            print(f"{size:>10}  {name}")
        print(f"{total:>10}  total (bound {BOUND})")
        if total > BOUND:
            fail(f"the 640x480 report is {total} bytes, more than {BOUND}")


if __name__ == "__main__":
    main()
