#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes the two .msh meshes of glazed_meshes.xml: a bumpy closed blob of 2·N·(N−1) triangles,
once with per-vertex normals (the surface's analytic normals) and once without (flat facets).
One number a line: the course's own reader (ray/surface/Mesh.java) reads a line as one number.

  python3 make_meshes.py        # in this folder; rewrites blob_normals.msh and blob_flat.msh
"""
import math

N = 10  # segments around; N - 1 rings of N vertices, plus the two poles


def point(theta, phi):
    """A sphere of radius 0.6 with a bump r(θ, φ) = 0.6 (1 + 0.15 sin 3φ sin θ)."""
    r = 0.6 * (1 + 0.15 * math.sin(3 * phi) * math.sin(theta))
    return [r * math.sin(theta) * math.cos(phi), r * math.cos(theta), r * math.sin(theta) * math.sin(phi)]


def normal(theta, phi, h=1e-5):
    """The outward normal from the surface's partial derivatives (poles: straight up or down)."""
    if theta < 1e-9 or theta > math.pi - 1e-9:
        return [0.0, 1.0 if theta < 1 else -1.0, 0.0]
    a, b = point(theta + h, phi), point(theta - h, phi)
    c, d = point(theta, phi + h), point(theta, phi - h)
    dt = [x - y for x, y in zip(a, b)]
    dp = [x - y for x, y in zip(c, d)]
    n = [dp[1] * dt[2] - dp[2] * dt[1], dp[2] * dt[0] - dp[0] * dt[2], dp[0] * dt[1] - dp[1] * dt[0]]
    length = math.sqrt(sum(x * x for x in n))
    return [x / length for x in n]


params = [(0.0, 0.0)]
for i in range(1, N):
    for j in range(N):
        params.append((math.pi * i / N, 2 * math.pi * j / N))
params.append((math.pi, 0.0))
south = len(params) - 1
triangles = []
ring = lambda i, j: 1 + (i - 1) * N + j % N  # noqa: E731
for j in range(N):  # counter-clockwise seen from outside
    triangles.append((0, ring(1, j + 1), ring(1, j)))
    triangles.append((south, ring(N - 1, j), ring(N - 1, j + 1)))
for i in range(1, N - 1):
    for j in range(N):
        triangles.append((ring(i, j), ring(i, j + 1), ring(i + 1, j)))
        triangles.append((ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)))


def write(path, with_normals):
    with open(path, "w") as f:
        f.write(f"{len(params)}\n{len(triangles)}\nvertices\n")
        for t, p in params:
            f.writelines(f"{x:.6f}\n" for x in point(t, p))
        f.write("triangles\n")
        for tri in triangles:
            f.writelines(f"{k}\n" for k in tri)
        if with_normals:
            f.write("normals\n")
            for t, p in params:
                f.writelines(f"{x:.6f}\n" for x in normal(t, p))


write("blob_normals.msh", True)
write("blob_flat.msh", False)
