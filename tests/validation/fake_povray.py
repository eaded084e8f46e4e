# SPDX-License-Identifier: MIT
"""A stand-in for POV-Ray (run through WHITTED_POVRAY) that writes an image with known pixels,
or hangs, so that `whitted check` can be given exactly the POV-Ray output a test needs.
Reads Output_File_Name and +W/+H from the .ini it is given. The environment says what to do:
  FAKE_POVRAY_MODE     image (default) | hang | hang-ignoring-signals | hang-behind-a-shell (hangs;
                       the test installs it as_child)
  FAKE_POVRAY_CODES    r,g,b: the 16-bit code of every pixel (default 0,0,0)
  FAKE_POVRAY_PIXELS   x,y,channel,code;...: pixels that differ
  FAKE_POVRAY_SIZE     WxH instead of the .ini's size
  FAKE_POVRAY_CHANNELS 3 (default) or 4 (RGBA)
  FAKE_POVRAY_PIDFILE  where a hanging one writes its process id"""

import os
import re
import shlex
import signal
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import images  # noqa: E402


def install(directory, as_child=False):
    """Writes `directory`/povray, which runs this stand-in with the same Python; returns its
    path, for WHITTED_POVRAY. With `as_child` the script runs it as its child (no exec), as a
    wrapper script that does more afterwards would: signalling the script alone leaves it running."""
    wrapper = os.path.join(directory, "povray-child" if as_child else "povray")
    with open(wrapper, "w") as f:
        f.write(f"#!/bin/sh\n{'' if as_child else 'exec '}{shlex.quote(sys.executable)} "
                f"{shlex.quote(os.path.abspath(__file__))} \"$@\"\n")
    os.chmod(wrapper, 0o755)
    return wrapper


def main():
    text = open(sys.argv[1]).read()
    if os.environ.get("FAKE_POVRAY_MARKER"):  # a test's proof that POV-Ray was run
        open(os.environ["FAKE_POVRAY_MARKER"], "w").close()
    mode = os.environ.get("FAKE_POVRAY_MODE", "image")
    if mode.startswith("hang"):
        if mode == "hang-ignoring-signals":
            signal.signal(signal.SIGTERM, signal.SIG_IGN)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        pidfile = os.environ["FAKE_POVRAY_PIDFILE"]
        with open(pidfile + ".tmp", "w") as f:
            f.write(str(os.getpid()))
        os.rename(pidfile + ".tmp", pidfile)
        while True:
            time.sleep(1)
    output = re.search(r'Output_File_Name="([^"]*)"', text).group(1)
    width, height = int(re.search(r"\+W(\d+)", text).group(1)), int(re.search(r"\+H(\d+)", text).group(1))
    if "FAKE_POVRAY_SIZE" in os.environ:
        width, height = (int(v) for v in os.environ["FAKE_POVRAY_SIZE"].split("x"))
    codes = [int(v) for v in os.environ.get("FAKE_POVRAY_CODES", "0,0,0").split(",")]
    overrides = {}
    for item in filter(None, os.environ.get("FAKE_POVRAY_PIXELS", "").split(";")):
        x, y, c, code = (int(v) for v in item.split(","))
        overrides[(x, y, c)] = code
    images.png16(output, width, height, codes, overrides, int(os.environ.get("FAKE_POVRAY_CHANNELS", "3")))
    print("fake POV-Ray wrote", output)


if __name__ == "__main__":
    main()
