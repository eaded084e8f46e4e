#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Tests of the Cornell CS4620 course's XML scenes (docs/course-format.md).

  course_test.py corpus WHITTED CORPUS_DIR SCENE WORK     render CORPUS_DIR/SCENE.xml, encode it
      as the course did (clamp(c^(1/2.2)), (int)(255c + 0.5)) and compare with the course's own
      image SCENE.xml.soln.png: at least 99.9 % of pixels within 1/255 on every channel. Skipped
      (exit 77) when CORPUS_DIR is absent. Also checks that the scene converted to Whitted's YAML
      renders to the same floats.
  course_test.py course_image WHITTED DIR SCENE WORK      the same comparison for our own scenes
      DIR/SCENE.xml against DIR/SCENE.xml.course.png, the image the course's ray tracer made of
      them (tests/course/glazed/README.md says how). Never skipped.
  course_test.py closed WHITTED SCENES_DIR SCENE WORK      render one of tests/course/scenes and
      compare every pixel with the closed form computed here.
  course_test.py same WHITTED SCENES_DIR SCENE WORK        render X.xml and (convert X.xml ->
      X.yaml) and require the same floats, bit for bit.
  course_test.py pov_refuses WHITTED SCENES_DIR FILE WORK  `whitted convert FILE x.pov` refuses what
      POV-Ray cannot express, naming the feature at FILE:LINE:COL.

The linear EXR is read back here (32-bit floats, exact)."""

import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import SKIP, fresh_folder, read_exr, run  # noqa: E402  (tests/harness.py)


def render_floats(whitted, scene, work, name):
    exr = os.path.join(work, name + ".exr")
    run([whitted, "render", scene, "-o", exr, "-q"])  # 32-bit floats, no compression (the defaults)
    return read_exr(exr)


def course_encode(c):
    """The course's 8-bit encoding: clamp(c^(1/2.2), 0, 1), then (int)(255c + 0.5)."""
    v = max(c, 0.0) ** (1 / 2.2)
    v = min(max(v, 0.0), 1.0)
    return int(255 * v + 0.5)


def corpus(whitted, corpus_dir, scene, work):
    if not os.path.isdir(corpus_dir):
        print(f"SKIPPED: the course corpus {corpus_dir} is not present")
        return SKIP
    xml = os.path.join(corpus_dir, scene + ".xml")
    return compare_with_course(whitted, xml, xml + ".soln.png", scene, work)


def course_image(whitted, directory, scene, work):
    xml = os.path.join(directory, scene + ".xml")
    return compare_with_course(whitted, xml, xml + ".course.png", scene, work)


def compare_with_course(whitted, xml, course_png, scene, work):
    """Whitted's render of xml, encoded as the course encodes, against the course's 8-bit image:
    at least 99.9 % of pixels within 1/255 on every channel; and the scene converted to YAML
    renders the same floats."""
    from PIL import Image  # python3-pil

    width, height, rows = render_floats(whitted, xml, work, scene)
    reference = Image.open(course_png).convert("RGB")
    if reference.size != (width, height):
        sys.exit(f"FAIL {scene}: Whitted's image is {width}x{height}, the course's {reference.size}")
    ref = reference.load()
    within, exact, worst = 0, 0, 0
    for y in range(height):
        for x in range(width):
            error = max(abs(course_encode(rows[y][x][c]) - ref[x, y][c]) for c in range(3))
            within += error <= 1
            exact += error == 0
            worst = max(worst, error)
    share = within / (width * height)
    print(f"{scene}: {100 * share:.3f} % of {width}x{height} pixels within 1/255 ({width * height - exact} "
          f"differ at all), max error {worst}/255")
    # The same scene through Whitted's own format: the same floats.
    yaml_path = os.path.join(work, scene + ".yaml")
    run([whitted, "convert", xml, yaml_path])
    if render_floats(whitted, yaml_path, work, scene + "-yaml")[2] != rows:
        sys.exit(f"FAIL {scene}: the converted YAML renders differently from the XML")
    print(f"{scene}: converted to YAML, renders the same floats")
    if share < 0.999:
        sys.exit(f"FAIL {scene}: {100 * share:.3f} % within 1/255, below 99.9 %")
    return 0


# ---- closed forms for tests/course/scenes (orthographic camera at z = 10 looking down -z,
# a 4 x 4 world-unit window, a point light at `light`)


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


KD = (0.5, 0.6, 0.7)


def lit_rectangle(x, y, inside, normal=(0.0, 0.0, 1.0), z=1.0, light=(0.0, 0.0, 5.0), kd=KD):
    """Lambertian rectangle in the plane z (front face), seen at (x, y)."""
    if not inside(x, y):
        return (0.0, 0.0, 0.0)
    to_light = normalize([light[0] - x, light[1] - y, light[2] - z])
    cosine = max(0.0, dot(normal, to_light))
    return tuple(k * cosine for k in kd)


