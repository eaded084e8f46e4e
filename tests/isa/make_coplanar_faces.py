#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes tests/isa/coplanar_faces.nff: twelve toothed discs (144-sided polygons, each its own
object, opaque and glass in turn) lying in one plane, z = 1, each overlapping its neighbours, seen
at a slant with three lights. Where two discs overlap, a ray meets both faces at one distance in
real numbers, and Embree's float distances order them differently under different instruction
sets (FMA or not, packet width): the face shown followed the instruction set until the choice was
made in double by the exact rule (Accelerator::Impl::nearest_triangle: the first object wins).
The build before that rule fails isa.coplanar_faces on this scene (sse2, sse4.2, avx and avx2
each differ from avx512 from row 24 or 25 on).

usage: make_coplanar_faces.py > tests/isa/coplanar_faces.nff"""
import math

DISCS, TEETH, Z = 12, 36, 1.0
lines = ["# Written by tests/isa/make_coplanar_faces.py (its docstring says what the scene is for).",
         "b 0.078 0.361 0.753", "v", "from -1.1 -2.1 2.6", "at 0 0 0", "up 0 0 1", "angle 45", "hither 1",
         "resolution 512 512", "l 4 3 2", "l 1 -4 4", "l -3 1 5"]
materials = ["f 1 0.75 0.33 0.8 0.2 10 0 1", "f 0.3 0.6 0.9 0.3 0.3 20 0.6 1.5"]
for disc in range(DISCS):
    # A 4 x 3 grid, nudged so that no two discs are placed alike.
    cx = -0.9 + 1.8 * (disc % 4) / 3 + 0.07 * math.sin(disc * 1.7)
    cy = -0.9 + 1.8 * (disc // 4) / 3 + 0.07 * math.cos(disc * 2.3)
    r_in, r_out, phase = 0.36 + 0.013 * disc % 0.05, 0.44, disc * 0.37
    lines.append(materials[disc % 2])
    corners = []
    for k in range(TEETH * 4):
        a = phase + 2 * math.pi * k / (TEETH * 4)
        r = r_out if k % 4 in (1, 2) else r_in
        corners.append(f"{cx + r * math.cos(a):.6g} {cy + r * math.sin(a):.6g} {Z:.6g}")
    lines += [f"p {len(corners)}"] + corners
print("\n".join(lines))
