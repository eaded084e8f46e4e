#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Rays that start on a plane's far hits (docs/robustness.md, "Coordinates Embree can take").

The camera looks a hair below the horizon, so the middle pixel's ray (along x = 0) meets the
floor 1e11 away. A point light at (0, 2000, 1e11), behind the camera, lights the floor there at
n.l = 1e-8, and the shadow ray back to it crosses z = -1 at x = 0, y = 1000 (1e11 from both
ends, far outside the shadow windows, 2e-4 of the distance from the eye): a wall there
(x in [-2, 2], y in [2, 2000] at z = -1) hides the light. With no ambient light and a black
background the closed form of that pixel is exactly 0. The wall is, in turn: an instance of a
prototype 1e8 times larger scaled by 1e-8 (the shadow ray's origin, taken into the prototype's
space, was 1e19 there: Embree aborted, exit 134), a plain mesh, and a box shrunk the same way
(intersected in its own space in double).

For each: `render --crop` of the pixel equals a black render exactly (compare --tolerance 0),
and `explain` of it gives 0. The control, the same wall moved 100 to the side, leaves it lit
(kd I n.l = 5000: compare fails), so the check can fail.
Usage: far_plane_hits.py WHITTED WORK_DIR"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run  # noqa: E402  (tests/harness.py)

SCENE = """version: 1
camera: { eye: [0, 1, 6], look_at: [0, 0.99999999994, 0], fov: 45 }
image: { width: 9, height: 9, samples: 1, background: [0, 0, 0] }
ambient: 0
lights: [ { type: point, position: [0, 2000, 1e11], intensity: 1e12 } ]
prototypes:
  wall: { type: mesh, vertices: [[-2e8, 2e8, -1e8], [2e8, 2e8, -1e8], [2e8, 2e11, -1e8], [-2e8, 2e11, -1e8]],
          triangles: [[0, 1, 2], [0, 2, 3]] }
objects:
  - { type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: { kd: 0.5 } }
"""
WALLS = {
    "instance scaled 1e-8": "  - { type: instance, prototype: wall, material: { kd: 0.5 }, "
                            "transform: [ { scale: 1e-8 }, { translate: [SHIFT, 0, 0] } ] }\n",
    "mesh": "  - { type: mesh, vertices: [[-2, 2, -1], [2, 2, -1], [2, 2000, -1], [-2, 2000, -1]], "
            "triangles: [[0, 1, 2], [0, 2, 3]], material: { kd: 0.5 }, transform: [ { translate: [SHIFT, 0, 0] } ] }\n",
    "box scaled 1e-8": "  - { type: box, min: [-2e8, 2e8, -1.1e8], max: [2e8, 2e11, -1e8], material: { kd: 0.5 }, "
                       "transform: [ { scale: 1e-8 }, { translate: [SHIFT, 0, 0] } ] }\n",
}
CENTRE = "4,4,1,1"  # the middle pixel: its ray runs along x = 0


def main():
    whitted, work = os.path.abspath(sys.argv[1]), sys.argv[2]
    os.makedirs(work, exist_ok=True)
    failures = Failures()

    def whitted_run(*args, expect=0):
        return failures.run([whitted, *args], expect, timeout=120)

    black_scene = os.path.join(work, "black.yaml")
    with open(black_scene, "w") as f:
        f.write(SCENE.split("prototypes:")[0] + "objects: []\n")
    black = os.path.join(work, "black.exr")
    run([whitted, "render", black_scene, "-o", black, "--crop", CENTRE, "-q"], timeout=120)

    for what, wall in WALLS.items():
        for shift, shadowed in (("0", True), ("100", False)):
            name = f"{what.split()[0]}_{shift}"
            scene = os.path.join(work, name + ".yaml")
            with open(scene, "w") as f:
                f.write(SCENE + wall.replace("SHIFT", shift))
            image = os.path.join(work, name + ".exr")
            if whitted_run("render", scene, "-o", image, "--crop", CENTRE, "-q").returncode != 0:
                continue
            same = run([whitted, "compare", image, black, "--tolerance", "0"], expect=None, timeout=120).returncode == 0
            if same != shadowed:
                failures.fail(f"{what}, moved by {shift}: the pixel is {'black' if same else 'lit'}, expected "
                                f"{'black (the wall hides the light)' if shadowed else 'lit'}")
            explained = whitted_run("explain", scene, "--pixel", "4,4", "--json")
            if explained.returncode != 0:
                continue
            pixel = json.loads(explained.stdout)["pixel"]
            if (max(pixel) == 0) != shadowed:
                failures.fail(f"{what}, moved by {shift}: explain gives {pixel}")
            print(f"{what}, moved by {shift}: the pixel is {'black' if same else 'lit'}, explain {pixel[0]:g}")
    failures.finish()


if __name__ == "__main__":
    main()
