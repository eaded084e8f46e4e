#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes random_boxes.json into OUT_DIR: 20,000 boxes (axis-aligned, and turned about y) and
ellipsoids (spheres with a non-uniform scale, tilted) scattered on a mirror floor, many of them
overlapping, 400x300 with 2x2 samples, two lights, mirror materials, max depth 3. Written to be
unlike bench/generate.py (other shapes, transforms, JSON with indentation) as a check of scenes
made elsewhere. At its pixel (254, 237) a mirror ray starts 4e-5 above a turned box's top
(nearer than the 1e-4 a ray must travel), crosses that box and leaves it through its bottom, in
the floor's plane: Whitted gave that bottom the hit and POV-Ray the floor, 1,147 codes apart,
until a plane took such a tie (accelerator_exact.cpp, finish_hit). Coordinates keep 7 decimals, or
DECIMALS: with 3 (written as random_boxes_3.json), overlapping boxes share faces, met at exactly
the same t, and Whitted must show the box POV-Ray shows (PovrayTestOrder; seed 1 failed the cap
by 14,831 codes before, docs/validation.md, Known differences). The scene asks for POV-Ray's
intersection rules (render.intersection: povray), which `whitted check` renders with anyway, so
that `whitted render` of it gives the image `check` compares.
Usage: random_boxes.py OUT_DIR [N] [SEED] [DECIMALS]"""
import json
import random
import sys
from pathlib import Path


def scene(n: int, seed: int, decimals: int = 7) -> dict:
    rng = random.Random(seed)
    objects = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"}]
    for _ in range(n):
        x, z = rng.uniform(-20, 20), rng.uniform(-20, 10)
        kind = rng.random()
        if kind < 0.4:
            w, h, d = [round(rng.uniform(0.05, 0.4), decimals) for _ in range(3)]
            objects.append({"type": "box", "min": [-w, 0, -d], "max": [w, h, d], "material": rng.choice("abc"),
                            "transform": [{"rotate": {"axis": [0, 1, 0], "angle": round(rng.uniform(0, 180), 2)}},
                                          {"translate": [round(x, decimals), 0, round(z, decimals)]}]})
        elif kind < 0.7:
            lo = [round(x, decimals), 0, round(z, decimals)]
            objects.append({"type": "box", "min": lo,
                            "max": [round(lo[0] + rng.uniform(0.05, 0.5), decimals), round(rng.uniform(0.05, 0.6), decimals),
                                    round(lo[2] + rng.uniform(0.05, 0.5), decimals)],
                            "material": rng.choice("abc")})
        else:
            r = round(rng.uniform(0.05, 0.3), 3)
            objects.append({"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": rng.choice("abc"),
                            "transform": [{"scale": [r, round(r * rng.uniform(0.5, 2), 3), r]},
                                          {"rotate": {"axis": [1, 0, 0], "angle": round(rng.uniform(0, 90), 1)}},
                                          {"translate": [round(x, decimals), r * 1.5, round(z, decimals)]}]})
    return {"image": {"width": 400, "height": 300, "samples": 2, "background": [0.02, 0.03, 0.05]},
            "camera": {"eye": [0, 12, 24], "look_at": [0, 0, -2], "up": [0, 1, 0], "fov": 60},
            "render": {"max_depth": 3, "intersection": "povray"},
            "lights": [{"type": "point", "position": [-10, 20, 10], "intensity": 0.7},
                       {"type": "directional", "direction": [0.3, -1, -0.2], "intensity": 0.4}],
            "materials": {"floor": {"kd": 0.6, "ka": 0.05, "km": 0.25},
                          "a": {"kd": [0.7, 0.3, 0.2], "ks": 0.4, "p": 30},
                          "b": {"kd": [0.2, 0.4, 0.7], "ks": 0.2, "p": 8, "km": 0.3},
                          "c": {"kd": 0.1, "ks": 0.6, "p": 100, "km": 0.7}},
            "objects": objects}


def main() -> int:
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 20000
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 1
    decimals = int(sys.argv[4]) if len(sys.argv) > 4 else 7
    out.mkdir(parents=True, exist_ok=True)
    name = "random_boxes.json" if decimals == 7 else f"random_boxes_{decimals}.json"
    (out / name).write_text(json.dumps(scene(n, seed, decimals), indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
