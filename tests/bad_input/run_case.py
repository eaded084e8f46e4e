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
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import SANITIZER_MARKERS, Failures, fail, fresh_folder, run  # noqa: E402  (tests/harness.py)

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
    fail(f"{scene} is not listed in cases.txt")


def main():
    whitted, cases_dir, scene, work = sys.argv[1:5]
    expected_code, fragment = load_case(cases_dir, scene)
    fresh_folder(work)
    output = os.path.join(work, "OUT.exr")
    with open(output, "wb") as f:
        f.write(OLD_BYTES)
    env = dict(os.environ)
    # A huge allocation must become an error message, not a sanitizer abort.
    env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "detect_leaks=1") + ":allocator_may_return_null=1"
    command = [whitted, "render", os.path.join(cases_dir, scene), "-o", output, "-t", "1", "-q"]
    result = run(command, expect=None, timeout=60, text=False, env=env)
    stderr = result.stderr.decode("utf-8", "replace")
    print(f"{scene}: exit {result.returncode}: {stderr.strip()[:300]}")
    failures = Failures()
    if result.returncode < 0:
        failures.fail(f"killed by signal {-result.returncode}")
    else:
        failures.check(result.returncode == expected_code, f"exit code {result.returncode}, expected {expected_code}")
    failures.check(fragment in stderr, f"stderr holds '{fragment}'")
    failures.check(scene in stderr, f"stderr names the scene file '{scene}'")
    raw = sorted({hex(b) for b in result.stderr if b < 0x20 and b != 0x0A})
    failures.check(not raw, f"stderr holds no raw control characters {raw}")
    for marker in SANITIZER_MARKERS:
        failures.check(marker not in stderr, f"no sanitizer report ({marker})")
    with open(output, "rb") as f:
        failures.check(f.read() == OLD_BYTES, "the existing output is unchanged")
    leftovers = sorted(set(os.listdir(work)) - {"OUT.exr"})
    failures.check(not leftovers, f"no files left behind {leftovers}")
    if failures.messages:
        print("--- stderr ---\n" + stderr[-4000:])
    failures.finish()


if __name__ == "__main__":
    main()
