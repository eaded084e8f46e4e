#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Tests of NFF scenes (docs/nff.md).

  nff_test.py same WHITTED SCENE WORK          render SCENE.nff and (convert SCENE.nff -> .yaml)
      and require the same floats, bit for bit: the conversion keeps every value.
  nff_test.py check WHITTED SCENE WORK         `whitted check SCENE` against POV-Ray by the strict
      rule (docs/validation.md), at the scene's own size.
  nff_test.py corpus WHITTED CORPUS_DIR NAME WORK   the SPD database CORPUS_DIR/NAME.nff: it
      renders, its YAML conversion renders the same floats, and `whitted check` passes. Skipped
      (exit 77) with the reason when the corpus is absent: it is data kept outside the repository.

The linear EXR is read back by tests/course/course_test.py's reader (32-bit floats, exact)."""

import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import SKIP, fresh_folder, read_exr, run  # noqa: E402  (tests/harness.py)


def fresh(work):
    fresh_folder(work)


def same(whitted, scene, work):
    fresh(work)
    name = os.path.splitext(os.path.basename(scene))[0]
    yaml_path = os.path.join(work, name + ".yaml")
    run([whitted, "convert", scene, yaml_path])
    images = []
    for source, tag in ((scene, "nff"), (yaml_path, "yaml")):
        exr = os.path.join(work, f"{name}-{tag}.exr")
        run([whitted, "render", source, "-o", exr, "-q"])
        images.append(read_exr(exr))
    if images[0] != images[1]:
        sys.exit(f"FAIL {name}: render({os.path.basename(scene)}) and render(convert -> {name}.yaml) differ")
    width, height, rows = images[0]
    background = rows[0][0]
    drawn = sum(1 for row in rows for pixel in row if pixel != background)
    if drawn < width * height // 20:
        sys.exit(f"FAIL {name}: only {drawn} of {width * height} pixels differ from the corner's colour")
    print(f"{name}: the NFF and its YAML conversion render the same {width}x{height} floats ({drawn} pixels drawn)")


# Pixels a database may have beyond the cap, and why (docs/validation.md, "Known differences").
# Nothing else may differ: the share rule and every other rule still hold.
EXACT_TIES = {
    # The top faces of neighbouring gears overlap in the plane z = 1 (their teeth interpenetrate):
    # a ray through the overlap meets both at exactly the same distance, a tie between two meshes
    # of different colours, which POV-Ray breaks by its own order of testing objects; two more
    # pixels see such a tie through a transparent gear.
    "gears": 4,
}


def check(whitted, scene, work, allowed_ties=0):
    fresh(work)
    report = os.path.join(work, "report")
    result = subprocess.run([whitted, "check", scene, "--report", report], capture_output=True, text=True,
                            timeout=900)
    verdict = [line for line in result.stdout.splitlines() if line.startswith(("PASS", "FAIL"))]
    print("\n".join(verdict) if verdict else result.stdout[-2000:] + result.stderr[-2000:])
    if result.returncode == 0 and verdict and verdict[-1].startswith("PASS"):
        return
    if allowed_ties and result.returncode == 1:
        with open(os.path.join(report, "metrics.json")) as f:
            metrics = json.load(f)
        beyond = metrics["pixels"] - metrics["pixels_within"]
        if metrics["failed_rules"] == ["cap"] and beyond <= allowed_ties:
            print(f"{os.path.basename(scene)}: {beyond} pixel(s) beyond the cap, the known exact ties "
                  f"(at most {allowed_ties}); every other rule holds")
            return
    sys.exit(f"FAIL {scene}: whitted check did not pass (exit {result.returncode})")


def corpus(whitted, corpus_dir, name, work):
    scene = os.path.join(corpus_dir, name + ".nff")
    if not os.path.isfile(scene):
        print(f"SKIP {name}: the SPD corpus is not at {corpus_dir} (../shared/corpora/spd beside the checkout)")
        sys.exit(SKIP)
    same(whitted, scene, os.path.join(work, "same"))
    check(whitted, scene, os.path.join(work, "check"), EXACT_TIES.get(name, 0))


def main():
    modes = {"same": (same, 3), "check": (check, 3), "corpus": (corpus, 4)}
    if len(sys.argv) < 2 or sys.argv[1] not in modes or len(sys.argv) != 2 + modes[sys.argv[1]][1]:
        sys.exit(__doc__)
    function, _ = modes[sys.argv[1]]
    function(*sys.argv[2:])


if __name__ == "__main__":
    main()
