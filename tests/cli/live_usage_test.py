#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`whitted live`'s usage errors, before it serves anything: a scene that does not load exits 2
with its FILE:LINE:COL and prints no address; --port out of range exits 2; SIGINT stops a
running server with 130.

usage: live_usage_test.py WHITTED WORK_DIR
"""
import os
import re
import signal
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fresh_folder  # noqa: E402  (tests/harness.py)


whitted, work = sys.argv[1:3]
fresh_folder(work)
failures = Failures()
check = failures.check


bad = os.path.join(work, "bad.yaml")
with open(bad, "w") as f:
    f.write("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0] }\nimage: { width: 64, height: -48 }\n")
r = subprocess.run([whitted, "live", bad, "--no-open"], capture_output=True, text=True, timeout=60)
check(r.returncode == 2, f"bad scene: exit {r.returncode}")
check(re.search(re.escape(bad) + r":3:\d+: ", r.stderr) is not None, f"bad scene: FILE:LINE:COL in {r.stderr!r}")
check(r.stdout == "", f"bad scene: no address printed ({r.stdout!r})")

good = os.path.join(work, "good.yaml")
with open(good, "w") as f:
    f.write("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0] }\nimage: { width: 64, height: 48 }\n")
for port in ("70000", "0", "-1", "http"):
    r = subprocess.run([whitted, "live", good, "--no-open", "--port", port], capture_output=True, text=True,
                       timeout=60)
    check(r.returncode == 2 and "--port" in r.stderr and r.stdout == "",
          f"--port {port}: exit {r.returncode}, {r.stderr.strip()!r}")

r = subprocess.run([whitted, "live", os.path.join(work, "missing.yaml"), "--no-open"], capture_output=True, text=True,
                   timeout=60)
check(r.returncode == 2 and "missing.yaml" in r.stderr, f"missing scene: exit {r.returncode}, {r.stderr.strip()!r}")

server = subprocess.Popen([whitted, "live", good, "--no-open"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True)
line = server.stdout.readline()
check(re.fullmatch(r"whitted live: http://127\.0\.0\.1:\d+/\n", line) is not None, f"address printed: {line!r}")
server.send_signal(signal.SIGINT)
code = server.wait(timeout=30)
check(code == 130, f"SIGINT: exit {code}")

failures.finish()
