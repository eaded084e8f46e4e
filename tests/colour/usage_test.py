#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Usage checked before any work (docs/colour.md): every option that cannot apply to the output
format, an unknown display or view, an unreadable OCIO config, an output that is an input file
and an output name too long for the filesystem are errors with exit 2, in the house form, and
before the scene is read: the scene given here does not parse, so a message about the scene would
mean the check came too late. Nothing is written. The time each run took is printed beside
`whitted --version`'s, for a reader; it is not asserted (a test that times itself fails on a
loaded machine: it did once, at 14 s, beside a front-door build, 2026-12-03).

Usage: usage_test.py WHITTED EXAMPLES_DIR"""
import os
import shutil
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import Failures, run as run_program  # noqa: E402  (tests/harness.py)

whitted, examples = sys.argv[1], sys.argv[2]
failures = Failures()


def run(args, cwd):
    env = dict(os.environ)
    env.pop("OCIO", None)  # the built-in config's names are expected below
    best, result = None, None
    # The best of three, so that a loaded machine (ctest -j) does not make a fast check look slow.
    for _ in range(3):
        start = time.monotonic()
        result = run_program([whitted] + args, expect=None, timeout=60, cwd=cwd, env=env)
        elapsed = time.monotonic() - start
        best = elapsed if best is None else min(best, elapsed)
    return result, best


START_UP = None  # best-of-three seconds of `whitted --version`, set below


def expect_usage_error(args, cwd, fragments, label):
    result, seconds = run(args, cwd)
    problems = []
    if result.returncode != 2:
        problems.append(f"exit {result.returncode}, not 2")
    if not result.stderr.startswith("whitted: error: "):
        problems.append("not in the 'whitted: error:' form")
    for fragment in fragments:
        if fragment not in result.stderr:
            problems.append(f"message lacks {fragment!r}")
    if problems:
        failures.fail(f"{label}: {'; '.join(problems)}\n    stderr: {result.stderr.strip()}")
    else:
        print(f"ok   {label}: exit 2 in {seconds * 1000:.0f} ms (start-up {START_UP * 1000:.0f} ms): "
              f"{result.stderr.strip()[:110]}")


with tempfile.TemporaryDirectory() as work:
    START_UP = run(["--version"], work)[1]
    bad_scene = os.path.join(work, "unparsable.yaml")
    with open(bad_scene, "w") as f:
        f.write("version: 1\ncamera: [this is not a camera\n")
    cases = [
        (["-o", "a.jpg", "--bit-depth", "16"], ["--bit-depth 16", "a.jpg", "8 bits"]),
        (["-o", "a.jpeg", "--bit-depth", "16"], ["--bit-depth 16"]),
        (["-o", "a.png", "--half"], ["--half", ".exr files only"]),
        (["-o", "a.tif", "--exr-compression", "zip"], ["--exr-compression"]),
        (["-o", "a.jpg", "--exr-compression", "none"], ["--exr-compression"]),
        (["-o", "a.exr", "--bit-depth", "16"], ["--bit-depth", "scene-linear"]),
        (["-o", "a.exr", "--view", "Raw"], ["--view", "scene-linear"]),
        (["-o", "a.exr", "--display", "sRGB"], ["--display"]),
        (["-o", "a.exr", "--ocio-config", "/etc/passwd"], ["--ocio-config"]),
        (["-o", "a.png", "--display", "foo"], ["'foo'", "displays: sRGB, Gamma 2.2, BT.1886, Display P3"]),
        (["-o", "a.png", "--display", "Display P3", "--view", "Filmic"], ["'Filmic'", "views: Standard, Raw"]),
        (["-o", "a.png", "--view", "Log"], ["'Log'", "views: Standard, Raw"]),
        (["-o", "a.tif", "--ocio-config", "/etc/passwd"], ["/etc/passwd", "cannot load the OpenColorIO config"]),
        (["-o", "a.png", "--ocio-config", os.path.join(work, "missing.ocio")], ["no such file"]),
        (["-o", "a.png", "--ocio-config", work], ["it is a directory"]),
        (["-o", "a.webp"], ["unknown image type"]),
        (["-o", "x" * 252 + ".png"], ["256 bytes long", "allows 255"]),
    ]
    for extra, fragments in cases:
        expect_usage_error(["render", bad_scene] + extra, work, fragments, " ".join(a[:40] for a in extra))

    # The output is the scene, by the same name, another name, and a link.
    scene = os.path.join(work, "s.png")
    shutil.copy(os.path.join(examples, "lecture", "01-lambertian-sphere.yaml"), scene)
    os.symlink("s.png", os.path.join(work, "link.png"))
    before = open(scene, "rb").read()
    for output in ["s.png", "./s.png", os.path.join(work, "s.png"), "link.png"]:
        expect_usage_error(["render", "s.png", "-o", output], work, ["it is the scene file"], f"-o {output} (the scene)")
    failures.require(open(scene, "rb").read() == before, "the scene file was changed")

    # The output is one of the scene's mesh files (a hard link to it: the same file).
    meshes = os.path.join(work, "meshes")
    shutil.copytree(os.path.join(examples, "meshes"), meshes)
    os.link(os.path.join(meshes, "octahedron.obj"), os.path.join(meshes, "out.png"))
    result, _ = run(["render", "meshes.yaml", "-o", "out.png"], meshes)
    failures.check(result.returncode == 2 and "it is the mesh file" in result.stderr,
                   f"output over a mesh file: exit {result.returncode}: {result.stderr.strip()}")

    # A legal 240-byte name renders (its temporary name is longer than 255 bytes uncut).
    long_name = "y" * 236 + ".png"
    result, _ = run(["render", "s.png", "-q", "-o", long_name], work)
    failures.check(result.returncode == 0 and os.path.isfile(os.path.join(work, long_name)),
                   f"a 240-byte output name renders: exit {result.returncode}: {result.stderr.strip()}")
    leftovers = [n for n in os.listdir(work) if ".whitted-" in n]
    failures.require(not leftovers, f"temporary files left: {leftovers}")
    for name in ["a.jpg", "a.jpeg", "a.png", "a.tif", "a.exr", "a.webp"]:
        failures.require(not os.path.exists(os.path.join(work, name)), f"{name} was written by a refused command")

    # `whitted colour` refuses what it cannot do, in the same way.
    expect_usage_error(["colour", "--list", "--ocio-config", "/etc/passwd"], work, ["/etc/passwd"], "colour --list bad config")
    expect_usage_error(["colour", "--ocio-config", "x.ocio"], work, ["--ocio-config goes with --list"], "colour no --list")

    # A name given as '' (an unset shell variable) is refused, never taken for "not given": before,
    # `colour --write-config ''` wrote nothing and exited 0, `check --report ''` wrote no report.
    for args in (["render", bad_scene, "--output", ""], ["render", bad_scene, "--ocio-config", ""],
                 ["render", bad_scene, "--display", ""], ["render", bad_scene, "--view", ""],
                 ["check", bad_scene, "--report", ""], ["colour", "--write-config", ""],
                 ["colour", "--list", "--ocio-config", ""]):
        expect_usage_error(args, work, [f"{args[-2]}: an empty value", f"(whitted {args[0]} --help)"],
                           " ".join(args[:1] + args[2:-1]) + " ''")
    # CLI11's own refusals are in the same form, naming the command's help.
    expect_usage_error(["render", os.path.join(work, "missing.yaml")], work,
                       ["File does not exist", "(whitted render --help)"], "render a missing scene")
    expect_usage_error(["render", "--threads", "x", bad_scene], work, ["--threads", "(whitted render --help)"],
                       "render --threads x")

failures.finish()
