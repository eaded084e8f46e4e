#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The SPD benchmark's choice of the lights Tachyon would draw over the eye (bench/spd.py,
lights_at_the_eye): a light strictly nearer the eye ("from") than the hither distance, and only
those; the copy without them keeps every other line byte for byte.

  bench_spd_test.py rule WORK            on scenes written here from the NFF document's view
      entity: which distances are chosen, and the copy.
  bench_spd_test.py corpus CORPUS_DIR    on the seven SPD databases: gears' fifth light (0.034
      from the eye, hither 1) is the only one chosen. Skipped (exit 77) with the reason when the
      corpus is absent: it is data kept outside the repository."""

import os
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(here)), "bench"))
sys.path.insert(0, os.path.dirname(here))
import spd  # noqa: E402  (bench/spd.py)
from harness import SKIP, fresh_folder  # noqa: E402  (tests/harness.py)

VIEW = """b 0 0 0
v
from 0 0 -10
at 0 0 0
up 0 1 0
angle 45
hither {hither}
resolution 64 64
"""


def write(path, text):
    with open(path, "w") as f:
        f.write(text)
    return path


def expect(what, got, wanted):
    if got != wanted:
        sys.exit(f"FAIL {what}: {got!r}, expected {wanted!r}")


def rule(work):
    fresh_folder(work)

    # Distances from the eye (0, 0, -10) against hither 1: 0 (at the eye), 0.5 and 0.999 on
    # three axes are chosen; exactly 1, 1.001 and far are not.
    lights = ["l 0 0 -10", "l 0.5 0 -10", "l 0 -0.999 -10", "l 0 0 -9", "l 0 1.001 -10", "l 5 5 5 1 1 1",
              "l 0 0 -10.5 0.2 0.3 0.4"]
    text = VIEW.format(hither=1) + "\n".join(lights) + "\nf 1 1 1 1 0 1 0 0\ns 0 0 0 1\n"
    scene = write(os.path.join(work, "rule.nff"), text)
    first_light = VIEW.count("\n")
    chosen = spd.lights_at_the_eye(scene)
    expect("lights nearer the eye than hither", sorted(chosen), [first_light + i for i in (0, 1, 2, 6)])

    copy = spd.without_lines(scene, chosen, os.path.join(work, "rule-no-eye-light.nff"))
    with open(copy) as f:
        kept = f.read().splitlines()
    expect("the copy", kept, [line for n, line in enumerate(text.splitlines()) if n not in chosen])

    # hither 0: no light is nearer than that, even one at the eye; no view: nothing to compare with.
    at_eye = write(os.path.join(work, "h0.nff"), VIEW.format(hither=0) + "l 0 0 -10\n")
    expect("hither 0", spd.lights_at_the_eye(at_eye), set())
    expect("no view", spd.lights_at_the_eye(write(os.path.join(work, "nv.nff"), "l 0 0 0\ns 0 0 0 1\n")), set())
    # A word that is not a number (the render reports it) leaves its line out of the choice.
    expect("an unreadable eye",
           spd.lights_at_the_eye(write(os.path.join(work, "bad.nff"), "v\nfrom 0 0 x\nhither 1\nl 0 0 0\n")), set())
    unreadable = write(os.path.join(work, "badl.nff"), VIEW.format(hither=1) + "l 0 0 -1e\nl 0 0 -10\n")
    expect("an unreadable light", spd.lights_at_the_eye(unreadable), {first_light + 1})
    print("the rule holds: lights strictly within hither of the eye, and only those, are left out")


def corpus(corpus_dir):
    databases = spd.DATABASES
    missing = [d for d in databases if not os.path.isfile(os.path.join(corpus_dir, f"{d}.nff"))]
    if missing:
        print(f"SKIPPED: {', '.join(missing)} missing in {corpus_dir} (the SPD corpus is data kept outside "
              "this repository)")
        sys.exit(SKIP)
    for database in databases:
        path = os.path.join(corpus_dir, f"{database}.nff")
        chosen = spd.lights_at_the_eye(path)
        if database != "gears":
            expect(f"{database}'s lights at the eye", chosen, set())
            continue
        expect("gears' lights at the eye", len(chosen), 1)
        with open(path) as f:
            line = f.read().splitlines()[next(iter(chosen))]
        expect("gears' light at the eye", line.split()[:4], ["l", "-1.111", "-2.121", "2.626"])
    print("the seven databases: only gears' fifth light is at the eye")


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in ("rule", "corpus"):
        sys.exit(__doc__)
    (rule if sys.argv[1] == "rule" else corpus)(sys.argv[2])
