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
With --meshes, meshes stand among the cubes (cube_field_meshes.json): instances of a one-piece
prototype (an OBJ icosphere) and of a two-material group (a union in POV-Ray), an OBJ with two
MTL materials (two mesh2 objects), and a mesh far out on x (written about its own centre).
POV-Ray's hierarchy holds them too, so the ties among the cubes follow only if their bounding
boxes are POV-Ray's; with meshes the order was not followed at all before: 91.37 % agreed (turned:
91.45 %).
Usage: cube_field.py OUT_DIR [--turned] [--meshes] [N] [SEED]"""
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


TWO_TONE_OBJ = """mtllib two_tone.mtl
v -1 0 -1
v 1 0 -1
v 1 0 1
v -1 0 1
v 0 1.5 0
usemtl warm
f 1 2 5
f 2 3 5
usemtl cool
f 3 4 5
f 4 1 5
"""
TWO_TONE_MTL = """newmtl warm
Kd 0.8 0.4 0.1
newmtl cool
Kd 0.1 0.4 0.8
Ks 0.5
Ns 60
"""


def add_meshes(field: dict, out: Path, seed: int) -> None:
    """Meshes and instances spread through the field's object list (at its start, middle and end)."""
    rng = random.Random(seed + 1000)
    (out / "two_tone.obj").write_text(TWO_TONE_OBJ)
    (out / "two_tone.mtl").write_text(TWO_TONE_MTL)
    icosphere = Path(__file__).resolve().parent / "models" / "icosphere.obj"
    field["prototypes"] = {
        "ball": {"type": "mesh", "file": str(icosphere)},
        "tent": {"type": "group", "objects": [
            {"type": "mesh", "vertices": [[-1, 0, -1], [1, 0, -1], [0, 1.2, 0]], "triangles": [[0, 1, 2]],
             "material": "a"},
            {"type": "mesh", "vertices": [[-1, 0, 1], [1, 0, 1], [0, 1.2, 0]], "triangles": [[0, 1, 2]],
             "material": "b"}]}}
    meshes = []
    for _ in range(8):
        meshes.append({"type": "instance", "prototype": "ball", "material": rng.choice("abc"),
                       "transform": [{"scale": rng.uniform(0.3, 0.8)},
                                     {"rotate": {"axis": [0, 1, 0], "angle": rng.uniform(0, 360)}},
                                     {"translate": [rng.uniform(-18, 18), 0.6, rng.uniform(-18, 8)]}]})
    for _ in range(4):
        meshes.append({"type": "instance", "prototype": "tent",
                       "transform": [{"rotate": {"axis": [0, 1, 0], "angle": rng.uniform(0, 360)}},
                                     {"translate": [rng.uniform(-18, 18), 0, rng.uniform(-18, 8)]}]})
    meshes.append({"type": "mesh", "file": "two_tone.obj", "transform": {"translate": [rng.uniform(-10, 10), 0, -5]}})
    meshes.append({"type": "mesh", "vertices": [[29, 0, -3], [31, 0, -3], [30, 2, -3]], "triangles": [[0, 1, 2]],
                   "material": "c"})
    objects = field["objects"]
    for k, mesh in enumerate(meshes):
        objects.insert(1 + (len(objects) - 1) * k // (len(meshes) - 1), mesh)


def main() -> int:
    args = [a for a in sys.argv[1:] if a not in ("--turned", "--meshes")]
    if not args:
        sys.exit(__doc__)
    turned = "--turned" in sys.argv[1:]
    meshes = "--meshes" in sys.argv[1:]
    out = Path(args[0])
    n = int(args[1]) if len(args) > 1 else 20000
    seed = int(args[2]) if len(args) > 2 else 1
    out.mkdir(parents=True, exist_ok=True)
    field = scene(n, seed, turned)
    if meshes:
        add_meshes(field, out, seed)
    name = "cube_field" + ("_turned" if turned else "") + ("_meshes" if meshes else "") + ".json"
    (out / name).write_text(json.dumps(field))
    return 0


if __name__ == "__main__":
    sys.exit(main())
