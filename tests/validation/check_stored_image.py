#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted check --povray-image FILE --exposure E` (what the image tier runs) must fail for
each way a stored POV-Ray image can be the wrong one, and never run POV-Ray.

    check_stored_image.py WHITTED SOURCE_DIR

SOURCE_DIR is the project's root: the stored images are tests/image/ref/*.png (POV-Ray's own)
and their exposures tests/image/ref/references.txt.
"""

import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)


def main():
    whitted, root = sys.argv[1:3]
    pov = os.path.join(root, "tests", "pov")
    ref = os.path.join(root, "tests", "image", "ref")
    exposures = {}
    for line in open(os.path.join(ref, "references.txt")):
        if line.strip() and not line.startswith("#"):
            fields = line.split()
            exposures[fields[0]] = fields[1]
    env = dict(os.environ, WHITTED_POVRAY="/nonexistent/povray")  # POV-Ray must not be needed
    problems = Failures()

    def check(name, args, status, text):
        r = run([whitted, "check", "-q", *args], expect=None, timeout=60, env=env)
        out = r.stdout + r.stderr
        problems.check(r.returncode == status and text in out,
                       f"{name}: exit {r.returncode} (want {status} and {text!r} in the output), {out.strip()[-160:]!r}")

    scene = lambda n: os.path.join(pov, n + ".yaml")
    png = lambda n: os.path.join(ref, n + ".png")
    e = exposures["values_above_1"]
    problems.require(float(e) < 1, "values_above_1 should need an exposure below 1")
    check("right image, right exposure", [scene("values_above_1"), "--povray-image", png("values_above_1"),
                                          "--exposure", e], 0, "PASS")
    check("right image, twice the exposure", [scene("values_above_1"), "--povray-image", png("values_above_1"),
                                              "--exposure", repr(2 * float(e))], 1, "failed: share")
    check("another scene's image of the same size", [scene("orthographic"), "--povray-image", png("glazed_floor"),
                                                     "--exposure", exposures["glazed_floor"]], 1, "failed: share")
    check("image.samples 2 without the 2x image", [scene("samples_2"), "--povray-image", png("orthographic")], 1,
          "failed: size (192x144 vs 96x72)")
    check("--exposure without --povray-image", [scene("orthographic"), "--exposure", "0.5"], 2, "requires")
    check("no such image", [scene("orthographic"), "--povray-image", "/nonexistent.png"], 2, "")

    # Clipped: a stored image that is 65535 everywhere, where Whitted's is 0.25. Written by
    # Whitted's 16-bit PNG output of a background far above 1 (the display transform clips it).
    with tempfile.TemporaryDirectory() as tmp:
        bright, dark = os.path.join(tmp, "bright.yaml"), os.path.join(tmp, "dark.yaml")
        for path, value in ((bright, 50), (dark, 0.25)):
            with open(path, "w") as f:
                f.write(f"version: 1\ncamera: {{eye: [0, 0, 5], look_at: [0, 0, 0]}}\n"
                        f"image: {{width: 5, height: 3, background: [{value}, {value}, {value}]}}\n")
        white = os.path.join(tmp, "white.png")
        run([whitted, "render", "-q", bright, "-o", white, "--bit-depth", "16"], timeout=60)
        check("a stored image that clipped", [dark, "--povray-image", white], 1, "clipped")

    problems.finish()


if __name__ == "__main__":
    main()
