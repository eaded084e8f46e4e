#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""`whitted live`'s usage errors, before it serves anything: a scene that does not load exits 2
with its FILE:LINE:COL and prints no address; --port out of range exits 2; SIGINT stops a
running server with 130; SIGTERM during a check (a stand-in POV-Ray, tests/validation/fake_povray.py,
hanging behind a shell) exits 143 within 5 s, with POV-Ray's process group ended and $TMPDIR empty.

usage: live_usage_test.py WHITTED WORK_DIR
"""
import os
import re
import signal
import subprocess
import sys
import threading
import time
import urllib.request

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fresh_folder  # noqa: E402  (tests/harness.py)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "validation"))
import fake_povray  # noqa: E402


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



def running(pid):
    try:
        os.kill(pid, 0)
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ")[-1].split()[0] != "Z"  # a zombie is gone in all but name
    except (ProcessLookupError, FileNotFoundError):
        return False


# SIGTERM while a check runs: the check stops POV-Ray (its process group: the stand-in runs as
# a shell's child, which signalling the shell alone would leave running) and the program exits.
tmp, pidfile = os.path.join(work, "tmp"), os.path.join(work, "povray.pid")
os.makedirs(tmp)
environment = dict(os.environ, TMPDIR=tmp, WHITTED_POVRAY=fake_povray.install(work, as_child=True),
                   FAKE_POVRAY_MODE="hang-behind-a-shell", FAKE_POVRAY_PIDFILE=pidfile)
server = subprocess.Popen([whitted, "live", good, "--no-open"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True, env=environment)
port = int(re.fullmatch(r"whitted live: http://127\.0\.0\.1:(\d+)/\n", server.stdout.readline()).group(1))


def post_check():
    request = urllib.request.Request(f"http://127.0.0.1:{port}/check", data=b'{"values": {}}', method="POST",
                                     headers={"Content-Type": "application/json"})
    try:
        urllib.request.urlopen(request, timeout=60).read()
    except Exception:  # the check is stopped: an error answer or none
        pass


checker = threading.Thread(target=post_check, daemon=True)
checker.start()
started = time.monotonic()
while not os.path.exists(pidfile) and time.monotonic() - started < 30 and server.poll() is None:
    time.sleep(0.05)
check(os.path.exists(pidfile), "the check started (stand-in) POV-Ray")
if os.path.exists(pidfile):
    povray = int(open(pidfile).read())
    check(len(os.listdir(tmp)) > 0, f"while it runs, $TMPDIR holds the check's files ({sorted(os.listdir(tmp))})")
    sent = time.monotonic()
    server.send_signal(signal.SIGTERM)
    try:
        code = server.wait(timeout=10)
    except subprocess.TimeoutExpired:
        server.kill()
        code = server.wait()
    took = time.monotonic() - sent
    check(code == 143 and took < 5, f"SIGTERM during a check: exit {code} in {took:.2f} s")
    alive = running(povray)
    if alive:
        os.kill(povray, signal.SIGKILL)
    check(not alive, "POV-Ray (behind its shell) ended with it")
    check(os.listdir(tmp) == [], f"$TMPDIR is empty afterwards ({sorted(os.listdir(tmp))})")
else:
    server.kill()
    server.wait()

failures.finish()
