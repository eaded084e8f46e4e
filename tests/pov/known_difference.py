#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A POV-Ray tier scene with a few documented pixels where POV-Ray 3.7 itself is wrong (the
scene's header comment and docs/validation.md, "Known differences", show the exact arithmetic):
`whitted check` must fail it on the cap rule alone, and exactly those pixels must be beyond the
cap. Every other pixel must still be under it, and the share rule must hold; if the pixels ever
agree, this test fails too, so that the scene moves back to the plain list.
Usage: known_difference.py WHITTED SCENE REPORT_DIR X,Y [X,Y ...]   (at most 10 pixels: the
report lists the 10 worst)"""

import json
import os
import subprocess
import sys


def main():
    whitted, scene, report = sys.argv[1:4]
    expected = {tuple(int(v) for v in pixel.split(",")) for pixel in sys.argv[4:]}
    if not 1 <= len(expected) <= 10:
        sys.exit("usage: known_difference.py WHITTED SCENE REPORT_DIR X,Y [X,Y ...] (1 to 10 pixels)")
    run = subprocess.run([whitted, "check", scene, "--report", report], capture_output=True, text=True, timeout=120)
    print(run.stdout, run.stderr, sep="", end="")
    problems = []
    if run.returncode == 0:
        problems.append(f"the check passed: the known difference at {sorted(expected)} is gone; list the scene "
                        "with the others in tests/pov/CMakeLists.txt and drop it from docs/validation.md")
    elif run.returncode != 1:
        problems.append(f"the check could not be made (exit {run.returncode})")
    else:
        with open(os.path.join(report, "metrics.json")) as f:
            metrics = json.load(f)
        cap = metrics["max_error_cap_codes"]
        if metrics["failed_rules"] != ["cap"]:
            problems.append(f"rules failed: {metrics['failed_rules']}, expected only the cap")
        worst = metrics["worst_pixels"]
        beyond = {(p["x"], p["y"]) for p in worst if p["error_codes"] > cap}
        if beyond != expected:
            problems.append(f"pixels beyond the cap: {sorted(beyond)}, expected {sorted(expected)}")
        if len(beyond) == len(worst):
            problems.append("every listed worst pixel is beyond the cap, so there may be more than listed")
    for problem in problems:
        print("FAIL " + problem)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
