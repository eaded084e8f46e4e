#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A POV-Ray tier scene with one documented pixel where POV-Ray 3.7 itself departs from its
own rules (the scene's header comment and docs/validation.md, "Known differences"): `whitted
check` must fail it on the cap rule alone and only because of that pixel. Every other pixel
must still be under the cap, and the share rule must hold; if the pixel ever agrees, this test
fails too, so that the scene moves back to the plain list.
Usage: known_difference.py WHITTED SCENE REPORT_DIR X,Y"""

import json
import os
import subprocess
import sys


def main():
    whitted, scene, report, pixel = sys.argv[1:5]
    x, y = (int(v) for v in pixel.split(","))
    run = subprocess.run([whitted, "check", scene, "--report", report], capture_output=True, text=True, timeout=120)
    print(run.stdout, run.stderr, sep="", end="")
    problems = []
    if run.returncode == 0:
        problems.append(f"the check passed: the known difference at ({x}, {y}) is gone; list the scene with the "
                        "others in tests/pov/CMakeLists.txt and drop it from docs/validation.md")
    elif run.returncode != 1:
        problems.append(f"the check could not be made (exit {run.returncode})")
    else:
        with open(os.path.join(report, "metrics.json")) as f:
            metrics = json.load(f)
        worst = metrics["worst_pixels"]
        if metrics["failed_rules"] != ["cap"]:
            problems.append(f"rules failed: {metrics['failed_rules']}, expected only the cap")
        if not worst or (worst[0]["x"], worst[0]["y"]) != (x, y):
            problems.append(f"the worst pixel is {worst[:1]}, expected ({x}, {y})")
        if len(worst) > 1 and worst[1]["error_codes"] > metrics["max_error_cap_codes"]:
            problems.append(f"a second pixel is beyond the cap: {worst[1]}")
    for problem in problems:
        print("FAIL " + problem)
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
