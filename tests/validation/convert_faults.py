#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted convert` under faults (docs/robustness.md):
  - X.ini is a directory: the convert fails (exit 2, a `whitted: error:` message) and an
    existing X.pov is byte-for-byte as it was, with no temporary file left;
  - two converts of different scenes to the same X.pov at once, many times over: afterwards
    X.pov and X.ini always come from the same scene (each pair is compared with the one a lone
    convert of that scene writes), never the .pov of one beside the .ini of the other.
Usage: convert_faults.py WHITTED [--rounds N]"""

import argparse
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

OLD_BYTES = b"// the previous .pov: a failed convert must leave it as it was\n" * 50


def scene(width, radius):
    # Many spheres make the .pov large, so that each convert spends a while deleting the file it
    # replaced: the window in which another convert could slip between its two renames.
    spheres = "".join(f"  - {{ type: sphere, center: [{i % 40 - 20}, {i // 40 - 20}, -30], radius: {radius}, "
                      f"material: m }}\n" for i in range(1600))
    return (f"version: 1\ncamera: {{ eye: [0, 0, 5], look_at: [0, 0, 0] }}\n"
            f"image: {{ width: {width}, height: 48 }}\nlights:\n  - {{ type: point, position: [0, 5, 5] }}\n"
            f"materials:\n  m: {{ kd: 0.5 }}\nobjects:\n{spheres}")


def read(path):
    with open(path, "rb") as f:
        return f.read()


def ini_is_a_directory(whitted, directory, problems):
    source = os.path.join(directory, "a.yaml")
    with open(source, "w") as f:
        f.write(scene(64, 0.3))
    pov = os.path.join(directory, "x.pov")
    with open(pov, "wb") as f:
        f.write(OLD_BYTES)
    os.mkdir(os.path.join(directory, "x.ini"))
    problems.refused("x.ini a directory", [whitted, "convert", source, pov], ["whitted: error:", "x.ini"], timeout=60)
    problems.require(read(pov) == OLD_BYTES, "x.ini a directory: x.pov was changed by the failed convert")
    leftovers = sorted(set(os.listdir(directory)) - {"a.yaml", "x.pov", "x.ini"})
    problems.require(not leftovers, f"x.ini a directory: files left behind: {leftovers}")


def names_povray_cannot_open(whitted, directory, problems):
    """POV-Ray 3.7 cannot open `café.pov` (nor a name with a quote or a backslash, which the .ini
    quotes): such a target is refused before any work, and nothing is written."""
    source = os.path.join(directory, "a.yaml")
    with open(source, "w") as f:
        f.write(scene(64, 0.3))
    for name in ("café.pov", 'say"hi.pov', "back\\slash.pov", "tab\there.pov"):
        problems.refused(f"convert to {name!r}", [whitted, "convert", source, os.path.join(directory, name)],
                         ["POV-Ray 3.7 opens only files whose names are plain ASCII"], timeout=60)
        leftovers = sorted(set(os.listdir(directory)) - {"a.yaml"})
        problems.require(not leftovers, f"{name!r}: files written: {leftovers}")


def concurrent(whitted, directory, rounds, problems):
    sources, expected = {}, {}
    for name, width, radius in (("a", 64, 0.3), ("b", 80, 0.4)):
        sources[name] = os.path.join(directory, f"{name}.yaml")
        with open(sources[name], "w") as f:
            f.write(scene(width, radius))
        # The same file name as the race's: the .ini names the .pov and the image.
        os.mkdir(os.path.join(directory, f"alone_{name}"))
        alone = os.path.join(directory, f"alone_{name}", "same.pov")
        run([whitted, "convert", sources[name], alone], timeout=60)
        expected[name] = (read(alone), read(alone[:-4] + ".ini"))
    if expected["a"][0] == expected["b"][0] or expected["a"][1] == expected["b"][1]:
        problems.fail("the two scenes must differ in both files, or a mix could not be seen")
        return
    pov = os.path.join(directory, "same.pov")
    ini = pov[:-4] + ".ini"
    mixes = 0
    for round in range(rounds):
        processes = [subprocess.Popen([whitted, "convert", sources[name], pov], stderr=subprocess.DEVNULL)
                     for name in (("a", "b") if round % 2 == 0 else ("b", "a"))]
        codes = [p.wait(timeout=60) for p in processes]
        if codes != [0, 0]:
            problems.fail(f"round {round}: exit codes {codes}")
        pair = (read(pov), read(ini))
        if pair not in (expected["a"], expected["b"]):
            mixes += 1
    if mixes:
        problems.fail(f"{mixes} of {rounds} rounds left a .pov and an .ini of different scenes")
    leftovers = sorted(f for f in os.listdir(directory) if ".whitted-" in f)
    if leftovers:
        problems.fail(f"temporary files left behind: {leftovers}")
    print(f"two converts at once, {rounds} rounds: {mixes} mixed pairs")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("--rounds", type=int, default=40)
    args = parser.parse_args()
    failures = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-convert-faults-") as directory:
        ini_is_a_directory(args.whitted, directory, failures)
    with tempfile.TemporaryDirectory(prefix="whitted-convert-names-") as directory:
        names_povray_cannot_open(args.whitted, directory, failures)
    with tempfile.TemporaryDirectory(prefix="whitted-convert-race-") as directory:
        concurrent(args.whitted, directory, args.rounds, failures)
    failures.finish()


if __name__ == "__main__":
    main()
