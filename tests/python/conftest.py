# SPDX-License-Identifier: MIT
"""pytest set-up for the module's tests.

In the sanitizer build (scripts/test --sanitize) ctest starts /usr/bin/python3 with the ASan
runtime and libstdc++ in LD_PRELOAD, since python3 is not instrumented and the module is; ASan
must come first, and must see libstdc++ at start to intercept C++ exceptions. Once python3 is
running they are loaded, and the variable is dropped, so that the programs the module starts
(POV-Ray for `check`) run as they always do, not under a sanitizer they were not built for. A
test that starts python3 again (with the module) gives it back: WHITTED_TEST_PYTHON_PRELOAD.
"""
import os

if os.environ.pop("WHITTED_TEST_DROP_PRELOAD", None):
    os.environ["WHITTED_TEST_PYTHON_PRELOAD"] = os.environ.pop("LD_PRELOAD", "")
