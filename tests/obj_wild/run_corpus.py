#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""OBJ files from the wild: every OBJ file of Debian's assimp-testmodels, read by Whitted and
by Assimp (assimp-utils), against the checked-in table expected.tsv.

For each file (the table must list every one, and nothing else):
  - `assimp info FILE`: accepted or not, and the faces of its triangle meshes, as the table says
    (Assimp's info runs its post-processing, which turns degenerate triangles into lines and
    points, so that count can be lower than Whitted's: the table says where and why);
  - `whitted render` of a scene with the mesh and no `material:` (its MTL materials, or the
    default one): either it renders with exactly the table's triangle count (from --stats), or
    it is refused with exit code 2, a message holding the table's fragment and naming
    FILE:LINE:COL;
  - for a file that renders and that Assimp reads, the triangles Assimp's own triangulation
    writes (`assimp export -tri`, an OBJ of triangles only) must number the same, and Whitted's
    render of that export and of the original file, both as flat silhouettes (ambient only),
    must cover the same pixels from two views: Assimp's triangulation checks Whitted's.
Usage: run_corpus.py WHITTED CORPUS_DIR TABLE WORK_DIR"""

import os
import re
import shutil
import sys

from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fail, fresh_folder, run  # noqa: E402  (tests/harness.py)

SIZE = 96  # silhouette images: SIZE x SIZE pixels, one sample each
# Pixels whose coverage may differ between the two triangulations of the same polygons: rays
# through a shared edge, and Assimp writing coordinates with 6 decimals. Measured: at most 0.
MAX_SILHOUETTE_DIFFERENCE = 4
LOCATION = re.compile(r"\.(obj|mtl|yaml):\d+:\d+: ")


def plural(count, noun):
    return f"{count} {noun}" + ("" if str(count) == "1" else "s")


def read_table(path):
    table = {}
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.rstrip("\n")
            if not line.strip() or line.startswith("#"):
                continue
            fields = [field.strip() for field in line.split("|")]
            if len(fields) != 4:
                fail(f"{path}:{number}: expected 4 fields separated by '|', got {len(fields)}")
            name, assimp, outcome, detail = fields
            if name in table:
                fail(f"{path}:{number}: {name} is listed twice")
            if outcome not in ("renders", "refused"):
                fail(f"{path}:{number}: outcome must be 'renders' or 'refused', got '{outcome}'")
            table[name] = {"assimp": assimp, "outcome": outcome, "detail": detail, "line": number}
    return table


def assimp_info(path):
    """(accepted, faces of triangle meshes, (min, max) corners) from `assimp info`."""
    result = run(["assimp", "info", path], expect=None, timeout=120, errors="replace")
    out = result.stdout + result.stderr
    if result.returncode != 0 or "ERROR" in out:
        return False, None, None
    triangles = 0
    for match in re.finditer(r"^\s+\d+ \(.*\): \[(\d+) / \d+ / (\d+) \| (\w+)\]", out, re.M):
        if match.group(3) == "triangle":
            triangles += int(match.group(2))
    corners = []
    for key in ("Minimum point", "Maximum point"):
        match = re.search(key + r"\s+\(([-\d.e+]+) ([-\d.e+]+) ([-\d.e+]+)\)", out)
        corners.append([float(v) for v in match.groups()] if match else None)
    return True, triangles, corners


def scene_text(mesh, material, eye, look_at):
    lines = ["version: 1",
             f"camera: {{ eye: [{eye[0]!r}, {eye[1]!r}, {eye[2]!r}], look_at: [{look_at[0]!r}, {look_at[1]!r}, "
             f"{look_at[2]!r}], up: {up_for(eye, look_at)}, fov: 40 }}",
             f"image: {{ width: {SIZE}, height: {SIZE} }}",
             "ambient: 1",
             "lights: [ { type: point, position: " + f"[{eye[0]!r}, {eye[1]!r}, {eye[2]!r}]" + " } ]",
             "objects:",
             "  - type: mesh",
             "    file: " + yaml_string(mesh)]
    if material:
        lines.append("    material: " + material)
    return "\n".join(lines) + "\n"


def up_for(eye, look_at):
    view = [a - b for a, b in zip(eye, look_at)]
    # +y, unless the view is (nearly) along it.
    if abs(view[1]) > 0.99 * (sum(v * v for v in view) ** 0.5):
        return "[0, 0, 1]"
    return "[0, 1, 0]"


def yaml_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def views(corners):
    """Two cameras on the box: an oblique one, and one along the box's thinnest axis (a flat
    mesh such as concave_polygon.obj is then seen face on)."""
    low, high = corners
    centre = [(a + b) / 2 for a, b in zip(low, high)]
    extent = [b - a for a, b in zip(low, high)]
    radius = max(1e-6, 0.5 * sum(e * e for e in extent) ** 0.5)
    distance = radius / 0.30  # fov 40: the box's sphere fills most of the picture
    oblique = [0.48, 0.40, 0.78]
    thinnest = extent.index(min(extent))
    axis = [0.0, 0.0, 0.0]
    axis[thinnest] = 1.0
    axis[(thinnest + 1) % 3] = 0.05  # not exactly along it, so that up is never parallel
    cameras = []
    for direction in (oblique, axis):
        norm = sum(d * d for d in direction) ** 0.5
        cameras.append([c + distance * d / norm for c, d in zip(centre, direction)])
    return centre, cameras


def render(whitted, scene_path, image_path):
    result = run([whitted, "render", scene_path, "-o", image_path, "--stats", "-q", "-t", "2"], expect=None,
                 timeout=300, errors="replace")
    return result.returncode, result.stderr


def covered(image_path):
    image = Image.open(image_path).convert("L")
    return [value > 0 for value in image.getdata()]


def main():
    whitted, corpus, table_path, work = sys.argv[1:5]
    problems = Failures()
    if not os.path.isdir(corpus):
        fail(f"{corpus} is missing: install assimp-testmodels (scripts/setup --with-test-tools)")
    if not shutil.which("assimp"):
        fail("the assimp command is missing: install assimp-utils (scripts/setup --with-test-tools)")
    table = read_table(table_path)
    files = sorted(os.path.relpath(os.path.join(d, f), corpus)
                   for d, _, names in os.walk(corpus) for f in names if f.lower().endswith(".obj"))
    for name in sorted(set(table) - set(files)):
        problems.fail(f"{name}: in the table (line {table[name]['line']}) but not in {corpus}")
    fresh_folder(work)
    counts = {"renders": 0, "refused": 0}
    for name in files:
        path = os.path.join(corpus, name)
        if name not in table:
            problems.fail(f"{name}: a new OBJ file, not in {table_path}")
            continue
        expect = table[name]
        base = os.path.join(work, name.replace("/", "_"))
        accepted, assimp_triangles, corners = assimp_info(path)
        seen_assimp = str(assimp_triangles) if accepted else "rejects"
        if seen_assimp != expect["assimp"]:
            problems.fail(f"{name}: assimp info gives {seen_assimp}, the table says {expect['assimp']}")

        # As a user would load it: MTL materials, or the default material.
        eye, look_at = [3.0, 2.0, 5.0], [0.0, 0.0, 0.0]
        if accepted and corners[0] and corners[1]:
            look_at, cameras = views(corners)
            eye = cameras[0]
        with open(base + ".yaml", "w", encoding="utf-8") as f:
            f.write(scene_text(path, None, eye, look_at))
        code, stderr = render(whitted, base + ".yaml", base + ".png")
        triangles = re.search(r"; (\d+) triangles,", stderr)
        if expect["outcome"] == "refused":
            counts["refused"] += 1
            if code != 2:
                problems.fail(f"{name}: exit code {code}, expected 2 (refused: {expect['detail']})")
            elif expect["detail"] not in stderr:
                problems.fail(f"{name}: the message lacks '{expect['detail']}': {stderr.strip()}")
            elif not LOCATION.search(stderr):
                problems.fail(f"{name}: the message names no FILE:LINE:COL: {stderr.strip()}")
            else:
                print(f"ok {name}: refused: {stderr.strip().splitlines()[-1]}")
            continue
        counts["renders"] += 1
        if code != 0 or not triangles:
            problems.fail(f"{name}: exit code {code}, expected a render: {stderr.strip()}")
            continue
        if triangles.group(1) != expect["detail"]:
            problems.fail(f"{name}: {triangles.group(1)} triangles, the table says {expect['detail']}")
            continue
        if not accepted:
            print(f"ok {name}: renders, {plural(triangles.group(1), 'triangle')} (Assimp rejects it)")
            continue

        # Assimp's own triangulation of the same file, as triangles only.
        export = base + ".assimp.obj"
        if problems.run(["assimp", "export", path, export, "-fobjnomtl", "-tri"], timeout=120,
                        errors="replace").returncode != 0:
            continue
        with open(export, "rb") as f:
            exported = sum(1 for line in f if line.startswith(b"f "))
        if str(exported) != expect["detail"]:
            problems.fail(f"{name}: Assimp's triangulation has {exported} triangles, Whitted's {expect['detail']}")
            continue
        _, cameras = views(corners)
        differences = []
        for v, camera in enumerate(cameras):
            masks = []
            for label, mesh in (("whitted", path), ("assimp", export)):
                scene = f"{base}.view{v}.{label}.yaml"
                with open(scene, "w", encoding="utf-8") as f:
                    f.write(scene_text(mesh, "{ ka: 1 }", camera, look_at))
                code, stderr = render(whitted, scene, scene[:-5] + ".png")
                if code != 0:
                    problems.fail(f"{name}: silhouette render of {label} failed: {stderr.strip()}")
                    break
                masks.append(covered(scene[:-5] + ".png"))
            if len(masks) != 2:
                break
            different = sum(a != b for a, b in zip(*masks))
            differences.append(different)
            if sum(masks[0]) == 0:
                problems.fail(f"{name}: view {v} shows nothing of the mesh")
            if different > MAX_SILHOUETTE_DIFFERENCE:
                problems.fail(f"{name}: view {v}: {different} pixels covered by one triangulation only "
                                f"(at most {MAX_SILHOUETTE_DIFFERENCE}); see {base}.view{v}.*.png")
        print(f"ok {name}: renders, {plural(triangles.group(1), 'triangle')} (assimp info: {expect['assimp']} in "
              f"triangle meshes); pixels covered by only one of Whitted's and Assimp's triangulations, per view: "
              f"{differences}")
    print(f"obj_wild: {len(files)} OBJ files: {counts['renders']} render, {counts['refused']} refused; "
          f"{len(problems.messages)} mismatches")
    problems.finish()


if __name__ == "__main__":
    main()
