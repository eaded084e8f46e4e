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


def ini_is_a_directory(whitted, directory):
    problems = []
    source = os.path.join(directory, "a.yaml")
    with open(source, "w") as f:
        f.write(scene(64, 0.3))
    pov = os.path.join(directory, "x.pov")
    with open(pov, "wb") as f:
        f.write(OLD_BYTES)
    os.mkdir(os.path.join(directory, "x.ini"))
    run = subprocess.run([whitted, "convert", source, pov], capture_output=True, text=True, timeout=60)
    if run.returncode != 2:
        problems.append(f"x.ini a directory: exit {run.returncode}, expected 2")
    if "whitted: error:" not in run.stderr or "x.ini" not in run.stderr:
        problems.append(f"x.ini a directory: message does not name x.ini: {run.stderr!r}")
    if read(pov) != OLD_BYTES:
        problems.append("x.ini a directory: x.pov was changed by the failed convert")
    leftovers = sorted(set(os.listdir(directory)) - {"a.yaml", "x.pov", "x.ini"})
    if leftovers:
        problems.append(f"x.ini a directory: files left behind: {leftovers}")
    print("x.ini is a directory: exit", run.returncode, "ok" if not problems else "")
    return problems


def names_povray_cannot_open(whitted, directory):
    """POV-Ray 3.7 cannot open `café.pov` (nor a name with a quote or a backslash, which the .ini
    quotes): such a target is refused before any work, and nothing is written."""
    problems = []
    source = os.path.join(directory, "a.yaml")
    with open(source, "w") as f:
        f.write(scene(64, 0.3))
    for name in ("café.pov", 'say"hi.pov', "back\\slash.pov", "tab\there.pov"):
        run = subprocess.run([whitted, "convert", source, os.path.join(directory, name)], capture_output=True,
                             text=True, timeout=60)
        if run.returncode != 2 or "POV-Ray 3.7 opens only files whose names are plain ASCII" not in run.stderr:
            problems.append(f"{name!r}: exit {run.returncode}, {run.stderr!r}")
        leftovers = sorted(set(os.listdir(directory)) - {"a.yaml"})
        if leftovers:
            problems.append(f"{name!r}: files written: {leftovers}")
        print(f"convert to {name!r}: exit {run.returncode}", "ok" if not problems else "")
    return problems


def concurrent(whitted, directory, rounds):
    problems = []
    sources, expected = {}, {}
    for name, width, radius in (("a", 64, 0.3), ("b", 80, 0.4)):
        sources[name] = os.path.join(directory, f"{name}.yaml")
        with open(sources[name], "w") as f:
            f.write(scene(width, radius))
        # The same file name as the race's: the .ini names the .pov and the image.
        os.mkdir(os.path.join(directory, f"alone_{name}"))
        alone = os.path.join(directory, f"alone_{name}", "same.pov")
        subprocess.run([whitted, "convert", sources[name], alone], check=True, capture_output=True, timeout=60)
        expected[name] = (read(alone), read(alone[:-4] + ".ini"))
    if expected["a"][0] == expected["b"][0] or expected["a"][1] == expected["b"][1]:
        return ["the two scenes must differ in both files, or a mix could not be seen"]
    pov = os.path.join(directory, "same.pov")
    ini = pov[:-4] + ".ini"
    mixes = 0
    for round in range(rounds):
        processes = [subprocess.Popen([whitted, "convert", sources[name], pov], stderr=subprocess.DEVNULL)
                     for name in (("a", "b") if round % 2 == 0 else ("b", "a"))]
        codes = [p.wait(timeout=60) for p in processes]
        if codes != [0, 0]:
            problems.append(f"round {round}: exit codes {codes}")
        pair = (read(pov), read(ini))
        if pair not in (expected["a"], expected["b"]):
            mixes += 1
    if mixes:
        problems.append(f"{mixes} of {rounds} rounds left a .pov and an .ini of different scenes")
    leftovers = sorted(f for f in os.listdir(directory) if ".whitted-" in f)
    if leftovers:
        problems.append(f"temporary files left behind: {leftovers}")
    print(f"two converts at once, {rounds} rounds: {mixes} mixed pairs")
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("--rounds", type=int, default=40)
    args = parser.parse_args()
    failures = []
    with tempfile.TemporaryDirectory(prefix="whitted-convert-faults-") as directory:
        failures += ini_is_a_directory(args.whitted, directory)
    with tempfile.TemporaryDirectory(prefix="whitted-convert-names-") as directory:
        failures += names_povray_cannot_open(args.whitted, directory)
    with tempfile.TemporaryDirectory(prefix="whitted-convert-race-") as directory:
        failures += concurrent(args.whitted, directory, args.rounds)
    for problem in failures:
        print("FAIL " + problem)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
