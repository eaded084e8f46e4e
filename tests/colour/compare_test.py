#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted compare` knows what it compares (docs/colour.md): a linear EXR against the same
render written through each display (sRGB, Gamma 2.2, BT.1886, Display P3, Raw; PNG, TIFF, JPEG)
passes, because both are turned into linear Rec.709 from their metadata, and it says so for each
file; within the quantisation of the display-referred file only, so a wrong decoding (display
codes taken as light, or the wrong curve) fails. A file whose values are no known transfer
function (a view of a config of our own with a square-root curve) is refused with exit 2.

Usage: compare_test.py WHITTED EXAMPLES_DIR"""
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

whitted, examples = sys.argv[1], sys.argv[2]
failures = Failures()
env = dict(os.environ)
env.pop("OCIO", None)


def whitted_in(work, args, expect=0):
    """whitted ARGS in WORK, without $OCIO; an exit status but EXPECT (None: any) is a failure."""
    if expect is None:
        return run([whitted] + args, None, timeout=120, cwd=work, env=env)
    return failures.run([whitted] + args, expect, timeout=120, cwd=work, env=env)


# A display with a square-root curve: a plain power law, but none Whitted recognises.
SQRT_CONFIG = """ocio_profile_version: 2
roles:
  default: lin
  scene_linear: lin
file_rules:
  - !<Rule> {name: Default, colorspace: lin}
displays:
  Odd:
    - !<View> {name: Root, colorspace: root}
colorspaces:
  - !<ColorSpace>
    name: lin
  - !<ColorSpace>
    name: root
    from_scene_reference: !<ExponentTransform> {value: [0.5, 0.5, 0.5, 1]}
"""

with tempfile.TemporaryDirectory() as work:
    scene = os.path.join(examples, "lecture", "09-glazed-floor.yaml")
    run([whitted, "render", scene, "-q", "-o", "linear.exr"], timeout=120, cwd=work, env=env)
    # file, extra options, tolerance in 16-bit codes: half an 8-bit code times the largest slope of
    # the decoding (2.4 for the 2.4 power law; P3's matrix adds up to 1.45 times that), or 3
    # 16-bit codes in a 16-bit file (half a code of rounding times the slope, and OCIO's own).
    cases = [
        ("srgb.png", ["--display", "sRGB"], 320),
        ("gamma22.png", ["--display", "Gamma 2.2"], 320),
        ("bt1886.png", ["--display", "BT.1886"], 320),
        ("p3.png", ["--display", "Display P3"], 480),
        ("raw16.png", ["--view", "Raw", "--bit-depth", "16"], 2),
        ("srgb16.tif", ["--display", "sRGB"], 3),
        ("p3-16.tif", ["--display", "Display P3"], 3),
        ("gamma22-8.tif", ["--display", "Gamma 2.2", "--bit-depth", "8"], 320),
        # JPEG is lossy: within 3000 codes for 99 % of the pixels (most are far closer), and no
        # pixel off by more than a quarter of the range (the pass rule's cap, --max-error).
        ("srgb.jpg", ["--display", "sRGB"], 3000, 0.99, 16384),
    ]
    for name, options, tolerance, *rest in cases:
        fraction = str(rest[0] if rest else 1)
        # Where every pixel must be within the tolerance, the cap on any one pixel is the same.
        cap = str(rest[1] if len(rest) > 1 else max(tolerance, 64))
        if whitted_in(work, ["render", scene, "-q", "-o", name] + options).returncode != 0:
            continue
        result = whitted_in(work, ["compare", "linear.exr", name, "--clip", "--tolerance", str(tolerance),
                                   "--min-fraction", fraction, "--max-error", cap])
        out = result.stdout
        if result.returncode != 0:
            print(out)
        elif "linear.exr: linear, Rec.709 primaries" not in out or "used as it is" not in out:
            failures.fail(f"{name}: compare does not say the EXR is used as it is:\n{out}")
        elif not any(line.startswith(f"{name}: ") and line.endswith(
                "used as it is" if "Raw" in options else "converted to linear Rec.709") for line in out.splitlines()):
            failures.fail(f"{name}: compare does not say what it did with the file:\n{out}")
        else:
            print(f"ok   {name}: {out.strip().splitlines()[-1]}")
        # Tighter than the file's quantisation allows must fail: the tolerance above is earned.
        whitted_in(work, ["compare", "linear.exr", name, "--clip", "--tolerance", str(tolerance / 8), "--min-fraction",
                          fraction, "--max-error", cap], expect=1)

    with open(os.path.join(work, "root.ocio"), "w") as f:
        f.write(SQRT_CONFIG)
    if whitted_in(work, ["render", scene, "-q", "-o", "root.png", "--ocio-config", "root.ocio"]).returncode == 0:
        result = whitted_in(work, ["compare", "linear.exr", "root.png"], expect=None)
        if result.returncode != 2 or "whitted: error: cannot compare 'root.png'" not in result.stderr:
            failures.fail(f"root.png: compare exit {result.returncode}, not 2 with a reason: {result.stderr.strip()}")
        else:
            print(f"ok   root.png refused: {result.stderr.strip()}")

failures.finish()
