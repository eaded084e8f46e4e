#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Placement invariance (docs/validation.md, "Far from the origin and at other scales"): a scene
moved far from the origin, or scaled about it, is the same picture, so Whitted must render it as
it renders the scene where it stands. For one scene this renders the scene as written, then the
scene with every object wrapped in one group that moves it by T·(1, −0.61, 0.37) for several T
in each decade from 1e2 to 1e6, or scales it by k from 1e-3 to 1e3 (the camera and the point
lights moved or scaled alike), and compares each image with the first by `whitted compare`'s
default rule: 99.9 % of pixels within 2/65535 and none beyond 64/65535 (in linear values, as the
EXRs `whitted render` writes).

  placement.py SCENE.yaml WORK_DIR

Renders in this process through the Python module (PYTHONPATH=build/python), which gives the
pixels `whitted render` writes. Needs Debian's python3-yaml and python3-numpy (scripts/setup
installs them with the test tools)."""

import os
import sys

import numpy as np
import whitted
import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures  # noqa: E402  (tests/harness.py)

DIRECTION = (1.0, -0.61, 0.37)
# Not powers of two: a dyadic factor moves a float coordinate exactly, and hides what rounding does.
TRANSLATIONS = (170.0, 610.0, 2.3e3, 8.9e3, 3.7e4, 7.9e4, 2.9e5, 1.1e6)
SCALES = (1.3e-3, 0.021, 0.37, 3.3, 47.0, 730.0)


def placed(scene, translate=None, scale=None):
    """The scene moved by `translate` (a vector) or scaled by `scale` about the origin."""
    if translate is not None:
        move = lambda p: [a + b for a, b in zip(p, translate)]  # noqa: E731
        step = {"translate": list(translate)}
    else:
        move = lambda p: [scale * a for a in p]  # noqa: E731
        step = {"scale": [scale, scale, scale]}
    camera = scene["camera"]
    for key in ("eye", "look_at"):
        camera[key] = move(camera[key])
    if scale is not None:  # lengths of the view: the orthographic view, the window camera's distance
        for key in ("view_width", "view_height", "projection_distance"):
            if key in camera:
                camera[key] *= scale
    for light in scene.get("lights", []):
        if "position" in light:
            light["position"] = move(light["position"])
    scene["objects"] = [{"type": "group", "transform": [step], "objects": scene["objects"]}]
    return scene


def compare(first, second):
    """`whitted compare`'s default rule on two linear images: (passed, summary)."""
    codes = np.abs(first.astype(np.float64) - second.astype(np.float64)).max(axis=2) * 65535
    within = float(np.mean(codes <= 2))
    worst = float(codes.max())
    passed = within >= 0.999 and worst <= 64
    y, x = np.unravel_index(int(np.argmax(codes)), codes.shape)
    return passed, f"{100 * within:.3f}% of pixels within 2/65535 (99.9% required), max {worst:.1f} codes (cap 64) at ({x}, {y})"


def main():
    source, work = sys.argv[1:3]
    os.makedirs(work, exist_ok=True)
    # Mesh files are named relative to the scene: the placed scenes sit beside the same folders.
    folder = os.path.dirname(os.path.abspath(source))
    for entry in os.listdir(folder):
        link = os.path.join(work, entry)
        if os.path.isdir(os.path.join(folder, entry)) and not os.path.lexists(link):
            os.symlink(os.path.join(folder, entry), link)
    with open(source) as f:
        text = f.read()
    origin = whitted.render(whitted.load(source), threads=1)
    failures = Failures()
    cases = [(f"translate_{t:g}", dict(translate=[t * c for c in DIRECTION])) for t in TRANSLATIONS]
    cases += [(f"scale_{k:g}", dict(scale=k)) for k in SCALES]
    for name, how in cases:
        scene = placed(yaml.load(text, Loader=yaml.CSafeLoader), **how)
        path = os.path.join(work, name + ".yaml")
        with open(path, "w") as f:
            yaml.dump(scene, f, Dumper=yaml.CSafeDumper, sort_keys=True)
        passed, summary = compare(origin, whitted.render(whitted.load(path), threads=1))
        failures.check(passed, f"{name}: {summary}")
    if failures.messages:
        changed = ", ".join(m.split(":")[0] for m in failures.messages)
        print(f"placement: {os.path.basename(source)} changes when {changed}", file=sys.stderr)
    failures.finish()


if __name__ == "__main__":
    main()