def glazed_sphere(x, y):
    r2 = x * x + y * y
    if r2 >= 1:
        return (0.0, 0.0, 0.0)
    z = math.sqrt(1 - r2)
    n = (x, y, z)
    r0 = ((1.5 - 1) / (1.5 + 1)) ** 2
    fresnel = r0 + (1 - r0) * (1 - z) ** 5  # n·v = z
    to_light = normalize([-x, -y, 10 - z])
    return tuple((1 - fresnel) * k * max(0.0, dot(n, to_light)) for k in (0.4, 0.5, 0.8))


def square(x, y):
    return -1 < x < 1 and -1 < y < 1


CLOSED_FORMS = {
    "ortho_box": lambda x, y: lit_rectangle(x, y, square),
    "mesh_flat": lambda x, y: lit_rectangle(x, y, square),
    "mesh_smooth": lambda x, y: lit_rectangle(x, y, square, normal=(0.0, 0.6, 0.8)),
    "back_face": lambda x, y: (0.0, 0.0, 0.0),
    "group": lambda x, y: lit_rectangle(x, y, lambda a, b: 0.75 < a < 1.25 and -1 < b < 1),
    "group_rotate": lambda x, y: lit_rectangle(x, y, lambda a, b: -0.1 < a < 0.1 and -1 < b < 1, z=0.25),
    "samples": lambda x, y: lit_rectangle(x, y, lambda a, b: -0.95 < a < 1.05 and -0.95 < b < 1.05),
    "glazed": glazed_sphere,
}
GRID = {"samples": 2}


def closed(whitted, scenes_dir, scene, work):
    width, height, rows = render_floats(whitted, os.path.join(scenes_dir, scene + ".xml"), work, scene)
    form, n = CLOSED_FORMS[scene], GRID.get(scene, 1)
    worst, lit = 0.0, 0
    for j in range(height):
        for i in range(width):
            expected = [0.0, 0.0, 0.0]
            for b in range(n):
                for a in range(n):
                    x0 = (i + (a + 0.5) / n) / width - 0.5
                    y0 = 0.5 - (j + (b + 0.5) / n) / height
                    value = form(4 * x0, 4 * y0)
                    expected = [e + v / (n * n) for e, v in zip(expected, value)]
            got = rows[j][i]
            lit += any(g > 0 for g in got)
            worst = max(worst, max(abs(g - e) for g, e in zip(got, expected)))
            if max(abs(g - e) for g, e in zip(got, expected)) > 2e-6:
                sys.exit(f"FAIL {scene}: pixel ({i}, {j}) is {got}, the closed form {expected}")
    if scene != "back_face" and lit < width * height // 50:
        sys.exit(f"FAIL {scene}: only {lit} pixels lit; the scene is not what the test assumes")
    print(f"{scene}: {width}x{height} pixels match the closed form (max difference {worst:.2e}); {lit} lit")
    return 0


def same(whitted, scenes_dir, scene, work):
    xml = os.path.join(scenes_dir, scene + (".yaml" if os.path.exists(os.path.join(scenes_dir, scene + ".yaml"))
                                            else ".xml"))
    yaml_path = os.path.join(work, scene + "-converted.yaml")
    run([whitted, "convert", xml, yaml_path])
    a = render_floats(whitted, xml, work, scene)
    b = render_floats(whitted, yaml_path, work, scene + "-yaml")
    if a != b:
        sys.exit(f"FAIL {scene}: render({os.path.basename(xml)}) and render(convert -> {scene}.yaml) differ")
    lit = sum(any(c > 0 for c in px) for row in a[2] for px in row)
    if lit == 0:
        sys.exit(f"FAIL {scene}: the image is black; the comparison proves nothing")
    print(f"{scene}: the scene and its YAML conversion render the same {a[0]}x{a[1]} floats ({lit} pixels lit)")
    return 0


def pov_refuses(whitted, scenes_dir, scene, work):
    """`whitted convert SCENE x.pov` must refuse, exit 2, naming the feature and FILE:LINE:COL."""
    expected = {
        "glazed.xml": "glazed.xml:4:1: cannot convert to POV-Ray: render.convention: course",
        "fresnel_pov.yaml": "fresnel_pov.yaml:8:25: cannot convert to POV-Ray: fresnel_ior",
    }[scene]
    pov = os.path.join(work, "x.pov")
    result = subprocess.run([whitted, "convert", os.path.join(scenes_dir, scene), pov], capture_output=True,
                            text=True, timeout=60)
    if result.returncode != 2 or expected not in result.stderr:
        sys.exit(f"FAIL {scene}: exit {result.returncode}, stderr {result.stderr.strip()!r}; expected exit 2 and "
                 f"'{expected}'")
    if os.listdir(work):
        sys.exit(f"FAIL {scene}: files left behind: {os.listdir(work)}")
    print(f"{scene}: refused: {result.stderr.strip()}")
    return 0


def main():
    mode, whitted, directory, scene, work = sys.argv[1:6]
    fresh_folder(work)
    modes = {"corpus": corpus, "course_image": course_image, "closed": closed, "same": same,
             "pov_refuses": pov_refuses}
    return modes[mode](whitted, directory, scene, work)


if __name__ == "__main__":
    sys.exit(main())
