#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Image tests whose every pixel is derived by hand, here, from docs/scene-format.md §5:
nothing is stored, nothing comes from an earlier render.

    closed_form.py WHITTED OUT_DIR

The camera is orthographic at eye (0, 0, 5) looking at the origin, so f = (0, 0, -1),
r = (1, 0, 0), u = (0, 1, 0), and the ray of screen point (x0, y0) starts at
(w·x0, w·y0·H/W, 5) for view width w and travels along -z. The only object is the plane z = 0,
which it hits at x = (w·x0, w·y0·H/W, 0) with n = (0, 0, 1) (facing the ray) and v = (0, 0, 1).
Nothing can shadow the plane, and it has no mirror term, so (§5.3)

    L = ka·Ia + Σ_i kd·I_i·(n·l_i) + ks·I_i·max(0, n·h_i)^p,   h_i = normalize(l_i + v)

where n·l_i > 0. With a directional light l is the same everywhere, so is every pixel; with a
point light at P, l = normalize(P − x) changes from pixel to pixel, and with samples n a pixel
is the mean of its n×n sub-pixel values at x0 = (i + (a + 0.5)/n)/W − 0.5 (§5.1).

Whitted stores each pixel as a float; the expected value is computed in double and the test
allows 1e-6 (0.066 of a 16-bit code), far inside the pass rule's 2/65535, so a wrong term,
sign, sample position or averaging fails. Sizes are odd (partly filled packets and tiles).
"""

import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import read_exr  # noqa: E402  (tests/harness.py)

TOLERANCE = 1e-6


def normalize(v):
    length = math.sqrt(sum(c * c for c in v))
    return [c / length for c in v]


def shade(x, case):
    """L at the plane point x (the formula above), per channel."""
    n = (0.0, 0.0, 1.0)
    v = (0.0, 0.0, 1.0)
    out = [case["ka"][c] * case["ambient"][c] for c in range(3)]
    for light in case["lights"]:
        if light["type"] == "directional":
            l = [-c for c in normalize(light["direction"])]
        else:
            l = normalize([p - q for p, q in zip(light["position"], x)])
        n_dot_l = sum(a * b for a, b in zip(n, l))
        if n_dot_l <= 1e-10:
            continue
        h = normalize([a + b for a, b in zip(l, v)])
        lobe = max(0.0, sum(a * b for a, b in zip(n, h))) ** case["p"]
        for c in range(3):
            out[c] += case["kd"][c] * light["intensity"][c] * n_dot_l + case["ks"][c] * light["intensity"][c] * lobe
    return out


def expected_pixel(i, j, case):
    width, height, samples, w = case["width"], case["height"], case["samples"], case["view_width"]
    total = [0.0, 0.0, 0.0]
    for b in range(samples):
        for a in range(samples):
            x0 = (i + (a + 0.5) / samples) / width - 0.5
            y0 = 0.5 - (j + (b + 0.5) / samples) / height
            value = shade((w * x0, w * y0 * height / width, 0.0), case)
            total = [t + s for t, s in zip(total, value)]
    return [t / (samples * samples) for t in total]


def vec(v):
    return "[" + ", ".join(repr(float(c)) for c in v) + "]"


def scene_yaml(case):
    lights = []
    for light in case["lights"]:
        where = "direction" if light["type"] == "directional" else "position"
        lights.append(f"  - {{type: {light['type']}, {where}: {vec(light[where])}, "
                      f"intensity: {vec(light['intensity'])}}}")
    return "\n".join([
        "version: 1",
        f"camera: {{type: orthographic, eye: [0, 0, 5], look_at: [0, 0, 0], view_width: {case['view_width']}}}",
        f"image: {{width: {case['width']}, height: {case['height']}, samples: {case['samples']}, "
        "background: [0.9, 0, 0.9]}",
        f"ambient: {vec(case['ambient'])}",
        "lights:",
        *lights,
        "objects:",
        f"  - {{type: plane, point: [0, 0, 0], normal: [0, 0, 1], material: "
        f"{{ka: {vec(case['ka'])}, kd: {vec(case['kd'])}, ks: {vec(case['ks'])}, p: {case['p']}}}}}",
        "",
    ])


CASES = {
    # Every pixel the same: ambient, diffuse and a Blinn highlight from one directional light.
    "directional_uniform": dict(width=37, height=23, samples=1, view_width=4.0, ambient=[0.5, 0.75, 1.0],
                                ka=[0.2, 0.1, 0.05], kd=[0.6, 0.4, 0.2], ks=[0.3, 0.3, 0.1], p=7,
                                lights=[dict(type="directional", direction=[-1.0, -2.0, -3.0],
                                             intensity=[0.9, 0.8, 0.7])]),
    # Every pixel different: a point light close to the plane, plus a directional one; values
    # above 1 near the light (stored unclipped in EXR). One sample per pixel: the packet path.
    "point_light_gradient": dict(width=31, height=17, samples=1, view_width=6.0, ambient=[1.0, 1.0, 1.0],
                                 ka=[0.1, 0.05, 0.02], kd=[0.7, 0.5, 0.3], ks=[0.5, 0.4, 0.3], p=20,
                                 lights=[dict(type="point", position=[0.7, -0.4, 0.8], intensity=[1.5, 1.2, 1.0]),
                                         dict(type="directional", direction=[1.0, 0.5, -2.0],
                                              intensity=[0.2, 0.3, 0.4])]),
    # The same light at 3×3 samples: each pixel is the mean of nine different values (render_pixel).
    "point_light_samples_3": dict(width=19, height=13, samples=3, view_width=6.0, ambient=[1.0, 1.0, 1.0],
                                  ka=[0.1, 0.05, 0.02], kd=[0.7, 0.5, 0.3], ks=[0.5, 0.4, 0.3], p=20,
                                  lights=[dict(type="point", position=[0.7, -0.4, 0.8],
                                               intensity=[1.5, 1.2, 1.0])]),
}


def run_case(whitted, out_dir, name, case):
    scene = os.path.join(out_dir, name + ".yaml")
    image = os.path.join(out_dir, name + ".exr")
    with open(scene, "w") as f:
        f.write(scene_yaml(case))
    if os.path.exists(image):
        os.remove(image)
    subprocess.run([whitted, "render", "-q", scene, "-o", image, "--exr-compression", "none"], check=True,
                   timeout=60)
    width, height, pixels = read_exr(image)
    if (width, height) != (case["width"], case["height"]):
        return [f"{name}: image is {width}x{height}, expected {case['width']}x{case['height']}"]
    worst, where, distinct = 0.0, None, set()
    for j in range(height):
        for i in range(width):
            expected = expected_pixel(i, j, case)
            got = pixels[j][i]
            distinct.add(got)
            for c in range(3):
                error = abs(got[c] - expected[c]) if math.isfinite(got[c]) else math.inf
                if not error <= worst:
                    worst, where = error, (i, j, c, got[c], expected[c])
    problems = []
    # The point-light cases must really vary (else they would test no more than the uniform one).
    if name != "directional_uniform" and len(distinct) < width * height // 2:
        problems.append(f"{name}: only {len(distinct)} distinct pixels of {width * height}")
    if worst > TOLERANCE:
        i, j, c, got, expected = where
        problems.append(f"{name}: pixel ({i}, {j}) channel {'RGB'[c]} is {got!r}, derived {expected!r} "
                        f"(error {worst:.3g} > {TOLERANCE})")
    print(f"{name}: {width}x{height}, {case['samples']}x{case['samples']} samples, "
          f"max |Whitted - derived| = {worst:.3g}" + (" FAIL" if problems else ""))
    return problems


def main():
    if len(sys.argv) != 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    whitted, out_dir = sys.argv[1:]
    os.makedirs(out_dir, exist_ok=True)
    problems = []
    for name, case in CASES.items():
        problems += run_case(whitted, out_dir, name, case)
    for p in problems:
        print("FAIL " + p, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
