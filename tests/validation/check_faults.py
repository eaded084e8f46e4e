#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted check` under faults (docs/robustness.md):
  symlinks  `check --report r` where every file the report writes is already in r/ as a
            symlink to a file elsewhere (r/povray.log -> ../victim/povray.log, ...): the
            check passes, every file elsewhere is byte-for-byte unchanged, and r/ holds
            regular files. Runs the real POV-Ray (POVRAY, default: povray on PATH).
  signals   SIGTERM to whitted, and SIGINT to its process group (what Ctrl-C sends), while a
            stand-in POV-Ray (fake_povray.py) hangs, once more with one that ignores both
            signals, and once more with one that a wrapper script runs as its child (the
            script's process group must end, not the script alone): whitted exits 143/130
            within 5 s, POV-Ray is no longer running, and
            $TMPDIR (private to the test) holds no whitted-check-* or whitted-povray-home-*.
  povray-signals  the same with the real POV-Ray, on a scene it takes many seconds to render.
Usage: check_faults.py WHITTED symlinks SCENE [--povray POVRAY] | signals | povray-signals"""

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fake_povray  # noqa: E402
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)
REPORT_FILES = ["povray.log", "povray-16bit.png", "scene.pov", "scene.ini", "ours.exr", "povray.exr", "ours.png",
                "povray.png", "diff.png", "metrics.json", "report-data.js", "report.html"]
SCENE = ("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0] }\n"
         "image: { width: 96, height: 72, background: [0.5, 0.25, 0.125] }\n"
         "lights: []\nmaterials: {}\nobjects: []\n")


def symlinks(whitted, scene, povray):
    problems = []
    with tempfile.TemporaryDirectory(prefix="whitted-check-symlinks-") as d:
        victim, report = os.path.join(d, "victim"), os.path.join(d, "r")
        os.mkdir(victim)
        os.mkdir(report)
        for name in REPORT_FILES:
            with open(os.path.join(victim, name), "w") as f:
                f.write(f"precious {name}: must not be overwritten through a symlink\n")
            os.symlink(os.path.join("..", "victim", name), os.path.join(report, name))
        environment = dict(os.environ)
        if povray:
            environment["WHITTED_POVRAY"] = povray
        result = run([whitted, "check", scene, "-q", "--report", report], expect=None, timeout=120, env=environment)
        print("check --report r (r full of symlinks): exit", result.returncode, result.stdout.strip())
        if result.returncode != 0:
            problems.append(f"symlinks: exit {result.returncode}: {result.stdout!r} {result.stderr!r}")
        for name in REPORT_FILES:
            with open(os.path.join(victim, name)) as f:
                if f.read() != f"precious {name}: must not be overwritten through a symlink\n":
                    problems.append(f"symlinks: r/{name} was written through its symlink")
            path = os.path.join(report, name)
            if os.path.islink(path) or not os.path.isfile(path):
                problems.append(f"symlinks: r/{name} is not a regular file afterwards")
    return problems


def running(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie is gone in all but name; /proc says which.
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ")[-1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def stop_and_inspect(process, name, sig, to_group, povray, tmp):
    """Sends `sig` to a running `whitted check` (or its process group) and checks what must hold
    afterwards: it ended within 5 s with 128 + sig, POV-Ray (pid `povray`) ended with it, and
    nothing is left in `tmp` ($TMPDIR). Returns (problems, stderr, seconds taken, leftovers)."""
    sent = time.monotonic()
    if to_group:
        os.killpg(process.pid, sig)
    else:
        process.send_signal(sig)
    problems = []
    try:
        _, err = process.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        _, err = process.communicate()
        problems.append(f"{name}: whitted still running 10 s after the signal")
    took = time.monotonic() - sent
    if process.returncode != 128 + sig.value:
        problems.append(f"{name}: exit {process.returncode}, expected {128 + sig.value} ({err.strip()!r})")
    if took > 5:
        problems.append(f"{name}: took {took:.1f} s to stop (limit 5 s)")
    if running(povray):
        os.kill(povray, signal.SIGKILL)
        problems.append(f"{name}: POV-Ray (pid {povray}) still running after whitted ended")
    leftovers = sorted(os.listdir(tmp))
    if leftovers:
        problems.append(f"{name}: temporary directories left in $TMPDIR: {leftovers}")
    return problems, err, took, leftovers


def interrupt(whitted, d, mode, sig, to_group):
    tmp = os.path.join(d, f"tmp-{mode}-{sig.name}")
    os.mkdir(tmp)
    pidfile = os.path.join(d, f"pid-{mode}-{sig.name}")
    scene = os.path.join(d, "background.yaml")
    povray_program = fake_povray.install(d, as_child=mode == "hang-behind-a-shell")
    environment = dict(os.environ, TMPDIR=tmp, WHITTED_POVRAY=povray_program, FAKE_POVRAY_MODE=mode,
                       FAKE_POVRAY_PIDFILE=pidfile)
    process = subprocess.Popen([whitted, "check", scene, "-q"], env=environment, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, start_new_session=True)
    name = f"{sig.name} to {'the process group' if to_group else 'whitted'}, POV-Ray {mode}"
    started = time.monotonic()
    while not os.path.exists(pidfile) and time.monotonic() - started < 30 and process.poll() is None:
        time.sleep(0.05)
    if not os.path.exists(pidfile):
        process.kill()
        out, err = process.communicate()
        return [f"{name}: POV-Ray never started ({out!r} {err!r})"]
    with open(pidfile) as f:
        povray = int(f.read())
    leftovers_before = sorted(os.listdir(tmp))
    problems, err, took, leftovers = stop_and_inspect(process, name, sig, to_group, povray, tmp)
    if "interrupted" not in err:
        problems.append(f"{name}: no 'interrupted' message: {err!r}")
    print(f"{name}: exit {process.returncode} in {took:.2f} s; $TMPDIR held {leftovers_before} while POV-Ray ran, "
          f"{leftovers} after" + ("" if problems else ", ok"))
    if not leftovers_before:
        problems.append(f"{name}: no temporary directory seen while POV-Ray ran: is $TMPDIR used at all?")
    return problems


# Whitted renders this in about a second; POV-Ray, at 4x4 samples (3200x2400 pixels), mirrors
# and 40 spheres, for well over ten.
BIG_SCENE = """version: 1
camera: { eye: [0, 3, 9], look_at: [0, 0.5, 0], fov: 55 }
image: { width: 800, height: 600, samples: 4, background: [0.1, 0.1, 0.15] }
render: { max_depth: 6 }
lights:
  - { type: point, position: [-5, 8, 6], intensity: 0.5 }
  - { type: point, position: [5, 6, 4], intensity: 0.3 }
materials:
  mirror: { ka: 0.02, kd: 0.2, ks: 0.3, p: 60, km: 0.4 }
objects:
  - { type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: mirror }
""" + "".join(f"  - {{ type: sphere, center: [{x}, 0.6, {z}], radius: 0.5, material: mirror }}\n"
              for x in range(-4, 5) for z in range(-4, 1))


def children(pid):
    found = []
    for task in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{task}/children") as f:
                found += [int(c) for c in f.read().split()]
        except FileNotFoundError:
            pass
    return found


def povray_interrupt(whitted, d, sig, to_group):
    tmp = os.path.join(d, f"tmp-povray-{sig.name}")
    os.mkdir(tmp)
    scene = os.path.join(d, "big.yaml")
    name = f"real POV-Ray, {sig.name} to {'the process group' if to_group else 'whitted'}"
    process = subprocess.Popen([whitted, "check", scene, "-q"], env=dict(os.environ, TMPDIR=tmp),
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    povray, started = None, time.monotonic()
    while povray is None and time.monotonic() - started < 60 and process.poll() is None:
        time.sleep(0.05)
        found = children(process.pid) if process.poll() is None else []
        povray = found[0] if found else None
    if povray is None:
        process.kill()
        out, err = process.communicate()
        return [f"{name}: POV-Ray never started ({out!r} {err!r})"]
    time.sleep(1.0)  # well into POV-Ray's render
    if process.poll() is not None:
        return [f"{name}: the check ended before the signal (exit {process.returncode}): scene too small"]
    problems, err, took, leftovers = stop_and_inspect(process, name, sig, to_group, povray, tmp)
    print(f"{name}: exit {process.returncode} in {took:.2f} s, {leftovers} left" + ("" if problems else ", ok"))
    return problems


def povray_signals(whitted):
    problems = []
    with tempfile.TemporaryDirectory(prefix="whitted-check-povray-signals-") as d:
        with open(os.path.join(d, "big.yaml"), "w") as f:
            f.write(BIG_SCENE)
        problems += povray_interrupt(whitted, d, signal.SIGTERM, to_group=False)
        problems += povray_interrupt(whitted, d, signal.SIGINT, to_group=True)
    return problems


def signals(whitted):
    problems = []
    with tempfile.TemporaryDirectory(prefix="whitted-check-signals-") as d:
        with open(os.path.join(d, "background.yaml"), "w") as f:
            f.write(SCENE)
        problems += interrupt(whitted, d, "hang", signal.SIGTERM, to_group=False)
        problems += interrupt(whitted, d, "hang", signal.SIGINT, to_group=True)
        # A POV-Ray that ignores both: whitted must kill it (SIGKILL after 2 s) and still clean up.
        problems += interrupt(whitted, d, "hang-ignoring-signals", signal.SIGTERM, to_group=False)
        problems += interrupt(whitted, d, "hang-ignoring-signals", signal.SIGINT, to_group=True)
        # POV-Ray run by a wrapper script as its child: the whole group must end, not the script alone.
        problems += interrupt(whitted, d, "hang-behind-a-shell", signal.SIGTERM, to_group=False)
        problems += interrupt(whitted, d, "hang-behind-a-shell", signal.SIGINT, to_group=True)
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("what", choices=["symlinks", "signals", "povray-signals"])
    parser.add_argument("scene", nargs="?")
    parser.add_argument("--povray")
    args = parser.parse_args()
    if args.what == "symlinks":
        problems = symlinks(args.whitted, args.scene, args.povray)
    elif args.what == "signals":
        problems = signals(args.whitted)
    else:
        problems = povray_signals(args.whitted)
    failures = Failures()
    for problem in problems:
        failures.fail(problem)
    failures.finish()


if __name__ == "__main__":
    main()
