#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""`whitted render`'s overrides (docs/cli.md): --width/--height/--samples/--max-depth/
--intersection replace the scene's settings as if the file said them, --crop renders a window
whose pixels are the whole render's bit for bit, `-` reads the scene from standard input, and
every mistake is a usage error (exit 2) before any work, leaving an existing output as it was.
Also: the nearest-name suggestions, `explain --summary` and `--intersection`, and the warning for pixels past the
largest float.

Each expectation is derived from the rule, not from a render of this code: the size from the
aspect-ratio rule, the crop from the whole render's own pixels, stdin from the file's render,
an override from the same scene with the value written into the file.

Usage: overrides_test.py WHITTED SOURCE_DIR WORK_DIR
"""
import os
import sys

import numpy as np
import OpenImageIO as oiio
import yaml

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, fresh_folder, read_pixels  # noqa: E402  (tests/harness.py)

whitted, source, work = sys.argv[1:4]
fresh_folder(work)
failures = Failures()


def run(args, expect=0, stdin=None):
    """whitted ARGS in the work folder, its output as bytes."""
    return failures.run([whitted, *args], expect, cwd=work, input=stdin, text=False)


def read_exr(name):
    return read_pixels(os.path.join(work, name))


check = failures.require


# A small lecture scene with a mirror (depth matters), rendered at an odd size.
scene_path = os.path.join(source, "examples", "lecture", "09-glazed-floor.yaml")
with open(scene_path) as f:
    scene = yaml.safe_load(f)
scene["image"].update({"width": 97, "height": 61})
base = os.path.join(work, "base.yaml")
with open(base, "w") as f:
    yaml.safe_dump(scene, f)


def written(name, **changes):
    """The base scene with settings written into the file, as the overrides should act."""
    variant = yaml.safe_load(yaml.safe_dump(scene))
    for key, value in changes.items():
        section, field = key.split(".")
        variant.setdefault(section, {})[field] = value
    path = os.path.join(work, name)
    with open(path, "w") as f:
        yaml.safe_dump(variant, f)
    return path


# --- overrides act as the file's own settings ---------------------------------------------------
cases = [
    (["--width", "40", "--height", "30"], {"image.width": 40, "image.height": 30}),
    # One side alone keeps the aspect ratio: 97x61 at width 50 -> round(50*61/97) = round(31.44) = 31.
    (["--width", "50"], {"image.width": 50, "image.height": 31}),
    # Height 20 -> round(20*97/61) = round(31.80) = 32.
    (["--height", "20"], {"image.width": 32, "image.height": 20}),
    (["--samples", "2"], {"image.samples": 2}),
    (["--max-depth", "1"], {"render.max_depth": 1}),
    (["--intersection", "povray"], {"render.intersection": "povray"}),
]
for i, (args, changes) in enumerate(cases):
    run(["render", base, "-q", "-o", f"over{i}.exr", *args])
    run(["render", written(f"written{i}.yaml", **changes), "-q", "-o", f"written{i}.exr"])
    a, b = read_exr(f"over{i}.exr"), read_exr(f"written{i}.exr")
    check(a.shape == b.shape and np.array_equal(a, b),
          f"{' '.join(args)}: not the image of the scene that says {changes} ({a.shape} vs {b.shape})")
# The samples and depth overrides change the image, so their comparisons above could fail; the
# intersection rule (the same image on this scene) is named in the file's metadata.
run(["render", base, "-q", "-o", "file.exr"])
for i in (3, 4):
    check(not np.array_equal(read_exr(f"over{i}.exr"), read_exr("file.exr")),
          f"{' '.join(cases[i][0])}: the same image as without it")
settings = oiio.ImageInput.open(os.path.join(work, "over5.exr")).spec().getattribute("whitted:settings")
check("intersection povray" in str(settings), f"--intersection povray: metadata says {settings!r}")

# --- the crop window is the whole render's pixels --------------------------------------------------
run(["render", base, "-q", "-o", "whole.exr", "--samples", "2"])
whole = read_exr("whole.exr")
for x, y, w, h in [(0, 0, 97, 61), (0, 0, 1, 1), (96, 60, 1, 1), (31, 17, 40, 33), (5, 40, 92, 21)]:
    name = f"crop_{x}_{y}_{w}_{h}.exr"
    run(["render", base, "-q", "-o", name, "--samples", "2", "--crop", f"{x},{y},{w},{h}"])
    part = read_exr(name)
    check(part.shape == (h, w, 3), f"--crop {x},{y},{w},{h}: image is {part.shape}")
    check(part.shape == (h, w, 3) and np.array_equal(part, whole[y:y + h, x:x + w]),
          f"--crop {x},{y},{w},{h}: pixels differ from the whole render's")
# Cropped layers too.
run(["render", base, "-q", "-o", "whole_layers.exr", "--layers", "diffuse,N"])
run(["render", base, "-q", "-o", "crop_layers.exr", "--layers", "diffuse,N", "--crop", "10,11,12,13"])
check(np.array_equal(read_exr("crop_layers.exr"), read_exr("whole_layers.exr")[11:24, 10:22]),
      "--crop with --layers: the layers differ from the whole render's")

# --- the scene on standard input -------------------------------------------------------------------
with open(base, "rb") as f:
    text = f.read()
run(["render", "-", "-q", "-o", "stdin.exr"], stdin=text)
check(np.array_equal(read_exr("stdin.exr"), read_exr("file.exr")), "render - : not the file's image")
# NFF and course XML on standard input are told by their first line.
nff = b"v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 16 12\nb 0 0 0\n" \
      b"l 3 3 3\nf 1 0 0 0.8 0 1 0 1\ns 0 0 0 1\n"
with open(os.path.join(work, "ball.nff"), "wb") as f:
    f.write(nff)
run(["render", "-", "-q", "-o", "stdin_nff.exr"], stdin=nff)
run(["render", "ball.nff", "-q", "-o", "file_nff.exr"])
check(np.array_equal(read_exr("stdin_nff.exr"), read_exr("file_nff.exr")), "render - (NFF): not the file's image")
# A bad scene on standard input is named <stdin> with its line and column.
lines = text.split(b"\n")
width_line = next(i for i, line in enumerate(lines) if b"width: 97" in line)
lines[width_line] = lines[width_line].replace(b"97", b"x")
bad = run(["render", "-", "-q", "-o", "bad_stdin.exr"], expect=2, stdin=b"\n".join(lines))
check(f"<stdin>:{width_line + 1}:".encode() in bad.stderr, f"render - (bad): not at its line: {bad.stderr!r}")

# --- mistakes are usage errors before any work, and the output stays -------------------------------
with open(os.path.join(work, "keep.exr"), "wb") as f:
    f.write(b"previous image")
usage = [
    (["--crop", "1,2,3"], "X,Y,WIDTH,HEIGHT"),
    (["--crop", "1,2,3,4,5"], "X,Y,WIDTH,HEIGHT"),
    (["--crop", "a,b,c,d"], "X,Y,WIDTH,HEIGHT"),
    (["--crop", "0,0,0,5"], "at least 1"),
    (["--crop", "-1,0,5,5"], "at least 0"),
    (["--crop", "90,0,8,5"], "does not lie inside the 97x61 image"),
    (["--crop", "0,60,1,2"], "does not lie inside the 97x61 image"),
    (["--crop", "0,0,10,10", "--width", "5"], "does not lie inside the 5x3 image"),
    (["--width", "0"], "--width"),
    (["--width", "65537"], "--width"),
    (["--height", "-3"], "--height"),
    (["--samples", "17"], "--samples"),
    (["--max-depth", "0"], "--max-depth"),
    (["--max-depth", "257"], "--max-depth"),
    (["--intersection", "fast"], "--intersection"),
    (["--width", "65536", "--height", "65536"], "the limit is 65536 per side and 268435456 pixels"),
]
for args, fragment in usage:
    result = run(["render", base, "-q", "-o", "keep.exr", *args], expect=2)
    check(fragment.encode() in result.stderr, f"{' '.join(args)}: message lacks '{fragment}': {result.stderr!r}")
with open(os.path.join(work, "keep.exr"), "rb") as f:
    check(f.read() == b"previous image", "a refused render changed its output")
# A huge width alone: the height follows within the limit check, not an overflow.
result = run(["render", base, "-q", "-o", "keep.exr", "--width", "65536"], expect=2)
check(f"65536x{int(65536 * 61 / 97 + 0.5)}".encode() in result.stderr, f"--width 65536: {result.stderr!r}")

# check's thread count is checked as render's is (10**9 crashed in TBB's arena set-up).
result = run(["check", base, "-q", "-t", "1000000000"], expect=2)
check(b"--threads" in result.stderr, f"check -t 10**9: {result.stderr!r}")

import re

# --- suggestions ------------------------------------------------------------------------------------
result = run(["rendr", base], expect=2)
check(b"did you mean 'render'" in result.stderr, f"rendr: {result.stderr!r}")
# Every name --help lists is a command, aliases too ("colour, color").
for line in run(["--help"]).stdout.decode().split("Subcommands:\n", 1)[1].splitlines():
    if not line.startswith("  "):
        break
    for name in re.split(r"  +", line.strip())[0].split(", "):
        run([name, "--help"], expect=0)
result = run(["render", base, "-o", "x.exr", "--layers", "difuse"], expect=2)
check(b"did you mean 'diffuse'" in result.stderr, f"--layers difuse: {result.stderr!r}")
result = run(["\x1b]0;title\x07"], expect=2)
check(b"\x1b" not in result.stderr, f"an escape sequence reached the terminal: {result.stderr!r}")

# --- explain --summary --------------------------------------------------------------------------------
# A dozen lines whose six colour terms add up to the pixel, and whose float pixel is the EXR's.
import re
result = run(["explain", base, "--pixel", "48,50", "--summary"])
lines = result.stdout.decode().splitlines()
check(len(lines) <= 16, f"explain --summary printed {len(lines)} lines")
numbers = r"\(([-+0-9.e]+), ([-+0-9.e]+), ([-+0-9.e]+)\)"
terms = {}
for line in lines:
    match = re.match(r"  (\w+) +" + numbers, line)
    if match:
        terms[match.group(1)] = np.array([float(match.group(k)) for k in (2, 3, 4)])
colour_terms = ["ambient", "diffuse", "specular", "mirror", "transmission", "background"]
check(all(name in terms for name in colour_terms + ["pixel"]), f"explain --summary lacks a term: {lines}")
if all(name in terms for name in colour_terms + ["pixel"]):
    total = sum(terms[name] for name in colour_terms)
    check(np.allclose(total, terms["pixel"], rtol=1e-12, atol=1e-15), f"terms {total} do not add to {terms['pixel']}")
exr_match = re.search(r"the EXR's R, G, B: " + numbers, result.stdout.decode())
check(exr_match is not None and np.array_equal(
    np.array([float(exr_match.group(k)) for k in (1, 2, 3)], np.float32), read_exr("file.exr")[50, 48]),
    f"explain --summary: the EXR value is not the render's: {exr_match and exr_match.group(0)}")
run(["explain", base, "--pixel", "48,50", "--summary", "--json"], expect=2)

# --- explain --intersection -----------------------------------------------------------------------
# As render's: the scene explained as if the file said render.intersection. The same lines,
# the file's name aside; under POV-Ray's rule the camera ray looks from t = 1e-4 to 1e7
# (docs/pov-model.md §3), under the exact one from 0.
povray_file = written("explain_povray.yaml", **{"render.intersection": "povray"})
by_option = run(["explain", base, "--pixel", "48,50", "--intersection", "povray"]).stdout.decode()
by_file = run(["explain", povray_file, "--pixel", "48,50"]).stdout.decode()
by_option = by_option.replace(os.path.basename(base), "SCENE").splitlines()
by_file = by_file.replace(os.path.basename(povray_file), "SCENE").splitlines()
check(by_option == by_file and len(by_option) > 5,
      f"explain --intersection povray is not the explanation of the file that says it: {by_option[:4]} vs {by_file[:4]}")
check("t in (0.0001, 10000000)" in "\n".join(by_option), f"explain --intersection povray: camera ray {by_option[3:5]}")
exact = run(["explain", base, "--pixel", "48,50", "--intersection", "exact"]).stdout.decode()
check("camera ray" in exact and "t in (0, " in exact, f"explain --intersection exact: {exact[:400]}")
result = run(["explain", base, "--pixel", "48,50", "--intersection", "fast"], expect=2)
check(b"--intersection" in result.stderr, f"explain --intersection fast: {result.stderr!r}")

# Names reach the terminal escaped, and --json is JSON whatever bytes a name holds (an MTL
# material name may be Latin-1).
with open(os.path.join(work, "escape.yaml"), "w") as f:
    f.write("version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: 8}\n"
            "lights: [{type: point, position: [0, 0, 5]}]\nmaterials:\n  \"\\e]0;title\\a\": {kd: 1}\n"
            "objects:\n  - {type: sphere, center: [0, 0, 0], radius: 1, material: \"\\e]0;title\\a\"}\n")
for extra in ([], ["--summary"]):
    result = run(["explain", "escape.yaml", "--pixel", "4,4", *extra])
    check(b"\\x1b]0;title\\x07" in result.stdout and b"\x1b" not in result.stdout and b"\x07" not in result.stdout,
          f"explain {extra}: a name's control characters reached the terminal: {result.stdout[:300]!r}")
with open(os.path.join(work, "latin1.mtl"), "wb") as f:
    f.write(b"newmtl Gr\xfcn\nKd 1 1 1\n")
with open(os.path.join(work, "latin1.obj"), "wb") as f:
    f.write(b"mtllib latin1.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nusemtl Gr\xfcn\nf 1 2 3\n")
with open(os.path.join(work, "latin1.yaml"), "w") as f:
    f.write("version: 1\ncamera: {eye: [0, 0, 5], look_at: [0, 0, 0]}\nimage: {width: 8, height: 8}\n"
            "lights: [{type: point, position: [0, 0, 5]}]\nobjects:\n  - {type: mesh, file: latin1.obj}\n")
result = run(["explain", "latin1.yaml", "--pixel", "4,4", "--json"])
try:
    import json
    explained = json.loads(result.stdout)
    check("Gr\ufffdn" in json.dumps(explained, ensure_ascii=False),
          "explain --json: the Latin-1 name is not written as U+FFFD")
except ValueError as e:
    failures.fail(f"explain --json with a Latin-1 material name is not JSON: {e}")

# --- radiance past the largest float -----------------------------------------------------------------
# A colour of 1e258 (a fuzzer's find): the pixels are +inf in the EXR, and the render says so.
overflow = os.path.join(source, "tests", "fuzz", "regressions", "fuzz_render", "colour_1e258_overflows_the_pixel.nff")
result = run(["render", overflow, "-q", "-o", "overflow.exr"])
image = read_exr("overflow.exr")
count = int(np.isinf(image).sum())
check(count > 0 and f"warning: {count} pixel value(s) exceed the largest float".encode() in result.stderr,
      f"overflow: {count} inf values, stderr {result.stderr!r}")
result = run(["render", base, "-q", "-o", "finite.exr"])
check(b"warning" not in result.stderr, f"a finite render warned: {result.stderr!r}")

# --- past a file size limit (ulimit -f) -------------------------------------------------------------
# The write fails with a message (exit 1) instead of SIGXFSZ killing the process; the previous
# output stays and no temporary file is left.
import resource
with open(os.path.join(work, "limited.exr"), "wb") as f:
    f.write(b"previous image")
before = set(os.listdir(work))
limited = failures.run([whitted, "render", base, "-q", "-o", "limited.exr"], expect=1, cwd=work, text=False,
                       preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096)))
check(limited.returncode == 1 and b"File too large" in limited.stderr,
      f"ulimit -f: exit {limited.returncode}, {limited.stderr!r}")
with open(os.path.join(work, "limited.exr"), "rb") as f:
    check(f.read() == b"previous image", "ulimit -f: the previous output changed")
check(set(os.listdir(work)) == before, f"ulimit -f: files left: {set(os.listdir(work)) - before}")

failures.finish("PASS: overrides, crop, standard input, usage errors, suggestions")
