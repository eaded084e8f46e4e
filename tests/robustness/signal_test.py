#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Signals during a large render (docs/robustness.md):
  - SIGINT after 1 s, and SIGTERM after 1 s: exit 130 / 143 within 2 s, the previous output
    byte-for-byte intact, no temporary file left;
  - SIGKILL after 1.5 s: the previous output byte-for-byte intact;
  - SIGINT after 1 s during heavy_tile.yaml, whose every 16x16 tile takes over a minute
    (256 samples x 256 mirror bounces x 49 lights per pixel): still exit 130 within 2 s;
  - `whitted convert` of a 720k-triangle mesh interrupted (SIGINT, SIGTERM, SIGKILL) at five
    points of its run: each of the .pov and .ini is the previous one or the complete new one,
    and no temporary file is left (after SIGKILL, only the killed run's own temporary, which
    the next convert removes).
Usage: signal_test.py WHITTED [--threads N]"""

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

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


def interrupt_render(whitted, directory, threads, sig, after, scene_text):
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


def grid_obj(path, n):
    """An n x n grid of quads as 2 n^2 triangles, with normals: a large OBJ quickly."""
    with open(path, "w") as f:
        f.write("".join(f"v {i / n:.6f} {0.1 * ((i * j) % 7) / n:.6f} {j / n:.6f}\n"
                        for i in range(n + 1) for j in range(n + 1)))
        f.write("".join(f"vn 0 1 {((i + j) % 5) / 50:.6f}\n" for i in range(n + 1) for j in range(n + 1)))
        faces = []
        for i in range(n):
            for j in range(n):
                a, b, c, d = i * (n + 1) + j + 1, (i + 1) * (n + 1) + j + 1, (i + 1) * (n + 1) + j + 2, i * (n + 1) + j + 2
                faces.append(f"f {a}//{a} {b}//{b} {c}//{c}\nf {a}//{a} {c}//{c} {d}//{d}\n")
        f.write("".join(faces))


def convert_cases(whitted, directory):
    """Interrupts `whitted convert` at several points; returns the problems found."""
    grid_obj(os.path.join(directory, "grid.obj"), 600)
    scene = os.path.join(directory, "mesh.yaml")
    with open(scene, "w") as f:
        f.write("version: 1\ncamera: { eye: [0.5, 2, 2], look_at: [0.5, 0, 0.5] }\n"
                "image: { width: 64, height: 48 }\nlights:\n  - { type: point, position: [0, 5, 0] }\n"
                "materials:\n  m: { kd: 0.5 }\nobjects:\n  - { type: mesh, file: grid.obj, material: m }\n")
    pov, ini = os.path.join(directory, "out.pov"), os.path.join(directory, "out.ini")
    started = time.monotonic()
    run([whitted, "convert", scene, pov])
    duration = time.monotonic() - started
    complete = {pov: open(pov, "rb").read(), ini: open(ini, "rb").read()}
    expected_files = {"grid.obj", "mesh.yaml", "out.pov", "out.ini"}
    problems = []
    for sig, fraction in ((signal.SIGINT, 0.3), (signal.SIGTERM, 0.6), (signal.SIGINT, 0.8),
                          (signal.SIGINT, 0.95), (signal.SIGKILL, 0.8)):
        for path in (pov, ini):
            with open(path, "wb") as f:
                f.write(OLD_BYTES)
        process = subprocess.Popen([whitted, "convert", scene, pov], stderr=subprocess.DEVNULL)
        time.sleep(duration * fraction)
        process.send_signal(sig)
        process.wait(timeout=20)
        allowed = {0, 128 + sig.value} if sig != signal.SIGKILL else {0, -signal.SIGKILL.value}
        if process.returncode not in allowed:
            problems.append(f"convert, {sig.name} at {fraction:.0%}: exit {process.returncode}")
        for path in (pov, ini):
            if open(path, "rb").read() not in (OLD_BYTES, complete[path]):
                problems.append(f"convert, {sig.name} at {fraction:.0%}: {os.path.basename(path)} is neither "
                                "the previous file nor the complete new one")
        leftovers = sorted(set(os.listdir(directory)) - expected_files)
        if sig == signal.SIGKILL and leftovers:
            # SIGKILL cannot be caught: in the instant between naming a finished file and
            # moving it into place the killed process leaves its temporary. It must be that and
            # nothing else, and the next convert to the same name must remove it.
            ours = {f".{os.path.basename(p)}.whitted-{process.pid}.tmp{os.path.splitext(p)[1]}" for p in (pov, ini)}
            if not set(leftovers) <= ours:
                problems.append(f"convert, SIGKILL at {fraction:.0%}: files left behind: {leftovers}")
            run([whitted, "convert", scene, pov])
            leftovers = sorted(set(os.listdir(directory)) - expected_files)
            if leftovers:
                problems.append(f"convert after a SIGKILL: the killed run's temporaries were not removed: {leftovers}")
        elif leftovers:
            problems.append(f"convert, {sig.name} at {fraction:.0%}: files left behind: {leftovers}")
        print(f"convert ({duration:.2f} s uninterrupted), {sig.name} at {fraction:.0%}: exit {process.returncode}"
              + ("" if problems else ", ok"))
    return problems


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("whitted")
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    failures = Failures()
    with tempfile.TemporaryDirectory(prefix="whitted-signal-") as directory:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "heavy_tile.yaml")) as f:
            heavy = f.read()
        for sig, after, name, text in ((signal.SIGINT, 1.0, "large", SCENE), (signal.SIGTERM, 1.0, "large", SCENE),
                                       (signal.SIGKILL, 1.5, "large", SCENE), (signal.SIGINT, 1.0, "heavy tile", heavy)):
            problems, took = interrupt_render(args.whitted, directory, args.threads, sig, after, text)
            print(f"{name} render, {sig.name} after {after} s: stopped in {took:.3f} s" + ("" if problems else ", ok"))
            for problem in problems:
                failures.fail(problem)
    with tempfile.TemporaryDirectory(prefix="whitted-signal-convert-") as directory:
        for problem in convert_cases(args.whitted, directory):
            failures.fail(problem)
    failures.finish()


if __name__ == "__main__":
    main()
