#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes cube_field.json (or cube_field_turned.json with --turned) into OUT_DIR: 20,000 equal
cubes of side 0.3 standing on a mirror floor at random places, most of them overlapping others,
in three materials (two of them mirrors), 400x300, one point light. The way a field of equal
objects is usually generated, and a field of exact ties: where two cubes overlap, a ray meets
both tops at the very same t, and the renderer must show the one POV-Ray shows (it keeps the
first its bounding hierarchy tests; PovrayTestOrder, docs/pov-model.md §3). Before Whitted
followed that order, 9 % of this field's pixels showed the other cube. With --turned each cube
is turned about y by a random angle (0-360 degrees), 91.77 % agreeing before; there a rotation
whose y entry rounded to 1 - 2^-53 also put two tops an ulp apart in one renderer and not in the
other (Transform::rotate now keeps that entry exactly 1).
Usage: cube_field.py OUT_DIR [--turned] [N] [SEED]"""
import json
import random
import sys
from pathlib import Path


def scene(n: int, seed: int, turned: bool) -> dict:
    rng = random.Random(seed)
    objects = [{"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "material": "floor"}]
    for _ in range(n):
        x, z = rng.uniform(-20, 20), rng.uniform(-20, 10)
        material = rng.choice("abc")
        if turned:
            objects.append({"type": "box", "min": [-0.15, 0, -0.15], "max": [0.15, 0.3, 0.15], "material": material,
                            "transform": [{"rotate": {"axis": [0, 1, 0], "angle": rng.uniform(0, 360)}},
                                          {"translate": [x, 0, z]}]})
        else:
            objects.append({"type": "box", "min": [x - 0.15, 0, z - 0.15], "max": [x + 0.15, 0.3, z + 0.15],
                            "material": material})
    return {"image": {"width": 400, "height": 300},
            "camera": {"eye": [0, 12, 24], "look_at": [0, 0, -2], "up": [0, 1, 0], "fov": 60},
            "lights": [{"type": "point", "position": [-10, 20, 10], "intensity": 0.7}],
            "materials": {"floor": {"kd": 0.6, "km": 0.25},
                          "a": {"kd": [0.7, 0.3, 0.2]},
                          "b": {"kd": [0.2, 0.4, 0.7], "km": 0.3},
                          "c": {"kd": 0.1, "ks": 0.6, "p": 100, "km": 0.7}},
            "objects": objects}


def main() -> int:
    args = [a for a in sys.argv[1:] if a != "--turned"]
    if not args:
        sys.exit(__doc__)
    turned = "--turned" in sys.argv[1:]
    out = Path(args[0])
    n = int(args[1]) if len(args) > 1 else 20000
    seed = int(args[2]) if len(args) > 2 else 1
    out.mkdir(parents=True, exist_ok=True)
    name = "cube_field_turned.json" if turned else "cube_field.json"
    (out / name).write_text(json.dumps(scene(n, seed, turned)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
