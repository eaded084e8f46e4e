#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""A write that fails part-way (here: the file-size limit, RLIMIT_FSIZE, with SIGXFSZ ignored,
so that write() fails with EFBIG as it would with ENOSPC on a full disk) ends with exit 1 and
one `whitted: error:` line, leaves no temporary file, and leaves an existing output as it was;
for every output format.

Usage: write_failure_test.py WHITTED EXAMPLES_DIR"""
import os
import resource
import signal
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

whitted, examples = sys.argv[1], sys.argv[2]
failures = Failures()
scene = os.path.join(examples, "lecture", "09-glazed-floor.yaml")
LIMIT = 4000  # bytes: every format's 640x480 image of the scene is larger (the JPEG, 7.5 kB)


def limited():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (LIMIT, LIMIT))


with tempfile.TemporaryDirectory() as work:
    for name in ["out.exr", "out.png", "out.jpg", "out.tif"]:
        path = os.path.join(work, name)
        with open(path, "wb") as f:
            f.write(b"the previous image")
        result = run([whitted, "render", scene, "-q", "-o", name], expect=None, timeout=120, cwd=work,
                     preexec_fn=limited)
        problems = []
        if result.returncode != 1:
            problems.append(f"exit {result.returncode}, not 1")
        lines = result.stderr.strip().splitlines()
        if len(lines) != 1 or not lines[0].startswith("whitted: error: cannot write"):
            problems.append("not one 'whitted: error: cannot write' line")
        if open(path, "rb").read() != b"the previous image":
            problems.append("the existing file was changed")
        left = [n for n in os.listdir(work) if ".whitted-" in n]
        if left:
            problems.append(f"temporary files left: {left}")
        failures.check(not problems, f"{name}: {'; '.join(problems) or lines[0]}\n    stderr: {result.stderr.strip()}")

failures.finish()
