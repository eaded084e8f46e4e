#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The bench's own programs on input they were not written for: usage on --help (exit 0), a
message naming the file (and the line, for a .rays file) with exit 1 or 2 for a file that is
missing or not theirs, never a signal; a YAML scene the fast scanner leaves to libyaml is
timed by libyaml alone, not an abort.

usage: bench_tools_test.py WHITTED_EMBREE_RATE WHITTED_PARSE_BENCH WORK_DIR
"""
import pathlib
import subprocess
import sys


def run(args):
    done = subprocess.run(args, capture_output=True, text=True, timeout=60)
    if done.returncode < 0:
        sys.exit(f"FAIL: {args} ended by signal {-done.returncode}: {done.stderr[-400:]}")
    return done


def expect(done, code, needle, what):
    text = done.stdout + done.stderr
    if done.returncode != code or needle not in text:
        sys.exit(f"FAIL: {what}: exit {done.returncode} (want {code}), output lacks {needle!r}:\n{text[-600:]}")
    print(f"ok: {what}")


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    rate, parse, work = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    work.mkdir(parents=True, exist_ok=True)
    missing = str(work / "no-such-file")
    not_rays = work / "not.rays"
    not_rays.write_text("image 64 48\ncamera 0 0 5 0 0 0 0 1 0 60\nteapot 1 2 3\n")
    short = work / "short.rays"
    short.write_text("image 64 48\ncamera 0 0 5 0 0 0 0 1 0\n")
    no_image = work / "no-image.rays"
    no_image.write_text("camera 0 0 5 0 0 0 0 1 0 60\nlight 1 1 1\n")
    good = work / "one-sphere.rays"
    good.write_text("image 16 12\ncamera 0 0 5 0 0 0 0 1 0 60\nmax_depth 2\nlight 2 2 4\nsphere 0 0 0 1 0\n")

    expect(run([rate, "--help"]), 0, "usage:", "embree_rate --help")
    expect(run([rate]), 2, "usage:", "embree_rate without a file")
    expect(run([rate, missing]), 1, f"cannot read {missing}", "embree_rate, a missing file")
    expect(run([rate, str(not_rays)]), 1, f"{not_rays}:3: 'teapot' is not an item", "embree_rate, an unknown item")
    expect(run([rate, str(short)]), 1, f"{short}:2: a number is missing", "embree_rate, a camera without fov")
    expect(run([rate, str(no_image)]), 1, "no 'image WIDTH HEIGHT' line", "embree_rate, no image line")
    done = run([rate, str(good), "--threads", "1"])
    expect(done, 0, "rays: camera 192 ", "embree_rate, a one-sphere scene (16 x 12 camera rays)")

    # YAML of a form the fast scanner gives to libyaml (an anchor and its alias).
    aliased = work / "aliased.yaml"
    aliased.write_text(
        "version: 1\n"
        "image: {width: 8, height: 6}\n"
        "camera: {eye: [0, 0, 5], look_at: [0, 0, 0], fov: 60}\n"
        "materials:\n  red: &red {kd: [0.8, 0.1, 0.1]}\n  also_red: *red\n"
        "lights: [{type: point, position: [2, 2, 4], intensity: 1}]\n"
        "objects: [{type: sphere, center: [0, 0, 0], radius: 1, material: also_red}]\n")
    expect(run([parse, "--help"]), 0, "usage:", "parse_bench --help")
    expect(run([parse]), 2, "usage:", "parse_bench without a file")
    expect(run([parse, missing]), 1, "scene file not found", "parse_bench, a missing file")
    expect(run([parse, "/etc/passwd" if pathlib.Path("/etc/passwd").exists() else str(not_rays)]), 1,
           ":1:1:", "parse_bench, a file that is not a scene")
    expect(run([parse, "--runs", "1", str(aliased)]), 0, "(left to libyaml)", "parse_bench, YAML left to libyaml")


if __name__ == "__main__":
    main()
