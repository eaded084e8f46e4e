#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the OBJ + MTL files used by meshes.yaml (run it from anywhere; it writes next to itself).

icosphere.obj   an icosahedron subdivided 3 times and pushed onto the unit sphere: 642 vertices,
                1280 triangles, with a `vn` normal on every corner (smooth shading in Whitted)
octahedron.obj  8 triangles and no `vn` lines (flat shading)
shapes.mtl      the two materials they use

Usage: python3 make_meshes.py [--subdivisions N]
"""
import argparse
import math
from pathlib import Path

MTL = """\
# Materials for icosphere.obj and octahedron.obj (written by make_meshes.py).
# Whitted reads Ka -> ka, Kd -> kd, Ks -> ks, Ns -> p; illum 3 also sets km = Ks (a mirror).

# A glazed orange: diffuse plus a Blinn-Phong highlight, no mirror (illum 2).
newmtl glaze
Ka 0.03 0.016 0.005
Kd 0.6 0.3 0.08
Ks 0.3 0.3 0.3
Ns 80
illum 2

# Dark steel: little diffuse, and illum 3 makes it a mirror with km = Ks = 0.4.
newmtl steel
Ka 0.02 0.02 0.02
Kd 0.15 0.16 0.18
Ks 0.4 0.4 0.4
Ns 120
illum 3
"""


def normalize(v):
    length = math.sqrt(sum(c * c for c in v))
    return tuple(c / length for c in v)


def icosphere(subdivisions):
    t = (1 + math.sqrt(5)) / 2
    vertices = [normalize(v) for v in [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
        (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
        (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
             (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
             (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
             (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        midpoint = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                va, vb = vertices[a], vertices[b]
                vertices.append(normalize(tuple((x + y) / 2 for x, y in zip(va, vb))))
                midpoint[key] = len(vertices) - 1
            return midpoint[key]

        finer = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            finer += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = finer
    return vertices, faces


def write_obj(path, header, material, vertices, faces, with_normals):
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    lines += ["mtllib shapes.mtl", f"o {path.stem}"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    if with_normals:  # on the unit sphere the normal is the position
        lines += [f"vn {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines.append(f"usemtl {material}")
    for face in faces:
        a, b, c = (i + 1 for i in face)  # OBJ indices start at 1
        lines.append(f"f {a}//{a} {b}//{b} {c}//{c}" if with_normals else f"f {a} {b} {c}")
    path.write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--subdivisions", type=int, default=3, help="icosphere subdivision steps (default 3)")
    args = parser.parse_args()
    here = Path(__file__).resolve().parent

    (here / "shapes.mtl").write_text(MTL)
    vertices, faces = icosphere(args.subdivisions)
    write_obj(here / "icosphere.obj",
              f"Unit icosphere, {args.subdivisions} subdivisions: {len(vertices)} vertices, {len(faces)} triangles.\n"
              "Written by make_meshes.py. Every corner has a vn normal, so Whitted shades it smoothly.",
              "glaze", vertices, faces, with_normals=True)
    octahedron = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    octahedron_faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4),
                        (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    write_obj(here / "octahedron.obj",
              "Unit octahedron: 6 vertices, 8 triangles, counter-clockwise seen from outside.\n"
              "Written by make_meshes.py. No vn lines, so Whitted shades each face flat.",
              "steel", octahedron, octahedron_faces, with_normals=False)


if __name__ == "__main__":
    main()
