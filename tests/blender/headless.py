# SPDX-License-Identifier: MIT
"""What each blender.* driver (test_*.py, run by the system Python) does first: skip, saying why,
where Blender cannot run the add-on, and run one script of this folder in headless Blender.
The scripts Blender runs (scene.py, checks.py, ...) run inside Blender's own Python and report
through the files they write and Blender's exit status (--python-exit-code 1), so they need
neither this module nor tests/harness.py."""

import os
import shutil
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import fail, run, skip  # noqa: E402  (tests/harness.py)

HERE = os.path.dirname(os.path.abspath(__file__))


def require_blender():
    """Skips the test without Blender, and in the sanitizer build: Blender is not built with
    AddressSanitizer, so it cannot load the ASan-built module (the runtime must come first); the
    plain build's run of the test is the one that counts."""
    if shutil.which("blender") is None:
        skip("blender is not installed (apt-get install blender)")
    if os.environ.get("WHITTED_TEST_SANITIZED"):
        skip("sanitizer build: Blender cannot load the ASan-built whitted module; run in the plain build (scripts/test)")


def blender(script, *args, expect=0, **kwargs):
    """Runs SCRIPT, a file of this folder, in headless Blender (factory settings) with ARGS after
    `--`; fails the test unless Blender exits with EXPECT (None: any). KWARGS go to harness.run."""
    return run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                os.path.join(HERE, script), "--", *args], expect=expect, **kwargs)
