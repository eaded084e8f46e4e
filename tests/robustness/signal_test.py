#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Signals during a large render (docs/robustness.md):
  - SIGINT after 1 s, and SIGTERM after 1 s: exit 130 / 143 within 2 s, the previous output
    byte-for-byte intact, no temporary file left;
  - SIGKILL after 1.5 s: the previous output byte-for-byte intact;
  - SIGINT after 1 s during heavy_tile.yaml, whose every 16x16 tile takes over a minute
    (256 samples x 256 mirror bounces x 49 lights per pixel): still exit 130 within 2 s.
Usage: signal_test.py WHITTED [--threads N]"""

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time

# Many mirrors and lights at a high resolution: seconds of work on any machine, tiles short.
SCENE = """version: 1
camera: { eye: [0, 3, 9], look_at: [0, 0.5, 0], fov: 55 }
image: { width: 2400, height: 1800, samples: 4, background: [0.1, 0.1, 0.15] }
render: { max_depth: 8 }
lights:
  - { type: point, position: [-5, 8, 6], intensity: 0.6 }
  - { type: point, position: [5, 6, 4], intensity: 0.4 }
materials:
  mirror: { ka: 0.02, kd: 0.2, ks: 0.4, p: 60, km: 0.6 }
objects:
  - { type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: mirror }
""" + "".join(
    f"  - {{ type: sphere, center: [{x}, 0.6, {z}], radius: 0.55, material: mirror }}\n"
    for x in range(-4, 5, 2) for z in range(-4, 3, 2))

OLD_BYTES = b"the previous render: must survive any signal\n" * 100


def run(whitted, directory, threads, sig, after, scene_text):
    output = os.path.join(directory, "out.exr")
    with open(output, "wb") as f:
        f.write(OLD_BYTES)
    scene = os.path.join(directory, "big.yaml")
    with open(scene, "w") as f:
        f.write(scene_text)
    process = subprocess.Popen([whitted, "render", scene, "-o", output, "-t", str(threads), "-q"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    time.sleep(after)
    if process.poll() is not None:
        return [f"the render ended before the signal (exit {process.returncode}): scene too small"], 0.0
    sent = time.monotonic()
    process.send_signal(sig)
    try:
        _, stderr = process.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        process.communicate()
        return [f"{sig.name}: still running 10 s later"], 10.0
    took = time.monotonic() - sent
    problems = []
    with open(output, "rb") as f:
        if f.read() != OLD_BYTES:
            problems.append(f"{sig.name}: the previous output was changed")
    if sig != signal.SIGKILL:
        expected = 128 + sig.value
        if process.returncode != expected:
            problems.append(f"{sig.name}: exit {process.returncode}, expected {expected}")
        if took > 2.0:
            problems.append(f"{sig.name}: took {took:.2f} s to stop (limit 2 s)")
        leftovers = sorted(set(os.listdir(directory)) - {"out.exr", "big.yaml"})
        if leftovers:
            problems.append(f"{sig.name}: files left behind: {leftovers}")
    else:
        for f in os.listdir(directory):  # a killed process cannot clean up; the next test starts clean
            if f not in ("out.exr", "big.yaml"):
                os.remove(os.path.join(directory, f))
    return problems, took


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    failures = []
    with tempfile.TemporaryDirectory(prefix="whitted-signal-") as directory:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "heavy_tile.yaml")) as f:
            heavy = f.read()
        for sig, after, name, text in ((signal.SIGINT, 1.0, "large", SCENE), (signal.SIGTERM, 1.0, "large", SCENE),
                                       (signal.SIGKILL, 1.5, "large", SCENE), (signal.SIGINT, 1.0, "heavy tile", heavy)):
            problems, took = run(args.whitted, directory, args.threads, sig, after, text)
            print(f"{name} render, {sig.name} after {after} s: stopped in {took:.3f} s" + ("" if problems else ", ok"))
            failures += problems
    for problem in failures:
        print("FAIL " + problem)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
