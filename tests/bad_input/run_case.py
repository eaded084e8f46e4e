#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Runs one case of the bad-input catalogue (cases.txt) through `whitted render` and checks
what a user relies on when the input is wrong:
  - the exit code is the expected one (2 for bad input);
  - stderr holds no control character but newlines (a scene's text must not drive the terminal);
  - stderr holds the expected message fragment and names the scene file;
  - the existing output image is byte-for-byte unchanged and no temporary file is left;
  - no sanitizer report (when built with --sanitize), no crash, no hang.
Usage: run_case.py WHITTED CASES_DIR SCENE_FILE WORK_DIR"""

import os
import shutil
import subprocess
import sys

SANITIZER_MARKERS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:", "UndefinedBehaviorSanitizer")
OLD_BYTES = b"previous output: must survive a failed render\n" * 64


def load_case(cases_dir, scene):
    with open(os.path.join(cases_dir, "cases.txt"), encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            name, code, fragment = (part.strip() for part in line.split("|", 2))
            if name == scene:
                return int(code), fragment
    sys.exit(f"run_case: {scene} is not listed in cases.txt")


def main():
    whitted, cases_dir, scene, work = sys.argv[1:5]
    expected_code, fragment = load_case(cases_dir, scene)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    output = os.path.join(work, "OUT.exr")
    with open(output, "wb") as f:
        f.write(OLD_BYTES)
    env = dict(os.environ)
    # A huge allocation must become an error message, not a sanitizer abort.
    env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "detect_leaks=1") + ":allocator_may_return_null=1"
    command = [whitted, "render", os.path.join(cases_dir, scene), "-o", output, "-t", "1", "-q"]
    try:
        result = subprocess.run(command, capture_output=True, timeout=60, env=env)
    except subprocess.TimeoutExpired:
        sys.exit(f"FAIL {scene}: no answer within 60 s")
    stderr = result.stderr.decode("utf-8", "replace")
    problems = []
    if result.returncode < 0:
        problems.append(f"killed by signal {-result.returncode}")
    elif result.returncode != expected_code:
        problems.append(f"exit code {result.returncode}, expected {expected_code}")
    if fragment not in stderr:
        problems.append(f"stderr lacks '{fragment}'")
    if scene not in stderr:
        problems.append(f"stderr does not name the scene file '{scene}'")
    raw = sorted({hex(b) for b in result.stderr if b < 0x20 and b != 0x0A})
    if raw:
        problems.append(f"stderr holds raw control characters {raw}")
    for marker in SANITIZER_MARKERS:
        if marker in stderr:
            problems.append(f"sanitizer report ({marker})")
    with open(output, "rb") as f:
        if f.read() != OLD_BYTES:
            problems.append("the existing output was changed")
    leftovers = sorted(set(os.listdir(work)) - {"OUT.exr"})
    if leftovers:
        problems.append(f"files left behind: {leftovers}")
    if problems:
        print(f"FAIL {scene}: " + "; ".join(problems))
        print("--- stderr ---\n" + stderr[-4000:])
        sys.exit(1)
    print(f"ok {scene}: exit {result.returncode}: {stderr.strip()[:300]}")


if __name__ == "__main__":
    main()
